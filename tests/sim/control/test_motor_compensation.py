"""The id controller's motors compensate the joints' damping and dry friction, within their limits.

The compensation is checked against its formula written out branch by branch, and in a trial's
controller against MuJoCo's own joint parameters and the motors' force range.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim.control.torque import InverseDynamicsController, motor_compensation
from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

finite = st.floats(-50.0, 50.0, allow_nan=False)
positive = st.floats(0.0, 10.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(damping=positive, friction=positive, qdot=finite, vf=st.floats(1e-4, 1.0))
def test_compensation_is_damping_plus_a_saturated_friction(damping, friction, qdot, vf):
    got = motor_compensation(np.array([damping]), np.array([friction]), np.array([qdot]), vf)[0]
    if abs(qdot) >= vf:
        expected = damping * qdot + friction * (1.0 if qdot > 0 else -1.0)
    else:
        expected = damping * qdot + friction * qdot / vf
    assert got == pytest.approx(expected, rel=1e-12, abs=1e-12)
    # Odd in the velocity, and the friction's share never exceeds the friction.
    back = motor_compensation(np.array([damping]), np.array([friction]), np.array([-qdot]), vf)
    assert back[0] == pytest.approx(-got, abs=1e-12)
    assert abs(got - damping * qdot) <= friction + 1e-12


@pytest.fixture(scope="module")
def trial_controller():
    options = BalanceTrialOptions(controller="id")
    setup = BalanceSetup.create("palm_push_two_feet", options=options)
    controller = InverseDynamicsController.for_trial(
        setup.analysis,
        setup.analysis.stance.q.copy(),
        options,
        None,
        setup.sim,
        setup.support_v_index,
    )
    return setup, controller


def test_the_trial_controller_reads_mujocos_damping_and_friction(trial_controller):
    setup, controller = trial_controller
    m, sim = setup.sim.model, setup.sim
    np.testing.assert_array_equal(controller.joint_damping, m.dof_damping[sim.dof_adr])
    np.testing.assert_array_equal(controller.joint_friction, m.dof_frictionloss[sim.dof_adr])
    assert controller.joint_friction.max() > 0  # Talos declares friction: the test means something


def test_motor_torques_stay_within_the_effort_limits_while_moving(trial_controller):
    """The QP bounds what the motor applies (its torque plus the compensation), not its share."""
    setup, controller = trial_controller
    sim, m, d = setup.sim, setup.sim.model, setup.sim.data
    q = setup.analysis.stance.q.copy()
    rng = np.random.default_rng(7)
    lo, hi = m.actuator_forcerange[sim.actuator_ids].T
    for _ in range(4):
        v = np.zeros(controller.nv)
        v[6:] = 0.8 * rng.standard_normal(controller.nv - 6)  # fast joints: a large compensation
        out = controller.step(0.0, q, v)
        d.qvel[:] = 0.0
        d.qvel[sim.dof_adr] = v[sim.v_index]
        controller.actuate(sim, out)
        applied = d.ctrl[sim.actuator_ids]
        # Independently: the QP's torque plus damping and friction at the same velocities.
        qd = v[sim.v_index]
        expected = (
            out.tau[sim.v_index - 6]
            + m.dof_damping[sim.dof_adr] * qd
            + m.dof_frictionloss[sim.dof_adr]
            * np.clip(qd / controller.gains.friction_velocity, -1, 1)
        )
        np.testing.assert_allclose(applied, expected, atol=1e-9)
        if not out.torque_limited:
            assert np.all(applied <= hi + 1e-6) and np.all(applied >= lo - 1e-6)


def test_a_hand_holding_a_table_holds_through_a_pelvis_push():
    """Talos on one foot, its gripper on a table (set 8's spent stance): 0.75 of the boundary at 0°.

    Without the friction's compensation the gripper rolled past 5° and the trunk tipped (the
    same trial on the code before the change; docs/studies/hand-contacts.md).
    """
    from pathlib import Path

    from impact_balance.sim.studies.push import START_COM_VELOCITY, boundary_impulse
    from impact_balance.sim.trials.balance_trial import Push, run_balance_trial

    stance = Path(__file__).parents[3] / "studies/held_out_8"
    options = BalanceTrialOptions(controller="id", after=1.0)
    setup = BalanceSetup.create(
        str(stance / "talos_right_foot_right_hand_hold_left_toe_front.yaml"), options=options
    )
    a = setup.analysis
    impulse = 0.75 * boundary_impulse(
        a.areas.com_velocity_area, a.stance.mass, 0.0, START_COM_VELOCITY
    )
    result = run_balance_trial(
        setup, push=Push(0.0, impulse, 0.05, options.settle, "base_link"), options=options
    )
    summary = result.summary()
    assert summary["outcome"] == "balanced", summary
    assert not summary["events"]
