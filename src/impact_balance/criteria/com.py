"""Maximum contact velocity: the CoM-velocity criterion (paper sec. V-C) and the ZMP one.

CoM criterion. Every post-impact vertex is ``c0 + s d_j`` (c0 the pre-impact planar CoM
velocity, s the approach speed, d_j the jump per unit speed), and the CoM velocity area is
``{x : G x <= h}``. All vertices stay inside for ``s <= min_{k,j: G_k d_j > 0} (h_k - G_k c0)
/ (G_k d_j)``: that minimum IS the maximum contact velocity, exactly (no search, no QP).
The set of post-impact velocities is the convex hull of the vertices, so the vertices suffice.

ZMP criterion (paper Experiment 1). The impulsive force ``F = iota / dt`` at the impact point
is added to the gravity-compensating wrench (m g up, through the CoM). The predicted ZMP
``z = N(F) / (m g + F_z)`` stays in ``{G z <= h}`` iff ``G N(F) <= h (m g + F_z)`` while
``m g + F_z > 0``: again linear in the approach speed per vertex and per edge, so exact.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from impact_balance._jit import njit
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel

__all__ = [
    "ComCriterion",
    "VelocityLimit",
    "capped_velocity",
    "first_exit",
    "max_contact_velocity",
    "safe_contact_velocity",
    "safe_interval",
    "speed_interval",
    "zmp_max_contact_velocity",
]

#: Margin under which a point counts as on the boundary (same units as the area).
BOUNDARY_TOLERANCE = 1e-10


@dataclass(frozen=True)
class VelocityLimit:
    """The largest safe approach speed.

    Attributes:
        max_approach_speed: m/s (``inf`` when no approach speed can leave the area).
        status: "ok"; "unbounded" (no limit); "already_falling" (the pre-impact state is
            already outside, so 0); "cannot_balance" (empty area, so 0).
        limiting_vertex: Index of the post-impact vertex that reaches the boundary first.
        limiting_edge: Index of the area's half-plane it reaches.
    """

    max_approach_speed: float
    status: str
    limiting_vertex: int | None = None
    limiting_edge: int | None = None

    @property
    def is_finite(self) -> bool:
        return math.isfinite(self.max_approach_speed)


def first_exit(
    margins: np.ndarray, rates: np.ndarray, tol: float = BOUNDARY_TOLERANCE
) -> VelocityLimit:
    """Largest s >= 0 with ``margins[k] - s * rates[j, k] >= 0`` for all j, k.

    Args:
        margins: (n_c,) slack of the starting point in each half-plane.
        rates: (n_v, n_c) rate at which vertex j uses up half-plane k's slack.
    """
    margins = np.ascontiguousarray(margins, dtype=float)
    rates = np.ascontiguousarray(rates, dtype=float).reshape(-1, margins.size)
    return _limit(*_first_exit(margins, rates, tol))


#: Statuses of the compiled :func:`_first_exit`, by its code.
_STATUSES = ("ok", "already_falling", "unbounded")


def _limit(code: int, speed: float, j: int, k: int) -> VelocityLimit:
    """The :class:`VelocityLimit` of a compiled answer ``(code, speed, vertex, edge)``."""
    if code == 0:
        return VelocityLimit(speed, "ok", j, k)
    return VelocityLimit(0.0 if code == 1 else float("inf"), _STATUSES[code])


@njit(cache=True)
def _first_exit(margins, rates, tol):
    """:func:`first_exit` compiled: ``(code, speed, vertex, edge)``, code an index of
    ``_STATUSES``. The smallest ratio ``max(margin_k, 0) / rate_jk`` over the rates above
    ``tol`` times the largest one (and 1), the first in row-major order on a tie (numpy's
    ``argmin``): a few hundred flops, which numpy spent ~15 us of call overhead on.
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


