"""The bundled stances realise what their scenario files describe; ik.solve_stance works."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.exceptions import ImpactBalanceError
from impact_balance.geometry.polygon import Polygon
from impact_balance.robot.ik import IKError, IKOptions, solve_stance, stance_residuals
from impact_balance.robot.robot import load_robot
from impact_balance.scenario import load_scenario

STANCES = [
    "palm_push_two_feet",
    "palm_push_ramp",
    "kick_one_foot",
    "talos_three_contacts",
    "g1_two_feet",
    "palm_push_mu010",
    "palm_push_mu024",
    "palm_push_mu040",
]
Z = np.array([0.0, 0.0, 1.0])


def _stance(name: str) -> ib.Stance:
    return load_scenario(name).build_stance()


def _angle_deg(a: np.ndarray, b: np.ndarray) -> float:
    return math.degrees(
        math.acos(float(np.clip(np.dot(a, b) / np.linalg.norm(a) / np.linalg.norm(b), -1, 1)))
    )


def _support(stance: ib.Stance) -> Polygon:
    """Horizontal projection of the convex hull of all contact corners."""
    return Polygon.from_points(np.vstack([c.corners()[:, :2] for c in stance.contacts]))


def _sole_rectangle(contact: ib.Contact) -> Polygon:
    return Polygon.from_points(contact.corners()[:, :2])


@pytest.mark.parametrize("name", STANCES)
def test_bundled_stance_is_balanced(name: str) -> None:
    analysis = ib.analyze(name)
    assert analysis.verdict == "balanced"
    assert analysis.com_velocity_inside
    answer = analysis.impact
    assert answer is not None
    assert math.isfinite(answer.max_contact_velocity) and answer.max_contact_velocity > 0
    assert 0 < answer.zmp_max_contact_velocity < answer.max_contact_velocity


@pytest.mark.parametrize("name", STANCES[:5])
def test_ground_contacts_touch_the_ground_and_com_is_supported(name: str) -> None:
    stance = _stance(name)
    for contact in stance.contacts:
        if abs(contact.normal[2]) > 0.99:  # flat soles lie on z = 0
            assert abs(contact.position[2]) < 1e-5
    assert _support(stance).contains(stance.com[:2], 1e-9)


def test_ramp_stance() -> None:
    stance = _stance("palm_push_ramp")
    left, right = stance.contacts
    assert left.spec.frame == "left_sole_link" and right.spec.frame == "right_sole_link"
    assert _angle_deg(left.normal, Z) < 0.05
    assert abs(_angle_deg(right.normal, Z) - 30.0) < 0.5
    assert right.normal[0] < 0  # toe up: the ramp rises forward, its normal leans backwards
    assert abs(left.position[2]) < 1e-5
    assert np.all(right.corners()[:, 2] > 0.01)  # the ramp foot is off the ground plane
    # CoM over the midpoint of the two sole centres, inside the support.
    np.testing.assert_allclose(
        stance.com[:2], 0.5 * (left.position[:2] + right.position[:2]), atol=1e-5
    )
    assert _support(stance).contains(stance.com[:2], 1e-9)


def test_kick_stance() -> None:
    scenario = load_scenario("kick_one_foot")
    stance = scenario.build_stance()
    (right,) = stance.contacts
    assert right.spec.frame == "right_sole_link"
    assert _angle_deg(right.normal, Z) < 0.05
    left_sole = stance.frame_pose("left_sole_link")
    assert left_sole.translation[2] > 0.1  # lifted
    assert left_sole.translation[0] > right.position[0] + 0.15  # forward
    assert _sole_rectangle(right).contains(stance.com[:2], 1e-9)
    np.testing.assert_allclose(stance.com[:2], right.position[:2], atol=1e-5)
    # The impact point is at the toe of the lifted foot.
    assert scenario.impact is not None and scenario.impact.frame == "left_sole_link"
    toe = left_sole * scenario.impact.offset.se3()
    assert toe.translation[0] > left_sole.translation[0] + 0.09


def test_three_contact_stance() -> None:
    stance = _stance("talos_three_contacts")
    assert len(stance.contacts) == 3
    hand = stance.contacts[2]
    assert hand.spec.frame == "gripper_left_base_link"
    assert abs(hand.normal[2]) < 1e-3  # horizontal normal: a wall
    np.testing.assert_allclose(
        hand.normal, [0.0, -1.0, 0.0], atol=1e-3
    )  # wall on the left, normal into the robot
    for foot in stance.contacts[:2]:
        assert _angle_deg(foot.normal, Z) < 0.05


def test_palm_push_gripper_in_front_of_chest() -> None:
    scenario = load_scenario("palm_push_two_feet")
    stance = scenario.build_stance()
    gripper = stance.frame_pose("gripper_right_base_link").translation
    assert 0.35 <= gripper[0] <= 0.45 and 0.95 <= gripper[2] <= 1.05
    for foot in stance.contacts:
        assert _angle_deg(foot.normal, Z) < 0.05 and abs(foot.position[2]) < 1e-5
    centre = 0.5 * (stance.contacts[0].position[:2] + stance.contacts[1].position[:2])
    np.testing.assert_allclose(stance.com[:2], centre, atol=1e-5)


def test_impact_friction_sweep_is_monotonic() -> None:
    limits = [
        ib.analyze(f"palm_push_mu{tag}").impact.max_contact_velocity
        for tag in ("010", "024", "040")
    ]
    assert limits[0] > limits[1] > limits[2]
    assert limits[1] == pytest.approx(ib.analyze("palm_push_two_feet").impact.max_contact_velocity)


def test_solve_stance_moves_the_com() -> None:
    robot = load_robot("talos")
    q0 = robot.configuration("half_sitting")
    data = robot.model.createData()
    com0 = pin.centerOfMass(robot.model, data, q0)
    target = com0[:2] + np.array([0.02, 0.0])
    feet = ["left_sole_link", "right_sole_link"]
    q = solve_stance(
        robot, q0, com_target_xy=target, fixed_frames=feet, options=IKOptions(tolerance=1e-6)
    )
    com = pin.centerOfMass(robot.model, data, q)
    np.testing.assert_allclose(com[:2], target, atol=1e-6)
    pin.framesForwardKinematics(robot.model, data, q0)
    targets = {f: pin.SE3(data.oMf[robot.frame_id(f)]) for f in feet}
    assert max(stance_residuals(robot, q, targets).values()) < 1e-6
    lo, hi = robot.model.lowerPositionLimit[7:], robot.model.upperPositionLimit[7:]
    assert np.all(q[7:] >= lo - 1e-9) and np.all(q[7:] <= hi + 1e-9)


def test_solve_stance_reports_unreachable_targets() -> None:
    robot = load_robot("talos")
    q0 = robot.configuration("half_sitting")
    far = pin.SE3(np.eye(3), np.array([2.0, -0.25, 1.0]))
    with pytest.raises(IKError) as info:
        solve_stance(
            robot,
            q0,
            {"gripper_right_base_link": far},
            fixed_frames=["left_sole_link", "right_sole_link"],
            options=IKOptions(max_iterations=30),
        )
    err = info.value
    assert isinstance(err, ImpactBalanceError)
    assert err.iterations == 30 and err.q.shape == (robot.model.nq,)
    assert err.residuals["gripper_right_base_link.position"] > 0.3  # the arm is ~0.6 m long
