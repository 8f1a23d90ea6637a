"""analyze() reuses what a robot caches between analyses, and never an earlier analysis' answer.

Scenarios that differ only in their joint values share the robot's plan for those joint names
(and its Data, look-ups and limits): each one's stance must be its own configuration, set
here from the model directly, and its answer must not depend on what was analysed before it.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.exceptions import ScenarioError

NAME = "palm_push_two_feet"


def _moved(scenario, offsets: list[float]):
    """The scenario with its first joints moved by ``offsets`` (rad), the same joint names."""
    joints = dict(scenario.joints)
    for name, offset in zip(list(joints)[: len(offsets)], offsets, strict=False):
        joints[name] = joints[name] + offset
    return scenario.replace(joints=joints)


def _configuration(scenario) -> np.ndarray:
    """The scenario's q before the stance lifts it (base given): from the model directly."""
    robot = scenario.load_robot()
    model = robot.model
    q = robot.configuration(scenario.configuration)
    for name, value in scenario.joints.items():
        q[model.joints[model.getJointId(name)].idx_q] = value
    q[:3] = scenario.base.position
    return q


def _answer(analysis) -> tuple[float, ...]:
    impact = analysis.impact
    return (
        impact.max_contact_velocity,
        impact.zmp_max_contact_velocity,
        analysis.areas.com_velocity_area.area,
        analysis.areas.zmp_area.area,
        *analysis.stance.com,
    )


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.floats(-0.04, 0.04), min_size=6, max_size=6))
def test_each_posture_gets_its_own_answer_whatever_came_before(offsets):
    base = ib.load_scenario(NAME)
    assert base.base is not None and base.base.rpy is not None  # q[3:7] from the rpy
    a, b = _moved(base, offsets[:3]), _moved(base, offsets[3:])
    first_a, first_b = ib.analyze(a), ib.analyze(b)
    again_b, again_a = ib.analyze(b), ib.analyze(a)
    for scenario, analysis in ((a, first_a), (b, first_b)):
        np.testing.assert_array_equal(analysis.stance.q[7:], _configuration(scenario)[7:])
    assert _answer(again_a) == _answer(first_a)  # the order does not matter, to the last digit
    assert _answer(again_b) == _answer(first_b)
    if not np.array_equal(first_a.stance.q, first_b.stance.q):
        assert _answer(first_a) != _answer(first_b)  # another posture, another answer


def test_a_joint_outside_its_limits_is_refused_after_accepted_values_of_the_same_joints():
    base = ib.load_scenario(NAME)
    ib.analyze(base)
    name = next(iter(base.joints))
    robot = base.load_robot()
    upper = float(robot.joint_slot(name).upper)
    for _ in range(2):
        with pytest.raises(ScenarioError) as info:
            ib.analyze(base.replace(joints={**base.joints, name: upper + 1e-3}))
        assert info.value.field == f"joints.{name}"
    assert _answer(ib.analyze(base)) == _answer(ib.analyze(base))
