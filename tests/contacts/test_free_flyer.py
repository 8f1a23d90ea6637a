"""``has_free_flyer`` answers each model's own root joint, however often and in whatever order."""

from __future__ import annotations

import pinocchio as pin
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import load_scenario
from impact_balance.contacts.stance import has_free_flyer


def root_is_free_flyer(model: pin.Model) -> bool:
    return model.njoints > 1 and model.joints[1].shortname() == "JointModelFreeFlyer"


def sample(free_flyer: bool) -> pin.Model:
    return pin.buildSampleModelHumanoid(free_flyer)


@settings(max_examples=40, deadline=None)
@given(kinds=st.lists(st.booleans(), min_size=1, max_size=12))
def test_each_model_gets_its_own_answer(kinds):
    models = []
    for free_flyer in kinds:
        model = sample(free_flyer)  # new models, some at the ids of dropped ones
        assert has_free_flyer(model) is free_flyer is root_is_free_flyer(model)
        models.append(model)
        if len(models) > 2:
            models.pop(0)
    for model in models:  # asked again
        assert has_free_flyer(model) is root_is_free_flyer(model)


def test_bundled_robots_and_a_fixed_arm():
    robot = load_scenario("palm_push_two_feet").load_robot()
    assert has_free_flyer(robot.model) and has_free_flyer(robot.model)
    arm = pin.buildSampleModelManipulator()
    assert not has_free_flyer(arm) and not has_free_flyer(arm)


def test_a_model_given_a_root_joint_after_an_answer():
    model = pin.Model()
    assert not has_free_flyer(model)
    model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
    assert has_free_flyer(model)
