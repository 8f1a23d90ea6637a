"""Why a stance cannot balance: the torque limit or the friction that empties its area.

Checked independently: the torque case by editing the model's effort limit around the
reported factor and recomputing the areas; the friction case against the closed-form
smallest friction of a single contact whose force must point at the CoM.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.balance.areas import balance_areas
from impact_balance.balance.infeasibility import explain_cannot_balance
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.robot.robot import example_robot_data_root

SIMPLE = example_robot_data_root() / "simple_humanoid_description"
FEET = [ContactSpec("l_ankle", 0.7, (0.2, 0.1)), ContactSpec("r_ankle", 0.7, (0.2, 0.1))]


def _simple_humanoid():
    robot = ib.load_robot(
        None,
        SIMPLE / "urdf" / "simple_humanoid.urdf",
        SIMPLE / "srdf" / "simple_humanoid.srdf",
        "half_sitting",
    )
    # A private copy of the model: the test edits its effort limits.
    return dataclasses.replace(robot, model=pin.Model(robot.model))


def _stance(robot):
    stance = Stance(robot, robot.configuration(), FEET)
    q = stance.q.copy()
    q[2] -= stance.lowest_contact_height()
    return Stance(robot, q, FEET)


def test_simple_humanoid_torque_limits():
    robot = _simple_humanoid()
    stance = _stance(robot)
    areas = balance_areas(stance, torque_limits=True)
    assert not areas.can_balance
    assert balance_areas(stance, torque_limits=False).can_balance  # only the limits stop it
    reason = areas.reason
    assert reason.kind == "torque_limits"
    assert reason.binding_joints and "torque limits" in str(reason)
    assert "\n" not in str(reason)
    first = reason.binding_joints[0]
    assert first.min_scale > 1.0
    assert reason.uniform_scale is not None and 1.0 < reason.uniform_scale <= first.min_scale + 1e-9
    # Independent check: raise that joint's limit in the model just below / above the factor.
    k = robot.model.joints[robot.model.getJointId(first.joint)].idx_v
    for factor, expected in ((0.99, False), (1.01, True)):
        edited = dataclasses.replace(robot, model=pin.Model(robot.model))
        edited.model.effortLimit[k - (edited.model.nv - edited.model.effortLimit.size)] *= (
            factor * first.min_scale
        )
        assert balance_areas(_stance(edited), torque_limits=True).can_balance == expected, factor


def test_simple_humanoid_through_analyze(tmp_path):
    path = tmp_path / "simple.yaml"
    path.write_text(
        f"robot: {{urdf: {SIMPLE / 'urdf' / 'simple_humanoid.urdf'},"
        f" srdf: {SIMPLE / 'srdf' / 'simple_humanoid.srdf'},"
        " standing: half_sitting}\n"
        "contacts:\n"
        "  - {frame: l_ankle, friction: 0.7, size: [0.2, 0.1]}\n"
        "  - {frame: r_ankle, friction: 0.7, size: [0.2, 0.1]}\n"
    )
    analysis = ib.analyze(str(path))
    assert analysis.cannot_balance_reason is analysis.areas.reason
    d = json.loads(json.dumps(analysis.to_dict(), allow_nan=False))
    r = d["cannot_balance_reason"]
    assert r["kind"] == "torque_limits"
    assert {"joint", "effort", "min_scale"} <= set(r["binding_joints"][0])
    from impact_balance.analysis.report import format_analysis

    assert "reason: the joint torque limits" in format_analysis(analysis)


def test_friction_case_matches_closed_form():
    """One contact 0.3 m ahead of the CoM's vertical: the force must go from the centre of
    pressure to the CoM, so the contact needs mu >= (horizontal distance to the rectangle)
    / height, per pyramid axis, in the contact frame."""
    robot = ib.load_robot("talos")
    scenario = ib.load_scenario("kick_one_foot")
    q = scenario.build_stance().q
    size = (0.1, 0.06)
    spec = ContactSpec("right_sole_link", 0.05, size, pin.SE3(np.eye(3), np.array([0.3, 0.1, 0.0])))
    stance = Stance(robot, q, [spec])
    areas = balance_areas(stance, torque_limits=True)
    assert not areas.can_balance
    reason = areas.reason
    assert reason.kind == "friction"
    c = stance.contacts[0]
    v = c.rotation.T @ (stance.com - c.position)
    gap = max(abs(v[0]) - size[0] / 2, abs(v[1]) - size[1] / 2, 0.0)
    assert reason.min_friction == pytest.approx(gap / v[2], rel=3e-3)
    # and that friction indeed balances (torque limits off: the diagnosis relaxes them)
    ok = Stance(robot, q, [dataclasses.replace(spec, friction=reason.min_friction * 1.01)])
    assert balance_areas(ok, torque_limits=False).can_balance


def test_upside_down_foot_is_com_outside():
    """A sole contact flipped upside down pushes the robot down: no friction and no torque
    can carry the weight."""
    robot = ib.load_robot("talos")
    q = ib.load_scenario("kick_one_foot").build_stance().q
    flipped = ContactSpec(
        "right_sole_link", 0.7, (0.2, 0.1), pin.SE3(pin.rpy.rpyToMatrix(np.pi, 0, 0), np.zeros(3))
    )
    stance = Stance(robot, q, [flipped])
    assert not balance_areas(stance, torque_limits=False).can_balance
    reason = explain_cannot_balance(stance, torque_limits=True)
    assert reason.kind == "com_outside" and "static-equilibrium" in str(reason)


def test_both_feet_flipped_through_analyze():
    """Both soles upside down (what a GUI user did): an explained answer, not a solver error."""
    scenario = ib.load_scenario("palm_push_two_feet")
    contacts = [
        c.model_copy(update={"offset": c.offset.model_copy(update={"rpy": (np.pi, 0.0, 0.0)})})
        for c in scenario.contacts
    ]
    analysis = ib.analyze(scenario.model_copy(update={"contacts": contacts}))
    assert not analysis.areas.can_balance
    assert analysis.cannot_balance_reason.kind == "com_outside"