@njit(cache=True)
def _jump_rates(impulse_rates, mass, G):
    """``rates[j, k] = (iota_j,xy / m) . G_k``: the rate (m/s per m/s of approach speed) at which
    post-impact vertex j uses up half-plane k's margin (``ImpactModel.com_jump_rates @ G.T``,
    compiled: a governor builds it every posture).
    """
    rates = np.empty((impulse_rates.shape[0], G.shape[0]))
    for j in range(impulse_rates.shape[0]):
        x, y = impulse_rates[j, 0] / mass, impulse_rates[j, 1] / mass
        for k in range(G.shape[0]):
            rates[j, k] = x * G[k, 0] + y * G[k, 1]
    return rates


@njit(cache=True)
def _com_exit(G, h, c0x, c0y, rates, tol):
    """:func:`_first_exit` of the margins ``h - G c0`` of the CoM velocity ``c0``."""
    margins = np.empty(h.size)
    for k in range(h.size):
        margins[k] = h[k] - (G[k, 0] * c0x + G[k, 1] * c0y)
    return _first_exit(margins, rates, tol)


@njit(cache=True)
def _com_exits(G, h, c0x, c0y, rates, jumps, tol):
    """:func:`_com_exit` for ``rates`` and for the jumps ``jumps`` (k, 2), whose rates per
    edge are ``jumps G^T``: the two answers' 8 numbers.
    """
    margins = np.empty(h.size)
    for k in range(h.size):
        margins[k] = h[k] - (G[k, 0] * c0x + G[k, 1] * c0y)
    edge = np.empty((jumps.shape[0], h.size))
    for j in range(jumps.shape[0]):
        for k in range(h.size):
            edge[j, k] = jumps[j, 0] * G[k, 0] + jumps[j, 1] * G[k, 1]
    a = _first_exit(margins, rates, tol)
    b = _first_exit(margins, edge, tol)
    return a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]


def speed_interval(
    margins: np.ndarray, rates: np.ndarray, tol: float = BOUNDARY_TOLERANCE
) -> tuple[float, float] | None:
    """All s >= 0 with ``margins[k] - s * rates[j, k] >= 0`` for all j, k: ``(lo, hi)`` or None.

    Each constraint is linear in s, so the solutions form an interval: a positive rate caps
    s from above (s <= margin / rate), a negative one from below (s >= margin / rate, which
    matters only for a negative margin), a zero rate needs a non-negative margin. ``hi`` is
    inf when nothing caps s. With every margin >= 0, ``lo`` = 0 and ``hi`` is
    :func:`first_exit`'s maximum.
    """
    scale = tol * max(1.0, float(np.abs(rates).max(initial=0.0)))
    positive, negative = rates > scale, rates < -scale
    flat = ~(positive | negative)
    m = np.broadcast_to(margins, rates.shape)
    if (m[flat] < -tol).any():
        return None  # a vertex outside that the impact does not move along that edge's normal
    inside = bool((margins >= -tol).all())
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = m / rates
    hi = float(
        np.min(np.maximum(ratio[positive], 0.0) if inside else ratio[positive], initial=np.inf)
    )
    lo = 0.0 if inside else max(0.0, float(np.max(ratio[negative], initial=0.0)))
    if lo > hi * (1.0 + 1e-12) + tol:
        return None
    return lo, max(lo, hi)


