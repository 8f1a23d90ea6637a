"""solve_stance's options: the defaults of the former keyword arguments, read by the iterations."""

from __future__ import annotations

import dataclasses

import numpy as np
import pinocchio as pin
import pytest

from impact_balance.robot.ik import IKError, IKOptions, solve_stance, stance_residuals
from impact_balance.robot.robot import load_robot

FEET = ["left_sole_link", "right_sole_link"]


def test_defaults_and_frozen():
    options = IKOptions()
    assert (
        options.posture_cost,
        options.joint_costs,
        options.base_orientation_cost,
        options.max_iterations,
        options.tolerance,
        options.damping,
        options.solver,
    ) == (1e-3, None, 1e-2, 500, 1e-6, 1e-9, "daqp")
    with pytest.raises(dataclasses.FrozenInstanceError):
        options.tolerance = 1.0  # type: ignore[misc]


def test_iterations_and_tolerance_come_from_the_options():
    robot = load_robot("talos")
    q0 = robot.configuration("half_sitting")
    data = robot.model.createData()
    com = pin.centerOfMass(robot.model, data, q0)
    target = com[:2] + np.array([0.03, 0.0])

    def solve(options: IKOptions):
        return solve_stance(robot, q0, None, target, fixed_frames=FEET, options=options)

    with pytest.raises(IKError) as info:
        solve(IKOptions(max_iterations=1))
    assert info.value.iterations == 1
    loose = solve(IKOptions(tolerance=1e-3))
    pin.framesForwardKinematics(robot.model, data, q0)
    feet = {f: pin.SE3(data.oMf[robot.frame_id(f)]) for f in FEET}
    assert max(stance_residuals(robot, loose, feet, target).values()) <= 1e-3
    tight = solve(IKOptions(tolerance=1e-8))
    assert max(stance_residuals(robot, tight, feet, target).values()) <= 1e-8
