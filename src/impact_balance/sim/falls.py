"""Fall detection: when does a simulated (or logged) robot count as fallen?

The criterion's promise is zero-step balance: every sustained contact stays where it is, and the
robot comes back to rest. So a trial *fails* (the robot "fell") at the first of:

- ``contact_lost``: a contact's normal force stays below ``min_force`` (1 N) for longer than
  ``lost_time`` (20 ms), counted from the end of the disturbance: while an impulsive push acts
  (10-50 ms) the feet may unload, as the criterion treats the push as instantaneous and judges
  the state it leaves; short flickers during an impact are tolerated the same way. A contact
  counts only once it has carried ``load_force`` (20 N): a hand resting on a wall with hardly
  any load is not "lost" when it carries none.
- ``contact_tilted``: a contact frame rotates more than ``max_tilt`` (5 degrees) from its initial
  orientation: a sole rolling over its edge.
- ``contact_slipped``: a contact frame's origin moves more than ``max_slip`` (1 cm) from its
  initial position.
- ``base_dropped``: the base falls more than ``max_drop`` (10 cm) below its initial height.
- ``not_at_rest``: at the end of the trial (at least ``settle_time``, 2.5 s, after the
  disturbance) the CoM speed is above ``rest_speed`` (5 cm/s).

Everything is measured in the world frame; the detector only sees arrays, so the same logic
serves the MuJoCo trials and recorded logs.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field

import numpy as np

__all__ = ["FallCriteria", "FallDetector", "FallVerdict"]


@dataclass(frozen=True)
class FallCriteria:
    """Thresholds of :class:`FallDetector` (SI units, angles in radians)."""

    min_force: float = 1.0
    load_force: float = 20.0
    lost_time: float = 0.02
    max_tilt: float = np.deg2rad(5.0)
    max_slip: float = 0.01
    max_drop: float = 0.10
    settle_time: float = 2.5
    rest_speed: float = 0.05

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class FallVerdict:
    """Outcome of a trial: ``fell``, the ``reason`` (see the module docstring), when, and the details."""

    fell: bool
    reason: str | None
    time: float | None
    detail: str = ""


@dataclass
class FallDetector:
    """Watches contacts, base height and CoM speed; latches the first failure.

    Args:
        names: Contact names (for the messages).
        positions: Initial contact frame positions (k x 3, m, world).
        rotations: Initial contact frame rotations (k x 3 x 3, world).
        base_height: Initial base height (m).
        criteria: Thresholds.
    """

    names: Sequence[str]
    positions: np.ndarray
    rotations: np.ndarray
    base_height: float
    criteria: FallCriteria = field(default_factory=FallCriteria)
    verdict: FallVerdict = field(default_factory=lambda: FallVerdict(False, None, None), init=False)
    max_tilt: float = field(default=0.0, init=False)
    max_slip: float = field(default=0.0, init=False)
    _low_since: np.ndarray = field(init=False)
    _loaded: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.positions = np.asarray(self.positions, dtype=float).reshape(-1, 3)
        self.rotations = np.asarray(self.rotations, dtype=float).reshape(-1, 3, 3)
        self._low_since = np.full(len(self.names), np.nan)
        self._loaded = np.zeros(len(self.names), dtype=bool)

    @property
    def fell(self) -> bool:
        return self.verdict.fell

    def _fail(self, reason: str, t: float, detail: str) -> None:
        if not self.verdict.fell:
            self.verdict = FallVerdict(True, reason, float(t), detail)

    def update(self, t: float, positions: np.ndarray, rotations: np.ndarray, normal_forces: np.ndarray | None,
               base_height: float, impulsive: bool = False) -> bool:
        """Check one sample (contact frame poses, normal forces in N or None if unknown); returns ``fell``.

        ``impulsive``: a push is acting now; unloading does not count until it ends.
        """
        c = self.criteria
        positions = np.asarray(positions, dtype=float).reshape(-1, 3)
        rotations = np.asarray(rotations, dtype=float).reshape(-1, 3, 3)
        for i, name in enumerate(self.names):
            slip = float(np.linalg.norm(positions[i] - self.positions[i]))
            # Rotation angle between the initial and current orientation.
            cos = (np.trace(self.rotations[i].T @ rotations[i]) - 1.0) / 2.0
            tilt = float(np.arccos(np.clip(cos, -1.0, 1.0)))
            self.max_slip = max(self.max_slip, slip)
            self.max_tilt = max(self.max_tilt, tilt)
            if tilt > c.max_tilt:
                self._fail("contact_tilted", t, f"{name} tilted {np.rad2deg(tilt):.1f} deg")
            if slip > c.max_slip:
                self._fail("contact_slipped", t, f"{name} moved {100 * slip:.1f} cm")
            if normal_forces is not None:
                self._loaded[i] |= normal_forces[i] >= c.load_force
                if impulsive or not self._loaded[i]:
                    self._low_since[i] = np.nan
                elif normal_forces[i] < c.min_force:
                    if np.isnan(self._low_since[i]):
                        self._low_since[i] = t
                    elif t - self._low_since[i] > c.lost_time:
                        self._fail("contact_lost", t, f"{name} unloaded for more than {1e3 * c.lost_time:.0f} ms")
                else:
                    self._low_since[i] = np.nan
        if self.base_height - base_height > c.max_drop:
            self._fail("base_dropped", t, f"base {100 * (self.base_height - base_height):.0f} cm below its start")
        return self.verdict.fell

    def finish(self, t: float, com_velocity: np.ndarray) -> FallVerdict:
        """Final check at the end of the trial: the CoM must be back near rest."""
        speed = float(np.linalg.norm(np.asarray(com_velocity, dtype=float)))
        if speed > self.criteria.rest_speed:
            self._fail("not_at_rest", t, f"CoM speed {speed:.3f} m/s at the end")
        return self.verdict