class ComCriterion:
    """The CoM velocity criterion of one area and one impact model, for any pre-impact CoM velocity.

    What does not depend on the CoM velocity is computed once: the area's half-planes
    ``G x <= h`` and the rates ``d_j . G_k`` (m/s per m/s of approach speed) at which the
    post-impact vertices use up each half-plane's margin. :meth:`limit` and :meth:`interval`
    then cost a few microseconds per CoM velocity (a governor's velocity-only tick).
    :func:`max_contact_velocity` and :func:`safe_interval` are these two methods.

    With a ``velocity_margin`` d > 0 (m/s), every post-impact CoM velocity must lie at least d
    inside the area (the area eroded by a disc of radius d: each half-plane moved in by d), a
    margin for the impact model's error; 0 is the paper's criterion.

    Attributes:
        area: The CoM velocity area (world x, y), m/s.
        impact: The impact model.
        velocity_margin: d, m/s.
    """

    __slots__ = ("G", "area", "h", "impact", "rates", "velocity_margin")

    def __init__(self, area: Polygon, impact: ImpactModel, velocity_margin: float = 0.0):
        self.area = area
        self.impact = impact
        self.velocity_margin = float(velocity_margin)
        if area.is_empty:
            self.G = self.h = self.rates = None
            return
        self.G, self.h = area.halfplanes  # unit rows: h - G x is the distance inside each edge
        if self.velocity_margin:
            self.h = self.h - self.velocity_margin
        self.rates = _jump_rates(impact.impulse_rates, float(impact.mass), self.G)

    def margins(self, com_velocity: Sequence[float]) -> np.ndarray:
        """``h - G c0``: the slack of the pre-impact CoM velocity in each half-plane (less the
        velocity margin), m/s.
        """
        return self.h - self.G @ np.asarray(com_velocity, dtype=float)[:2]

    def limit(self, com_velocity: Sequence[float]) -> VelocityLimit:
        """Largest approach speed keeping every post-impact CoM velocity in the area (m/s)."""
        if self.G is None:
            return VelocityLimit(0.0, "cannot_balance")
        c0x, c0y = float(com_velocity[0]), float(com_velocity[1])
        return _limit(*_com_exit(self.G, self.h, c0x, c0y, self.rates, BOUNDARY_TOLERANCE))

    def limits(
        self, com_velocity: Sequence[float], jumps: np.ndarray
    ) -> tuple[VelocityLimit, VelocityLimit]:
        """:meth:`limit`, and the same limit for other post-impact jumps ``jumps`` (k, 2: the
        CoM velocity jumps per m/s of approach speed, world xy, e.g. another impact model's;
        its vertex j is row j), in one compiled call (a governor's tick).
        """
        if self.G is None:
            cannot = VelocityLimit(0.0, "cannot_balance")
            return cannot, cannot
        c0x, c0y = float(com_velocity[0]), float(com_velocity[1])
        out = _com_exits(
            self.G,
            self.h,
            c0x,
            c0y,
            self.rates,
            np.ascontiguousarray(jumps, dtype=float),
            BOUNDARY_TOLERANCE,
        )
        return _limit(*out[:4]), _limit(*out[4:])

    def interval(
        self, com_velocity: Sequence[float], limit: VelocityLimit | None = None
    ) -> tuple[float, float] | None:
        """The safe approach speeds ``(lo, hi)`` (see :func:`safe_interval`); ``limit``,
        :meth:`limit`'s answer for the same velocity when the caller has it.
        """
        if self.G is None:
            return None
        if limit is not None and limit.status in ("ok", "unbounded"):
            return 0.0, limit.max_approach_speed
        return speed_interval(self.margins(com_velocity), self.rates)


def safe_interval(
    area: Polygon,
    impact: ImpactModel,
    com_velocity: Sequence[float],
    limit: VelocityLimit | None = None,
) -> tuple[float, float] | None:
    """The approach speeds s >= 0 whose whole post-impact CoM velocity set lies in ``area``.

    The post-impact vertices ``c0 + s d_j`` are linear in s, so these speeds form one
    interval ``(s_lo, s_hi)`` (m/s; ``s_hi`` may be inf); None when it is empty (or the
    area is). With ``c0`` inside the area, ``s_lo`` = 0 and ``s_hi`` is the maximum contact
    velocity. With ``c0`` outside (the robot falls without an impact), a non-empty interval
    is the impacts that catch the fall: ``s_lo`` > 0.

    ``limit``, :func:`max_contact_velocity`'s answer for the same data when the caller has it:
    with ``c0`` inside, the interval is ``(0, limit)`` and is not computed again.
    """
    if area.is_empty:
        return None
    if limit is not None and limit.status in ("ok", "unbounded"):
        return 0.0, limit.max_approach_speed
    return ComCriterion(area, impact).interval(com_velocity)


