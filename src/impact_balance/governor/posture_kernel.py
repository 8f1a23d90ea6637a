"""A governor's compiled postures: from pinocchio's arrays to the areas, impact model and cap.

After pinocchio (the contacts' poses and Jacobians, the CoM, the centroidal momentum matrix, the
composite inertia), :func:`kinematics_posture_kernel` makes the contact points, lever arms, CoM,
CoM Jacobian, g(q) and impact point, and runs the one compiled posture,
:func:`~impact_balance.criteria.posture_kernel.posture_kernel` (the one
:func:`~impact_balance.analyze` runs: areas, impact model and criterion rates at once);
:func:`postures_kernel` does that and the tick's exit for every row of a batch. Where the
posture kernel answers :data:`~impact_balance.criteria.posture_kernel.FALLBACK`, the caller takes
the one-posture path, which answers (or raises) as :func:`~impact_balance.analyze` does.
"""

from __future__ import annotations

import math

import numpy as np

from impact_balance._jit import cache_depends_on, njit
from impact_balance.balance import areas
from impact_balance.contacts import wrench_polytope
from impact_balance.criteria import com, linear_exit
from impact_balance.criteria import posture_kernel as posture
from impact_balance.criteria.linear_exit import exit_kernel, interval_kernel
from impact_balance.criteria.posture_kernel import posture_kernel
from impact_balance.geometry import polygon
from impact_balance.impact import model
from impact_balance.projection import kernel, walk

__all__ = ["kinematics_posture_kernel", "postures_kernel"]


@njit(cache=True)
def kinematics_posture_kernel(
    faces: np.ndarray,
    rotations: np.ndarray,
    local: np.ndarray,
    origin: np.ndarray,
    com_local: np.ndarray,
    centroidal: np.ndarray,
    gravity_vector: np.ndarray,
    torques: bool,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    mass: float,
    gravity: float,
    plane_height: float,
    w: float,
    hint: np.ndarray,
    max_pivots: int,
    constants: np.ndarray,
    point_local: np.ndarray,
    inertia: np.ndarray,
    normal: np.ndarray,
    cone: np.ndarray,
) -> tuple:  # type: ignore[type-arg]
    """The compiled posture from pinocchio's arrays, with what a posture keeps of them.

    :func:`~impact_balance.criteria.posture_kernel.posture_kernel` after the contact points,
    lever arms, CoM, CoM Jacobian, g(q) and impact point.

    Args:
        faces: (m, 16, 6) the contacts' CWC faces in their frames.
        rotations: (m, 3, 3) the contacts' contact-to-world rotations.
        local: (m, 3) the contact points, stance frame (origin at ``origin``), m.
        origin: (3,) the stance frame's origin in world, m.
        com_local: (3,) the CoM, stance frame, m.
        centroidal: (6, nv) the centroidal momentum matrix (linear rows first: m J_com).
        gravity_vector: (3,) the model's gravity, world, m/s^2.
        torques: Whether the torque limits bound the wrenches.
        jacobians: (6m, nv) the contacts' stacked Jacobians ((0, 0) without torques).
        torque_indices: The torque-limited joints' velocity indices.
        torque_limits: Their limits, N m.
        mass: kg.
        gravity: g, m/s^2.
        plane_height: h, m.
        w: omega, 1/s.
        hint: The walk's warm start (read and written).
        max_pivots: The walk's pivot bound.
        constants: :func:`~impact_balance.criteria.posture_kernel.constants`.
        point_local: (3,) the impact point, stance frame, m.
        inertia: (3, 3) the composite rotational inertia about the CoM, world axes, kg m^2.
        normal: (3,) the impact normal.
        cone: (3, N) the impact's friction-cone generators.

    Returns:
        The posture kernel's answer and ``(com, com_jacobian, point)``: the CoM (3,), world, m;
        ``J_com`` (3, nv, column-major as numpy's ``Ag[:3] / m``); the impact point (3,),
        world, m. The numbers of the array expressions of
        :meth:`~impact_balance.governor.posture.PostureEvaluator.kinematics` (``g(q)`` by
        BLAS's product, as numpy's).
    """
    m, nv = local.shape[0], centroidal.shape[1]
    positions, arms = np.empty((m, 3)), np.empty((m, 3))
    com, arm, point = np.empty(3), np.empty(3), np.empty(3)
    for c in range(3):
        for i in range(m):
            positions[i, c] = local[i, c] + origin[c]
            arms[i, c] = local[i, c] - com_local[c]
        com[c] = com_local[c] + origin[c]
        arm[c] = point_local[c] - com_local[c]
        point[c] = point_local[c] + origin[c]
    linear = np.asfortranarray(centroidal[:3])  # m J_com
    com_jacobian = np.empty((nv, 3)).T
    for r in range(3):
        for i in range(nv):
            com_jacobian[r, i] = linear[r, i] / mass
    # g(q) = -Ag[:3]^T g (see PostureEvaluator.kinematics)
    gravity_torques = -np.dot(gravity_vector, linear) if torques else np.zeros(nv)
    answer = posture_kernel(
        faces, rotations, positions, arms, jacobians, torque_indices, torque_limits,
        gravity_torques, mass * gravity, plane_height - com[2], com[0], com[1], w, hint,
        max_pivots, constants, arm, mass, inertia, normal, cone,
    )  # fmt: skip
    return answer + (com, com_jacobian, point)  # noqa: RUF005 (numba: tuple concatenation)


