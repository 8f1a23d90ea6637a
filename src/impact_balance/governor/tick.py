"""The arithmetic of a governor's tick once its posture is known, in one compiled call.

A tick's CoM velocity is ``J_com(q) v`` (world, m/s); the "com" criterion's answer is then the
first exit of the post-impact vertices from the CoM velocity area
(:func:`~impact_balance.criteria.linear_exit.exit_kernel` of the margins ``h - G c0``, the
numbers :meth:`~impact_balance.criteria.com.ComCriterion.limit` gives). :func:`velocity_exit`
does both, with the checks of ``v`` and of the CoM speed, in one call: a governor's
velocity-only tick is then this call and the answer object. A batch computes its rows' CoM
velocities with the same product, so a row and a single tick agree to the last digit.
"""

from __future__ import annotations

import math

import numpy as np

from impact_balance._jit import cache_depends_on, njit
from impact_balance.criteria import linear_exit
from impact_balance.criteria.linear_exit import exit_kernel, interval_kernel

__all__ = [
    "CANNOT_BALANCE",
    "NOT_FINITE",
    "TOO_FAST",
    "com_velocity",
    "velocity_exit",
]

#: :func:`velocity_exit`'s codes beyond :data:`~impact_balance.criteria.linear_exit.EXIT_STATUSES`'
#: (0 "ok", 1 "already_falling", 2 "unbounded"): v not finite (or beyond any physical value),
#: the CoM speed above the bound, an empty area (no half-planes).
NOT_FINITE, TOO_FAST, CANNOT_BALANCE = -1, -2, 3


@njit(cache=True)
def com_velocity(J: np.ndarray, v: np.ndarray, out: np.ndarray) -> float:
    """``out = J v`` (J (3, nv), v (nv,); the CoM velocity, m/s).

    By BLAS's matrix-vector product, as numpy's ``J @ v`` (the same numbers, which the CoM
    speed bound is decided on). Returns ``|v|^2`` (inf or NaN when v is not finite or
    overflows).
    """
    squared = 0.0
    for i in range(v.size):
        squared += v[i] * v[i]
    if not math.isfinite(squared):
        return squared
    c = np.dot(J, v)
    out[0], out[1], out[2] = c[0], c[1], c[2]
    return squared


@njit(cache=True)
def velocity_exit(
    J: np.ndarray,
    v: np.ndarray,
    G: np.ndarray,
    h: np.ndarray,
    rates: np.ndarray,
    tol: float,
    max_speed_squared: float,
    out: np.ndarray,
) -> tuple[int, float, int, int, float, float]:
    """The CoM velocity ``out = J v`` (m/s, world) and the CoM criterion's first exit.

    Args:
        J: (3, nv) the CoM Jacobian.
        v: (nv,) the generalized velocity.
        G: (n_c, 2) the CoM velocity area's half-plane normals, (0, 2) for an empty area.
        h: (n_c,) their offsets less the velocity margin, m/s.
        rates: (n_v, n_c) the post-impact vertices' rates (``ComCriterion.rates``).
        tol: The boundary tolerance, m/s.
        max_speed_squared: The CoM speed bound squared, (m/s)^2.
        out: (3,) written with the CoM velocity.

    Returns:
        ``(code, speed, vertex, edge, lo, hi)``: ``code`` an index of ``EXIT_STATUSES`` with
        :func:`~impact_balance.criteria.linear_exit.exit_kernel`'s answer and the safe interval
        ``(lo, hi)`` (m/s; from inside ``(0, speed)``; already falling
        :func:`~impact_balance.criteria.linear_exit.interval_kernel`'s, NaN when there is none);
        or :data:`NOT_FINITE`, :data:`TOO_FAST`, :data:`CANNOT_BALANCE` (then the rest is
        unused).
    """
    squared = com_velocity(J, v, out)
    if not math.isfinite(squared):
        return NOT_FINITE, 0.0, -1, -1, 0.0, 0.0
    cx, cy, cz = out[0], out[1], out[2]
    if not cx * cx + cy * cy + cz * cz <= max_speed_squared:
        return TOO_FAST, 0.0, -1, -1, 0.0, 0.0
    if G.shape[0] == 0:
        return CANNOT_BALANCE, 0.0, -1, -1, 0.0, 0.0
    margins = np.empty(h.size)
    for k in range(h.size):
        margins[k] = h[k] - (G[k, 0] * cx + G[k, 1] * cy)
    code, speed, vertex, edge = exit_kernel(margins, rates, tol)
    lo, hi = 0.0, speed
    if code == 1:  # already falling: the safe speeds, if any, catch the fall
        found, lo, hi = interval_kernel(margins, rates, tol)
        if not found:
            lo = hi = math.nan
    return code, speed, vertex, edge, lo, hi


cache_depends_on(velocity_exit, linear_exit)
