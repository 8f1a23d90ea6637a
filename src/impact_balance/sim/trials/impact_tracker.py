"""The impact of a balance trial, measured as the simulation runs (:class:`ImpactTracker`).

Called once per MuJoCo step, before the step, with the contact forces that acted during the
previous step and the current velocities (MuJoCo's ``mj_step`` computes the forces of a step
from the state it starts from; they act until the next state). The impact begins in the first
step with a force at the impact point; its window ends at the separation (no force at the
impact point) or ``max_duration`` after it began if the point stays on the surface. Over the
window the tracker integrates the impulse at the impact point and at every sustained contact
(the sustained contacts' forces before the impact subtracted: their part of the impact), and
keeps the planar CoM velocity at both ends.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from impact_balance.sim.trials.result import ImpactMeasurement

__all__ = ["MAX_IMPACT_DURATION", "ImpactTracker"]

#: Longest impact window, s: a limb may stay on the surface after the impact.
MAX_IMPACT_DURATION = 0.02


@dataclass
class ImpactTracker:
    """Online measurement of the impact (see the module docstring).

    Attributes:
        normal: Unit surface normal, from the surface into the robot (world).
        dt: Simulation step (s).
        max_duration: Longest window (s).
    """

    normal: np.ndarray
    dt: float
    max_duration: float = MAX_IMPACT_DURATION
    start: float | None = field(default=None, init=False)
    end: float | None = field(default=None, init=False)
    _prev: tuple[Any, ...] | None = field(default=None, init=False)
    _baseline: np.ndarray | None = field(default=None, init=False)
    _impulse: np.ndarray = field(default_factory=lambda: np.zeros(3), init=False)
    _sustained: np.ndarray | None = field(default=None, init=False)
    _before: tuple[Any, ...] | None = field(default=None, init=False)
    _after: np.ndarray | None = field(default=None, init=False)

    @property
    def touched(self) -> bool:
        """Whether the impact point has touched the surface."""
        return self.start is not None

    @property
    def done(self) -> bool:
        """Whether the impact's window has ended."""
        return self.end is not None

    def update(
        self,
        t: float,
        impact_force: np.ndarray,
        sustained_forces: np.ndarray,
        point_velocity: np.ndarray,
        com_velocity: np.ndarray,
    ) -> None:
        """One step: the forces of the last step, the impact point's and the CoM's velocity now.

        One step: forces that acted over the last step (N, world, on the robot), the impact point's
        velocity and the CoM velocity now (m/s, world).
        """
        touching = bool(np.any(impact_force != 0.0))
        if self.start is None and touching and self._prev is not None:
            t_prev, v_prev, c_prev, f_prev = self._prev
            self.start = t_prev
            self._before = (
                float(-self.normal @ v_prev),
                np.asarray(c_prev[:2], dtype=float).copy(),
            )
            self._baseline = f_prev.copy()
            self._sustained = np.zeros_like(sustained_forces)
        if self.start is not None and self.end is None:
            if touching and t - self.start <= self.max_duration + 1e-12:
                self._impulse += impact_force * self.dt
                self._sustained += (sustained_forces - self._baseline) * self.dt
            else:
                self.end = float(t)
                self._after = np.asarray(com_velocity[:2], dtype=float).copy()
        self._prev = (
            float(t),
            np.asarray(point_velocity, dtype=float).copy(),
            np.asarray(com_velocity, dtype=float).copy(),
            np.asarray(sustained_forces, dtype=float).copy(),
        )

    def measurement(
        self, t: float, com_velocity: np.ndarray, hold: dict[str, Any] | None = None
    ) -> ImpactMeasurement | None:
        """The impact measured so far (None before the contact).

        An unfinished window ends at ``t``.
        """
        if self.start is None:
            return None
        end = self.end if self.end is not None else float(t)
        after = (
            self._after if self._after is not None else np.asarray(com_velocity[:2], dtype=float)
        )
        assert self._before is not None and self._impulse is not None
        assert self._sustained is not None  # set at the contact
        approach, before = self._before
        return ImpactMeasurement(
            self.start,
            approach,
            (self.start, end),
            self._impulse.copy(),
            self._sustained.copy(),
            before,
            after,
            hold,
        )
