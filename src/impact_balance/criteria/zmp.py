"""The ZMP criterion (paper Experiment 1): :class:`ZmpCriterion`.

The impulsive force ``F = iota / dt`` at the impact point is added to the
gravity-compensating wrench (m g up, through the CoM). The predicted ZMP
``z = N(F) / (m g + F_z)`` stays in ``{G z <= h}`` iff ``G N(F) <= h (m g + F_z)`` while
``m g + F_z > 0``: linear in the approach speed per vertex and per edge, so the maximum
contact velocity is exact, as the CoM criterion's. The answer does not depend on the CoM
velocity.
"""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from impact_balance._jit import cache_depends_on, njit
from impact_balance.criteria import linear_exit
from impact_balance.criteria.criterion import CriterionName
from impact_balance.criteria.linear_exit import BOUNDARY_TOLERANCE, exit_kernel, limit_of_exit
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.geometry import polygon
from impact_balance.geometry.polygon import Polygon, edge_halfplanes
from impact_balance.impact.model import ImpactModel

__all__ = ["ZmpCriterion", "zmp_exit_kernel", "zmp_max_contact_velocity"]


class ZmpCriterion:
    """The ZMP criterion of one ZMP support area, one impact model and one CoM.

    Attributes:
        name: "zmp".
        zmp_area: ZMP support area (world x, y on the plane), m.
        impact: The impact model.
        com: CoM (3,), world, m.
        plane_height: h, the height of the ZMP plane, m.
        gravity: m/s^2.
        duration: Impact duration dt, s (impulsive force = impulse / dt).
    """

    name: ClassVar[CriterionName] = "zmp"

    def __init__(
        self,
        zmp_area: Polygon,
        impact: ImpactModel,
        com: npt.ArrayLike,
        plane_height: float,
        gravity: float,
        duration: float,
    ):
        self.zmp_area = zmp_area
        self.impact = impact
        self.com = np.asarray(com, dtype=float)
        self.plane_height = plane_height
        self.gravity = gravity
        self.duration = duration

    def limit(self, com_velocity: npt.ArrayLike = (0.0, 0.0)) -> ContactVelocityLimit:
        """Largest approach speed keeping the predicted ZMP in the ZMP area.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s: not used (the ZMP criterion
                does not depend on it).

        Returns:
            The limit (m/s); "cannot_balance" (0) for an empty area, "already_falling" (0)
            when the CoM's vertical is outside the area.
        """
        return zmp_max_contact_velocity(
            self.zmp_area,
            self.impact,
            self.com,
            self.plane_height,
            self.gravity,
            self.duration,
        )


def zmp_max_contact_velocity(
    zmp_area: Polygon,
    impact: ImpactModel,
    com: npt.ArrayLike,
    plane_height: float,
    gravity: float,
    duration: float,
) -> ContactVelocityLimit:
    """Largest approach speed keeping the predicted ZMP in ``zmp_area`` (paper Experiment 1).

    Args:
        zmp_area: ZMP support area (world x, y on the plane), m.
        impact: The impact model.
        com: CoM (3,), world, m.
        plane_height: h, the height of the ZMP plane, m.
        gravity: m/s^2.
        duration: Impact duration dt, s (impulsive force = impulse / dt).

    Returns:
        The limit (m/s); "cannot_balance" (0) for an empty area, "already_falling" (0)
        when the CoM's vertical is outside the area; the lift-off bound (no limiting edge)
        when the impulse would lift the robot first.
    """
    if zmp_area.is_empty:
        return ContactVelocityLimit(0.0, "cannot_balance")
    c = np.asarray(com, dtype=float)
    rest = (
        float(impact.mass * gravity), np.ascontiguousarray(impact.point, dtype=float),
        float(c[0]), float(c[1]), float(plane_height), float(duration),
        np.ascontiguousarray(impact.impulse_rates, dtype=float), BOUNDARY_TOLERANCE,
    )  # fmt: skip
    vertices = zmp_area.vertices
    if len(vertices) >= 3:  # the half-planes in the same call: the polygon's own numbers
        code, speed, j, k = _area_exit(np.ascontiguousarray(vertices, dtype=float), *rest)
    else:  # a segment's or a point's bounds
        G, h = zmp_area.halfplanes
        code, speed, j, k = zmp_exit_kernel(G, h, *rest)
    if code == 0 and k < 0:  # the lift-off bound: no limiting edge
        return ContactVelocityLimit(speed, "ok", j, None)
    return limit_of_exit(code, speed, j, k)


