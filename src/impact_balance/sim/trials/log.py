"""A trial's time series as a log table (schema of :mod:`impact_balance.logs.schema`)."""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
import pandas as pd

from impact_balance.logs import (
    LogColumns,
    force_columns,
    joint_position_column,
    joint_velocity_column,
)
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.impact_trial import TrialRecord

__all__ = ["LOG_START", "LogRecorder", "log_frame"]

_FloatArray = npt.NDArray[np.float64]

#: Logs start here (s): the first steps settle the model's initial contact penetration (the
#: contacts carry nothing at t = 0, then briefly one foot carries thousands of newtons), a
#: transient of the simulation's start, not of the robot's motion.
LOG_START = 0.05


def _rotations(quaternions_wxyz: np.ndarray) -> np.ndarray:
    """(T, 3, 3) rotation matrices of unit quaternions (w, x, y, z)."""
    w, x, y, z = quaternions_wxyz.T
    return np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
        ],
        axis=1,
    )


def log_frame(sim: SimModel, record: TrialRecord, start: float = LOG_START) -> pd.DataFrame:
    """The log of an impact trial, one row per step from ``start`` (s) on.

    One row per step from ``start`` (s) on: time, base pose (quaternion x, y, z, w) and world-axes
    velocities, every actuated joint's position and velocity (welded ones at the stance, velocity
    0), the contact forces on the robot and MuJoCo's CoM and CoM velocity.

    MuJoCo's free joint stores the angular velocity in the base frame: it is rotated to world axes.
    """
    cols = LogColumns()
    quat = record.qpos[:, 3:7]
    omega_world = np.einsum("tij,tj->ti", _rotations(quat), record.qvel[:, 3:6])
    data: dict[str, np.ndarray] = {cols.time: record.time}
    for k, name in enumerate(cols.base_position):
        data[name] = record.qpos[:, k]
    for name, k in zip(cols.base_quaternion, (1, 2, 3, 0), strict=False):
        data[name] = quat[:, k]
    for k, name in enumerate(cols.base_linear_velocity):
        data[name] = record.qvel[:, k]
    for k, name in enumerate(cols.base_angular_velocity):
        data[name] = omega_world[:, k]
    robot = sim.robot
    simulated = {name: i for i, name in enumerate(sim.joint_names)}
    T = record.time.size
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        if name in simulated:
            i = simulated[name]
            q, v = record.qpos[:, sim.qpos_adr[i]], record.qvel[:, sim.dof_adr[i]]
        else:
            value = sim.stance.q[slot.idx_q]
            if slot.nq == 2:  # continuous joint, (cos, sin)
                value = float(np.arctan2(sim.stance.q[slot.idx_q + 1], sim.stance.q[slot.idx_q]))
            q, v = np.full(T, value), np.zeros(T)
        data[joint_position_column(name)] = q
        data[joint_velocity_column(name)] = v
    for name, force in record.forces.items():
        for column, values in zip(force_columns(name), force.T, strict=False):
            data[column] = values
    for k, name in enumerate(cols.com):
        data[name] = record.com[:, k]
    for k, name in enumerate(cols.com_velocity):
        data[name] = record.com_velocity[:, k]
    frame = pd.DataFrame(data)
    return frame[frame[cols.time] >= start - 1e-12].reset_index(drop=True)


class LogRecorder:
    """A log built step by step (the balance trials' loop).

    It reads pinocchio's ``(q, v)`` and MuJoCo's state; :func:`log_frame` builds the same columns
    from an impact trial's recorded arrays.
    """

    def __init__(self, sim: SimModel, contact_names: list[str], impact: bool):
        cols = LogColumns()
        robot = sim.robot
        slots = [robot.joint_slot(n) for n in robot.joint_names]
        self.q_index = np.array([s.idx_q for s in slots])
        self.v_index = np.array([robot.model.joints[s.id].idx_v for s in slots])
        self.columns = [
            cols.time,
            *cols.base_position,
            *cols.base_quaternion,
            *cols.base_linear_velocity,
            *cols.base_angular_velocity,
        ]
        self.columns += [joint_position_column(n) for n in robot.joint_names]
        self.columns += [joint_velocity_column(n) for n in robot.joint_names]
        self.columns += list(cols.zmp) + list(cols.com) + list(cols.com_velocity)
        for name in contact_names:
            self.columns += list(force_columns(name))
        if impact:
            self.columns += list(force_columns("impact"))
        self.rows: list[np.ndarray] = []

    def add(
        self,
        t: float,
        q: _FloatArray,
        v: _FloatArray,
        sim: SimModel,
        zmp: _FloatArray,
        forces: _FloatArray,
        impact_force: _FloatArray | None,
    ) -> None:
        """One row: time, base and joint state, ZMP, CoM, contact forces (and the impact's).

        Args:
            t: Time (s).
            q: Configuration (nq, pinocchio order).
            v: Velocity (nv, pinocchio order).
            sim: The trial's MuJoCo model, at the state ``(q, v)``.
            zmp: Measured ZMP (m, world).
            forces: Each sustained contact's force (k x 3, N, world).
            impact_force: The impact point's force (3, N, world), None without an impact.
        """
        # The CoM columns are MuJoCo's own (subtree CoM and velocity): a cross-check for the log
        # checker, which recomputes them with pinocchio from the base and joint columns.
        # After mj_step, MuJoCo's CoM quantities still describe the state before the step: refresh
        # them for the current state (position-dependent stages only; the next step recomputes
        # them anyway).
        mujoco.mj_kinematics(sim.model, sim.data)
        mujoco.mj_comPos(sim.model, sim.data)
        mujoco.mj_comVel(sim.model, sim.data)
        com, com_velocity = sim.com(), sim.com_velocity()
        lin, ang = sim.base_velocity_world()
        qj, vj = q[self.q_index], v[self.v_index]
        parts = [[t], q[:7], lin, ang, qj, vj, zmp, com, com_velocity, forces.ravel()]
        if impact_force is not None:
            parts.append(impact_force)
        self.rows.append(np.concatenate([np.asarray(p, dtype=float).ravel() for p in parts]))

    def frame(self) -> pd.DataFrame:
        """The rows so far as a log frame (:mod:`impact_balance.logs` columns)."""
        return pd.DataFrame(np.array(self.rows), columns=self.columns)
