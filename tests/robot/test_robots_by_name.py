"""Robots by name: example-robot-data's floating-base robots, their feet and their up axis."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import UnknownRobotError
from impact_balance.robot.robot import (
    BUNDLED_ROBOTS,
    EXAMPLE_ROBOTS,
    example_robot_data_root,
    load_robot,
    robot_names,
)
from impact_balance.scenario import Scenario

NOT_Z_UP = {"human"}


def test_go2_by_name_loads_its_urdf_and_srdf_standing():
    robot = load_robot("go2")
    assert robot.urdf_path == example_robot_data_root() / "go2_description/urdf/go2.urdf"
    assert robot.standing == "standing"
    mass = sum(i.mass for i in robot.model.inertias)
    assert mass == pytest.approx(16.09, abs=0.01)
    standing = robot.configuration("standing")
    assert standing[2] == pytest.approx(0.335)  # the SRDF's root_joint height
    assert not np.allclose(standing, robot.configuration("neutral"))
    assert robot.foot_frames == ("FL_foot", "FR_foot", "RL_foot", "RR_foot")


def test_an_unknown_name_lists_every_robot_by_name():
    with pytest.raises(UnknownRobotError) as info:
        load_robot("go3")
    assert info.value.field == "robot" and info.value.value == "go3"
    assert "go2" in info.value.valid and "talos" in info.value.valid
    assert "valid robots: a1, alex," in str(info.value) and "go2" in str(info.value)


def test_bundled_robots_come_first_and_are_not_shadowed():
    names = list(robot_names())
    assert names[: len(BUNDLED_ROBOTS)] == list(BUNDLED_ROBOTS)
    assert set(EXAMPLE_ROBOTS) <= set(names)
    assert load_robot("talos").urdf_path.name == "talos_reduced.urdf"


@pytest.mark.parametrize("name", sorted(EXAMPLE_ROBOTS))
def test_every_robot_by_name_loads_and_stands_z_up(name):
    robot = load_robot(name)
    assert robot.model.nq > 7 and robot.model.names[1] == "root_joint"
    assert robot.standing in robot.reference_configurations
    problem = robot.up_axis_problem(robot.configuration())
    if name in NOT_Z_UP:
        assert problem is not None
    else:
        assert problem is None, problem


def test_human_is_named_as_not_z_up_with_the_base_that_stands_it_up():
    robot = load_robot("human")
    q = robot.configuration()
    up = robot.up_direction(q)
    assert up is not None and abs(up[1]) > 0.99  # y up
    problem = robot.up_axis_problem(q)
    assert problem is not None
    assert "'human' is not z-up" in problem and "along +y" in problem
    assert "base: {position: [0.0, 0.0, 0.979], rpy: [1.5708, 0.0, 0.0]}" in problem


def _human(base=None):
    data = {
        "robot": "human",
        "contacts": [
            {"frame": "left_foot", "friction": 0.7, "size": [0.2, 0.1], "normal": [0, 0, 1]},
            {"frame": "right_foot", "friction": 0.7, "size": [0.2, 0.1], "normal": [0, 0, 1]},
        ],
    }
    if base is not None:
        data["base"] = base
    return Scenario.model_validate(data)


def test_analyze_of_a_lying_robot_warns_and_the_suggested_base_stands_it_up():
    from impact_balance.analysis.analyze import analyze

    lying = analyze(_human())
    codes = [d.code for d in lying.warnings]
    assert codes[0] == "robot_not_z_up" and lying.warnings[0].field == "base"
    assert re.search(r"not z-up.*along \+y.*base: \{position", lying.warnings[0].message)
    assert not lying.areas.can_balance  # on its side: "not enough friction"
    upright = _human({"position": [0.0, 0.0, 0.979], "rpy": [1.5708, 0.0, 0.0]})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        stance = upright.build_stance()
        result = analyze(upright)
    assert "robot_not_z_up" not in [d.code for d in result.warnings]
    feet_z = [c.position[2] for c in stance.contacts]
    assert max(abs(z) for z in feet_z) < 0.05  # standing on its feet, near the ground
    assert result.areas.can_balance and result.areas.com_velocity_area.area > 0


@settings(max_examples=25, deadline=None)
@given(
    rpy=st.tuples(st.floats(-math.pi, math.pi), st.floats(-1.5, 1.5), st.floats(-math.pi, math.pi))
)
def test_any_base_tilt_past_45_degrees_is_named_and_the_suggested_base_stands_it_up(rpy):
    robot = load_robot("go2")
    q = robot.configuration()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(np.array(rpy))).coeffs()
    up = robot.up_direction(q)
    problem = robot.up_axis_problem(q)
    assert (problem is None) == (up[2] >= math.cos(math.radians(45.0)))
    if problem is None:
        return
    match = re.search(r"base: \{position: \[(.*)\], rpy: \[(.*)\]\}$", problem)
    assert match, problem
    position, angles = (np.array([float(x) for x in g.split(",")]) for g in match.groups())
    q[:3] = position
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(angles)).coeffs()
    assert robot.up_axis_problem(q) is None
    assert robot.up_direction(q)[2] > math.cos(math.radians(11.0))
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q)
    lowest = min(data.oMf[robot.frame_id(f)].translation[2] for f in robot.foot_frames)
    assert abs(lowest) < 1e-3  # on the ground


def test_a_robot_by_name_points_at_frames_by_its_name():
    assert load_robot("go2").listing_command == "impact-balance frames go2"
    assert load_robot("talos").listing_command == "impact-balance frames talos"
