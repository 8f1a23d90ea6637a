"""A stance moved to another configuration is the stance computed there, to the last digit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import load_scenario
from impact_balance.contacts.stance import Stance

SCENARIOS = ("palm_push_two_feet", "kick_one_foot", "g1_two_feet", "solo12_kick_three_feet")


def assert_same_stance(got: Stance, want: Stance) -> None:
    for name in ("q", "origin", "com", "com_local", "com_inertia", "gravity_torques"):
        assert np.array_equal(getattr(got, name), getattr(want, name)), name
    assert got.mass == want.mass
    assert len(got.contacts) == len(want.contacts)
    for a, b in zip(got.contacts, want.contacts, strict=True):
        assert a.spec == b.spec
        for name in ("rotation", "position", "jacobian", "local_position"):
            assert np.array_equal(getattr(a, name), getattr(b, name)), name


@pytest.fixture(scope="module", params=SCENARIOS)
def placed(request):
    scenario = load_scenario(request.param)
    robot = scenario.load_robot()
    stance = scenario.build_stance(robot)
    return robot, stance, [c.spec for c in stance.contacts]


@settings(max_examples=30, deadline=None)
@given(shift=st.tuples(*[st.floats(-1e4, 1e4, allow_nan=False)] * 3))
def test_a_moved_base_keeps_the_kinematics_and_moves_the_world_positions(placed, shift):
    robot, stance, specs = placed
    q = stance.q.copy()
    q[:3] += shift
    moved = stance.moved_to(q)
    assert_same_stance(moved, Stance(robot, q, specs))
    assert not np.shares_memory(moved.com_local, stance.com_local)
    assert not np.shares_memory(moved.contacts[0].jacobian, stance.contacts[0].jacobian)


@settings(max_examples=10, deadline=None)
@given(index=st.integers(7, 200), step=st.floats(0.01, 0.05), sign=st.sampled_from([-1, 1]))
def test_another_configuration_computes_the_stance_again(placed, index, step, sign):
    robot, stance, specs = placed
    q = stance.q.copy()
    q[index % (q.size - 7) + 7] += sign * step  # a joint
    moved = stance.moved_to(q)
    assert_same_stance(moved, Stance(robot, q, specs))
    assert not np.array_equal(moved.gravity_torques, stance.gravity_torques)


def test_a_scenario_without_base_is_lifted_once():
    scenario = load_scenario("palm_push_two_feet").model_copy(update={"base": None})
    robot = scenario.load_robot()
    stance = scenario.build_stance(robot)
    assert stance.q[2] != scenario.configuration_vector(robot)[2]  # it was lifted
    assert abs(stance.lowest_contact_height()) <= 1e-12  # its lowest corner on the ground
    assert_same_stance(stance, Stance(robot, stance.q, [c.spec for c in stance.contacts]))
