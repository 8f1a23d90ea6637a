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

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .impact import ImpactModel
from .polygon import Polygon

__all__ = ["VelocityLimit", "max_contact_velocity", "zmp_max_contact_velocity", "capped_velocity", "first_exit"]

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
        return bool(np.isfinite(self.max_approach_speed))


def first_exit(margins: np.ndarray, rates: np.ndarray, tol: float = BOUNDARY_TOLERANCE) -> VelocityLimit:
    """Largest s >= 0 with ``margins[k] - s * rates[j, k] >= 0`` for all j, k.

    Args:
        margins: (n_c,) slack of the starting point in each half-plane.
        rates: (n_v, n_c) rate at which vertex j uses up half-plane k's slack.
    """
    if np.any(margins < -tol):
        return VelocityLimit(0.0, "already_falling")
    positive = rates > tol * max(1.0, float(np.abs(rates).max(initial=0.0)))
    if not positive.any():
        return VelocityLimit(float("inf"), "unbounded")
    with np.errstate(divide="ignore", invalid="ignore"):
        ratios = np.where(positive, np.maximum(margins, 0.0) / rates, np.inf)
    flat = int(np.argmin(ratios))
    j, k = divmod(flat, rates.shape[1])
    return VelocityLimit(float(ratios.flat[flat]), "ok", j, k)


def max_contact_velocity(area: Polygon, impact: ImpactModel, com_velocity: Sequence[float]) -> VelocityLimit:
    """Largest approach speed keeping every post-impact CoM velocity in ``area`` (m/s)."""
    if area.is_empty:
        return VelocityLimit(0.0, "cannot_balance")
    G, h = area.halfplanes
    c0 = np.asarray(com_velocity, dtype=float)[:2]
    return first_exit(h - G @ c0, impact.com_jump_rates @ G.T)


def zmp_max_contact_velocity(
    zmp_area: Polygon, impact: ImpactModel, com: np.ndarray, plane_height: float, gravity: float, duration: float
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
    # Numerator N(F) = (-tau_y + h f_x, tau_x + h f_y), linear in F; N(0) = m g c_xy.
    forces = impact.impulse_rates / duration  # (2N, 3) force per unit approach speed
    tau = np.cross(p, forces)
    numer = np.column_stack([-tau[:, 1] + plane_height * forces[:, 0], tau[:, 0] + plane_height * forces[:, 1]])
    margins = weight * (h - G @ np.asarray(com, dtype=float)[:2])
    rates = numer @ G.T - forces[:, 2:3] * h[None, :]
    limit = first_exit(margins, rates)
    # The ZMP exists only while the vertical force stays positive (no lift-off).
    pulling = forces[:, 2] < 0
    if limit.status != "already_falling" and pulling.any():
        lift = float(np.min(weight / -forces[pulling, 2]))
        if lift < limit.max_approach_speed:
            j = int(np.flatnonzero(pulling)[np.argmin(weight / -forces[pulling, 2])])
            return VelocityLimit(lift, "ok", j, None)
    return limit


def capped_velocity(reference: Sequence[float], normal: np.ndarray, max_approach_speed: float) -> np.ndarray:
    """``reference`` with its approach component -n.v capped at ``max_approach_speed``.

    This is the minimiser of ||v - v_ref|| subject to -n.v <= max (the paper's QP objective).
    """
    v = np.asarray(reference, dtype=float).copy()
    excess = -(normal @ v) - max_approach_speed
    if np.isfinite(max_approach_speed) and excess > 0:
        v += excess * normal
    return v
