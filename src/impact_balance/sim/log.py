"""A trial's time series as a log table (schema of :mod:`impact_balance.logs.schema`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..logs import LogColumns, force_columns, joint_position_column, joint_velocity_column
from .model import SimModel
from .trial import TrialRecord

__all__ = ["log_frame", "LOG_START"]

#: Logs start here (s): the first steps settle the model's initial contact penetration (the
#: contacts carry nothing at t = 0, then briefly one foot carries thousands of newtons), a
#: transient of the simulation's start, not of the robot's motion.
LOG_START = 0.05


def _rotations(quaternions_wxyz: np.ndarray) -> np.ndarray:
    """(T, 3, 3) rotation matrices of unit quaternions (w, x, y, z)."""
    w, x, y, z = quaternions_wxyz.T
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=-1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=-1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=-1),
    ], axis=1)


def log_frame(sim: SimModel, record: TrialRecord, start: float = LOG_START) -> pd.DataFrame:
    """One row per step from ``start`` (s) on: time, base pose (quaternion x, y, z, w) and world-axes velocities, every
    actuated joint's position and velocity (welded ones at the stance, velocity 0), the contact
    forces on the robot and MuJoCo's CoM and CoM velocity.

    MuJoCo's free joint stores the angular velocity in the base frame: it is rotated to world axes.
    """
    cols = LogColumns()
    quat = record.qpos[:, 3:7]
    omega_world = np.einsum("tij,tj->ti", _rotations(quat), record.qvel[:, 3:6])
    data: dict[str, np.ndarray] = {cols.time: record.time}
    for k, name in enumerate(cols.base_position):
        data[name] = record.qpos[:, k]
    for name, k in zip(cols.base_quaternion, (1, 2, 3, 0)):
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
        for column, values in zip(force_columns(name), force.T):
            data[column] = values
    for k, name in enumerate(cols.com):
        data[name] = record.com[:, k]
    for k, name in enumerate(cols.com_velocity):
        data[name] = record.com_velocity[:, k]
    frame = pd.DataFrame(data)
    return frame[frame[cols.time] >= start - 1e-12].reset_index(drop=True)
