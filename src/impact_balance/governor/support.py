"""The governor's optional second impact model: the robot standing on its supports.

The paper's impact model lets the composite robot float through the impact (the post-impact
CoM velocities form a set, one vertex per friction-cone edge and restitution bound). On some
stances the supports change the jump: G1's feet keep it from turning about its CoM, so its
CoM velocity jump is larger than any vertex of the floating set (docs/validation.md, "A
contact-aware impact model"). :class:`ContactAwareLimit` adds, to the criterion's post-impact
set, the jump of :func:`impact_balance.contact_impact.contact_impact` (every support corner a
unilateral, frictional, plastic point contact; no preload) at both ends of the restitution
range: the governor then answers for the union of the two models' post-impact CoM velocities,
i.e. the smaller of the two maximum approach speeds (``Governor(..., contact_aware=True)``).

Cost. The contact-aware jump is a fixed point of small QPs (2 to 40 ms per posture, warm
started from the previous posture's answer); it changes slowly with the posture, so it is
recomputed on the first posture and then every ``every``-th posture evaluation (default 5: every
10 ms at 500 Hz) and, in between, the last jump rates are used with the current posture's area
and CoM velocity. The jump is linear in the approach speed (no preload), so one solve per
restitution bound at 1 m/s gives the rates.

Caveat: the frictional impact LCP may have several solutions; the warm start continues the
branch of the first posture (on the ramp near the wall, the lateral jump of that branch is
+0.12 per m/s where a cold start finds +0.043, the simulated one; the cap differs by up to
2.5 %; docs/contact_aware_governor.md).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..contact_impact import contact_impact
from ..criteria import VelocityLimit, first_exit, speed_interval
from ..exceptions import GovernorError
from ..impact import ImpactSpec
from ..polygon import Polygon
from ..stance import Stance

__all__ = ["ContactAwareLimit", "ContactAwareAnswer", "contact_aware_rates"]


def contact_aware_rates(stance: Stance, spec: ImpactSpec, warm: list[np.ndarray] | None = None
                        ) -> tuple[np.ndarray, list[np.ndarray], bool]:
    """The contact-aware CoM velocity jump per m/s of approach speed, world xy, at the lower and
    the upper restitution bound: ``(rates (2, 2), body velocity changes (for a warm start),
    converged)``."""
    rates, states, converged = [], [], True
    for k, c_r in enumerate(spec.restitution):
        guess = None if warm is None else warm[k]
        r = contact_impact(stance, spec, 1.0, restitution=float(c_r), initial_dxi=guess)
        rates.append(r.com_velocity_jump.copy())
        states.append(np.concatenate([r.com_velocity_jump_3d, r.angular_velocity_jump]))
        converged &= r.converged
    return np.array(rates), states, converged


@dataclass(frozen=True)
class ContactAwareAnswer:
    """The contact-aware model's part of one tick's answer.

    Attributes:
        limit: Largest approach speed keeping both contact-aware post-impact CoM velocities in
            the area (m/s), as :class:`~impact_balance.criteria.VelocityLimit` (vertex 0: the
            lower restitution bound, 1: the upper).
        interval: The approach speeds ``(lo, hi)`` that keep them in, or None.
        rates: (2, 2) the jumps per m/s used (world xy).
        age: Posture evaluations since the rates were computed (0: this posture's).
        converged: Whether the fixed point was reached when they were computed.
    """

    limit: VelocityLimit
    interval: tuple[float, float] | None
    rates: np.ndarray
    age: int
    converged: bool


class ContactAwareLimit:
    """The contact-aware jump's speed limit for a governor (module docstring); not thread-safe
    (its governor calls it under its lock).

    Args:
        spec: The scenario's impact (composite inertia model).
        every: Recompute the jump rates every this many posture evaluations (>= 1).
    """

    def __init__(self, spec: ImpactSpec, every: int = 5):
        if spec.inertia != "composite":
            raise GovernorError("contact_aware", spec.inertia, "the contact-aware model is the composite one")
        if not (isinstance(every, (int, np.integer)) and every >= 1):
            raise GovernorError("contact_aware_every", every, "must be an integer >= 1")
        self.spec = spec
        self.every = int(every)
        self._rates: np.ndarray | None = None
        self._warm: list[np.ndarray] | None = None
        self._converged = True
        self._age = 0
        self._count = 0

    def new_posture(self, stance_of: Callable[[], Stance]) -> None:
        """A posture was evaluated; ``stance_of()`` builds its :class:`Stance` (called only when
        the rates are due)."""
        if self._rates is None or self._count % self.every == 0:
            self._rates, self._warm, self._converged = contact_aware_rates(stance_of(), self.spec, self._warm)
            self._age = 0
        else:
            self._age += 1
        self._count += 1

    def answer(self, area: Polygon, com_velocity: np.ndarray) -> ContactAwareAnswer:
        """The limit and interval (m/s of approach speed) for the CoM velocity area ``area``
        (world xy, m/s) and the pre-impact CoM velocity (world, m/s)."""
        if self._rates is None:
            raise GovernorError("contact_aware", None, "no posture evaluated yet")
        if area.is_empty:
            return ContactAwareAnswer(VelocityLimit(0.0, "cannot_balance"), None, self._rates, self._age,
                                      self._converged)
        G, h = area.halfplanes
        margins = h - G @ np.asarray(com_velocity, dtype=float)[:2]
        rates = self._rates @ G.T  # (2, edges): m/s of margin used per m/s of approach speed
        return ContactAwareAnswer(first_exit(margins, rates), speed_interval(margins, rates), self._rates,
                                  self._age, self._converged)


def combine(floating: tuple[float, float] | None, aware: tuple[float, float] | None) -> tuple[float, float] | None:
    """The approach speeds (m/s) safe for both models: the intersection of two safe intervals
    (or None)."""
    if floating is None or aware is None:
        return None
    lo, hi = max(floating[0], aware[0]), min(floating[1], aware[1])
    return (lo, hi) if lo <= hi else None
