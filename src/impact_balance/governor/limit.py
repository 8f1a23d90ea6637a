"""What a governor answers at one control tick: the speed limit, and the capped reference."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from impact_balance.exceptions import GovernorError

__all__ = ["SpeedLimit", "cap_approach"]


@dataclass(frozen=True, slots=True)
class SpeedLimit:
    """The impact speed allowed from one posture and CoM velocity.

    Frames and units: world axes (z up), m/s. The approach speed of an end-effector velocity
    ``u`` is ``-normal . u`` (positive towards the surface).

    Attributes:
        criterion: "com" (the CoM velocity area, paper sec. V-C) or "zmp" (the predicted ZMP
            stays in the ZMP support area, the paper's Experiment 1 comparison).
        max_approach_speed: The criterion's maximum approach speed, m/s (``inf``: no speed
            is unsafe; 0 when the robot is already falling or cannot balance), the number
            ``impact-balance analyze`` reports as ``max_contact_velocity``.
        status: "ok", "unbounded", "already_falling" or "cannot_balance"
            (see :class:`~impact_balance.criteria.com.VelocityLimit`).
        limiting_vertex: Index of the post-impact vertex (CoM) or impulse vertex (ZMP) that
            reaches the area's boundary first (None unless "ok").
        limiting_edge: Index of the area's edge it reaches (None unless "ok"; None also for
            the ZMP criterion's lift-off bound).
        safe_interval: The approach speeds ``(lo, hi)`` (m/s) that keep the robot balanced,
            or None when there are none. With the CoM velocity inside its area it is
            ``(0, max_approach_speed)``; outside (a falling start) it is the range of impacts
            that bring it back inside (``lo > 0``), as :func:`~impact_balance.criteria.com.safe_interval`.
            The ZMP criterion has no falling start: ``(0, max)`` or None.
        com_velocity: The CoM velocity the answer is for (3,), world, m/s.
        normal: The impact surface's unit normal (3,), world, pointing into the robot.
        point: The impact point at this posture (3,), world, m.
        posture_reused: True when the posture was the previous call's (within the governor's
            ``posture_tolerance``) and only the CoM velocity was new (the fast path).
        binding: Which impact model gave the maximum: "floating" (the paper's set; the only
            one unless the governor is ``contact_aware``) or "contact_aware" (then
            ``limiting_vertex`` is the row of its jump rates, ``ContactAwareAnswer.rates``:
            0 / 1 the lower / upper restitution bound with one start, else one row per
            solution found, ``ContactAwareAnswer.restitution`` giving each row's bound).
    """

    criterion: str
    max_approach_speed: float
    status: str
    limiting_vertex: int | None
    limiting_edge: int | None
    safe_interval: tuple[float, float] | None
    com_velocity: np.ndarray
    normal: np.ndarray
    point: np.ndarray
    posture_reused: bool
    binding: str = "floating"

    @property
    def ceiling(self) -> float:
        """Largest approach speed :meth:`cap` lets through, m/s: the safe interval's top,
        0 when there is no safe speed.
        """
        return 0.0 if self.safe_interval is None else self.safe_interval[1]

    def cap(self, reference_velocity: Sequence[float]) -> np.ndarray:
        """``reference_velocity`` (world, m/s) with its approach speed brought into the safe
        interval; see :func:`cap_approach`.
        """
        return cap_approach(reference_velocity, self.normal, self.safe_interval)


def cap_approach(
    reference_velocity: Sequence[float], normal: np.ndarray, interval: tuple[float, float] | None
) -> np.ndarray:
    """The end-effector velocity nearest ``reference_velocity`` whose approach speed is safe.

    Only the component along ``normal`` changes (the tangential part is kept): this is the
    minimiser of ``||u - u_ref||`` under the speed bounds, the paper's QP objective, and
    :func:`~impact_balance.criteria.com.capped_velocity` when the robot is balanced. With
    ``s = -normal . u_ref``:

    - ``s <= 0`` (moving away or along the surface: no impact): unchanged;
    - ``interval`` None (no approach speed is safe): the approach component is removed
      (``s`` becomes 0: do not hit);
    - otherwise ``s`` is clamped into ``[lo, hi]``: capped at ``hi``, and, for a falling start
      (``lo > 0``), raised to ``lo``, the slowest impact that catches the fall. A caller that
      must never speed up takes ``min(s_ref, s_capped)`` itself.

    Args:
        reference_velocity: (3,) world, m/s.
        normal: (3,) unit normal of the surface, world, pointing into the robot.
        interval: The safe approach speeds ``(lo, hi)``, m/s (``hi`` may be inf), or None.
    """
    try:
        u = np.array(reference_velocity, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise GovernorError(
            "reference_velocity", reference_velocity, "must be 3 numbers (world, m/s)"
        ) from None
    if not math.isfinite(float(u @ u)):
        raise GovernorError("reference_velocity", reference_velocity, "must be finite")
    s = -float(normal @ u)
    if s <= 0.0:
        return u
    lo, hi = (0.0, 0.0) if interval is None else interval
    target = min(max(s, lo), hi)
    if target != s:
        u += (s - target) * normal
    return u
