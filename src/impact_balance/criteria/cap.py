"""Approach-speed clamps: the end-effector velocity nearest a reference whose approach is safe.

The approach speed of an end-effector velocity ``v`` (world, m/s) is ``s = -normal . v``
(positive towards the surface; ``normal`` is the surface's unit normal, pointing into the
robot). Each clamp changes only the component along ``normal`` (the tangential part is
kept): it is the minimiser of ``||v - v_ref||`` under the speed bounds, the paper's QP
objective. All three are :func:`clamp_approach_speed`; they differ where the callers need
different answers:

==========================  ===================  ==========================  ====================
clamp                       no safe speed        reference moving away        falling start
                            (interval None)      (``s <= 0``)                 (``lo > 0``)
==========================  ===================  ==========================  ====================
:func:`capped_velocity`     (takes a maximum)    kept                         (not applicable)
:func:`safe_contact_velocity`  None (no answer)  kept if ``lo = 0``, else     ``s`` raised to ``lo``
                                                 raised to ``lo``
:func:`cap_approach`        approach removed     kept (no impact)             ``s`` raised to ``lo``
                            (``s`` becomes 0)
==========================  ===================  ==========================  ====================

:func:`safe_contact_velocity` is the analysis's answer (``analyze``: ``contact_velocity`` is
null when no speed is safe, and a falling robot needs an impact to catch its fall, even from a
reference moving away); :func:`cap_approach` is the governor's per-tick command (a controller
always gets a velocity: without a safe speed, do not hit; without an approach, no impact).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from impact_balance.constants import MAX_SPEED
from impact_balance.exceptions import GovernorError

__all__ = ["cap_approach", "capped_velocity", "clamp_approach_speed", "safe_contact_velocity"]


def clamp_approach_speed(
    reference: npt.ArrayLike, normal: npt.ArrayLike, lo: float, hi: float
) -> npt.NDArray[np.float64]:
    """``reference`` with its approach speed ``-normal . v`` clamped into ``[lo, hi]``.

    Args:
        reference: End-effector velocity, world, m/s.
        normal: Unit normal of the surface (same size), world, pointing into the robot.
        lo: Lowest approach speed, m/s (``-inf``: no lower bound).
        hi: Highest approach speed, m/s (``inf``: no upper bound).

    Returns:
        A new array: ``reference`` moved along ``normal`` only, unchanged when its approach
        speed is already in ``[lo, hi]``.
    """
    v = np.array(reference, dtype=float)
    n = np.asarray(normal, dtype=float)
    speed = -(n @ v)
    target = min(max(speed, lo), hi)
    if target != speed:
        v += (speed - target) * n
    return v


def capped_velocity(
    reference: npt.ArrayLike, normal: npt.ArrayLike, max_contact_velocity: float
) -> npt.NDArray[np.float64]:
    """``reference`` with its approach speed capped at ``max_contact_velocity``.

    This is the minimiser of ``||v - v_ref||`` subject to ``-n.v <= max`` (the paper's QP
    objective). Slower approaches, and references moving away, are kept.

    Args:
        reference: End-effector velocity, world, m/s.
        normal: Unit normal of the surface, world, pointing into the robot.
        max_contact_velocity: m/s (inf: no cap).

    Returns:
        The capped velocity, world, m/s.
    """
    return clamp_approach_speed(reference, normal, -math.inf, max_contact_velocity)


def safe_contact_velocity(
    reference: npt.ArrayLike, normal: npt.ArrayLike, interval: tuple[float, float] | None
) -> npt.NDArray[np.float64] | None:
    """``reference`` with its approach speed moved to the nearest speed of the safe interval.

    With the CoM velocity inside the area the interval is ``[0, max]``, and this is
    :func:`capped_velocity`. With the robot already falling it is ``[lo, hi]``, ``lo > 0``:
    a reference approach speed below ``lo`` is raised to ``lo`` (a softer impact would not
    catch the fall), one above ``hi`` capped. A reference moving away from the surface, with
    ``lo`` = 0, is kept: there is no impact.

    Args:
        reference: End-effector velocity, world, m/s.
        normal: Unit normal of the surface, world, pointing into the robot.
        interval: The safe approach speeds ``(lo, hi)``, m/s (``hi`` may be inf), or None.

    Returns:
        The velocity, world, m/s; None when no speed is safe (``interval`` None).
    """
    if interval is None:
        return None
    lo, hi = interval
    return clamp_approach_speed(reference, normal, lo if lo > 0 else -math.inf, hi)


def cap_approach(
    reference_velocity: npt.ArrayLike,
    normal: npt.ArrayLike,
    interval: tuple[float, float] | None,
) -> npt.NDArray[np.float64]:
    """The end-effector velocity nearest ``reference_velocity`` whose approach speed is safe.

    With ``s = -normal . u_ref``:

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

    Returns:
        The velocity (3,), world, m/s.

    Raises:
        GovernorError: ``reference_velocity`` is not 3 finite numbers, or its speed (norm) is
            above :data:`~impact_balance.constants.MAX_SPEED` m/s (the scenario's bound).
    """
    try:
        if np.asarray(reference_velocity).dtype.kind not in "iuf":  # no complex, text, object
            raise TypeError(reference_velocity)
        u = np.array(reference_velocity, dtype=float).reshape(3)
    except (TypeError, ValueError):
        raise GovernorError(
            "reference_velocity", reference_velocity, "must be 3 real numbers (world, m/s)"
        ) from None
    bad = np.flatnonzero(~np.isfinite(u))
    if bad.size:
        raise GovernorError(
            "reference_velocity", reference_velocity, f"must be finite (entry {int(bad[0])})"
        )
    if math.hypot(*u) > MAX_SPEED:
        raise GovernorError(
            "reference_velocity", reference_velocity, f"the speed must be at most {MAX_SPEED:g} m/s"
        )
    n = np.asarray(normal, dtype=float)
    if -float(n @ u) <= 0.0:
        return u
    lo, hi = (0.0, 0.0) if interval is None else interval
    return clamp_approach_speed(u, n, lo, hi)
