"""A MuJoCo model's state in the governor's (pinocchio's) conventions, by joint name.

mink works on a MuJoCo model: ``qpos`` (the free joint's quaternion w first), ``qvel`` and its
displacements ``Δq`` (the free joint's linear velocity in the world, its angular velocity in
the body). The governor reads pinocchio's ``q`` and ``v`` (quaternion x, y, z, w; the base's
linear and angular velocity in the base frame). :class:`MujocoState` maps one onto the other
for a MuJoCo model of the governor's robot: the same joint names (MuJoCo's reading of the same
URDF, or :mod:`impact_balance.sim`'s model), its free joint's body the URDF's root link.
MuJoCo joints the pinocchio model does not have (a scene's other bodies) are ignored.
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.contacts.stance import has_free_flyer
from impact_balance.exceptions import GovernorError

__all__ = ["MujocoState"]

#: MuJoCo's 1-dof joint types (a pinocchio revolute, prismatic or continuous joint).
_FREE = int(mujoco.mjtJoint.mjJNT_FREE)
_ONE_DOF = (int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE))


class MujocoState:
    """The map between a MuJoCo model's ``qpos``/``qvel`` and a pinocchio model's ``q``/``v``.

    Args:
        model: The pinocchio model (the governor's robot).
        mj_model: A MuJoCo model of the same robot (joints named as in the URDF).
        free_joint: The MuJoCo free joint of the robot's base; None: the model's only one.

    Raises:
        GovernorError: A pinocchio joint missing from the MuJoCo model (or of another kind),
            no free joint or several for a floating-base robot, an unknown ``free_joint``.
    """

    def __init__(
        self, model: pin.Model, mj_model: mujoco.MjModel, free_joint: str | None = None
    ) -> None:
        self.nq, self.nv, self.mj_nv = model.nq, model.nv, mj_model.nv
        self.free: tuple[int, int] | None = None  # (qposadr, dofadr) of the base's free joint
        if has_free_flyer(model):
            self.free = _free_joint(mj_model, free_joint)
        single, pairs = [], []  # (idx_q, idx_v, qposadr, dofadr)
        first = 2 if self.free is not None else 1
        for jid in range(first, model.njoints):
            name, joint = model.names[jid], model.joints[jid]
            index = mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, name)
            kind = int(mj_model.jnt_type[index]) if index >= 0 else None
            if kind not in _ONE_DOF:
                raise GovernorError(
                    "mj_model", name, "the robot's joint is not a hinge or slide joint there"
                )
            entry = (
                joint.idx_q,
                joint.idx_v,
                mj_model.jnt_qposadr[index],
                mj_model.jnt_dofadr[index],
            )
            if joint.nq == 1:
                single.append(entry)
            elif joint.nq == 2 and joint.nv == 1:
                pairs.append(entry)
            else:
                raise GovernorError("model", name, "only 1-dof joints are mapped to MuJoCo")
        s = np.asarray(single, dtype=np.int64).reshape(-1, 4)
        p = np.asarray(pairs, dtype=np.int64).reshape(-1, 4)
        self._q, self._v, self._qpos, self._dof = (s[:, k] for k in range(4))
        self._pq, self._pv, self._pqpos, self._pdof = (p[:, k] for k in range(4))

    def q(self, qpos: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pinocchio's ``q`` of MuJoCo's ``qpos``."""
        x = np.asarray(qpos, dtype=float)
        q = np.zeros(self.nq)
        if self.free is not None:
            a = self.free[0]
            q[:3] = x[a : a + 3]
            w, qx, qy, qz = x[a + 3 : a + 7]
            q[3:7] = (qx, qy, qz, w)
        q[self._q] = x[self._qpos]
        angle = x[self._pqpos]
        q[self._pq], q[self._pq + 1] = np.cos(angle), np.sin(angle)
        return q

    def qpos(self, q: npt.ArrayLike, qpos: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """MuJoCo's ``qpos`` of pinocchio's ``q`` (a copy of ``qpos`` for the other joints)."""
        x = np.asarray(q, dtype=float)
        out = np.array(qpos, dtype=float)
        if self.free is not None:
            a = self.free[0]
            out[a : a + 3] = x[:3]
            out[a + 3 : a + 7] = (x[6], x[3], x[4], x[5])
        out[self._qpos] = x[self._q]
        out[self._pqpos] = np.arctan2(x[self._pq + 1], x[self._pq])
        return out

    def base_rotation(self, qpos: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The base's world rotation (3 x 3; identity for a fixed base)."""
        if self.free is None:
            return np.eye(3)
        x = np.asarray(qpos, dtype=float)
        w, qx, qy, qz = x[self.free[0] + 3 : self.free[0] + 7]
        out: npt.NDArray[np.float64] = pin.Quaternion(w, qx, qy, qz).normalized().matrix()
        return out

    def v(self, qpos: npt.ArrayLike, qvel: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Pinocchio's ``v`` of MuJoCo's ``qvel`` (the base's linear velocity to the base frame)."""
        y = np.asarray(qvel, dtype=float)
        v = np.zeros(self.nv)
        if self.free is not None:
            d = self.free[1]
            v[:3] = self.base_rotation(qpos).T @ y[d : d + 3]
            v[3:6] = y[d + 3 : d + 6]
        v[self._v] = y[self._dof]
        v[self._pv] = y[self._pdof]
        return v

    def columns(
        self, qpos: npt.ArrayLike, matrix: npt.NDArray[np.float64]
    ) -> npt.NDArray[np.float64]:
        """``matrix`` (rows x nv, acting on pinocchio's ``v``) as acting on MuJoCo's ``qvel``.

        ``matrix @ v(qpos, qvel) == columns(qpos, matrix) @ qvel`` for every ``qvel``.
        """
        out = np.zeros((matrix.shape[0], self.mj_nv))
        if self.free is not None:
            d = self.free[1]
            out[:, d : d + 3] = matrix[:, :3] @ self.base_rotation(qpos).T
            out[:, d + 3 : d + 6] = matrix[:, 3:6]
        out[:, self._dof] = matrix[:, self._v]
        out[:, self._pdof] = matrix[:, self._pv]
        return out


def _free_joint(mj_model: mujoco.MjModel, name: str | None) -> tuple[int, int]:
    """(qposadr, dofadr) of the robot's free joint in ``mj_model``."""
    free = [j for j in range(mj_model.njnt) if int(mj_model.jnt_type[j]) == _FREE]
    if name is not None:
        j = mujoco.mj_name2id(mj_model, mujoco.mjtObj.mjOBJ_JOINT, name)
        if j not in free:
            raise GovernorError("free_joint", name, "is not a free joint of the MuJoCo model")
        free = [j]
    if len(free) != 1:
        raise GovernorError(
            "free_joint", None, f"the MuJoCo model has {len(free)} free joints: name the robot's"
        )
    return int(mj_model.jnt_qposadr[free[0]]), int(mj_model.jnt_dofadr[free[0]])
