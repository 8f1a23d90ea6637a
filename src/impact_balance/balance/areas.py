"""The ZMP support area and the CoM velocity area of a stance (paper sec. IV).

Under the LIPM constraints the moment about the CoM is zero, so the resultant force passes
through the CoM and meets the plane ``z = h`` at the ZMP

    zmp = c_xy + (h - c_z) / (m g) * f_xy,

and the zero-step capture condition (the DCM stays in the ZMP support area) gives the CoM
velocity area ``{ omega (zmp - c_xy) }``, omega = sqrt(g / (c_z - h)). Both areas are affine
images of ONE projection: the set of feasible resultant horizontal forces, obtained by
projecting the contact-wrench polytope (:mod:`impact_balance.contacts.wrench_polytope`).

A ZMP margin ``M`` (m) shrinks the ZMP support area to the points at least ``M`` inside its
edges (:meth:`~impact_balance.geometry.polygon.Polygon.inset`), as a controller that keeps
its ZMP away from the edges does; the CoM velocity area follows (it is the same set, scaled
by omega).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

import numpy as np

from impact_balance._jit import cache_depends_on, njit
from impact_balance.balance.infeasibility import CannotBalanceReason, explain_cannot_balance
from impact_balance.balance.lipm import lipm_omega
from impact_balance.constants import GRAVITY
from impact_balance.contacts import wrench_polytope as constraints
from impact_balance.contacts.stance import Stance
from impact_balance.contacts.wrench_polytope import (
    WrenchPolytope,
    assemble_arrays,
    assemble_polytope,
    face_blocks,
    friction_scaling,
    wrench_polytope,
)
from impact_balance.exceptions import SolverError
from impact_balance.geometry import polygon
from impact_balance.geometry.polygon import (
    MERGE_AREA_TOLERANCE,
    Polygon,
    edge_halfplanes,
    inset_polygon,
)
from impact_balance.projection import kernel, project_polytope, walk
from impact_balance.projection.kernel import LINE, OK
from impact_balance.projection.walk import MAX_PIVOTS, NO_HINT, certified_walk

__all__ = [
    "FORCE_BOX",
    "FORCE_TOLERANCE",
    "MERGE_TOLERANCE",
    "BalanceAreas",
    "Projected",
    "areas_from_arrays",
    "areas_from_polytope",
    "assembled_areas",
    "balance_areas",
    "posture_areas",
    "projected_from_arrays",
    "warm_up",
    "with_reason",
]

#: Projection tolerance on the resultant horizontal force, as a fraction of m g.
FORCE_TOLERANCE = 1e-8
#: Vertices closer than this (units of m g) to a neighbour or to the line through their
#: neighbours are merged: a kink of 1e-6 (c_z - h) m ~ 1 micron in the ZMP area is noise of
#: the model (e.g. feet aligned to 1e-7 m by IK), not a feature.
MERGE_TOLERANCE = 1e-6
#: Clipping box on the resultant horizontal force for unbounded directions, in units of m g.
FORCE_BOX = 1e3


@dataclass(frozen=True)
class BalanceAreas:
    """Both areas of a stance.

    Attributes:
        force_area: Feasible resultant horizontal forces divided by m g (dimensionless).
        zmp_area: ZMP support area, world (x, y) on the plane, m.
        com_velocity_area: CoM velocity area (zero-step capture region), world axes, m/s.
        omega: LIPM natural frequency, 1/s.
        com: CoM, m.  plane_height: h, m.  mass: kg.  gravity: m/s^2.
        n_lp: LPs solved by the projection.
        reason: Why the stance cannot balance when the areas are empty and they were
            computed from a stance (:func:`balance_areas`, :func:`~impact_balance.analyze`);
            None otherwise. See :mod:`impact_balance.balance.infeasibility`.
        zmp_margin: The margin (m) by which ``zmp_area`` (and so ``com_velocity_area``) was
            shrunk; ``force_area`` is the projection itself, without it.
    """

    force_area: Polygon
    zmp_area: Polygon
    com_velocity_area: Polygon
    omega: float
    com: np.ndarray
    plane_height: float
    mass: float
    gravity: float
    n_lp: int = 0
    reason: CannotBalanceReason | None = None
    zmp_margin: float = 0.0

    @property
    def can_balance(self) -> bool:
        """False when the stance cannot hold the robot at rest (empty areas)."""
        return not self.com_velocity_area.is_empty

    def com_velocity_area_inset(self, margin: float) -> Polygon:
        """The CoM velocity area of ``zmp_area`` shrunk by ``margin`` more metres.

        What a controller that keeps its ZMP that far inside can use; empty when nothing is left.
        """
        return _velocity_area(self.zmp_area.inset(margin), self.omega, self.com)

    @property
    def zmp_area_without_margin(self) -> Polygon:
        """The ZMP support area before the margin (equal to ``zmp_area`` when it is 0)."""
        if self.zmp_margin == 0.0 or self.force_area.is_empty:
            return self.zmp_area
        return self.force_area.affine(self.plane_height - float(self.com[2]), self.com[:2])


def _velocity_area(zmp: Polygon, w: float, com: np.ndarray) -> Polygon:
    """The CoM velocity area of ZMP support area ``zmp``: ``w (z - c_xy)`` over its points z."""
    return Polygon.empty() if zmp.is_empty else zmp.affine(w, -w * com[:2])


def areas_from_polytope(
    polytope: WrenchPolytope, plane_height: float = 0.0, zmp_margin: float = 0.0
) -> BalanceAreas:
    """Project a contact-wrench polytope and map it to the ZMP and CoM velocity areas.

    The ZMP support area is shrunk by ``zmp_margin`` (m).
    """
    com = polytope.com
    w = lipm_omega(float(com[2]), plane_height, polytope.gravity, field="plane_height")
    depth = plane_height - float(com[2])  # < 0
    # Work in units of m g so that tolerances mean the same for every robot, and in
    # friction-normalised variables so that a large or small friction keeps full precision.
    A, b, C, d, E = (np.ascontiguousarray(x, dtype=np.float64) for x in polytope.projection_data())
    # The walk, its certificate and both maps in one compiled call (a governor's every tick).
    walked = _walk_areas(
        A,
        b,
        C,
        d,
        E,
        FORCE_BOX,
        MAX_PIVOTS,
        MERGE_TOLERANCE,
        MERGE_AREA_TOLERANCE,
        depth,
        float(com[0]),
        float(com[1]),
        w,
        float(zmp_margin),
        NO_HINT,
    )
    return _projected(
        walked,
        (A, b, C, d, E),
        com,
        w,
        plane_height,
        polytope.mass,
        polytope.gravity,
        float(zmp_margin),
    ).areas()


def areas_from_arrays(
    faces: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    mass: float,
    com: np.ndarray,
    gravity: float,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    plane_height: float = 0.0,
    zmp_margin: float = 0.0,
) -> BalanceAreas:
    """``areas_from_polytope(assemble_polytope(...))`` in one compiled call.

    For contacts whose frictions are all at most 1 (no friction scaling): a governor's every
    tick.

    The arguments are :func:`~impact_balance.contacts.wrench_polytope.assemble_polytope`'s
    (``faces`` (m, 16, 6); ``com`` (3,) world, m), then the plane height (m) and the ZMP
    margin (m).
    """
    return projected_from_arrays(
        faces,
        rotations,
        positions,
        arms,
        mass,
        com,
        gravity,
        jacobians,
        torque_indices,
        torque_limits,
        gravity_torques,
        plane_height,
        zmp_margin,
    ).areas()


def posture_areas(
    faces: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    mass: float,
    com: np.ndarray,
    gravity: float,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    frictions: Sequence[float],
    plane_height: float = 0.0,
    zmp_margin: float = 0.0,
    hint: np.ndarray | None = None,
) -> BalanceAreas | Projected:
    """The areas step of one posture, from its arrays: what a governor and ``analyze()`` run.

    Contacts whose frictions are all at most 1: :func:`projected_from_arrays` (assembly,
    walk and maps in one compiled call); else the polytope in friction-normalised variables
    (:func:`~impact_balance.contacts.wrench_polytope.assemble_polytope` with
    :func:`~impact_balance.contacts.wrench_polytope.friction_scaling`) and
    :func:`areas_from_polytope`. Bretl's projection answers where the walk does not, as there.

    The arguments are :func:`~impact_balance.contacts.wrench_polytope.assemble_polytope`'s
    (``faces`` (m, 16, 6); ``positions`` (m, 3) world and ``arms`` (m, 3) contact point minus
    CoM, m; ``com`` (3,) world, m), the contacts' frictions, the plane height (m), the ZMP
    margin (m) and the walk's warm start (see :func:`projected_from_arrays`).

    Raises:
        ScenarioError: The plane is not below the CoM. SolverError: The projection failed.
    """
    arrays = (
        faces,
        rotations,
        positions,
        arms,
        mass,
        com,
        gravity,
        jacobians,
        torque_indices,
        torque_limits,
        gravity_torques,
    )
    if frictions and max(frictions) > 1.0:
        polytope = assemble_polytope(*arrays, friction_scaling(frictions, list(rotations)))
        return areas_from_polytope(polytope, plane_height, zmp_margin)
    return projected_from_arrays(*arrays, plane_height, zmp_margin, hint)


def projected_from_arrays(
    faces: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    mass: float,
    com: np.ndarray,
    gravity: float,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    plane_height: float = 0.0,
    zmp_margin: float = 0.0,
    hint: np.ndarray | None = None,
) -> Projected:
    """:func:`areas_from_arrays` before its :class:`BalanceAreas` is built.

    A governor's tick reads only the CoM velocity area; :meth:`Projected.areas` builds the rest
    on demand.

    ``hint``: an int64 array (2 + the number of wrench variables, e.g. 2 + 6 per contact) the
    walk reads its start from and writes its optimal basis to: one caller that projects
    postures in a row (a governor) keeps it between calls and saves the walk's crash start;
    the polygon is the same either way (to rounding).
    """
    if hint is None:
        hint = NO_HINT
    elif not (
        isinstance(hint, np.ndarray)
        and hint.dtype == np.int64
        and hint.ndim == 1
        and hint.flags.writeable
    ):
        raise ValueError(
            f"hint must be a writable 1-D int64 numpy array, not {type(hint).__name__} "
            f"{getattr(hint, 'dtype', '')}".rstrip()
        )
    w = lipm_omega(float(com[2]), plane_height, gravity, field="plane_height")
    depth = plane_height - float(com[2])
    positions = np.ascontiguousarray(positions, dtype=np.float64)  # no copy when they are
    arms = np.ascontiguousarray(arms, dtype=np.float64)
    jacobians = np.ascontiguousarray(jacobians, dtype=np.float64)
    torque_limits = np.ascontiguousarray(torque_limits, dtype=np.float64)
    gravity_torques = np.ascontiguousarray(gravity_torques, dtype=np.float64)
    out = _assembled_areas(
        face_blocks(faces, rotations),
        positions,
        arms,
        jacobians,
        np.ascontiguousarray(torque_indices, dtype=np.int64),
        torque_limits,
        gravity_torques,
        mass * gravity,
        FORCE_BOX,
        MAX_PIVOTS,
        MERGE_TOLERANCE,
        MERGE_AREA_TOLERANCE,
        depth,
        float(com[0]),
        float(com[1]),
        w,
        float(zmp_margin),
        hint,
    )
    return _projected(out[5:], out[:5], com, w, plane_height, mass, gravity, float(zmp_margin))


class Projected(NamedTuple):
    """One projection's areas as arrays.

    The CoM velocity area (with its half-planes) is a :class:`Polygon`; the rest is what
    :meth:`areas` needs to build the :class:`BalanceAreas`.

    ``force``, ``zmp`` (k, 2): the force area (units of m g) and the ZMP support area (world,
    m) vertices; ``w`` omega (1/s); ``com`` (3,) m; ``plane_height`` m; ``mass`` kg;
    ``gravity`` m/s^2; ``margin`` the ZMP margin, m.
    """

    force: np.ndarray
    bounded: bool
    zmp: np.ndarray
    zmp_bounded: bool
    com_velocity_area: Polygon
    n_lp: int
    w: float
    com: np.ndarray
    plane_height: float
    mass: float
    gravity: float
    margin: float

    def areas(self) -> BalanceAreas:
        """The :class:`BalanceAreas` (the same CoM velocity area object)."""
        return BalanceAreas(
            Polygon(self.force, self.bounded),
            Polygon(self.zmp, self.zmp_bounded),
            self.com_velocity_area,
            self.w,
            np.array(self.com, dtype=float),
            self.plane_height,
            self.mass,
            self.gravity,
            self.n_lp,
            zmp_margin=self.margin,
        )


def _projected(
    walked: tuple[Any, ...],
    data: tuple[Any, ...],
    com: np.ndarray,
    w: float,
    plane_height: float,
    mass: float,
    gravity: float,
    margin: float,
) -> Projected:
    """The areas from :func:`_walk_areas`' answer ``walked`` on the projection data ``data``.

    ``data`` is ``(A, b, C, d, E)``: where the walk cannot answer, project_polytope chooses as it
    always does, and the same compiled maps make the ZMP and CoM velocity areas.
    """
    status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h = walked
    n_lp = 1
    if status != OK or force.shape[0] == 0:
        A, b, C, d, E = data
        result = project_polytope(
            A,
            b,
            C,
            d,
            E,
            tol=FORCE_TOLERANCE,
            box=FORCE_BOX,
            merge_tol=MERGE_TOLERANCE,
            method="auto" if status == LINE else "bretl",
        )
        force, bounded, n_lp = result.polygon.vertices, result.polygon.bounded, result.n_lp
        zmp, zmp_bounded, vel, vel_bounded = _maps(
            np.ascontiguousarray(force),
            bounded,
            plane_height - float(com[2]),
            float(com[0]),
            float(com[1]),
            w,
            margin,
        )
        G = np.empty((0, 2))
    # The criterion reads the CoM velocity area's half-planes: the compiled call made them.
    velocity_area = (
        Polygon.with_halfplanes(vel, bool(vel_bounded), G, h)
        if len(G)
        else Polygon(vel, bool(vel_bounded))
    )
    return Projected(
        force,
        bool(bounded),
        zmp,
        bool(zmp_bounded),
        velocity_area,
        n_lp,
        w,
        com,
        plane_height,
        mass,
        gravity,
        margin,
    )


def warm_up() -> None:
    """Load the compiled map that the fallback path calls from Python.

    The fallback path (a walk refused, Bretl's polygon mapped in :func:`_projected`) calls it;
    numba loads a cached function on its first call. A governor calls this when it is built.
    """
    _maps(np.zeros((0, 2)), True, -1.0, 0.0, 0.0, 1.0, 0.0)


@njit(cache=True)
def _affine(v, scale, ox, oy):
    """:meth:`Polygon.affine`'s vertices ``v * scale + (ox, oy)``, the same numbers."""
    out = np.empty_like(v)
    for i in range(v.shape[0]):
        out[i, 0] = v[i, 0] * scale + ox
        out[i, 1] = v[i, 1] * scale + oy
    return out


@njit(cache=True)
def _maps(force, bounded, depth, cx, cy, w, margin):
    """The ZMP support area (shrunk by ``margin``) and the CoM velocity area of a force area.

    ``force``: vertices, units of m g. Returns ``(zmp, zmp_bounded, vel, vel_bounded)``, the
    numbers :class:`Polygon`'s ``affine`` and ``inset`` give (``depth`` = h - c_z, CoM
    ``(cx, cy)``).
    """
    empty = np.empty((0, 2))
    if force.shape[0] == 0:
        return empty, True, empty, True
    if not margin > 0.0:
        return _affine(force, depth, cx, cy), bounded, _affine(force, w * depth, 0.0, 0.0), bounded
    if force.shape[0] < 3:  # a point or a segment: nothing is a margin inside
        return empty, True, empty, True
    zmp = inset_polygon(_affine(force, depth, cx, cy), margin)
    if zmp.shape[0] == 0:
        return zmp, bounded, empty, True
    return zmp, bounded, _affine(zmp, w, -w * cx, -w * cy), bounded


@njit(cache=True)
def _walk_areas(
    A, b, C, d, E, box, max_pivots, merge_tol, area_tol, depth, cx, cy, w, margin, hint
):
    """:func:`~impact_balance.projection.walk.certified_walk` and :func:`_maps` in one call.

    Returns ``(status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h)``, ``G, h`` the
    CoM velocity area's half-planes when it has 3 vertices or more (else none).
    """
    status, force, bounded, _, _, _ = certified_walk(
        A, b, C, d, E, box, max_pivots, merge_tol, area_tol, hint
    )
    zmp, zmp_bounded, vel, vel_bounded = _maps(force, bounded, depth, cx, cy, w, margin)
    if vel.shape[0] >= 3:
        G, h = edge_halfplanes(vel)
    else:
        G, h = np.empty((0, 2)), np.empty(0)
    return status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h


@njit(cache=True)
def _assembled_areas(
    blocks,
    positions,
    arms,
    jacobians,
    torque_indices,
    torque_limits,
    gravity_torques,
    weight,
    box,
    max_pivots,
    merge_tol,
    area_tol,
    depth,
    cx,
    cy,
    w,
    margin,
    hint,
):
    """The polytope's arrays in units of m g, and :func:`_walk_areas` on them.

    The arrays are those of :func:`~impact_balance.contacts.wrench_polytope.assemble_polytope`,
    as ``WrenchPolytope.projection_data`` without scaling. Returns
    ``(A, b, C, d, E) + _walk_areas(...)``.
    """
    A, b, C, G = assemble_arrays(
        blocks, positions, arms, jacobians, torque_indices, torque_limits, gravity_torques
    )
    b = b / weight
    d = np.zeros(4)
    d[0] = weight / weight  # (m g, 0, 0, 0) / (m g)
    E = G[:2].copy()
    status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, Gv, hv = _walk_areas(
        A, b, C, d, E, box, max_pivots, merge_tol, area_tol, depth, cx, cy, w, margin, hint
    )
    return A, b, C, d, E, status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, Gv, hv


#: The compiled pipeline of one posture (assembly, walk, certificate, maps), for compiled callers
#: that run it in their own call (:mod:`impact_balance.criteria.posture_kernel`).
assembled_areas = _assembled_areas

# The compiled functions above embed the polygon module's, the walk's and the assembly's.
cache_depends_on(_maps, polygon)
cache_depends_on(_walk_areas, polygon, walk, kernel)
cache_depends_on(_assembled_areas, polygon, walk, kernel, constraints)


def balance_areas(
    stance: Stance,
    plane_height: float = 0.0,
    torque_limits: bool = True,
    gravity: float = GRAVITY,
    zmp_margin: float = 0.0,
) -> BalanceAreas:
    """ZMP support area (shrunk by ``zmp_margin``, m) and CoM velocity area of ``stance``."""
    # validate the plane before any work
    lipm_omega(float(stance.com[2]), plane_height, gravity, field="plane_height")
    areas = areas_from_polytope(
        wrench_polytope(stance, torque_limits, gravity), plane_height, zmp_margin
    )
    return with_reason(areas, stance, torque_limits, gravity)


def with_reason(
    areas: BalanceAreas, stance: Stance, torque_limits: bool, gravity: float
) -> BalanceAreas:
    """``areas`` with :attr:`BalanceAreas.reason` filled in when they are empty."""
    if areas.can_balance or areas.reason is not None:
        return areas
    if not areas.force_area.is_empty:  # the stance balances; the margin leaves nothing
        return dataclasses.replace(
            areas,
            reason=CannotBalanceReason(
                "zmp_margin",
                f"no point of the ZMP support area is {areas.zmp_margin:g} m "
                "(the ZMP margin) inside its edges",
            ),
        )
    try:
        reason = explain_cannot_balance(stance, torque_limits, gravity)
    except SolverError as exc:  # the areas are the answer; an explanation is a bonus
        reason = CannotBalanceReason("unknown", f"the diagnosis failed ({exc})")
    return dataclasses.replace(areas, reason=reason)
