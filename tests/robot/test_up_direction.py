"""Robot.up_direction: the feet-to-CoM axis, computed in a Data of its own per thread."""

from __future__ import annotations

import threading

import numpy as np
import pinocchio as pin
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.robot.robot import load_robot


def _independent_up(robot, q):
    """The feet-to-CoM unit vector from a fresh Data, with numpy's mean and norm."""
    data = robot.model.createData()
    com = pin.centerOfMass(robot.model, data, q)
    pin.updateFramePlacements(robot.model, data)
    feet = np.mean([data.oMf[robot.model.getFrameId(f)].translation for f in robot.foot_frames], 0)
    direction = com - feet
    return direction / np.linalg.norm(direction)


def _configuration(robot, seed):
    """A random configuration within the joint limits (clipped to +-3 where unbounded)."""
    model = robot.model
    lower = np.maximum(model.lowerPositionLimit, -3.0)
    upper = np.minimum(model.upperPositionLimit, 3.0)
    rng = np.random.default_rng(seed)
    q = lower + rng.random(model.nq) * (upper - lower)
    quaternion = rng.normal(size=4)
    q[3:7] = quaternion / np.linalg.norm(quaternion)
    return q


@settings(max_examples=40, deadline=None)
@given(st.sampled_from(["talos", "go2", "human"]), st.integers(0, 2**32 - 1))
def test_up_direction_equals_a_fresh_data_computation_to_the_last_digit(name, seed):
    robot = load_robot(name)
    q = _configuration(robot, seed)
    got = robot.up_direction(q)
    assert got is not None
    np.testing.assert_array_equal(got, _independent_up(robot, q))
    assert abs(float(got @ got) - 1.0) < 1e-12


def test_up_direction_leaves_the_stances_scratch_data_alone():
    robot = load_robot("talos")
    scratch = robot.thread_data()
    q = _configuration(robot, 1)
    pin.forwardKinematics(robot.model, scratch.data, q)
    before = scratch.data.oMi[1].translation.copy()
    robot.up_direction(_configuration(robot, 2))
    np.testing.assert_array_equal(scratch.data.oMi[1].translation, before)


def test_up_direction_in_threads_answers_each_threads_configuration():
    robot = load_robot("talos")
    configurations = [_configuration(robot, seed) for seed in range(4)]
    want = [_independent_up(robot, q) for q in configurations]
    failures: list[str] = []
    barrier = threading.Barrier(len(configurations))

    def run(k: int) -> None:
        barrier.wait()
        for _ in range(200):
            got = robot.up_direction(configurations[k])
            if got is None or not np.array_equal(got, want[k]):
                failures.append(f"thread {k}: {got} != {want[k]}")
                return

    threads = [threading.Thread(target=run, args=(k,)) for k in range(len(configurations))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert failures == []