cache_depends_on(
    kinematics_posture_kernel, areas, polygon, walk, kernel, wrench_polytope, model, com, posture
)


@njit(cache=True, nogil=True)
def postures_kernel(
    faces: np.ndarray,
    rotations: np.ndarray,
    local: np.ndarray,
    origins: np.ndarray,
    com_locals: np.ndarray,
    centroidal: np.ndarray,
    gravity_vector: np.ndarray,
    torques: bool,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    scalars: np.ndarray,
    hint: np.ndarray,
    max_pivots: int,
    constants: np.ndarray,
    point_locals: np.ndarray,
    inertias: np.ndarray,
    normal: np.ndarray,
    cone: np.ndarray,
    velocities: np.ndarray,
    same: np.ndarray,
    codes: np.ndarray,
    speeds: np.ndarray,
    vertices: np.ndarray,
    edges: np.ndarray,
    intervals: np.ndarray,
    com_velocities: np.ndarray,
    points: np.ndarray,
    max_speed_squared: float,
) -> int:
    """:func:`kinematics_posture_kernel` and the tick's exit for every posture of a batch.

    The GIL is released. Row i (of ``same``, ``velocities``, the outputs) has the generalized
    velocity ``velocities[i]`` (nv,) and the posture of row i - 1 where ``same[i]``, else the
    next posture of the per-posture arguments (leading axis: the rows where ``same`` is
    false, in order): :func:`kinematics_posture_kernel`'s ``rotations`` (m, 3, 3), ``local``
    (m, 3), ``origins`` and ``com_locals`` (3,), ``centroidal`` (6, nv), ``jacobians`` (6m, nv)
    or (0, 0), ``point_locals`` (3,), ``inertias`` (3, 3), ``scalars`` (mass kg, g m/s^2, plane
    height m, omega 1/s, velocity margin m/s, boundary tolerance; row 0 holds the common
    ones).

    Writes ``com_velocities[i]`` (J_com v, m/s, BLAS's product as a tick's), ``points[i]`` (the
    impact point, m) and the numbers of a governor's tick
    (:func:`~impact_balance.governor.tick.velocity_exit`): ``codes[i]`` (int64: the exit
    kernel's code, an index of ``EXIT_STATUSES``), ``speeds[i]`` (m/s: 0 already falling, inf
    unbounded), ``vertices[i]`` and ``edges[i]`` (int64, -1 but for code 0) and
    ``intervals[i]`` (the safe interval ``(lo, hi)``, m/s, NaN when there is none); or
    ``codes[i] = -1`` where the caller takes the one-posture path (the other outputs of the row
    are then not written).

    Returns the first row whose CoM speed squared is not at most ``max_speed_squared``
    ((m/s)^2, the single tick's test), -1 if none. Only the first ``same.size`` rows are read
    and written; the per-posture arguments may have more (unused) leading entries.
    """
    gravity, plane_height = scalars[0, 1], scalars[0, 2]
    velocity_margin, tol = scalars[0, 4], scalars[0, 5]
    G, h, rates = np.empty((0, 2)), np.empty(0), np.empty((0, 0))
    J, point = np.zeros((velocities.shape[1], 3)).T, np.zeros(3)
    answered = False  # whether G, h, rates hold the last posture's
    p = -1  # the posture of row i
    too_fast = -1
    for i in range(same.size):
        codes[i] = -1
        if not same[i]:
            p += 1
            answer = kinematics_posture_kernel(
                faces, rotations[p], local[p], origins[p], com_locals[p], centroidal[p],
                gravity_vector, torques, jacobians[p], torque_indices, torque_limits,
                scalars[p, 0], gravity, plane_height, scalars[p, 3], hint, max_pivots,
                constants, point_locals[p], inertias[p], normal, cone,
            )  # fmt: skip
            answered = answer[0] == 0
            G, h, rates, J, point = answer[7], answer[8], answer[11], answer[13], answer[14]
            if answered and velocity_margin:
                h = h - velocity_margin
        c = np.dot(J, velocities[i])
        com_velocities[i, 0], com_velocities[i, 1], com_velocities[i, 2] = c[0], c[1], c[2]
        if too_fast < 0 and not c[0] * c[0] + c[1] * c[1] + c[2] * c[2] <= max_speed_squared:
            too_fast = i
        points[i, 0], points[i, 1], points[i, 2] = point[0], point[1], point[2]
        if answered:
            margins = np.empty(h.size)
            for k in range(h.size):
                margins[k] = h[k] - (G[k, 0] * c[0] + G[k, 1] * c[1])
            code, speed, vertex, edge = exit_kernel(margins, rates, tol)
            codes[i], speeds[i], vertices[i], edges[i] = code, speed, vertex, edge
            intervals[i, 0], intervals[i, 1] = 0.0, speed
            if code == 1:  # already falling: the safe speeds, if any, catch the fall
                found, lo, hi = interval_kernel(margins, rates, tol)
                intervals[i, 0], intervals[i, 1] = (lo, hi) if found else (math.nan, math.nan)
    return too_fast


cache_depends_on(
    postures_kernel,
    areas,
    polygon,
    walk,
    kernel,
    wrench_polytope,
    model,
    com,
    linear_exit,
    posture,
)
