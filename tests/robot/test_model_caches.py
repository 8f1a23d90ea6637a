"""The robot's caches answer what the model answers now, never an earlier value or model.

`Robot.joint_assignment` keeps a plan per set of joint names (indices and accepted ranges) and
checks each call's values against it; `Robot.up_direction` computes only the feet's
placements. Every check compares with the model read directly (pinocchio, a fresh Data), and a
robot given another model drops every cache.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import ScenarioError
from impact_balance.robot.robot import load_robot

NAMES = ("torso_2_joint", "arm_left_4_joint", "leg_right_3_joint", "leg_left_4_joint")


def _limits(model: pin.Model, name: str) -> tuple[int, float, float]:
    """(q index, lower, upper) of a 1-dof joint, read from the model."""
    joint = model.joints[model.getJointId(name)]
    idx = joint.idx_q
    return idx, float(model.lowerPositionLimit[idx]), float(model.upperPositionLimit[idx])


def _expected(model: pin.Model, joints: dict[str, float]) -> tuple[list[int], list[float], str]:
    """Indices and values, and the first refused joint's name ("" when none), from the model."""
    indices, values = [], []
    for name, value in joints.items():
        idx, lo, hi = _limits(model, name)
        if not lo - 1e-9 <= value <= hi + 1e-9:
            return [], [], name
        indices.append(idx)
        values.append(value)
    return indices, values, ""


def _check(robot, joints: dict[str, float]) -> None:
    indices, values, refused = _expected(robot.model, joints)
    if refused:
        with pytest.raises(ScenarioError) as info:
            robot.joint_assignment(joints)
        assert info.value.field == f"joints.{refused}"
        return
    idx, got = robot.joint_assignment(joints)
    assert idx.tolist() == indices
    assert got.tolist() == values  # the values given, to the last digit
    assert not idx.flags.writeable and not got.flags.writeable


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1.2, 1.2), min_size=2 * len(NAMES), max_size=2 * len(NAMES)))
def test_the_same_names_with_other_values_get_those_values_checked_against_the_limits(raw):
    """Two assignments of the same names in a row (the second from the names' plan): each
    answers its own values, and a value outside the limits is refused wherever it comes."""
    robot = load_robot("talos")
    for part in (raw[: len(NAMES)], raw[len(NAMES) :]):
        _check(robot, dict(zip(NAMES, part, strict=True)))


def test_a_refused_value_after_accepted_ones_is_refused_every_time():
    robot = load_robot("talos")
    _, lo, hi = _limits(robot.model, "arm_left_4_joint")
    good = {"torso_2_joint": 0.0, "arm_left_4_joint": 0.5 * (lo + hi)}
    robot.joint_assignment(good)
    for bad in (hi + 1e-6, lo - 1e-6, math.nan):
        for _ in range(2):
            with pytest.raises(ScenarioError) as info:
                robot.joint_assignment({**good, "arm_left_4_joint": bad})
            assert info.value.field == "joints.arm_left_4_joint"
    assert robot.joint_assignment(good)[1].tolist() == list(good.values())


def test_values_at_the_limits_slack_are_accepted_and_beyond_it_refused():
    robot = load_robot("talos")
    _, lo, hi = _limits(robot.model, "leg_left_4_joint")
    robot.joint_assignment({"leg_left_4_joint": 0.5 * (lo + hi)})  # the plan exists
    assert robot.joint_assignment({"leg_left_4_joint": hi + 1e-9})[1][0] == hi + 1e-9
    assert robot.joint_assignment({"leg_left_4_joint": lo - 1e-9})[1][0] == lo - 1e-9
    with pytest.raises(ScenarioError):
        robot.joint_assignment({"leg_left_4_joint": hi + 2e-9})


def test_a_robot_given_another_model_answers_from_it():
    """Its joint limits, effort limits and up axis are the new model's, after the old one's
    answers were cached."""
    robot = dataclasses.replace(load_robot("talos"))  # its own caches, the shared model
    q = robot.configuration()
    idx, lo, hi = _limits(robot.model, "arm_left_4_joint")
    value = 0.5 * (lo + hi)
    robot.joint_assignment({"arm_left_4_joint": value})
    old_up = robot.up_direction(q)
    old_effort = robot.effort_limits[1].copy()
    assert robot.up_axis_problem(q) is None

    model = pin.Model(robot.model)  # a copy, edited: the shared model stays as it was
    upper = np.array(model.upperPositionLimit)
    upper[idx] = value - 0.1
    model.upperPositionLimit = upper
    model.effortLimit = 0.5 * np.asarray(model.effortLimit)
    base = model.inertias[1]
    # A heavy mass 20 m to the side of the base: the CoM leaves the feet's vertical.
    model.inertias[1] = base + pin.Inertia(10.0 * robot.mass, np.array([0.0, 20.0, 0.0]), np.eye(3))
    robot.model = model

    with pytest.raises(ScenarioError) as info:
        robot.joint_assignment({"arm_left_4_joint": value})
    assert info.value.field == "joints.arm_left_4_joint"
    np.testing.assert_array_equal(robot.effort_limits[1], 0.5 * old_effort)
    up = robot.up_direction(q)
    data = model.createData()
    com = pin.centerOfMass(model, data, q)
    pin.updateFramePlacements(model, data)
    feet = np.mean([data.oMf[model.getFrameId(f)].translation for f in robot.foot_frames], 0)
    np.testing.assert_array_equal(up, (com - feet) / np.linalg.norm(com - feet))
    assert up[2] < 0.5 < old_up[2]
    assert robot.up_axis_problem(q) is not None  # not the cached answer of the old model
    assert load_robot("talos").up_axis_problem(q) is None  # the shared robot is untouched


def test_setting_the_same_model_again_keeps_the_caches():
    robot = dataclasses.replace(load_robot("talos"))
    slots = robot._joint_slots
    robot.model = robot.model
    assert robot._joint_slots is slots


def test_threads_assigning_the_same_names_each_get_their_own_values():
    """The names' plan keeps the last values accepted; threads that alternate two sets of
    values for the same names never get the other thread's."""
    import threading

    robot = dataclasses.replace(load_robot("talos"))
    middle = {name: 0.5 * sum(_limits(robot.model, name)[1:]) for name in NAMES}
    sets = [{name: v + 0.01 * k for name, v in middle.items()} for k in range(4)]
    failures: list[str] = []
    barrier = threading.Barrier(len(sets))

    def run(k: int) -> None:
        want = list(sets[k].values())
        barrier.wait()
        try:
            for _ in range(2000):
                got = robot.joint_assignment(sets[k])[1].tolist()
                if got != want:
                    failures.append(f"thread {k}: {got} != {want}")
                    return
        except Exception as exc:  # reported, not lost in the thread
            failures.append(f"thread {k}: {exc!r}")

    threads = [threading.Thread(target=run, args=(k,)) for k in range(len(sets))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert failures == []
