"""The held-stance maximum with the angular momentum it leaves: each bound's jump and its
effective twin ``j + S(Ic dw) / (m h (1 + omega tau))``, rayed against the area here from the
contact-aware model directly; absent without tau; the fallback the analysis's default."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import analyze, load_scenario
from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from impact_balance.impact.contact_aware import contact_impact
from tests.helpers.held_stance import NOT_CONVERGING, ray


def _independent(analysis, tau: float) -> dict[tuple[float, bool], float]:
    """The ray of each bound's jump (False) and effective jump (True), from first principles."""
    spec = analysis.impact.model.spec
    stance = analysis.stance
    G, h = analysis.areas.com_velocity_area.halfplanes
    h = h - analysis.scenario.velocity_margin
    c0 = analysis.com_velocity[:2]
    omega, g = analysis.areas.omega, analysis.scenario.gravity
    height = g / omega**2
    rays = {}
    for c in spec.restitution:
        answer = contact_impact(stance, spec, 1.0, restitution=float(c))
        L = stance.com_inertia @ answer.angular_velocity_jump
        shift = np.array([L[1], -L[0]]) / (stance.mass * height * (1.0 + omega * tau))
        rays[float(c), False] = ray(G, h, c0, answer.com_velocity_jump)
        rays[float(c), True] = ray(G, h, c0, answer.com_velocity_jump + shift)
    return rays


@pytest.mark.parametrize(
    ("name", "tau", "changes"),
    [
        ("palm_push_two_feet", 0.1, {}),
        ("g1_two_feet", 0.0, {"zmp_margin": 0.01}),
        ("jvrc1_kick_one_foot", 0.1, {}),
        ("romeo_two_feet", 0.5, {"velocity_margin": 0.02, "com_velocity": (0.03, -0.02)}),
    ],
)
def test_with_tau_the_answer_is_the_smallest_of_the_four_rays(name, tau, changes):
    scenario = load_scenario(name).replace(angular_momentum_damping_time=tau, **changes)
    analysis = analyze(scenario)
    answer = held_stance_max_contact_velocity(analysis)
    term = answer.angular_momentum
    assert term is not None and not answer.fell_back
    rays = _independent(analysis, tau)
    assert term.damping_time == tau
    assert term.max_contact_velocity == pytest.approx(min(rays.values()), rel=1e-9)
    assert (term.binding_restitution, term.binding_effective) == min(rays, key=rays.get)
    # The jump's own answer is the one without the term, unchanged; the term only lowers it.
    plain = min(v for (_, effective), v in rays.items() if not effective)
    assert answer.max_contact_velocity == pytest.approx(plain, rel=1e-9)
    assert term.max_contact_velocity <= answer.max_contact_velocity


def test_a_foot_impact_below_the_com_keeps_the_jumps_answer():
    """A kick leaves an angular momentum whose effective jump is smaller: both ends, so the
    answer is the jump's own (the same rule as the floating default's)."""
    analysis = analyze(load_scenario("kick_one_foot").replace(angular_momentum_damping_time=0.1))
    answer = held_stance_max_contact_velocity(analysis)
    term = answer.angular_momentum
    assert np.all(
        np.linalg.norm(term.effective_jumps, axis=1) < np.linalg.norm(answer.jumps, axis=1)
    )
    assert term.max_contact_velocity == answer.max_contact_velocity
    assert term.binding_effective is False


@settings(max_examples=6, deadline=None)
@given(tau=st.one_of(st.just(0.0), st.floats(1e-3, 100.0)))
def test_the_answer_with_the_term_grows_with_tau_towards_the_one_without(tau):
    base = load_scenario("talos_side_slope")
    slow = held_stance_max_contact_velocity(
        analyze(base.replace(angular_momentum_damping_time=tau))
    ).angular_momentum
    slower = held_stance_max_contact_velocity(
        analyze(base.replace(angular_momentum_damping_time=2 * tau + 1.0))
    )
    assert slow.max_contact_velocity <= slower.angular_momentum.max_contact_velocity + 1e-12
    assert slower.angular_momentum.max_contact_velocity <= slower.max_contact_velocity + 1e-12
    # The effective jump moves from the jump by exactly gain S(L) / m.
    gain = slow.gain
    L = slow.angular_momentum
    np.testing.assert_allclose(
        slow.effective_jumps - slower.jumps,
        gain * np.column_stack([L[:, 1], -L[:, 0]]) / analyze(base).stance.mass,
        atol=1e-12,
    )


def test_without_tau_there_is_no_block_and_the_answer_is_as_with_it():
    scenario = load_scenario("palm_push_two_feet")
    off = held_stance_max_contact_velocity(analyze(scenario))
    on = held_stance_max_contact_velocity(
        analyze(scenario.replace(angular_momentum_damping_time=0.1))
    )
    assert off.angular_momentum is None and "angular_momentum" not in off.to_dict()
    assert off.max_contact_velocity == on.max_contact_velocity
    np.testing.assert_array_equal(off.jumps, on.jumps)
    doc = json.loads(json.dumps(on.to_dict(), allow_nan=False))
    assert doc["angular_momentum"] == {
        "damping_time": 0.1,
        "gain": on.angular_momentum.gain,
        "angular_momentum": on.angular_momentum.angular_momentum.tolist(),
        "effective_jumps": on.angular_momentum.effective_jumps.tolist(),
        "max_contact_velocity": on.angular_momentum.max_contact_velocity,
        "status": "ok",
        "binding_restitution": on.angular_momentum.binding_restitution,
        "binding_effective": on.angular_momentum.binding_effective,
    }
    assert {k: v for k, v in doc.items() if k != "angular_momentum"} == off.to_dict()


def test_the_fallback_with_tau_is_the_analysis_default():
    scenario = load_scenario(NOT_CONVERGING).replace(
        zmp_margin=0.01, com_velocity=(0.0, 0.0), angular_momentum_damping_time=0.07
    )
    analysis = analyze(scenario)
    answer = held_stance_max_contact_velocity(analysis)
    assert answer.fell_back
    term = answer.angular_momentum
    assert term.max_contact_velocity == analysis.impact.default.max_contact_velocity
    assert term.max_contact_velocity < analysis.impact.com.max_contact_velocity
    assert term.binding_restitution is None and term.binding_effective is None
