"""The torque-controlled balance controller (inverse-dynamics QP): the QP's answer, and trials in
MuJoCo.

The QP's output is checked against independent computations: pinocchio's RNEA for the dynamics,
pinocchio's forward kinematics with the QP's accelerations for the contacts, and the contact wrench
cones of :mod:`impact_balance.contacts.cwc`. The trials simulate 1-1.5 s each.
"""

from __future__ import annotations

import json

import numpy as np
import pinocchio as pin
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.analysis.analyze import analyze
from impact_balance.cli import main
from impact_balance.contacts.cwc import cwc_faces_world
from impact_balance.scenario import load_scenario
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    Push,
    run_balance_trial,
)

SCENARIO = "palm_push_two_feet"
ID = BalanceTrialOptions(controller="id")


@pytest.fixture(scope="module")
def setup():
    return BalanceSetup.create(SCENARIO, options=ID)


@pytest.mark.parametrize("name", ["palm_push_two_feet", "palm_push_ramp"])
def test_qp_solution_obeys_dynamics_contacts_and_cones(name):
    analysis = analyze(load_scenario(name))
    gains = InverseDynamicsGains()
    controller = InverseDynamicsController(analysis, gains=gains)
    model, data = analysis.stance.model, analysis.stance.model.createData()
    rng = np.random.default_rng(3)
    q = analysis.stance.q.copy()
    for _trial in range(5):
        v = 0.3 * rng.standard_normal(model.nv)  # a moving robot: drifts and Coriolis terms matter
        out = controller.step(0.0, q, v)
        a, w = out.a, out.wrenches
        pin.framesForwardKinematics(model, data, q)
        tau_contacts = np.zeros(model.nv)
        for i, contact in enumerate(analysis.stance.contacts):
            fid = model.getFrameId(contact.spec.frame)
            J = pin.computeFrameJacobian(
                model, data, q, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
            tau_contacts += J.T @ w[i]
            rotation = data.oMf[fid].rotation
            # Inside the QP's cone (friction scaled, rectangle shrunk), hence inside the contact's
            # own.
            faces = cwc_faces_world(
                contact.spec.friction, contact.half_length, contact.half_width, rotation
            )
            assert (faces @ w[i]).max() <= 1e-6 * np.abs(w[i]).max()
            assert w[i][:3] @ rotation[:, 2] >= gains.min_normal_force - 1e-6
        # Floating base: RNEA's unactuated rows are balanced by the contact wrenches; the actuated
        # rows are tau.
        rnea = pin.rnea(model, data, q, v, a)
        np.testing.assert_allclose(rnea[:6], tau_contacts[:6], atol=1e-6 * np.abs(rnea).max())
        np.testing.assert_allclose(
            out.tau,
            np.clip(rnea[6:] - tau_contacts[6:], -controller.effort, controller.effort),
            atol=1e-6 * np.abs(rnea).max(),
        )
        # Contacts: the QP's accelerations give each contact frame the damped acceleration -K_c J v.
        pin.forwardKinematics(model, data, q, v, a)
        pin.updateFramePlacements(model, data)
        for contact in analysis.stance.contacts:
            fid = model.getFrameId(contact.spec.frame)
            acc = pin.getFrameClassicalAcceleration(
                model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            ).vector
            vel = pin.getFrameVelocity(
                model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            ).vector
            np.testing.assert_allclose(
                acc, -gains.contact_damping * vel, atol=1e-6 * (1 + np.abs(acc).max())
            )


def test_stands_still_for_a_second(setup):
    result = run_balance_trial(
        setup,
        push=Push(0.0, 1e-6, 0.01, start=0.0),
        options=BalanceTrialOptions(controller="id", after=1.0),
    )
    assert not result.fell, result.detail
    com = result.series["com"]
    assert np.abs(com - com[0]).max() < 2e-3
    assert np.linalg.norm(result.series["com_velocity"][-1]) < 5e-3
    assert result.max_slip < 1e-3 and np.rad2deg(result.max_tilt) < 0.5


def test_dcm_converges_after_a_small_push(setup):
    push = Push(np.pi / 2, 5.0, 0.05, start=0.2)
    result = run_balance_trial(
        setup, push=push, options=BalanceTrialOptions(controller="id", after=1.2)
    )
    assert not result.fell, result.detail
    s = result.series
    reference = s["dcm"][0]
    error = np.linalg.norm(s["dcm"] - reference, axis=1)
    end = int(np.searchsorted(s["time"], push.start + push.duration))
    later = int(np.searchsorted(s["time"], push.start + push.duration + 1.0))
    assert error[end] > 0.01  # the push moved the DCM (5 N s on 90 kg: about 0.06 m/s)
    # Unclamped, the DCM error decays as exp(-k t): after 1 s, exp(-2) = 0.14; allow for model
    # error.
    assert error[later] < 0.35 * error[end]
    assert not np.any(np.isnan(s["zmp_desired"]))


def test_a_push_far_outside_the_area_falls(setup):
    result = run_balance_trial(
        setup, push=Push(0.0, 90.0, 0.05), options=BalanceTrialOptions(controller="id", after=1.5)
    )
    assert result.fell and result.reason is not None
    assert result.com_velocity_margin_at_end < 0  # ~1 m/s, far outside the CoM velocity area


def test_cli_push_test_with_the_id_controller(capsys):
    code = main(
        [
            "push-test",
            SCENARIO,
            "--controller",
            "id",
            "--directions",
            "1",
            "--magnitudes",
            "5",
            "--json",
            "--no-journal",
        ]
    )
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert out["controller"]["name"] == InverseDynamicsController.name
    assert len(out["pushes"]) == 1 and out["pushes"][0]["fell"] is False


def test_unknown_controller_is_refused():
    from impact_balance.exceptions import SimulationError

    with pytest.raises(SimulationError, match="controller"):
        BalanceSetup.create(SCENARIO, options=BalanceTrialOptions(controller="mpc"))
