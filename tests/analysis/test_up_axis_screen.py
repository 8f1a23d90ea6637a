"""The up-axis warning, screened from the stance's own numbers, is the robot's check's.

``diagnose`` warns ``robot_not_z_up`` exactly when ``Robot.up_axis_problem`` answers (at any base
rotation and position), and its screen says "upright" only where that check says so.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import load_scenario
from impact_balance.analysis import diagnostics
from impact_balance.contacts.stance import Stance


@pytest.fixture(scope="module", params=["palm_push_two_feet", "kick_one_foot"])
def standing(request):
    # Both soles contacts, and one foot in the air (placed from the stance's kinematics).
    scenario = load_scenario(request.param)
    robot = scenario.load_robot()
    stance = scenario.build_stance(robot)
    return scenario, robot, stance.q.copy(), [c.spec for c in stance.contacts]


def at(robot, q0, specs, roll, pitch, shift=(0.0, 0.0, 0.0)):
    q = q0.copy()
    base = pin.Quaternion(q0[3:7]).normalized().matrix()
    q[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(roll, pitch, 0.0) @ base).coeffs()
    q[:3] += shift
    return Stance(robot, q, specs)


def warned(scenario, stance) -> bool:
    codes = [d.code for d in diagnostics.diagnose(scenario, stance, None)]
    return "robot_not_z_up" in codes


@settings(max_examples=60, deadline=None)
@given(
    roll=st.floats(-math.pi, math.pi),
    pitch=st.floats(-1.5, 1.5),
    shift=st.tuples(*[st.floats(-1e4, 1e4)] * 3),
)
def test_the_warning_is_the_robots_check(standing, roll, pitch, shift):
    scenario, robot, q0, specs = standing
    stance = at(robot, q0, specs, roll, pitch, shift)
    problem = robot.up_axis_problem(stance.q)
    assert warned(scenario, stance) is (problem is not None)
    if diagnostics._surely_upright(stance):
        assert problem is None


def test_at_the_checks_45_degrees_the_robot_answers(standing):
    scenario, robot, q0, specs = standing
    lo, hi = 0.0, 1.5  # the roll where the feet-to-CoM axis is 45 degrees from +z
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        up = robot.up_direction(at(robot, q0, specs, mid, 0.0).q)
        lo, hi = (mid, hi) if up[2] >= math.cos(math.radians(45.0)) else (lo, mid)
    for roll in (lo, hi, lo - 1e-9, hi + 1e-9):
        stance = at(robot, q0, specs, roll, 0.0)
        assert not diagnostics._surely_upright(stance)  # within the margin: the robot's check
        assert warned(scenario, stance) is (robot.up_axis_problem(stance.q) is not None)
    assert warned(scenario, at(robot, q0, specs, hi + 1e-3, 0.0))
    assert not warned(scenario, at(robot, q0, specs, lo - 1e-3, 0.0))


def test_the_screen_answers_where_the_feet_are_contacts(standing):
    _, robot, q0, specs = standing
    assert diagnostics._surely_upright(Stance(robot, q0, specs))  # both soles are contacts
    kick = load_scenario("kick_one_foot")
    kicking = kick.build_stance(kick.load_robot())
    assert len(kicking.contacts) < len(kicking.robot.foot_frames)
    assert diagnostics._surely_upright(kicking)  # a foot in the air, placed by the stance
    g1 = load_scenario("g1_two_feet")
    g1_robot = g1.load_robot()
    if not g1_robot.foot_frames:  # feet unknown: never warned
        assert diagnostics._surely_upright(g1.build_stance(g1_robot))
    assert np.isfinite(robot.up_direction(q0)).all()
