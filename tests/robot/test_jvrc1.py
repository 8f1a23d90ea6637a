"""JVRC-1 (jvrc-description) as a bundled robot, and its three bundled stances."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from impact_balance.analysis.analyze import analyze
from impact_balance.robot.robot import BUNDLED_ROBOTS, load_robot
from impact_balance.scenario import bundled_scenarios, load_scenario

JVRC1_SCENARIOS = ["jvrc1_palm_push_two_feet", "jvrc1_palm_push_ramp", "jvrc1_kick_one_foot"]


def test_jvrc1_loads_by_name_from_its_wheel():
    assert "jvrc1" in BUNDLED_ROBOTS
    robot = load_robot("jvrc1")
    assert robot.urdf_path.name == "jvrc1.urdf" and robot.urdf_path.is_file()
    assert "jvrc_description" in robot.urdf_path.parts
    assert pin.computeTotalMass(robot.model) == pytest.approx(62.4, abs=1e-9)
    # The URDF declares 100 N m on every actuated joint.
    assert np.all(np.asarray(robot.model.effortLimit[6:]) == 100.0)


def test_the_three_studies_are_bundled():
    assert set(JVRC1_SCENARIOS) <= set(bundled_scenarios())


@pytest.mark.parametrize("name", JVRC1_SCENARIOS)
def test_each_stance_balances_at_rest_with_a_bounded_answer(name):
    scenario = load_scenario(name)
    assert scenario.robot == "jvrc1"
    result = analyze(scenario)
    assert result.areas.can_balance
    assert result.impact is not None and 0.0 < result.impact.max_contact_velocity < 2.0


@pytest.mark.parametrize("name", JVRC1_SCENARIOS)
def test_torque_limits_do_not_bind_at_100_n_m(name):
    scenario = load_scenario(name)
    with_limits = analyze(scenario).impact
    without = analyze(scenario.replace(torque_limits=False)).impact
    assert with_limits.max_contact_velocity == pytest.approx(without.max_contact_velocity, 1e-9)


def test_answers_keep_the_papers_order():
    # HRP-4 (paper): two feet 0.397 < ramp 0.529 < kick 0.569 m/s; JVRC-1 keeps the order.
    v = [analyze(load_scenario(n)).impact.max_contact_velocity for n in JVRC1_SCENARIOS]
    assert v[0] < v[1] < v[2]
