"""The model update reuses one pinocchio Data per robot and thread, and caches look-ups.

Every check compares with pinocchio called directly on a Data of its own (the reference),
so a stance that read another stance's kinematics, or a stale cache, shows up as a mismatch.
"""

from __future__ import annotations

import copy
import pickle
import threading

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.contacts.wrench_polytope import grasp_matrix
from impact_balance.exceptions import ScenarioError
from impact_balance.robot.robot import load_robot

FEET = [
    ContactSpec("left_sole_link", 0.7, (0.2, 0.1)),
    ContactSpec("right_sole_link", 0.7, (0.2, 0.1)),
]
PALM = pin.SE3(np.eye(3), np.array([0.051, 0.0, -0.045]))
LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@pytest.fixture(scope="module")
def robot():
    return load_robot("talos")


def configurations(robot, n: int = 2) -> list[np.ndarray]:
    """Distinct configurations: half_sitting with the base and every joint moved."""
    rng = np.random.default_rng(7)
    out = []
    for _ in range(n):
        q = robot.configuration()
        q[:3] += rng.uniform(-0.1, 0.1, 3)
        q[7:] += rng.uniform(-0.2, 0.2, q.size - 7)
        out.append(q)
    return out


def reference(robot, q: np.ndarray, frame: str, offset: pin.SE3) -> dict[str, np.ndarray]:
    """What a stance at q must hold, from pinocchio on a fresh Data."""
    model = robot.model
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    pin.ccrba(model, data, q, np.zeros(model.nv))
    out = {
        "com": pin.centerOfMass(model, data, q, False).copy(),
        "com_inertia": data.Ig.inertia.copy(),
        "gravity": pin.computeGeneralizedGravity(model, data, q).copy(),
        "oMi": np.array([data.oMi[j].homogeneous for j in range(model.njoints)]),
    }
    for i, spec in enumerate(FEET):
        fid = model.getFrameId(spec.frame)
        out[f"R{i}"] = data.oMf[fid].rotation.copy()
        out[f"p{i}"] = data.oMf[fid].translation.copy()
        out[f"J{i}"] = pin.getFrameJacobian(model, data, fid, LWA)
    fid = model.getFrameId(frame)
    placement = data.oMf[fid] * offset
    J = pin.getFrameJacobian(model, data, fid, LWA)
    J[:3] -= pin.skew(placement.translation - data.oMf[fid].translation) @ J[3:]
    out["point"], out["point_J"] = placement.translation.copy(), J
    return out


def held(stance: Stance, frame: str, offset: pin.SE3) -> dict[str, np.ndarray]:
    """The same quantities, as the stance gives them."""
    placement, J = stance.point(frame, offset)
    out = {
        "com": stance.com,
        "com_inertia": stance.com_inertia,
        "gravity": stance.gravity_torques,
        "point": placement.translation,
        "point_J": J,
    }
    for i, c in enumerate(stance.contacts):
        out[f"R{i}"], out[f"p{i}"], out[f"J{i}"] = c.rotation, c.position, c.jacobian
    return out


def assert_matches(got: dict, expected: dict) -> None:
    for key, value in got.items():
        np.testing.assert_allclose(value, expected[key], rtol=0, atol=1e-12, err_msg=key)


def test_stances_of_one_robot_do_not_alias(robot):
    q1, q2 = configurations(robot)
    ref1, ref2 = (reference(robot, q, "gripper_right_base_link", PALM) for q in (q1, q2))
    assert not np.allclose(ref1["J0"], ref2["J0"])  # the two stances really differ
    a = Stance(robot, q1, FEET)
    kept = {k: v.copy() for k, v in held(a, "gripper_right_base_link", PALM).items()}
    b = Stance(robot, q2, FEET)  # overwrites the robot's scratch Data
    assert_matches(held(b, "gripper_right_base_link", PALM), ref2)
    # a's arrays are untouched, and a.point() recomputes a's kinematics, not b's.
    assert_matches(kept, ref1)
    assert_matches(held(a, "gripper_right_base_link", PALM), ref1)
    assert_matches(held(b, "gripper_right_base_link", PALM), ref2)
    Stance(robot, q2, FEET)
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, q1)
    np.testing.assert_allclose(
        a.frame_pose("torso_2_link").homogeneous,
        data.oMf[robot.model.getFrameId("torso_2_link")].homogeneous,
        rtol=0,
        atol=1e-12,
    )


def test_stance_data_is_a_data_of_its_own(robot):
    q1, q2 = configurations(robot)
    a = Stance(robot, q1, FEET)
    data = a.data
    assert data is not robot.thread_data().data
    Stance(robot, q2, FEET)
    np.testing.assert_allclose(
        np.array([data.oMi[j].homogeneous for j in range(robot.model.njoints)]),
        reference(robot, q1, "torso_2_link", PALM)["oMi"],
        rtol=0,
        atol=1e-12,
    )


