"""Synthetic robot logs generated with pinocchio (no simulator): the log checker's reference."""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

import impact_balance as ib
from impact_balance.logs.schema import LogColumns, joint_position_column, joint_velocity_column

__all__ = ["SCENARIO", "synthetic_log"]

#: The scenario every synthetic log moves.
SCENARIO = "palm_push_two_feet"


def synthetic_log(
    com_velocity_of_base: np.ndarray, T: float = 0.4, rate: float = 500.0, wiggle: float = 0.05
) -> tuple[Any, list[tuple[np.ndarray, np.ndarray]], Any]:
    """A log of the stance translated at a constant base velocity while the arms swing.

    Args:
        com_velocity_of_base: the base's (and so the CoM's mean) velocity, world axes (m/s).
        T: duration (s).
        rate: samples per second (Hz).
        wiggle: amplitude of the two arm joints' sine (rad, period 1 s).

    Returns:
        The log (a pandas DataFrame), its pinocchio states ``(q, v)`` row by row, and the
        scenario ``palm_push_two_feet`` it moves.
    """
    import pandas as pd

    scenario = ib.load_scenario(SCENARIO)
    stance = scenario.build_stance()
    robot = stance.robot
    model = robot.model
    q0 = stance.q
    times = np.arange(0.0, T, 1.0 / rate)
    arm = [robot.joint_slot(n) for n in ("arm_left_1_joint", "arm_right_4_joint")]
    cols = LogColumns()
    rows, states = [], []
    for t in times:
        q = q0.copy()
        v = np.zeros(model.nv)
        q[0:3] += com_velocity_of_base * t
        R = pin.Quaternion(q[6], q[3], q[4], q[5]).matrix()
        v[0:3] = R.T @ com_velocity_of_base  # pinocchio: base-frame linear velocity
        for s in arm:
            q[s.idx_q] += wiggle * np.sin(2 * np.pi * t)
            v[model.joints[s.id].idx_v] = wiggle * 2 * np.pi * np.cos(2 * np.pi * t)
        row = {cols.time: t}
        row.update(zip(cols.base_position, q[0:3], strict=True))
        row.update(zip(cols.base_quaternion, q[3:7], strict=True))
        row.update(zip(cols.base_linear_velocity, com_velocity_of_base, strict=True))
        row.update(zip(cols.base_angular_velocity, np.zeros(3), strict=True))
        for name in robot.joint_names:
            s = robot.joint_slot(name)
            row[joint_position_column(name)] = q[s.idx_q]
            row[joint_velocity_column(name)] = v[model.joints[s.id].idx_v]
        rows.append(row)
        states.append((q, v))
    return pd.DataFrame(rows), states, scenario
