"""``benchmarks/batch.py --profile``: where a batch row's microseconds go.

The N postures of the benchmark's path, each stage of a row's compiled call timed in a compiled
loop over the N postures of its own (inputs made beforehand; the walk's hint carried along the
path as the batch carries it, reset before each pass), the best CPU time of ``repeat`` passes:

- ``kinematics``: :func:`~impact_balance.governor.tree_kernel.tree_postures` per row (the
  batch's compiled kinematics), beside ``pinocchio``: the one-posture path's pinocchio step
  (``PostureEvaluator._placements``, the impact point, omega), what a row cost before;
- ``prologue``: the contact points, lever arms, CoM Jacobian and g(q) from the kinematics
  (``kinematics_posture_kernel`` less ``posture_kernel``);
- ``faces``: the contacts' faces in world axes; ``assembly``: the wrench polytope's rows, their
  scaling to m g (``assembled_areas`` less the walk and maps);
- ``walk``: the certified walk (re-certification of the previous row's chain, or a walk);
- ``areas``: the maps to the ZMP and CoM velocity areas and the half-planes;
- ``impact``: the impact map W, the impulse rates, the criterion's jump rates;
- ``cap``: ``J v``, the margins, the first exit (``postures_kernel`` less the per-posture call);
- ``glue``: the rest of a row of ``Governor.limits`` (Python: blocks, buffers, answers).

Differences of separately timed loops: each stage is within a few tenths of a microsecond.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import Any

import numpy as np

from benchmarks.speed.ticks import trajectory
from impact_balance._jit import njit
from impact_balance.balance.areas import _walk_areas, assembled_areas
from impact_balance.balance.lipm import lipm_omega
from impact_balance.governor import Governor
from impact_balance.governor.batch import _Buffers
from impact_balance.governor.posture_kernel import kinematics_posture_kernel, postures_kernel
from impact_balance.governor.tree_kernel import tree_postures
from impact_balance.projection.walk import MAX_PIVOTS, certified_walk

__all__ = ["profile_batch"]


@njit(cache=True)
def _faces_loop(faces, rotations):
    n, m = rotations.shape[0], rotations.shape[1]
    total = 0.0
    for p in range(n):
        blocks = np.empty((m, 32, 3))
        for i in range(m):
            blocks[i] = np.dot(faces[i].reshape(32, 3), rotations[p, i].T)
        total += blocks[0, 0, 0]
    return total


@njit(cache=True)
def _assembled_loop(blocks, positions, arms, jacobians, idx, lim, gtorques, weights, scalars,
                    constants, hint):  # fmt: skip
    box, merge_tol, area_tol, zmp_margin = constants[0], constants[1], constants[2], constants[3]
    total = 0
    for p in range(blocks.shape[0]):
        out = assembled_areas(
            blocks[p], positions[p], arms[p], jacobians[p], idx, lim, gtorques[p], weights[p],
            box, 5000, merge_tol, area_tol, scalars[p, 0], scalars[p, 1], scalars[p, 2],
            scalars[p, 3], zmp_margin, hint,
        )  # fmt: skip
        total += out[5]
    return total


@njit(cache=True)
def _walk_areas_loop(A, b, C, d, E, scalars, constants, hint):
    box, merge_tol, area_tol, zmp_margin = constants[0], constants[1], constants[2], constants[3]
    total = 0
    for p in range(A.shape[0]):
        out = _walk_areas(
            A[p], b[p], C[p], d, E[p], box, 5000, merge_tol, area_tol, scalars[p, 0],
            scalars[p, 1], scalars[p, 2], scalars[p, 3], zmp_margin, hint,
        )  # fmt: skip
        total += out[0]
    return total


@njit(cache=True)
def _walk_loop(A, b, C, d, E, constants, hint):
    box, merge_tol, area_tol = constants[0], constants[1], constants[2]
    total = 0
    for p in range(A.shape[0]):
        out = certified_walk(A[p], b[p], C[p], d, E[p], box, 5000, merge_tol, area_tol, hint)
        total += out[0]
    return total


@njit(cache=True)
def _kinematics_posture_loop(
    faces, rotations, local, origins, com_locals, centroidal, gravity_vector, jacobians, idx,
    lim, scalars, hint, constants, point_locals, inertias, normal, cone,
):  # fmt: skip
    total = 0.0
    for p in range(rotations.shape[0]):
        out = kinematics_posture_kernel(
            faces, rotations[p], local[p], origins[p], com_locals[p], centroidal[p],
            gravity_vector, True, jacobians[p], idx, lim, scalars[p, 0], scalars[0, 1],
            scalars[0, 2], scalars[p, 3], hint, 5000, constants, point_locals[p], inertias[p],
            normal, cone,
        )  # fmt: skip
        total += out[0]
    return total


def _best(fn: Callable[[], Any], repeat: int, reset: Callable[[], None], n: int) -> float:
    """The best CPU time of ``repeat`` calls of ``fn`` (``reset()`` untimed before each), us / n.

    CPU time of the process (one thread runs): the machine is shared, and a pass that waited
    for a core does not count the wait.
    """
    best = float("inf")
    for _ in range(repeat + 1):  # the first call compiles or loads
        reset()
        t0 = time.process_time()
        fn()
        best = min(best, time.process_time() - t0)
    return 1e6 * best / n


def profile_batch(name: str, n: int, repeat: int) -> dict[str, Any]:
    """Per batch row of scenario ``name`` (N = ``n`` path postures), us per stage."""
    g = Governor(name)
    qs, vs = trajectory(g, n)
    e = g._evaluator
    s = e.settings
    b = _Buffers(e)
    tree = b.tree
    assert tree is not None and e._compiled and e._torques
    m, nv = len(e._frames), e.model.nv
    rot, loc = np.zeros((n, m, 3, 3)), np.zeros((n, m, 3))
    jac, ori, com_l = np.zeros((n, 6 * m, nv)), np.zeros((n, 3)), np.zeros((n, 3))
    cen, pts, ine = np.zeros((n, 6, nv)), np.zeros((n, 3)), np.zeros((n, 3, 3))
    sca = np.zeros((n, 6))
    sca[0, 1:3] = b.scalars[0, 1:3]
    sca[0, 4:6] = b.scalars[0, 4:6]
    tree_args = (
        tree.parents, tree.kinds, tree.idx_q, tree.idx_v, tree.placements, tree.masses,
        tree.levers, tree.inertias, tree.frame_joints, tree.frame_placements, qs, e._free_flyer,
        True, float(s.plane_height), float(s.gravity), rot, loc, jac, ori, com_l, cen, pts,
        np.zeros((0, 3, nv)), ine, sca,
    )  # fmt: skip
    hint0 = e._hint.copy()
    hint = e._hint

    def reset() -> None:
        hint[:] = hint0

    out: dict[str, float] = {}
    out["kinematics"] = _best(lambda: tree_postures(*tree_args), repeat, reset, n)
    sca[:, 1:3] = sca[0, 1:3]

    def pinocchio_rows() -> None:
        R, L, J = np.empty((m, 3, 3)), np.empty((m, 3)), np.empty((6 * m, nv))
        for q in qs:
            origin, com_local, mass, _, _ = e._placements(q, R, L, J)
            e.impact_point()
            float(mass)
            lipm_omega(float(com_local[2]) + float(origin[2]), s.plane_height, s.gravity)

    out["pinocchio"] = _best(pinocchio_rows, repeat, reset, n)
    # the inputs of each stage, as kinematics_posture_kernel and posture_kernel make them
    positions = loc + ori[:, None, :]
    arms = loc - com_l[:, None, :]
    mass = sca[:, 0]
    gtorques = np.array([-(e._gravity @ cen[p, :3]) for p in range(n)])
    weights = mass * s.gravity
    com = com_l + ori
    blocks = np.array(
        [[np.dot(e._faces[i].reshape(32, 3), rot[p, i].T) for i in range(m)] for p in range(n)]
    )
    map_scalars = np.column_stack([s.plane_height - com[:, 2], com[:, 0], com[:, 1], sca[:, 3]])
    arrays = [
        assembled_areas(
            blocks[p], positions[p], arms[p], jac[p], e._idx, e._limit, gtorques[p], weights[p],
            e._constants[0], MAX_PIVOTS, e._constants[1], e._constants[2], *map_scalars[p],
            e._constants[3], hint,
        )[:5]
        for p in range(n)
    ]  # fmt: skip
    A, bb, C, E = (np.array([a[k] for a in arrays]) for k in (0, 1, 2, 4))
    d = arrays[0][3]
    k_args = (
        e._faces, rot, loc, ori, com_l, cen, e._gravity, jac, e._idx, e._limit, sca, hint,
        e._constants, pts, ine, e._normal, e._cone,
    )  # fmt: skip
    whole = _best(lambda: _kinematics_posture_loop(*k_args), repeat, reset, n)
    out["faces"] = _best(lambda: _faces_loop(e._faces, rot), repeat, reset, n)
    assembled = _best(
        lambda: _assembled_loop(
            blocks,
            positions,
            arms,
            jac,
            e._idx,
            e._limit,
            gtorques,
            weights,
            map_scalars,
            e._constants,
            hint,
        ),
        repeat,
        reset,
        n,
    )
    walk_areas = _best(
        lambda: _walk_areas_loop(A, bb, C, d, E, map_scalars, e._constants, hint), repeat, reset, n
    )
    out["walk"] = _best(lambda: _walk_loop(A, bb, C, d, E, e._constants, hint), repeat, reset, n)
    out["assembly"] = assembled - walk_areas
    out["areas"] = walk_areas - out["walk"]
    # the postures' call from the batch's buffers: all rows in one call
    same = np.zeros(n, dtype=np.bool_)
    codes, speeds = np.empty(n, dtype=np.int64), np.empty(n)
    vertices, edges = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    intervals, vel, pnt = np.empty((n, 2)), np.empty((n, 3)), np.empty((n, 3))
    p_args = (
        e._faces, rot, loc, ori, com_l, cen, e._gravity, True, jac, e._idx, e._limit, sca, hint,
        MAX_PIVOTS, e._constants, pts, ine, e._normal, e._cone, vs, same, codes, speeds,
        vertices, edges, intervals, vel, pnt, 1e4,
    )  # fmt: skip
    postures = _best(lambda: postures_kernel(*p_args), repeat, reset, n)
    batch = _best(lambda: g.limits(qs, vs), repeat, lambda: None, n)
    out["prologue, impact (W, rates), returned tuple"] = whole - out["faces"] - assembled
    out["cap"] = postures - whole
    out["glue"] = batch - postures - out["kinematics"]
    out["batch row"] = batch
    out["compiled posture call"] = whole
    return out
