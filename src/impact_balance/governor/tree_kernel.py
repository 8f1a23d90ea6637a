"""A batch's kinematics in compiled code: :class:`KinematicTree` and :func:`tree_postures`.

What a batch row needs from pinocchio (the contacts' placements and world-aligned Jacobians,
the CoM and ``m J_com``, the composite rotational inertia about the CoM, the impact point, the
LIPM's omega), computed for many configurations in one compiled call that releases the GIL, so
that a batch's threads run side by side. The tree is read once from a pinocchio model whose
joints are all free flyers or revolute joints about a joint axis (``RX``, ``RY``, ``RZ``: the
bundled robots); any other joint leaves :attr:`KinematicTree.supported` false, and so does a
library without numba (interpreted, the tree would be slower than pinocchio): the governor then
calls pinocchio. The numbers are pinocchio's to rounding (about 1e-15 m and 1e-13 of
the inertia, tested), not to the last digit: the batch's answers equal the single ticks' to
1e-9, not bit for bit.

Frames and units as :meth:`PostureEvaluator._placements
<impact_balance.governor.posture.PostureEvaluator>`'s: the stance frame (world axes, origin at
the base position: the free flyer's translation is set to zero), m, kg, kg m^2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance._jit import HAVE_NUMBA, njit

__all__ = ["KinematicTree", "tree_postures"]

#: Joint kinds of :attr:`KinematicTree.kinds`: the free flyer, revolute about x, y, z.
FREE_FLYER, REVOLUTE_X, REVOLUTE_Y, REVOLUTE_Z = 0, 1, 2, 3
_KINDS = {
    "JointModelFreeFlyer": FREE_FLYER,
    "JointModelRX": REVOLUTE_X,
    "JointModelRY": REVOLUTE_Y,
    "JointModelRZ": REVOLUTE_Z,
}


@dataclass(frozen=True)
class KinematicTree:
    """A pinocchio model's joints, bodies and some frames as arrays for :func:`tree_postures`.

    Joint 0 is the universe; joint j > 0 has parent ``parents[j]`` < j.

    Attributes:
        supported: Whether every joint is a free flyer or an ``RX``, ``RY``, ``RZ`` joint and
            numba compiles :func:`tree_postures` (the arrays are valid either way).
        parents: (nj,) int.
        kinds: (nj,) int, the joint kinds (:data:`FREE_FLYER`, ...; -1 for the universe).
        idx_q: (nj,) int, the joints' first configuration index.
        idx_v: (nj,) int, the joints' first velocity index.
        placements: (nj, 4, 4) each joint's placement in its parent joint's frame.
        masses: (nj,) kg, the body of each joint.
        levers: (nj, 3) m, its CoM in the joint's frame.
        inertias: (nj, 3, 3) kg m^2, its rotational inertia about its CoM, joint axes.
        frame_joints: (f,) int, the frames' parent joints (the contacts', then the impact's).
        frame_placements: (f, 4, 4) the frames' placements in their joints' frames.
    """

    supported: bool
    parents: npt.NDArray[np.int64]
    kinds: npt.NDArray[np.int64]
    idx_q: npt.NDArray[np.int64]
    idx_v: npt.NDArray[np.int64]
    placements: npt.NDArray[np.float64]
    masses: npt.NDArray[np.float64]
    levers: npt.NDArray[np.float64]
    inertias: npt.NDArray[np.float64]
    frame_joints: npt.NDArray[np.int64]
    frame_placements: npt.NDArray[np.float64]

    @classmethod
    def of(cls, model: pin.Model, frames: list[int]) -> KinematicTree:
        """The tree of ``model``, with the pinocchio frames ``frames`` (their indices)."""
        nj = model.njoints
        kinds = np.full(nj, -1, dtype=np.int64)
        supported = HAVE_NUMBA
        for j in range(1, nj):
            kind = _KINDS.get(model.joints[j].shortname(), -1)
            supported &= kind >= 0
            kinds[j] = kind
        return cls(
            supported,
            np.array([int(p) for p in model.parents], dtype=np.int64),
            kinds,
            np.array([max(int(j.idx_q), 0) for j in model.joints], dtype=np.int64),
            np.array([max(int(j.idx_v), 0) for j in model.joints], dtype=np.int64),
            np.array([m.homogeneous for m in model.jointPlacements]).reshape(nj, 4, 4),
            np.array([float(i.mass) for i in model.inertias]),
            np.array([i.lever for i in model.inertias]).reshape(nj, 3),
            np.array([i.inertia for i in model.inertias]).reshape(nj, 3, 3),
            np.array([int(model.frames[f].parentJoint) for f in frames], dtype=np.int64),
            np.array([model.frames[f].placement.homogeneous for f in frames]).reshape(
                len(frames), 4, 4
            ),
        )


@njit(cache=True, inline="always")
def _joint_motion(kind: int, q: np.ndarray, iq: int, out: np.ndarray) -> None:
    """The joint's motion at ``q`` as a 4 x 4 transform into ``out`` (Eigen's quaternion)."""
    for r in range(4):
        for c in range(4):
            out[r, c] = 1.0 if r == c else 0.0
    if kind == FREE_FLYER:
        x, y, z, w = q[iq + 3], q[iq + 4], q[iq + 5], q[iq + 6]
        tx, ty, tz = 2.0 * x, 2.0 * y, 2.0 * z
        twx, twy, twz = tx * w, ty * w, tz * w
        txx, txy, txz = tx * x, ty * x, tz * x
        tyy, tyz, tzz = ty * y, tz * y, tz * z
        out[0, 0], out[0, 1], out[0, 2] = 1.0 - (tyy + tzz), txy - twz, txz + twy
        out[1, 0], out[1, 1], out[1, 2] = txy + twz, 1.0 - (txx + tzz), tyz - twx
        out[2, 0], out[2, 1], out[2, 2] = txz - twy, tyz + twx, 1.0 - (txx + tyy)
        out[0, 3], out[1, 3], out[2, 3] = q[iq], q[iq + 1], q[iq + 2]
        return
    sine, cosine = math.sin(q[iq]), math.cos(q[iq])
    a = kind - REVOLUTE_X  # the axis
    b, d = (a + 1) % 3, (a + 2) % 3
    out[b, b], out[b, d], out[d, b], out[d, d] = cosine, -sine, sine, cosine


@njit(cache=True, inline="always")
def _compose(a: np.ndarray, b: np.ndarray, out: np.ndarray) -> None:
    """``out = a b`` for 4 x 4 rigid transforms (the last row left as it is)."""
    for r in range(3):
        for c in range(4):
            out[r, c] = a[r, 0] * b[0, c] + a[r, 1] * b[1, c] + a[r, 2] * b[2, c]
        out[r, 3] += a[r, 3]


@njit(cache=True, inline="always")
def _column(
    kind: int, k: int, pose: np.ndarray, point: np.ndarray, lin: np.ndarray, ang: np.ndarray
) -> None:
    """Velocity column ``k`` of a joint at ``pose`` for a point: linear and angular, world."""
    if kind == FREE_FLYER and k < 3:  # the base's linear velocity, in its own axes
        for r in range(3):
            lin[r], ang[r] = pose[r, k], 0.0
        return
    axis = k - 3 if kind == FREE_FLYER else kind - REVOLUTE_X
    ax, ay, az = pose[0, axis], pose[1, axis], pose[2, axis]
    dx, dy, dz = point[0] - pose[0, 3], point[1] - pose[1, 3], point[2] - pose[2, 3]
    lin[0], lin[1], lin[2] = ay * dz - az * dy, az * dx - ax * dz, ax * dy - ay * dx
    ang[0], ang[1], ang[2] = ax, ay, az


@njit(cache=True, inline="always")
def _width(kind: int) -> int:
    """The joint's velocity dimension."""
    return 6 if kind == FREE_FLYER else 1


