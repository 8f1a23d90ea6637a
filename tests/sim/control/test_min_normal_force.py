"""The id QP's minimum normal force acts along each contact's normal, offset rotation included.

A hand contact is the hand frame turned by the contact's ``offset.rpy``: its normal is not the
frame's z axis. Set 9's spent stance G1 on its right foot with its right palm on a table is the
check (docs/studies/hand-contacts.md, "Set 9's hand holds, after the fact"): with the row along
the frame's z the QP pressed the hand's friction cone to its edge at rest and the trunk tipped
within 3 s without a push.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    Push,
    run_balance_trial,
)

STANCE = (
    Path(__file__).parents[3]
    / "studies/held_out_9/g1_right_foot_right_hand_table_left_toe_front.yaml"
)


@pytest.fixture(scope="module")
def rest_trial():
    """A 3 s trial with a zero impulse; every control step's output and the controller kept."""
    options = BalanceTrialOptions(controller="id", after=2.7)
    setup = BalanceSetup.create(str(STANCE), options=options)
    outputs, controllers = [], []
    step = InverseDynamicsController.step

    def kept(self, t, q, v, *args):
        out = step(self, t, q, v, *args)
        outputs.append(out)
        controllers.append(self)
        return out

    InverseDynamicsController.step = kept
    try:
        # A push of zero impulse: a trial needs a disturbance; this one has none.
        push = Push(0.0, 0.0, 0.05, options.settle, "pelvis")
        result = run_balance_trial(setup, push=push, options=options)
    finally:
        InverseDynamicsController.step = step
    return setup, result.summary(), outputs, controllers[0]


def test_the_hand_contact_is_turned_by_its_offset(rest_trial):
    setup, _, _, _ = rest_trial
    hand = setup.analysis.stance.contacts[1]
    assert hand.spec.frame == "right_rubber_hand"
    frame_z = setup.analysis.stance.frame_pose(hand.spec.frame).rotation[:, 2]
    assert abs(float(frame_z @ hand.normal)) < 0.1  # the frame's z lies in the palm's face


def test_every_contact_carries_the_minimum_along_its_normal(rest_trial):
    setup, _, outputs, controller = rest_trial
    f_min = controller.gains.min_normal_force
    normals = [c.normal for c in setup.analysis.stance.contacts]
    out = outputs[0]  # the start posture: the analysis' normals
    for k, normal in enumerate(normals):
        assert float(normal @ out.wrenches[k][:3]) >= f_min - 1e-6


def test_the_start_posture_stands_without_a_push(rest_trial):
    setup, summary, outputs, _ = rest_trial
    assert summary["outcome"] == "balanced", summary
    assert not summary["events"]
    # The plan keeps the contacts' moment about the CoM near zero at rest (it was -0.43 N m at
    # 0.1 s and growing with the row along the frame's z, until the trunk tipped at 2.5 s).
    contacts = setup.analysis.stance.contacts
    for o in outputs[:: len(outputs) // 20]:
        moment = sum(
            np.cross(c.position - o.com, o.wrenches[k][:3]) + o.wrenches[k][3:]
            for k, c in enumerate(contacts)
        )
        assert np.abs(moment).max() < 0.1, (moment, o.com)