@njit(cache=True)
def zmp_exit_kernel(
    G: np.ndarray,
    h: np.ndarray,
    weight: float,
    point: np.ndarray,
    cx: float,
    cy: float,
    plane_height: float,
    duration: float,
    impulse_rates: np.ndarray,
    tol: float,
) -> tuple[int, float, int, int]:
    """:func:`zmp_max_contact_velocity` of a non-empty area: ``(code, speed, vertex, edge)``.

    ``code`` is an index of :data:`~impact_balance.criteria.linear_exit.EXIT_STATUSES`, as
    :func:`~impact_balance.criteria.linear_exit.exit_kernel` answers; ``edge`` is -1 (with
    code 0) when the lift-off bound is the answer (its ``vertex`` is the pulling impulse row).

    With F = iota / dt at the impact point p, ``N(F) - m g c_xy = (h_plane - p_z) F_xy + F_z
    p_xy``, so half-plane k (``G_k z <= h_k``) is used up at the rate ``iota . M_k`` per unit
    approach speed, with ``M_k = [(h_plane - p_z) G_k, G_k p_xy - h_k] / dt``, from the margin
    ``m g (h_k - G_k c_xy)``. The ZMP exists only while the vertical force stays positive: an
    impulse row pulling up (``iota_z < 0``) lifts the robot at ``m g / (-iota_z / dt)``, the
    answer when it comes first (the first such row on a tie). Matrix products are BLAS's, as
    numpy's ``@`` (the same numbers, compiled or not).

    Args:
        G: (k, 2) the ZMP area's unit outward edge normals.
        h: (k,) their offsets, m.
        weight: m g, N.
        point: (3,) the impact point, world, m.
        cx: The CoM's x, world, m.
        cy: The CoM's y, world, m.
        plane_height: The ZMP plane's height, m.
        duration: The impact's duration dt, s.
        impulse_rates: (n, 3) the impulse per unit approach speed, N s per m/s.
        tol: The boundary tolerance of the exit.

    Returns:
        ``(code, speed, vertex, edge)``: speed in m/s.
    """
    n = h.size
    M = np.empty((3, n))
    scale = (plane_height - float(point[2])) / duration
    p = np.empty(2)
    p[0], p[1] = point[0], point[1]
    c = np.empty(2)
    c[0], c[1] = cx, cy
    Gp = np.dot(G, p)
    Gc = np.dot(G, c)
    margins = np.empty(n)
    for k in range(n):
        M[0, k] = scale * G[k, 0]
        M[1, k] = scale * G[k, 1]
        M[2, k] = (Gp[k] - h[k]) / duration
        margins[k] = weight * (h[k] - Gc[k])
    code, speed, vertex, edge = exit_kernel(margins, np.dot(impulse_rates, M), tol)
    if code == 1:
        return code, speed, vertex, edge
    best, row = math.inf, -1
    for j in range(impulse_rates.shape[0]):
        fz = float(impulse_rates[j, 2]) / duration  # N per (m/s)
        if fz < 0.0:
            lift = weight / -fz  # a vanishing pull (friction ~1e-300) never lifts: inf
            if math.isnan(lift):  # numpy's argmin: the first NaN, never below the limit
                return code, speed, vertex, edge
            if row < 0 or lift < best:
                best, row = lift, j
    if row >= 0 and best < (speed if code == 0 else math.inf):
        return 0, best, row, -1
    return code, speed, vertex, edge


@njit(cache=True)
def _area_exit(
    vertices: np.ndarray,
    weight: float,
    point: np.ndarray,
    cx: float,
    cy: float,
    plane_height: float,
    duration: float,
    impulse_rates: np.ndarray,
    tol: float,
) -> tuple[int, float, int, int]:
    """:func:`zmp_exit_kernel` of the polygon of ``vertices`` (k >= 3, CCW).

    Its half-planes are :func:`~impact_balance.geometry.polygon.edge_halfplanes`' (the
    polygon's :attr:`~impact_balance.geometry.polygon.Polygon.halfplanes`).
    """
    G, h = edge_halfplanes(vertices)
    return zmp_exit_kernel(G, h, weight, point, cx, cy, plane_height, duration, impulse_rates, tol)


cache_depends_on(zmp_exit_kernel, linear_exit)
cache_depends_on(_area_exit, linear_exit, polygon)