@njit(cache=True, inline="always")
def _poses(
    parents: np.ndarray,
    kinds: np.ndarray,
    idx_q: np.ndarray,
    placements: np.ndarray,
    q: np.ndarray,
    free_flyer: bool,
    poses: np.ndarray,
    motion: np.ndarray,
    joint: np.ndarray,
) -> None:
    """Every joint's placement at ``q`` (stance frame: a free flyer's translation zero)."""
    for j in range(1, parents.size):
        _joint_motion(kinds[j], q, idx_q[j], motion)
        if free_flyer and j == 1:  # the first joint's translation: the stance frame's origin
            motion[0, 3] = motion[1, 3] = motion[2, 3] = 0.0
        _compose(poses[parents[j]], placements[j], joint)
        for r in range(3):
            for c in range(3):
                poses[j, r, c] = (
                    joint[r, 0] * motion[0, c] + joint[r, 1] * motion[1, c]
                    + joint[r, 2] * motion[2, c]
                )  # fmt: skip
            poses[j, r, 3] = (
                joint[r, 0] * motion[0, 3] + joint[r, 1] * motion[1, 3]
                + joint[r, 2] * motion[2, 3] + joint[r, 3]
            )  # fmt: skip
        poses[j, 3, 0] = poses[j, 3, 1] = poses[j, 3, 2] = 0.0
        poses[j, 3, 3] = 1.0