def test_joint_space_impact_does_not_leave_stale_kinematics(robot):
    q1, q2 = configurations(robot)
    a, b = Stance(robot, q1, FEET), Stance(robot, q2, FEET)
    spec = ib.ImpactSpec(
        "gripper_right_base_link", (-1.0, 0.0, 0.0), offset=PALM, inertia="joint_space"
    )
    model = ib.impact_model(b, spec)  # runs crba on the scratch Data at q2
    data = robot.model.createData()
    M = pin.crba(robot.model, data, q2)
    M = np.triu(M) + np.triu(M, 1).T
    J = reference(robot, q2, "gripper_right_base_link", PALM)["point_J"][:3]
    np.testing.assert_allclose(model.W, J @ np.linalg.solve(M, J.T), rtol=1e-12, atol=0)
    for stance, q in ((a, q1), (b, q2)):
        assert_matches(
            held(stance, "gripper_right_base_link", PALM),
            reference(robot, q, "gripper_right_base_link", PALM),
        )


def test_stances_in_threads_match_a_fresh_data(robot):
    qs = configurations(robot, 4)
    refs = [reference(robot, q, "gripper_right_base_link", PALM) for q in qs]
    errors: list[str] = []

    def work(offset: int) -> None:
        for k in range(40):
            i = (k + offset) % len(qs)
            got = held(Stance(robot, qs[i], FEET), "gripper_right_base_link", PALM)
            try:
                assert_matches(got, refs[i])
            except AssertionError as exc:
                errors.append(str(exc))

    threads = [threading.Thread(target=work, args=(t,)) for t in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors


def test_robot_copies_rebuild_their_caches(robot):
    q = configurations(robot, 1)[0]
    Stance(robot, q, FEET)  # populates the caches and the scratch Data
    expected = reference(robot, q, "gripper_right_base_link", PALM)
    for other in (pickle.loads(pickle.dumps(robot)), copy.deepcopy(robot)):
        assert other.thread_data() is not robot.thread_data()
        assert_matches(held(Stance(other, q, FEET), "gripper_right_base_link", PALM), expected)


def test_cached_limits_are_returned_as_copies(robot):
    idx, lim = robot.actuated_effort_limits()
    idx[:] = 0
    lim[:] = -1.0
    idx2, lim2 = robot.actuated_effort_limits()
    assert idx2.size == 32 and np.all(lim2 > 0) and len(set(idx2)) == idx2.size
    model = robot.model
    effort = np.asarray(model.effortLimit)
    np.testing.assert_array_equal(lim2, effort[idx2 - (model.nv - effort.size)])


def test_joint_assignment_matches_setting_joints_one_by_one(robot):
    model = robot.model
    joints = {"arm_left_4_joint": -0.5, "leg_right_3_joint": -0.4, "torso_2_joint": 0.1}
    q = robot.configuration()
    idx, values = robot.joint_assignment(joints)
    q[idx] = values
    expected = robot.configuration()
    for name, value in joints.items():
        expected[model.joints[model.getJointId(name)].idx_q] = value
    np.testing.assert_array_equal(q, expected)
    other = {**joints, "torso_2_joint": -0.1}  # same names, another value: not the cached answer
    q2 = robot.configuration()
    idx2, values2 = robot.joint_assignment(other)
    q2[idx2] = values2
    assert q2[model.joints[model.getJointId("torso_2_joint")].idx_q] == -0.1


@pytest.mark.parametrize(
    "joints, field",
    [
        ({"torso_2_joint": 0.1, "arm_left_4_joint": 5.0}, "joints.arm_left_4_joint"),
        ({"nope_joint": 0.0, "arm_left_4_joint": 5.0}, "joints.nope_joint"),
    ],
)
def test_joint_assignment_reports_the_first_bad_joint_every_time(robot, joints, field):
    for _ in range(2):  # a refused assignment is not cached
        with pytest.raises(ScenarioError) as info:
            robot.joint_assignment(joints)
        assert info.value.field == field


def test_grasp_matrix_blocks():
    positions = np.array([[0.1, -0.2, 0.3], [-1.0, 2.0, 0.5], [0.0, 0.0, -0.7]])
    G = grasp_matrix(positions)
    f, tau = np.array([1.0, -2.0, 3.0]), np.array([0.5, 0.25, -1.0])
    for i, p in enumerate(positions):
        w = np.zeros(6 * len(positions))
        w[6 * i : 6 * i + 6] = np.concatenate([f, tau])
        np.testing.assert_allclose(
            G @ w, np.concatenate([f, tau + np.cross(p, f)]), rtol=0, atol=1e-15
        )


def test_scenario_specs_follow_the_scenario_content():
    sc = ib.load_scenario("palm_push_two_feet")
    moved = sc.model_copy(update={"impact": sc.impact.model_copy(update={"friction": 0.5})})
    assert sc.impact.spec().friction == 0.24 and moved.impact.spec().friction == 0.5
    a = ib.analyze(sc).impact.max_contact_velocity
    assert ib.analyze(moved).impact.max_contact_velocity < a
