"""One posture's areas, impact model and criterion rates in one compiled call.

From a posture's arrays (the contacts' faces, rotations, points and lever arms, the Jacobians
and g(q) of the torque limits, the CoM, the composite inertia and the impact point), the
pipeline's compiled steps composed in one call instead of four: the contact wrench polytope's
assembly, the certified projection walk and the maps to the ZMP and CoM velocity areas with the
area's half-planes (:data:`~impact_balance.balance.areas.assembled_areas`, from the faces in
world axes of :func:`~impact_balance.contacts.wrench_polytope.face_blocks`), the
composite-rigid-body impact map W and the impulse rates
(:data:`~impact_balance.impact.model.composite_map_kernel`,
:data:`~impact_balance.impact.model.impulse_rates_kernel`), and the CoM criterion's jump rates
(:data:`~impact_balance.criteria.com.jump_rates_kernel`): the same numbers as the steps one by
one, fewer dispatches and fewer arrays handed back to Python. :func:`~impact_balance.analyze`
calls it from a stance's arrays, a governor from pinocchio's
(:func:`~impact_balance.governor.posture_kernel.kinematics_posture_kernel`).

It answers the common case only: a certified walk whose CoM velocity area has 3 vertices or
more, a positive definite composite inertia and an impact cone that separates the contact.
Otherwise it says so (:data:`FALLBACK`) and the caller takes the steps one by one, which answer
(or raise) as they always do.
"""

from __future__ import annotations

import numpy as np

from impact_balance._jit import cache_depends_on, njit
from impact_balance.balance import areas
from impact_balance.balance.areas import FORCE_BOX, MERGE_TOLERANCE, assembled_areas
from impact_balance.contacts import wrench_polytope
from impact_balance.criteria import com
from impact_balance.criteria.com import jump_rates_kernel
from impact_balance.geometry import polygon
from impact_balance.geometry.polygon import MERGE_AREA_TOLERANCE
from impact_balance.impact import model
from impact_balance.impact.model import composite_map_kernel, impulse_rates_kernel
from impact_balance.projection import kernel, walk
from impact_balance.projection.kernel import OK

__all__ = ["FALLBACK", "SEPARATION", "constants", "posture_kernel"]

#: :func:`posture_kernel`'s first answer when the caller must take the one-posture path.
FALLBACK = 1
#: The smallest normal response ``n^T W K_i`` an impact cone edge may have (the impact model's).
SEPARATION = 1e-12


@njit(cache=True)
def posture_kernel(
    faces: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    weight: float,
    depth: float,
    cx: float,
    cy: float,
    w: float,
    hint: np.ndarray,
    max_pivots: int,
    constants: np.ndarray,
    arm: np.ndarray,
    mass: float,
    inertia: np.ndarray,
    normal: np.ndarray,
    cone: np.ndarray,
) -> tuple:  # type: ignore[type-arg]
    """One posture's areas, impact model and CoM criterion rates.

    Args:
        faces: (m, 16, 6) the contacts' CWC faces in their frames.
        rotations: (m, 3, 3) the contacts' contact-to-world rotations.
        positions: (m, 3) the contact points, world, m.
        arms: (m, 3) contact point minus CoM, m.
        jacobians: (6m, nv) the contacts' stacked Jacobians ((0, 0) without torque limits).
        torque_indices: The torque-limited joints' velocity indices.
        torque_limits: Their limits, N m.
        gravity_torques: (nv,) g(q), N m.
        weight: m g, N.
        depth: h - c_z, m (< 0).
        cx: The CoM's x, world, m.
        cy: The CoM's y, world, m.
        w: omega, 1/s.
        hint: The walk's warm start (read and written).
        max_pivots: The walk's pivot bound.
        constants: The force box (units of m g), the merge's tolerances (units of m g, and of
            area), the ZMP margin (m), the restitution bounds (lo, hi): :func:`constants`.
        arm: (3,) impact point minus CoM, m.
        mass: kg.
        inertia: (3, 3) the composite rotational inertia about the CoM, world axes, kg m^2.
        normal: (3,) the impact normal.
        cone: (3, N) the impact's friction-cone generators.

    Returns:
        ``(code, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h, W, impulse_rates,
        rates)``: ``code`` 0, or :data:`FALLBACK` (the rest is then not to be read); the
        areas as :func:`~impact_balance.balance.areas.projected_from_arrays` makes them
        (``G``, ``h`` the CoM velocity area's half-planes), the
        impact map W (1/kg), the impulse rates (2N, 3) and the criterion's rates (2N, n_c).
    """
    box, merge_tol, area_tol, zmp_margin, lo, hi = constants
    blocks = np.empty((faces.shape[0], 32, 3))
    for i in range(faces.shape[0]):  # face_blocks: BLAS's product, as numpy's (the same numbers)
        blocks[i] = np.dot(faces[i].reshape(32, 3), rotations[i].T)
    out = assembled_areas(
        blocks, positions, arms, jacobians, torque_indices, torque_limits, gravity_torques,
        weight, box, max_pivots, merge_tol, area_tol, depth, cx, cy, w, zmp_margin, hint,
    )  # fmt: skip
    status, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h = out[5:]
    W = np.empty((3, 3))
    impulse, rates = np.empty((0, 3)), np.empty((0, 0))
    code = FALLBACK
    if status == OK and force.shape[0] > 0 and G.shape[0] > 0:
        if composite_map_kernel(arm, mass, inertia, W):
            finite, smallest, impulse = impulse_rates_kernel(normal, W, cone, lo, hi)
            if finite and smallest > SEPARATION:
                rates = jump_rates_kernel(impulse, mass, G)
                code = 0
    return code, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h, W, impulse, rates


def constants(zmp_margin: float, restitution: tuple[float, float]) -> np.ndarray:
    """:func:`posture_kernel`'s ``constants`` for a ZMP margin (m) and restitution bounds."""
    lo, hi = restitution
    return np.array(
        [FORCE_BOX, MERGE_TOLERANCE, MERGE_AREA_TOLERANCE, zmp_margin, lo, hi], dtype=float
    )


cache_depends_on(posture_kernel, areas, polygon, walk, kernel, wrench_polytope, model, com)