@njit(cache=True, inline="always")
def _masses(
    masses: np.ndarray,
    levers: np.ndarray,
    inertias: np.ndarray,
    poses: np.ndarray,
    first: np.ndarray,
    com: np.ndarray,
    inertia: np.ndarray,
) -> float:
    """The mass, CoM and composite rotational inertia about the CoM (world axes) at ``poses``.

    Writes ``com``, ``inertia`` and each body's first moment of mass ``first[j]``; returns the
    mass.
    """
    nj = masses.size
    for j in range(nj):
        for r in range(3):
            first[j, r] = masses[j] * (
                poses[j, r, 0] * levers[j, 0] + poses[j, r, 1] * levers[j, 1]
                + poses[j, r, 2] * levers[j, 2] + poses[j, r, 3]
            )  # fmt: skip
    inertia[:] = 0.0
    for j in range(nj):  # the bodies' rotational inertias about their own CoMs, world axes
        for r in range(3):
            for c in range(3):
                s = 0.0
                for k in range(3):
                    s += poses[j, r, k] * (
                        inertias[j, k, 0] * poses[j, c, 0] + inertias[j, k, 1] * poses[j, c, 1]
                        + inertias[j, k, 2] * poses[j, c, 2]
                    )  # fmt: skip
                inertia[r, c] += s
    total = 0.0
    com[:] = 0.0
    for j in range(nj):
        total += masses[j]
        for r in range(3):
            com[r] += first[j, r]
    for r in range(3):
        com[r] /= total
    for j in range(nj):  # the bodies' CoMs about the whole CoM (parallel axes)
        if masses[j] > 0.0:
            mj = masses[j]
            dx = first[j, 0] / mj - com[0]
            dy = first[j, 1] / mj - com[1]
            dz = first[j, 2] / mj - com[2]
            inertia[0, 0] += mj * (dy * dy + dz * dz)
            inertia[1, 1] += mj * (dx * dx + dz * dz)
            inertia[2, 2] += mj * (dx * dx + dy * dy)
            inertia[0, 1] -= mj * dx * dy
            inertia[0, 2] -= mj * dx * dz
            inertia[1, 2] -= mj * dy * dz
    inertia[1, 0], inertia[2, 0], inertia[2, 1] = inertia[0, 1], inertia[0, 2], inertia[1, 2]
    return total


@njit(cache=True, inline="always")
def _com_jacobian(
    parents: np.ndarray,
    kinds: np.ndarray,
    idx_v: np.ndarray,
    masses: np.ndarray,
    poses: np.ndarray,
    first: np.ndarray,
    mass_sub: np.ndarray,
    out: np.ndarray,
    lin: np.ndarray,
    ang: np.ndarray,
) -> None:
    """``m J_com`` (3, nv) into ``out``: each joint moves its subtree's mass about itself.

    ``first`` holds the bodies' first moments of mass and becomes the subtrees'.
    """
    nj = parents.size
    for j in range(nj):
        mass_sub[j] = masses[j]
    for j in range(nj - 1, 0, -1):  # subtrees, leaves first
        mass_sub[parents[j]] += mass_sub[j]
        for r in range(3):
            first[parents[j], r] += first[j, r]
    out[:] = 0.0
    sub = np.empty(3)
    for j in range(1, nj):
        if mass_sub[j] <= 0.0:
            continue
        for r in range(3):
            sub[r] = first[j, r] / mass_sub[j]
        for k in range(_width(kinds[j])):
            _column(kinds[j], k, poses[j], sub, lin, ang)
            for r in range(3):
                out[r, idx_v[j] + k] = mass_sub[j] * lin[r]


@njit(cache=True, inline="always")
def _frame_jacobian(
    parents: np.ndarray,
    kinds: np.ndarray,
    idx_v: np.ndarray,
    poses: np.ndarray,
    joint: int,
    point: np.ndarray,
    out: np.ndarray,
    lin: np.ndarray,
    ang: np.ndarray,
) -> None:
    """The (6, nv) Jacobian (linear rows first, world axes) of ``point`` on joint ``joint``."""
    out[:] = 0.0
    j = joint
    while j > 0:
        for k in range(_width(kinds[j])):
            _column(kinds[j], k, poses[j], point, lin, ang)
            for r in range(3):
                out[r, idx_v[j] + k] = lin[r]
                out[3 + r, idx_v[j] + k] = ang[r]
        j = parents[j]


