"""The mink limit on a MuJoCo model of the governor's robot: the state map between MuJoCo's and
pinocchio's conventions, the row against MuJoCo's own Jacobian of the point, the velocity it
reads, and the MuJoCo models it refuses."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor

mink = pytest.importorskip(
    "mink", reason="needs the mink extra (pip install 'impact-balance[mink]')"
)
mujoco = pytest.importorskip("mujoco", reason="needs the mink extra (mujoco)")
pytestmark = pytest.mark.sim  # the robot's MuJoCo model comes from impact_balance.sim

from impact_balance.governor.mink_limit import MinkApproachLimit  # noqa: E402
from impact_balance.governor.mujoco_state import MujocoState  # noqa: E402
from impact_balance.sim.model.urdf import robot_spec  # noqa: E402

GOVERNOR = Governor("palm_push_two_feet")
MODEL = GOVERNOR.robot.model
MJ_MODEL = robot_spec(GOVERNOR.robot, meshes=False)[0].compile()


def posture(seed: int) -> np.ndarray:
    """A pinocchio q near the scenario's: joints moved, the base turned."""
    rng = np.random.default_rng(seed)
    q = GOVERNOR.configuration.copy()
    q[7:] = np.clip(
        q[7:] + rng.uniform(-0.05, 0.05, MODEL.nq - 7),
        MODEL.lowerPositionLimit[7:],
        MODEL.upperPositionLimit[7:],
    )
    turn = pin.Quaternion(pin.rpy.rpyToMatrix(*rng.uniform(-0.2, 0.2, 3)))
    q[3:7] = (pin.Quaternion(q[6], *q[3:6]) * turn).normalized().coeffs()
    return q


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 10_000))
def test_the_state_map_round_trips_and_maps_velocities(seed):
    state = MujocoState(MODEL, MJ_MODEL)
    q = posture(seed)
    qpos = state.qpos(q, np.zeros(MJ_MODEL.nq))
    np.testing.assert_allclose(state.q(qpos), q, atol=1e-15)
    qvel = np.random.default_rng(seed).normal(0.0, 1.0, MJ_MODEL.nv)
    M = np.random.default_rng(seed + 1).normal(0.0, 1.0, (3, MODEL.nv))
    np.testing.assert_allclose(state.columns(qpos, M) @ qvel, M @ state.v(qpos, qvel), atol=1e-12)
    # MuJoCo's base velocity is the world's: its linear part rotated into the base frame.
    R = pin.Quaternion(q[6], *q[3:6]).matrix()
    np.testing.assert_allclose(state.v(qpos, qvel)[:3], R.T @ qvel[:3], atol=1e-15)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_row_is_mujocos_jacobian_of_the_point_and_the_governors_cap(seed):
    limit = MinkApproachLimit(GOVERNOR, MJ_MODEL)
    configuration = mink.Configuration(MJ_MODEL)
    q = posture(seed)
    configuration.update(limit.state.qpos(q, configuration.data.qpos))
    qvel = np.random.default_rng(seed).normal(0.0, 0.2, MJ_MODEL.nv)
    configuration.data.qvel[:] = qvel  # the configuration's velocity: read by default
    constraint = limit.compute_qp_inequalities(configuration, 0.002)
    expected = GOVERNOR.limit(q, limit.state.v(configuration.data.qpos, qvel))
    assert constraint.h[0] == pytest.approx(expected.ceiling * 0.002, rel=1e-15)
    # MuJoCo's own Jacobian of the impact point, on the body of the frame's joint.
    frame = MODEL.frames[MODEL.getFrameId(GOVERNOR.scenario.impact.frame)]
    body = MJ_MODEL.joint(MODEL.names[frame.parentJoint]).bodyid[0]
    data = mujoco.MjData(MJ_MODEL)
    data.qpos[:] = configuration.data.qpos
    mujoco.mj_forward(MJ_MODEL, data)
    jacp = np.zeros((3, MJ_MODEL.nv))
    mujoco.mj_jac(MJ_MODEL, data, jacp, None, expected.point, body)
    np.testing.assert_allclose(constraint.G[0], -expected.normal @ jacp, atol=1e-10)
    limit.velocity = np.zeros(MJ_MODEL.nv)  # the caller's velocity wins
    again = limit.compute_qp_inequalities(configuration, 0.002)
    at_rest = GOVERNOR.limit(q, np.zeros(MODEL.nv))
    assert again.h[0] == pytest.approx(at_rest.ceiling * 0.002, rel=1e-15)


def test_mujoco_models_of_another_robot_are_refused():
    empty = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><freejoint/><geom size='0.1'/></body></worldbody></mujoco>"
    )
    with pytest.raises(GovernorError) as e:
        MinkApproachLimit(GOVERNOR, empty)
    assert e.value.field == "mj_model" and e.value.value == MODEL.names[2]
    two = mujoco.MjModel.from_xml_string(
        "<mujoco><worldbody><body><freejoint/><geom size='0.1'/></body>"
        "<body><freejoint/><geom size='0.1'/></body></worldbody></mujoco>"
    )
    with pytest.raises(GovernorError) as e:
        MinkApproachLimit(GOVERNOR, two)
    assert e.value.field == "free_joint"
    with pytest.raises(GovernorError) as e:
        MinkApproachLimit(GOVERNOR, MJ_MODEL, free_joint="arm_right_1_joint")
    assert e.value.field == "free_joint"
