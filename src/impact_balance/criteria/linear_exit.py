"""The first exit of points moving linearly out of a polygon: the core of every criterion.

A criterion's post-impact points move linearly with the approach speed ``s`` (m/s): point
``j`` uses up the slack ``margins[k]`` of the area's half-plane ``k`` at the rate
``rates[j, k]`` (per m/s of approach speed), so it stays inside while
``margins[k] - s * rates[j, k] >= 0``. :func:`first_exit` is the largest such ``s`` (the
maximum contact velocity), :func:`speed_interval` all of them.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from impact_balance._jit import njit
from impact_balance.criteria.velocity_limit import ContactVelocityLimit, LimitStatus

__all__ = [
    "BOUNDARY_TOLERANCE",
    "EXIT_STATUSES",
    "exit_kernel",
    "first_exit",
    "interval_kernel",
    "limit_of_exit",
    "speed_interval",
]

#: Margin under which a point counts as on the boundary (same units as the area).
BOUNDARY_TOLERANCE = 1e-10

#: Statuses of the compiled :func:`exit_kernel`, by its code.
EXIT_STATUSES: tuple[LimitStatus, ...] = ("ok", "already_falling", "unbounded")


def first_exit(
    margins: npt.ArrayLike, rates: npt.ArrayLike, tol: float = BOUNDARY_TOLERANCE
) -> ContactVelocityLimit:
    """Largest s >= 0 with ``margins[k] - s * rates[j, k] >= 0`` for all j, k.

    Args:
        margins: (n_c,) slack of the starting point in each half-plane.
        rates: (n_v, n_c) rate at which vertex j uses up half-plane k's slack.
        tol: Margin under which a point counts as on the boundary.

    Returns:
        The limit: "already_falling" (0) when a margin is below ``-tol``, "unbounded" (inf)
        when no rate is positive, else "ok" with the limiting vertex j and half-plane k.
    """
    m = np.ascontiguousarray(margins, dtype=float)
    r = np.ascontiguousarray(rates, dtype=float).reshape(-1, m.size)
    code, speed, j, k = exit_kernel(m, r, tol)
    return limit_of_exit(code, speed, j, k)


def limit_of_exit(code: int, speed: float, j: int, k: int) -> ContactVelocityLimit:
    """The :class:`ContactVelocityLimit` of a compiled answer of :func:`exit_kernel`.

    Args:
        code: Index of the status in :data:`EXIT_STATUSES`.
        speed: The maximum contact velocity, m/s (used when the code is "ok").
        j: Limiting vertex (used when the code is "ok").
        k: Limiting half-plane (used when the code is "ok").

    Returns:
        The limit.
    """
    if code == 0:
        return ContactVelocityLimit(speed, "ok", j, k)
    return ContactVelocityLimit(0.0 if code == 1 else float("inf"), EXIT_STATUSES[code])


@njit(cache=True)
def exit_kernel(margins, rates, tol):
    """:func:`first_exit` compiled: ``(code, speed, vertex, edge)``.

    ``code`` is an index of :data:`EXIT_STATUSES`. The answer is the smallest ratio
    ``max(margin_k, 0) / rate_jk`` over the rates above ``tol`` times the largest one (and 1),
    the first in row-major order on a tie (numpy's ``argmin``).
    """
    n_v, n_c = rates.shape
    for k in range(n_c):
        if margins[k] < -tol:
            return 1, 0.0, -1, -1
    big = 1.0
    for j in range(n_v):
        for k in range(n_c):
            big = max(big, abs(rates[j, k]))
    threshold = tol * big
    best, bj, bk = math.inf, -1, -1
    for j in range(n_v):
        for k in range(n_c):
            r = rates[j, k]
            if r > threshold:
                s = max(margins[k], 0.0) / r
                if bj < 0 or s < best:
                    best, bj, bk = s, j, k
    if bj < 0:
        return 2, math.inf, -1, -1
    return 0, best, bj, bk


def speed_interval(
    margins: npt.ArrayLike, rates: npt.ArrayLike, tol: float = BOUNDARY_TOLERANCE
) -> tuple[float, float] | None:
    """All s >= 0 with ``margins[k] - s * rates[j, k] >= 0`` for all j, k.

    Each constraint is linear in s, so the solutions form an interval: a positive rate caps
    s from above (s <= margin / rate), a negative one from below (s >= margin / rate, which
    matters only for a negative margin), a zero rate needs a non-negative margin. ``hi`` is
    inf when nothing caps s. With every margin >= 0, ``lo`` = 0 and ``hi`` is
    :func:`first_exit`'s maximum.

    Args:
        margins: (n_c,) slack of the starting point in each half-plane.
        rates: (n_v, n_c) rate at which vertex j uses up half-plane k's slack.
        tol: Margin under which a point counts as on the boundary.

    Returns:
        ``(lo, hi)`` (m/s), or None when no speed is safe.
    """
    m = np.ascontiguousarray(margins, dtype=float)
    r = np.ascontiguousarray(rates, dtype=float).reshape(-1, m.size)
    found, lo, hi = interval_kernel(m, r, tol)
    return (lo, hi) if found else None


@njit(cache=True)
def interval_kernel(margins, rates, tol):
    """:func:`speed_interval` compiled: ``(found, lo, hi)`` (``lo``, ``hi`` unused unless found).

    The numbers of the array expression it replaced, to the last digit (elementwise ratios,
    their minimum and maximum): a zero rate is one within ``tol`` times the largest rate (and
    1); with every margin >= ``-tol`` the interval starts at 0 and its top is the smallest
    ``max(margin, 0) / rate`` over the positive rates.
    """
    n_v, n_c = rates.shape
    big = 0.0
    for j in range(n_v):
        for k in range(n_c):
            big = max(big, abs(rates[j, k]))
    scale = tol * max(1.0, big)
    inside = True
    for k in range(n_c):
        if not margins[k] >= -tol:
            inside = False
    hi, lo = math.inf, 0.0
    for j in range(n_v):
        for k in range(n_c):
            r = rates[j, k]
            if r > scale:
                ratio = margins[k] / r
                if inside and not ratio >= 0.0:
                    ratio = 0.0
                hi = min(hi, ratio)
            elif r < -scale:
                if not inside:
                    lo = max(lo, margins[k] / r)
            elif margins[k] < -tol:
                return False, 0.0, 0.0  # outside an edge the impact does not move it along
    if lo > hi * (1.0 + 1e-12) + tol:
        return False, 0.0, 0.0
    return True, lo, max(lo, hi)
