"""The held-stance jumps: the contact-aware model at the restitution bounds, the closed-form
floating frictionless impact, and the jump affine in the restitution between the bounds."""

from __future__ import annotations

import dataclasses
from functools import cache

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ImpactModelError
from impact_balance.impact.contact_aware import contact_impact
from impact_balance.impact.held_stance import held_stance_jumps
from impact_balance.impact.model import impact_model
from impact_balance.scenario import load_scenario


@cache
def _stance_and_spec(name: str, floating: bool = False):
    scenario = load_scenario(name)
    stance = scenario.build_stance()
    if floating:
        stance = Stance(stance.robot, stance.q, [])
    return stance, scenario.impact.spec()


@settings(max_examples=15, deadline=None)
@given(
    lo=st.floats(0.0, 1.0),
    width=st.floats(0.0, 1.0),
    nx=st.floats(-1.0, -0.3),
    nz=st.floats(-0.5, 0.5),
)
def test_floating_frictionless_jumps_are_the_closed_form_impulse(lo, width, nx, nz):
    """Without sustained contacts and friction, the impulse is lambda n with
    n . (v^- + W lambda n) = c v: lambda = (1 + c) v / (n W n), jump lambda n / m."""
    stance, spec = _stance_and_spec("g1_two_feet", floating=True)
    hi = min(1.0, lo + width)
    spec = dataclasses.replace(
        spec, friction=0.0, restitution=(lo, hi), normal=(nx, 0.2, nz), reference_velocity=None
    )
    held = held_stance_jumps(stance, spec)
    model = impact_model(stance, spec)
    n = model.normal
    for row, c in zip(held.jumps, (lo, hi), strict=True):
        impulse = (1.0 + c) / float(n @ model.W @ n) * n
        np.testing.assert_allclose(row, impulse[:2] / model.mass, atol=1e-8)
    assert held.restitution == (lo, hi)
    assert held.converged == (True, True) and held.all_converged


@pytest.mark.parametrize("name", ["palm_push_two_feet", "jvrc1_kick_one_foot"])
def test_rows_are_the_contact_aware_model_at_each_bound_and_affine_between(name):
    stance, spec = _stance_and_spec(name)
    spec = dataclasses.replace(spec, restitution=(0.1, 0.5))
    held = held_stance_jumps(stance, spec)
    assert held.all_converged
    for row, c in zip(held.jumps, (0.1, 0.5), strict=True):
        direct = contact_impact(stance, spec, 1.0, restitution=c)
        np.testing.assert_allclose(row, direct.com_velocity_jump, atol=1e-12)
    # The jump is linear in the approach speed and affine in c: the bounds cover every c.
    for t in (0.25, 0.6):
        c = 0.1 + t * 0.4
        middle = contact_impact(stance, spec, 2.0, restitution=c).com_velocity_jump / 2.0
        np.testing.assert_allclose(middle, (1 - t) * held.jumps[0] + t * held.jumps[1], atol=1e-7)
    assert not np.allclose(held.jumps[0], held.jumps[1])  # the restitution matters here


def test_too_few_iterations_are_reported_as_not_converged():
    stance, spec = _stance_and_spec("palm_push_two_feet")
    held = held_stance_jumps(stance, spec, max_iterations=1)
    assert held.converged == (False, False) and not held.all_converged
    assert held.iterations == 2


def test_the_joint_space_inertia_model_is_refused():
    stance, spec = _stance_and_spec("palm_push_two_feet")
    with pytest.raises(ImpactModelError) as info:
        held_stance_jumps(stance, dataclasses.replace(spec, inertia="joint_space"))
    assert info.value.field == "impact.inertia"


def _corner_arms(stance: Stance) -> np.ndarray:
    """(k, 4, 3) each sustained contact's corners minus the CoM, world, m (cwc_span's order)."""
    arms = []
    for c in stance.contacts:
        X, Y = c.half_length, c.half_width
        arms.append(
            [
                c.position + c.rotation @ np.array([px, py, 0.0]) - stance.com
                for px, py in ((X, Y), (X, -Y), (-X, Y), (-X, -Y))
            ]
        )
    return np.array(arms, dtype=float).reshape(len(stance.contacts), 4, 3)


@pytest.mark.parametrize("name", ["palm_push_two_feet", "g1_two_feet", "jvrc1_kick_one_foot"])
def test_the_angular_momentum_left_is_ic_dw_and_the_moment_of_all_impulses(name):
    """L = Ic dw of each bound's solution, and the moment about the CoM of the point's and
    every corner's impulses (arms from the contacts' own geometry and the impact model's point)."""
    stance, spec = _stance_and_spec(name)
    held = held_stance_jumps(stance, spec)
    assert held.all_converged and held.angular_momentum.shape == (2, 3)
    point = impact_model(stance, spec).point - stance.com
    arms = _corner_arms(stance)
    for row, c in enumerate(held.restitution):
        answer = contact_impact(stance, spec, 1.0, restitution=c)
        L = held.angular_momentum[row]
        np.testing.assert_allclose(L, stance.com_inertia @ answer.angular_velocity_jump, atol=1e-12)
        moment = np.cross(point, answer.impact_impulse) + np.cross(
            arms, answer.corner_impulses
        ).sum(axis=(0, 1))
        np.testing.assert_allclose(L, moment, rtol=0, atol=1e-9 * max(1.0, np.abs(L).max()))
        # The feet take part: their share of the moment is not negligible on the two-feet walls.
        if name != "jvrc1_kick_one_foot":
            feet = np.cross(arms, answer.corner_impulses).sum(axis=(0, 1))
            assert np.linalg.norm(feet) > 0.1 * np.linalg.norm(L)
    # Linear in the approach speed, as the jumps are.
    twice = contact_impact(stance, spec, 2.0, restitution=held.restitution[1])
    np.testing.assert_allclose(
        stance.com_inertia @ twice.angular_velocity_jump,
        2 * held.angular_momentum[1],
        rtol=1e-9,
        atol=1e-9,
    )
