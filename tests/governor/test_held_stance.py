"""The governor with the held-stance impact model (``Governor(impact_model="held-stance")``)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import analyze, load_scenario
from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor
from tests.helpers.held_stance import NOT_CONVERGING, ray


@pytest.fixture(scope="module")
def talos():
    scenario = load_scenario("palm_push_two_feet").replace(zmp_margin=0.01, velocity_margin=0.01)
    held = Governor(scenario, impact_model="held-stance")
    plain = Governor(scenario)
    q = held.configuration.copy()
    other = q.copy()
    other[-1] += 0.05  # a neighbouring posture (the last arm joint)
    return scenario, held, plain, q, other


@settings(max_examples=8, deadline=None)
@given(st.floats(-0.06, 0.06), st.floats(-0.06, 0.06))
def test_the_cap_is_the_held_stance_answer_of_the_same_posture(talos, vx, vy):
    _, governor, plain, q, _ = talos
    limit = governor.limit_com(q, (vx, vy))
    analysis = analyze(governor.scenario_at(q, limit.com_velocity))
    assert analysis.com_velocity_inside
    expected = held_stance_max_contact_velocity(analysis)
    assert not expected.fell_back
    assert limit.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-9)
    assert limit.binding == "held_stance" and limit.status == expected.status
    assert expected.restitution[limit.limiting_vertex] == expected.binding_restitution
    assert limit.safe_interval == pytest.approx((0.0, limit.max_contact_velocity), abs=1e-12)
    # the floating answer of the same governor state is the plain governor's, another number
    floating = plain.limit_com(q, (vx, vy))
    assert floating.binding == "floating"
    assert abs(floating.max_contact_velocity - limit.max_contact_velocity) > 1e-3


def test_the_jumps_are_the_initial_postures_at_another_posture(talos):
    scenario, governor, _, q, other = talos
    c = np.array([0.02, -0.01, 0.0])
    limit = governor.limit_com(other, c)
    # the area of the new posture, the jumps of the initial one (computed once)
    analysis = analyze(governor.scenario_at(other, c))
    G, h = analysis.areas.com_velocity_area.halfplanes
    h = h - scenario.velocity_margin
    initial = held_stance_max_contact_velocity(analyze(governor.scenario_at(q, c)))
    expected = min(ray(G, h, c[:2], j) for j in initial.jumps)
    assert limit.max_contact_velocity == pytest.approx(expected, abs=1e-9)
    np.testing.assert_allclose(governor.held_stance.jumps, initial.jumps, rtol=0, atol=1e-12)
    # ... which is not the held-stance answer of the new posture's own jumps
    own = held_stance_max_contact_velocity(analysis)
    assert own.max_contact_velocity != pytest.approx(expected, abs=1e-9)


def test_limit_and_limit_com_agree(talos):
    _, governor, _, q, _ = talos
    by_state = governor.limit(q, np.zeros(governor.nv))
    by_com = governor.limit_com(q, by_state.com_velocity)
    assert by_state.binding == by_com.binding == "held_stance"
    assert by_state.max_contact_velocity == pytest.approx(by_com.max_contact_velocity, abs=1e-12)
    assert governor.cap(limit=by_state)[0] == pytest.approx(by_state.max_contact_velocity)


def test_without_the_option_the_answer_is_the_analysis(talos):
    scenario, _, plain, q, _ = talos
    assert plain.held_stance is None
    limit = plain.limit_com(q, (0.0, 0.0))
    analysis = analyze(plain.scenario_at(q, limit.com_velocity))
    assert limit.binding == "floating"
    assert limit.max_contact_velocity == pytest.approx(analysis.impact.max_contact_velocity, 1e-12)
    floating = Governor(scenario, impact_model="floating").limit_com(q, (0.0, 0.0))
    assert floating.binding == "floating" and floating.safe_interval == limit.safe_interval
    assert floating.max_contact_velocity == limit.max_contact_velocity


def test_a_fixed_point_not_reached_answers_the_floating_model():
    scenario = load_scenario(str(NOT_CONVERGING)).replace(zmp_margin=0.01, com_velocity=(0, 0))
    held = Governor(scenario, impact_model="held-stance")
    assert held.held_stance is not None and not all(held.held_stance.converged)
    q = held.configuration
    answer = held.limit_com(q, (0.0, 0.0))
    plain = Governor(scenario).limit_com(q, (0.0, 0.0))
    assert answer.binding == "floating"
    assert answer.max_contact_velocity == plain.max_contact_velocity
    fallback = held_stance_max_contact_velocity(analyze(scenario))
    assert fallback.fell_back
    assert answer.max_contact_velocity == pytest.approx(fallback.max_contact_velocity, abs=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "needle"),
    [
        ({"impact_model": "bogus"}, "must be one of floating, held-stance"),
        ({"impact_model": "held_stance"}, "must be one of floating, held-stance"),
        ({"impact_model": None}, "must be one of floating, held-stance"),
        ({"impact_model": "held-stance", "criterion": "zmp"}, '"com" criterion only'),
        ({"impact_model": "held-stance", "com_reach": True}, "com_reach"),
        ({"impact_model": "held-stance", "contact_aware": True}, "contact_aware"),
    ],
)
def test_bad_options_are_refused_naming_impact_model(kwargs, needle):
    with pytest.raises(GovernorError) as info:
        Governor("palm_push_two_feet", **kwargs)
    assert info.value.field == "impact_model" and needle in str(info.value)


def test_the_batch_refuses_the_held_stance_model(talos):
    _, governor, _, q, _ = talos
    with pytest.raises(GovernorError) as info:
        governor.limits(q[None], np.zeros((1, governor.nv)))
    assert info.value.field == "impact_model"
