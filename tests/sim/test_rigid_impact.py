"""--rigid-impact: the joints keep their velocities through the impact, the impulse becomes the
rigid body's."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.sim import SimOptions, build_model
from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
from impact_balance.sim.trials.measure import measure

SCENARIO = "palm_push_two_feet"


@pytest.fixture(scope="module")
def sim():
    return build_model(SCENARIO, "servo", SimOptions(meshes=False))


@pytest.fixture(scope="module")
def trials(sim):
    out = {}
    for rigid in (False, True):
        record = run_trial(sim, TrialOptions(0.3, after=0.04, rigid_impact=rigid))
        out[rigid] = (record, measure(sim, record, 0.3))
    return out


def test_hold_keeps_every_joint_velocity_and_ends_at_the_end_of_compression(sim, trials):
    record, result = trials[True]
    hold = result.hold
    assert hold is not None and 0.001 <= hold["duration"] <= 0.02
    assert hold["max_joint_velocity_change"] < 1e-2  # rad/s, against joint speeds of ~0.5 rad/s
    n = np.asarray(sim.scenario.impact.normal, dtype=float)
    n /= np.linalg.norm(n)
    # impact_velocity[k] is the state after step k, at time[k] + dt.
    after = record.time + sim.model.opt.timestep
    approach = -record.impact_velocity @ n
    held = (after > hold["start"] + 1e-9) & (after <= hold["end"] + 1e-9)
    assert approach[held][-1] <= 0.0  # the point stopped approaching when the hold ended
    assert np.all(approach[held][:-1] > 0.0)  # ... and not before
    # Outside the hold the joints have their own rotor inertia again.
    np.testing.assert_allclose(sim.model.dof_armature[sim.dof_adr], sim.armature)


def test_held_impact_is_the_composite_one_up_to_the_sustained_contacts(sim, trials):
    free, held = trials[False][1], trials[True][1]
    # A servo-held arm gives way (joint_space); held joints transmit the rigid body's impulse
    # (composite).
    assert np.linalg.norm(held.impulse_measured) > 10 * np.linalg.norm(free.impulse_measured)
    assert held.predicted["composite"].relative_distance < 0.1
    assert (
        free.predicted["joint_space"].relative_distance
        < held.predicted["joint_space"].relative_distance
    )
    # Momentum: the CoM velocity jump is the impact's impulse plus the sustained contacts' (gravity
    # and the
    # contacts' forces before the impact subtracted), over the mass.
    total = held.impulse_measured + sum(held.sustained_impulses.values())
    mass = sim.stance.mass
    np.testing.assert_allclose(
        held.com_velocity_jump_measured, total[:2] / mass, atol=0.02 * np.linalg.norm(total) / mass
    )