def max_contact_velocity(
    area: Polygon, impact: ImpactModel, com_velocity: Sequence[float]
) -> VelocityLimit:
    """Largest approach speed keeping every post-impact CoM velocity in ``area`` (m/s)."""
    if area.is_empty:
        return VelocityLimit(0.0, "cannot_balance")
    return ComCriterion(area, impact).limit(com_velocity)


def zmp_max_contact_velocity(
    zmp_area: Polygon,
    impact: ImpactModel,
    com: np.ndarray,
    plane_height: float,
    gravity: float,
    duration: float,
) -> VelocityLimit:
    """Largest approach speed keeping the predicted ZMP in ``zmp_area`` (paper Experiment 1).

    Args:
        zmp_area: ZMP support area (world x, y on the plane), m.
        impact: The impact model.
        com: CoM, m. plane_height: h, m. gravity: m/s^2.
        duration: Impact duration dt, s (impulsive force = impulse / dt).
    """
    if zmp_area.is_empty:
        return VelocityLimit(0.0, "cannot_balance")
    G, h = zmp_area.halfplanes
    weight = impact.mass * gravity
    p = impact.point
    # With F = iota / dt at p, N(F) - m g c_xy = (plane_height - p_z) F_xy + F_z p_xy, so half-plane
    # k is used up at the rate G_k N_F - h_k F_z = iota . M_k per unit approach speed, with
    # M_k = [(plane_height - p_z) G_k, G_k p_xy - h_k] / dt.
    M = np.empty((3, len(h)))
    M[:2] = ((plane_height - float(p[2])) / duration) * G.T
    M[2] = (G @ p[:2] - h) / duration
    margins = weight * (h - G @ np.asarray(com, dtype=float)[:2])
    limit = first_exit(margins, impact.impulse_rates @ M)
    # The ZMP exists only while the vertical force stays positive (no lift-off).
    fz = impact.impulse_rates[:, 2] / duration  # N per (m/s)
    pulling = fz < 0
    if limit.status != "already_falling" and pulling.any():
        with np.errstate(
            over="ignore"
        ):  # a vanishing pull (friction ~1e-300) never lifts: inf is right
            lift = weight / -fz[pulling]
        j = int(lift.argmin())
        if lift[j] < limit.max_approach_speed:
            return VelocityLimit(float(lift[j]), "ok", int(np.flatnonzero(pulling)[j]), None)
    return limit


def capped_velocity(
    reference: Sequence[float], normal: np.ndarray, max_approach_speed: float
) -> np.ndarray:
    """``reference`` with its approach component -n.v capped at ``max_approach_speed``.

    This is the minimiser of ||v - v_ref|| subject to -n.v <= max (the paper's QP objective).
    """
    v = np.array(reference, dtype=float)
    excess = -(normal @ v) - max_approach_speed
    if math.isfinite(max_approach_speed) and excess > 0:
        v += excess * normal
    return v


def safe_contact_velocity(
    reference: Sequence[float], normal: np.ndarray, interval: tuple[float, float] | None
) -> np.ndarray | None:
    """``reference`` with its approach speed -n.v moved to the nearest speed of the safe ``interval``.

    With the CoM velocity inside the area the interval is ``[0, max]``, and this is
    :func:`capped_velocity`. With the robot already falling it is ``[lo, hi]``, ``lo > 0``:
    a reference within it is kept, one below ``lo`` is raised to ``lo`` (a softer impact
    would not catch the fall), one above ``hi`` capped. None when no speed is safe. (A
    reference moving away from the surface, with ``lo`` = 0, is kept: there is no impact.)
    """
    if interval is None:
        return None
    lo, hi = interval
    v = np.array(reference, dtype=float)
    speed = -(normal @ v)
    target = min(max(speed, lo), hi) if lo > 0 else min(speed, hi)
    if target != speed:
        v += (speed - target) * normal
    return v
