"""The id controller's QP plans with the simulated plant's inertia, ``M + h D``.

On iCub (1 N m s/rad on every joint, no rotor inertia; set 11's spent wall hold): the trial
controller's added inertia is MuJoCo's ``timestep * dof_damping`` of each simulated joint (zero
with an explicit integrator or with the gain off), and the torques it plans satisfy the equations
of motion written with pinocchio's recursive Newton-Euler algorithm plus that term.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import mujoco
import pinocchio as pin

from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

STANCE = (
    Path(__file__).parents[3]
    / "studies/held_out_11/icub_right_hand_wall_left_palm_oblique_side.yaml"
)


def _options(flag: bool) -> BalanceTrialOptions:
    return BalanceTrialOptions(
        controller="id", id_gains=InverseDynamicsGains(implicit_damping_inertia=flag)
    )


@pytest.fixture(scope="module")
def setup():
    return BalanceSetup.create(str(STANCE), options=_options(True))


def _controller(setup, flag: bool) -> InverseDynamicsController:
    return InverseDynamicsController.for_trial(
        setup.analysis,
        setup.analysis.stance.q.copy(),
        _options(flag),
        None,
        setup.sim,
        setup.support_v_index,
    )


def test_the_added_inertia_is_the_step_times_each_joints_damping(setup):
    sim = setup.sim
    controller = _controller(setup, True)
    expected = np.zeros(controller.nv - 6)
    expected[sim.v_index - 6] = sim.model.opt.timestep * sim.model.dof_damping[sim.dof_adr]
    np.testing.assert_array_equal(controller.implicit_inertia, expected)
    assert expected.min() > 0  # iCub damps every simulated joint: the test means something
    assert controller.describe()["gains"]["implicit_damping_inertia"] is True
    np.testing.assert_array_equal(_controller(setup, False).implicit_inertia, 0.0)


def test_an_explicit_integrator_adds_nothing(setup):
    model = setup.sim.model
    integrator = model.opt.integrator
    try:
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        np.testing.assert_array_equal(_controller(setup, True).implicit_inertia, 0.0)
    finally:
        model.opt.integrator = integrator


@pytest.mark.parametrize("flag", [True, False])
def test_the_planned_torques_obey_the_plants_equations_of_motion(setup, flag):
    """``tau = RNEA(q, v, a) + h D a - sum J_i^T w_i`` on the actuated rows, term or not."""
    controller = _controller(setup, flag)
    model, data = controller.model, controller.model.createData()
    q = setup.analysis.stance.q.copy()
    rng = np.random.default_rng(3)
    v = np.zeros(controller.nv)
    v[6:] = 0.05 * rng.standard_normal(controller.nv - 6)
    out = controller.step(0.0, q, v)
    # Within the effort limits, so the torques are the QP's, unclipped.
    assert not out.torque_limited
    assert np.all(np.abs(out.tau + controller.compensation(v)) <= controller.effort + 1e-9)
    expected = pin.rnea(model, data, q, v, out.a).copy()
    pin.computeJointJacobians(model, data, q)
    pin.framesForwardKinematics(model, data, q)
    for fid, offset, w in zip(
        controller.contact_frames, controller.contact_offsets, out.wrenches, strict=True
    ):
        J = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        r = (data.oMf[fid] * offset).translation - data.oMf[fid].translation
        J[:3] -= pin.skew(r) @ J[3:]
        expected -= J.T @ w
    added = controller.implicit_inertia * out.a[6:]
    np.testing.assert_allclose(out.tau, expected[6:] + added, atol=1e-6 * np.abs(out.tau).max())
    np.testing.assert_allclose(expected[:6], 0.0, atol=1e-6 * np.abs(expected).max())
    if flag:
        assert np.abs(added).max() > 1e-4  # the term is not lost in the tolerance


def _left_arm_first_step(flag: bool) -> tuple[np.ndarray, np.ndarray]:
    """The planned and realised accelerations (rad/s^2) of iCub's left elbow and wrist.

    A trial's controller and model: 50 control steps at rest (2 MuJoCo steps each), the left arm's
    joints then set moving at 0.1 rad/s, one control step, one MuJoCo step (the torques'
    first, whose damping the compensation cancels exactly).
    """
    options = _options(flag)
    setup = BalanceSetup.create(str(STANCE), options=options)
    sim = setup.sim
    m, d = sim.model, sim.data
    controller = _controller(setup, flag)
    arm = [i for i, n in enumerate(sim.joint_names) if n.startswith("l_wrist") or n == "l_elbow"]
    h = m.opt.timestep
    for k in range(51):
        if k == 50:
            d.qvel[sim.dof_adr[arm]] += 0.1
            mujoco.mj_forward(m, d)
        out = controller.step(2 * k * h, sim.configuration(), sim.velocity())
        controller.actuate(sim, out)
        before = d.qvel[sim.dof_adr[arm]].copy()
        mujoco.mj_step(m, d)
        realised = (d.qvel[sim.dof_adr[arm]] - before) / h
        mujoco.mj_step(m, d)
    assert not out.torque_limited
    return out.a[sim.v_index[arm]], realised


def test_a_light_damped_wrist_realises_the_plan_only_with_the_term():
    """iCub's wrists (M_ii 4.8e-4 to 1.4e-3 kg m^2, h D = 1e-3): MuJoCo's step against the plan."""
    planned, realised = _left_arm_first_step(True)
    scale = np.abs(planned).max()
    assert scale > 1.0  # the arm is asked to move
    np.testing.assert_allclose(realised, planned, atol=0.02 * scale)
    planned, realised = _left_arm_first_step(False)
    assert np.abs(realised - planned).max() > 0.3 * np.abs(planned).max()


@pytest.mark.slow
def test_icubs_wall_touch_holds_with_the_term_and_tips_without():
    """Set 11's wall hold, free joints, the left palm at the wall at 0.02 m/s, 0.3 s after it.

    With ``M`` alone the touch back-drives the wrist into its damping's saturation and the arm's
    swing turns the trunk past 5° within 0.2 s (docs/studies/hand-contacts.md); with the plant's
    inertia the trunk stays within 2°.
    """
    from impact_balance.sim.trials.balance_trial import run_balance_trial

    tilt = {}
    for flag in (True, False):
        options = BalanceTrialOptions(
            controller="id",
            after=0.3,
            id_gains=InverseDynamicsGains(implicit_damping_inertia=flag),
        )
        setup = BalanceSetup.create(str(STANCE), options=options)
        result = run_balance_trial(setup, impact_speed=0.02, options=options)
        summary = result.summary()
        assert result.impact is not None and result.impact.contact_time is not None
        tilt[flag] = summary["max_trunk_tilt_deg"]
        if flag:
            assert summary["outcome"] == "balanced", summary
    assert tilt[True] < 2.0 < 5.0 < tilt[False], tilt