@njit(cache=True, nogil=True)
def tree_postures(
    parents: np.ndarray,
    kinds: np.ndarray,
    idx_q: np.ndarray,
    idx_v: np.ndarray,
    placements: np.ndarray,
    masses: np.ndarray,
    levers: np.ndarray,
    inertias: np.ndarray,
    frame_joints: np.ndarray,
    frame_placements: np.ndarray,
    qs: np.ndarray,
    free_flyer: bool,
    torques: bool,
    plane_height: float,
    gravity: float,
    rotations: np.ndarray,
    local: np.ndarray,
    jacobians: np.ndarray,
    origins: np.ndarray,
    com_locals: np.ndarray,
    centroidal: np.ndarray,
    point_locals: np.ndarray,
    point_jacobians: np.ndarray,
    body_inertias: np.ndarray,
    scalars: np.ndarray,
) -> int:
    """The kinematics of configurations ``qs`` (n, nq) into a batch's per-posture buffers.

    The first arguments are :class:`KinematicTree`'s arrays (its frames: the m contacts', then
    the impact point's); ``free_flyer``: the model's first joint is a free flyer (its
    translation is the stance frame's origin, ``q[:3]``). For row p: ``rotations[p]``
    (m, 3, 3) and ``local[p]`` (m, 3) the contacts' contact-to-world rotations and points,
    ``jacobians[p]`` (6m, nv) their stacked Jacobians (linear rows first, world axes, at the
    contact point; only with ``torques``), ``origins[p]`` the stance frame's origin (the free
    flyer's translation, else 0), ``com_locals[p]`` the CoM, ``centroidal[p][:3]`` (3, nv)
    ``m J_com`` (the centroidal momentum matrix's linear rows; the others are set to 0),
    ``point_locals[p]`` the impact point and, where ``point_jacobians`` has rows (else
    (0, 3, nv)), ``point_jacobians[p]`` its (3, nv) translational Jacobian (world axes),
    ``body_inertias[p]`` the composite rotational inertia about the CoM (world axes),
    ``scalars[p, 0]`` the mass (kg) and ``scalars[p, 3]`` omega (1/s) for the plane at
    ``plane_height`` (m) and ``gravity`` (m/s^2).

    Returns the first row whose CoM is not strictly above the plane (its omega not computed;
    the caller's check names it), or -1.
    """
    nj, f = parents.size, frame_joints.size
    m = f - 1
    poses = np.empty((nj, 4, 4))
    motion, joint = np.empty((4, 4)), np.empty((4, 4))
    first, mass_sub = np.empty((nj, 3)), np.empty(nj)
    frame_poses = np.empty((f, 4, 4))
    lin, ang, com, inertia = np.empty(3), np.empty(3), np.empty(3), np.empty((3, 3))
    nv = centroidal.shape[2]
    point_jacobian = np.empty((6, nv))
    for r in range(4):
        for c in range(4):
            poses[0, r, c] = 1.0 if r == c else 0.0
    for p in range(qs.shape[0]):
        q = qs[p]
        _poses(parents, kinds, idx_q, placements, q, free_flyer, poses, motion, joint)
        total = _masses(masses, levers, inertias, poses, first, com, inertia)
        _com_jacobian(
            parents, kinds, idx_v, masses, poses, first, mass_sub, centroidal[p], lin, ang
        )
        for i in range(f):
            _compose(poses[frame_joints[i]], frame_placements[i], frame_poses[i])
        for i in range(m):
            for r in range(3):
                local[p, i, r] = frame_poses[i, r, 3]
                for c in range(3):
                    rotations[p, i, r, c] = frame_poses[i, r, c]
            if torques:
                _frame_jacobian(
                    parents, kinds, idx_v, poses, frame_joints[i], frame_poses[i, :3, 3],
                    jacobians[p, 6 * i : 6 * i + 6], lin, ang,
                )  # fmt: skip
        if point_jacobians.shape[0]:
            _frame_jacobian(
                parents, kinds, idx_v, poses, frame_joints[m], frame_poses[m, :3, 3],
                point_jacobian, lin, ang,
            )  # fmt: skip
            for r in range(3):
                for c in range(nv):
                    point_jacobians[p, r, c] = point_jacobian[r, c]
        for r in range(3):
            point_locals[p, r] = frame_poses[m, r, 3]
            origins[p, r] = q[r] if free_flyer else 0.0
            com_locals[p, r] = com[r]
            for c in range(3):
                body_inertias[p, r, c] = inertia[r, c]
        scalars[p, 0] = total
        height = com[2] + origins[p, 2]
        if not (math.isfinite(height) and height > plane_height):
            return p
        scalars[p, 3] = math.sqrt(gravity / (height - plane_height))
    return -1
