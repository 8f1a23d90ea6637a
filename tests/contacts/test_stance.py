"""A stance's kinematics are pinocchio's at its configuration (world frame), its contacts' frames
are named by their index when unknown, and building one never changes another's numbers."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import load_scenario
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.exceptions import UnknownFrameError

SCENARIOS = ("palm_push_two_feet", "g1_two_feet", "talos_three_contacts")


@pytest.fixture(scope="module", params=SCENARIOS)
def placed(request):
    scenario = load_scenario(request.param)
    robot = scenario.load_robot()
    q = scenario.configuration_vector(robot)
    return robot, q, scenario.contact_specs(robot, q)


def _pinocchio(robot, q, specs):
    """The stance's numbers from pinocchio's own algorithms on a Data of their own (world)."""
    model = robot.model
    data = model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    com = pin.centerOfMass(model, data, q, False).copy()
    pin.ccrba(model, data, q, np.zeros(model.nv))
    gravity = pin.computeGeneralizedGravity(model, data, q).copy()
    contacts = []
    for spec in specs:
        fid = robot.frame_id(spec.frame)
        placement = data.oMf[fid] * spec.offset
        J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        # the Jacobian of the offset point: v_p = v_o + w x (p - o)
        r = placement.translation - data.oMf[fid].translation
        J[:3] += np.cross(J[3:].T, r).T
        contacts.append((placement.rotation.copy(), placement.translation.copy(), J))
    return com, float(data.Ig.mass), data.Ig.inertia.copy(), gravity, contacts


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), scale=st.floats(0.0, 0.3))
def test_a_stance_is_pinocchio_at_its_configuration(placed, seed, scale):
    robot, q0, specs = placed
    model = robot.model
    dq = scale * np.random.default_rng(seed).uniform(-1.0, 1.0, model.nv)
    q = pin.integrate(model, q0, dq)
    stance = Stance(robot, q, specs)
    com, mass, inertia, gravity, contacts = _pinocchio(robot, q, specs)
    np.testing.assert_allclose(stance.com, com, rtol=0, atol=1e-12)
    assert stance.mass == pytest.approx(mass, rel=1e-14)
    np.testing.assert_allclose(stance.com_inertia, inertia, rtol=0, atol=1e-11)
    np.testing.assert_allclose(stance.gravity_torques, gravity, rtol=0, atol=1e-10)
    assert len(stance.contacts) == len(specs)
    for contact, spec, (rotation, position, J) in zip(
        stance.contacts, specs, contacts, strict=True
    ):
        assert contact.spec is spec
        np.testing.assert_allclose(contact.rotation, rotation, rtol=0, atol=1e-13)
        np.testing.assert_allclose(contact.position, position, rtol=0, atol=1e-12)
        np.testing.assert_allclose(contact.local_position, position - stance.origin, atol=1e-12)
        np.testing.assert_allclose(contact.jacobian, J, rtol=0, atol=1e-12)


def test_stances_share_no_array_and_do_not_change_each_other(placed):
    robot, q0, specs = placed
    first = Stance(robot, q0, specs)
    kept = {name: getattr(first, name).copy() for name in ("com", "com_inertia", "gravity_torques")}
    second = Stance(robot, pin.integrate(robot.model, q0, np.full(robot.model.nv, 0.05)), specs)
    for name, value in kept.items():
        assert np.array_equal(getattr(first, name), value), name
        assert not np.shares_memory(getattr(first, name), getattr(second, name)), name
    for a, b in zip(first.contacts, second.contacts, strict=True):
        for name in ("rotation", "position", "jacobian", "local_position"):
            assert not np.shares_memory(getattr(a, name), getattr(b, name)), name


@pytest.mark.parametrize("bad", [1, 2])
def test_an_unknown_contact_frame_is_named_with_its_index(placed, bad):
    robot, q0, specs = placed
    wrong = [*specs[:bad], ContactSpec("no_such_frame", 0.7, (0.2, 0.1))]
    with pytest.raises(UnknownFrameError) as info:
        Stance(robot, q0, wrong)
    assert info.value.field == f"contacts[{bad}].frame"
    assert "no_such_frame" in str(info.value)


def test_a_frames_local_position_is_its_world_one_less_the_origin(placed):
    robot, q0, specs = placed
    stance = Stance(robot, q0, specs)
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    for frame in (*robot.foot_frames, specs[0].frame):
        local = stance.local_frame_position(frame)
        world = data.oMf[robot.frame_id(frame)].translation
        np.testing.assert_allclose(local + stance.origin, world, rtol=0, atol=1e-12)
        np.testing.assert_allclose(
            local + stance.origin, stance.frame_pose(frame).translation, rtol=0, atol=1e-12
        )
    with pytest.raises(UnknownFrameError) as info:
        stance.local_frame_position("no_such_frame", field="feet")
    assert info.value.field == "feet"
