"""The CoM velocity criterion of many postures in one compiled call: :func:`posture_exits`.

A planner or a sweep asks for the maximum contact velocity of N postures of one robot, one
set of contacts and one impact. Per posture, the Python side computes what pinocchio gives
(contact poses and Jacobians, CoM, g(q)) and the impact model; this call then runs, for every
posture, the same compiled steps as one posture's analysis: the contact-wrench polytope's
assembly, the certified projection walk and the maps to the CoM velocity area
(:func:`~impact_balance.balance.areas.assembled_areas`), the area's half-planes, the jump
rates and the first exit (:func:`~impact_balance.criteria.linear_exit.exit_kernel`), with the
same numbers. It releases the GIL (``nogil``): threads can share the postures.

A posture the walk does not certify (Bretl's projection answers it), or whose CoM velocity
area has fewer than 3 vertices, is flagged (code :data:`FALLBACK`) for the caller to answer
by the one-posture path.
"""

from __future__ import annotations

import numpy as np

from impact_balance._jit import cache_depends_on, njit
from impact_balance.balance import areas
from impact_balance.balance.areas import assembled_areas
from impact_balance.contacts import wrench_polytope
from impact_balance.criteria import linear_exit
from impact_balance.criteria.linear_exit import exit_kernel
from impact_balance.geometry import polygon
from impact_balance.projection import kernel, walk
from impact_balance.projection.kernel import OK

__all__ = ["FALLBACK", "posture_exits"]

#: :func:`posture_exits`' code of a posture the caller answers by the one-posture path.
FALLBACK = -1


@njit(cache=True, nogil=True)
def posture_exits(
    blocks: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    weights: np.ndarray,
    depths: np.ndarray,
    coms: np.ndarray,
    omegas: np.ndarray,
    jumps: np.ndarray,
    com_velocities: np.ndarray,
    settings: np.ndarray,
    hint: np.ndarray,
    out: np.ndarray,
    same: np.ndarray,
) -> None:
    """The first exit of the post-impact CoM velocities of every posture.

    Per posture i (leading axis): ``blocks`` (m, 32, 3)
    (:func:`~impact_balance.contacts.wrench_polytope.face_blocks`), ``positions`` (m, 3) world
    and ``arms`` (m, 3) contact point minus CoM, m; ``jacobians`` (6m, nv) or (0, 0);
    ``gravity_torques`` (nv,) N m; ``weights`` m g, N; ``depths`` h - c_z, m; ``coms`` (3,)
    world, m; ``omegas`` 1/s; ``jumps`` (k, 2) CoM velocity jumps per m/s of approach speed
    (world xy; ``ImpactModel.com_jump_rates``); ``com_velocities`` (2,) world xy, m/s.
    ``torque_indices`` and ``torque_limits`` are common. ``settings`` is ``(box, max_pivots,
    merge_tol, area_tol, zmp_margin, velocity_margin, boundary_tol)``. ``hint`` is the walk's
    warm start, carried from one posture to the next. Where ``same[i]`` (bool) is true,
    posture i is posture i - 1 (only its CoM velocity is read): its area and rates are reused.

    Writes ``out[i] = (code, speed, vertex, edge)``: :func:`exit_kernel`'s answer, or code
    :data:`FALLBACK`.
    """
    box, merge_tol, area_tol = settings[0], settings[2], settings[3]
    max_pivots = int(settings[1])
    zmp_margin, velocity_margin, tol = settings[4], settings[5], settings[6]
    G, h = np.empty((0, 2)), np.empty(0)
    answered = False  # whether the last posture's area and rates are held in G, h
    for i in range(same.size):
        out[i, 0] = FALLBACK
        if same[i]:
            if answered:
                _exit(G, h, jumps[i], com_velocities[i], velocity_margin, tol, out, i)
            continue
        answered = False
        result = assembled_areas(
            blocks[i],
            positions[i],
            arms[i],
            jacobians[i],
            torque_indices,
            torque_limits,
            gravity_torques[i],
            weights[i],
            box,
            max_pivots,
            merge_tol,
            area_tol,
            depths[i],
            coms[i, 0],
            coms[i, 1],
            omegas[i],
            zmp_margin,
            hint,
        )
        status, force, G, h = result[5], result[6], result[12], result[13]
        if status != OK or force.shape[0] == 0 or G.shape[0] == 0:
            continue
        answered = True
        _exit(G, h, jumps[i], com_velocities[i], velocity_margin, tol, out, i)


@njit(cache=True)
def _exit(
    G: np.ndarray,
    h: np.ndarray,
    jumps: np.ndarray,
    com_velocity: np.ndarray,
    velocity_margin: float,
    tol: float,
    out: np.ndarray,
    i: int,
) -> None:
    """``out[i]`` = the first exit of ``com_velocity + s jumps[j]`` from ``G x <= h``.

    The area less the velocity margin (m/s); the numbers of
    :meth:`ComCriterion.limit <impact_balance.criteria.com.ComCriterion.limit>`.
    """
    c0x, c0y = com_velocity[0], com_velocity[1]
    margins = np.empty(h.size)
    for k in range(h.size):
        hk = h[k] - velocity_margin if velocity_margin != 0.0 else h[k]
        margins[k] = hk - (G[k, 0] * c0x + G[k, 1] * c0y)
    rates = np.empty((jumps.shape[0], h.size))
    for j in range(jumps.shape[0]):
        for k in range(h.size):
            rates[j, k] = jumps[j, 0] * G[k, 0] + jumps[j, 1] * G[k, 1]
    code, speed, vertex, edge = exit_kernel(margins, rates, tol)
    out[i, 0] = code
    out[i, 1] = speed
    out[i, 2] = vertex
    out[i, 3] = edge


cache_depends_on(_exit, linear_exit)
cache_depends_on(posture_exits, areas, polygon, walk, kernel, wrench_polytope, linear_exit)
