"""The compiled posture (posture_kernel) gives the one-posture steps' numbers to the last digit,
and the compiled tick (velocity_exit) the criterion's answer; postures it leaves to the steps
(a small area, another criterion) are still answered."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.linear_exit import speed_interval
from impact_balance.governor import Governor
from impact_balance.governor.posture import PostureEvaluator
from tests.helpers.postures import postures

SCENARIOS = ("palm_push_two_feet", "kick_one_foot", "g1_two_feet")
_CACHE: dict[str, tuple[Governor, PostureEvaluator, PostureEvaluator]] = {}


def evaluators(name: str) -> tuple[Governor, PostureEvaluator, PostureEvaluator]:
    """A governor, and two evaluators of its settings: one for the compiled call, one for the
    steps (each with its own warm start)."""
    if name not in _CACHE:
        g = Governor(name)
        compiled = PostureEvaluator(g.robot, g._evaluator.settings)
        steps = PostureEvaluator(g.robot, g._evaluator.settings)
        assert compiled._compiled
        _CACHE[name] = (g, compiled, steps)
    return _CACHE[name]


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    seed=st.integers(0, 2**32 - 1),
    spread=st.sampled_from([0.002, 0.02]),
)
def test_compiled_posture_is_the_steps_to_the_last_digit(name, seed, spread):
    g, compiled, steps = evaluators(name)
    for q in postures(g, 6, seed, spread):
        a = compiled._compiled_posture(q)  # evaluate()'s compiled path
        assert a is not None  # the kernel answered (not left to the steps)
        b = steps.evaluate(q, steps=True)
        ca, cb = a.com_criterion, b.com_criterion
        assert ca is not None and cb is not None
        np.testing.assert_array_equal(ca.area.vertices, cb.area.vertices)
        np.testing.assert_array_equal(ca.G, cb.G)
        np.testing.assert_array_equal(ca.h, cb.h)
        np.testing.assert_array_equal(ca.rates, cb.rates)
        for field in ("point", "normal", "cone", "W", "jacobian", "impulse_rates"):
            np.testing.assert_array_equal(getattr(a.impact, field), getattr(b.impact, field))
        assert a.impact.mass == b.impact.mass
        areas_a, areas_b = a.areas, b.areas
        for field in ("force_area", "zmp_area", "com_velocity_area"):
            np.testing.assert_array_equal(
                getattr(areas_a, field).vertices, getattr(areas_b, field).vertices
            )
        assert areas_a.omega == areas_b.omega
        np.testing.assert_array_equal(a.com_jacobian, b.com_jacobian)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(seed=st.integers(0, 2**32 - 1), speed=st.sampled_from([0.01, 0.3, 1.0, 5.0]))
def test_velocity_only_tick_is_the_criterion_answer(seed, speed):
    # An independent computation: the criterion object's own limit and interval (numpy and the
    # exit kernel), at the CoM velocity numpy's J @ v gives.
    g = evaluators("kick_one_foot")[0]
    q = g.configuration
    v = np.random.default_rng(seed).normal(0.0, speed, g.nv)
    answer = g.limit(q, v)
    posture = g.posture
    com_velocity = posture.com_jacobian @ v
    np.testing.assert_array_equal(answer.com_velocity, com_velocity)
    criterion = posture.com_criterion
    assert criterion is not None
    want = criterion.limit(com_velocity)
    assert answer.max_contact_velocity == want.max_contact_velocity
    assert answer.status == want.status
    assert answer.limiting_vertex == want.limiting_vertex
    assert answer.limiting_edge == want.limiting_edge
    if want.from_inside:
        assert answer.safe_interval == (0.0, want.max_contact_velocity)
    else:  # the margins by numpy's product there: equal to rounding
        want_interval = speed_interval(criterion.margins(com_velocity), criterion.rates)
        assert (answer.safe_interval is None) == (want_interval is None)
        if want_interval is not None:
            np.testing.assert_allclose(answer.safe_interval, want_interval, rtol=0, atol=1e-12)


def test_from_rates_is_the_constructed_criterion():
    g, compiled, _ = evaluators("palm_push_two_feet")
    posture = compiled.evaluate(g.configuration)
    made = posture.com_criterion
    assert made is not None
    built = ComCriterion(made.area, made.impact, made.velocity_margin)
    for field in ("G", "h", "rates"):
        np.testing.assert_array_equal(getattr(made, field), getattr(built, field))
    c = np.array([0.05, -0.02, 0.0])
    assert made.limit(c) == built.limit(c)


def test_velocity_margin_is_applied_by_the_compiled_posture():
    g = Governor("palm_push_two_feet", velocity_margin=0.02)
    plain = Governor("palm_push_two_feet")
    q = g.configuration.copy()
    q[10] += 0.01
    a, b = g.limit(q, np.zeros(g.nv)), plain.limit(q, np.zeros(g.nv))
    ca, cb = g.posture.com_criterion, plain.posture.com_criterion
    assert ca is not None and cb is not None
    np.testing.assert_array_equal(ca.h, cb.h - 0.02)
    assert a.max_contact_velocity < b.max_contact_velocity


@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_a_velocity_not_finite_is_refused_on_both_paths(bad):
    from impact_balance.exceptions import GovernorError

    g = evaluators("kick_one_foot")[0]
    v = np.zeros(g.nv)
    v[3] = bad
    q = g.configuration.copy()
    g.limit(q, np.zeros(g.nv))
    with pytest.raises(GovernorError, match=r"v = .*must be finite \(entry 3\)"):
        g.limit(q, v)  # the cached posture: the compiled tick finds it
    q[9] += 1e-3
    with pytest.raises(GovernorError, match=r"must be finite \(entry 3\)"):
        g.limit(q, v)  # a new posture: the compiled state check finds it


def test_a_posture_the_kernel_leaves_to_the_steps_is_answered_as_analyze():
    import impact_balance as ib
    from impact_balance.scenario import load_scenario

    # A ZMP margin that leaves no area: the kernel's answer has no half-planes, the steps answer.
    scenario = load_scenario("palm_push_two_feet").replace(zmp_margin=0.3)
    g = Governor(scenario)
    q = g.configuration.copy()
    q[10] += 0.01
    assert g._evaluator._compiled_posture(q) is None
    answer = g.limit(q, np.zeros(g.nv))
    assert answer.status == "cannot_balance" and answer.max_contact_velocity == 0.0
    assert answer.safe_interval is None
    analysis = ib.analyze(g.scenario_at(q, answer.com_velocity))
    assert analysis.impact.com.status == "cannot_balance"


def test_falling_starts_are_answered_by_the_compiled_tick_as_by_the_criterion():
    g = evaluators("kick_one_foot")[0]
    q = g.configuration
    rng = np.random.default_rng(5)
    seen = set()
    for scale in np.geomspace(0.05, 5.0, 60):
        v = rng.normal(0.0, scale, g.nv)
        answer = g.limit(q, v)
        seen.add((answer.status, answer.safe_interval is None))
        criterion = g.posture.com_criterion
        assert criterion is not None
        com_velocity = g.posture.com_jacobian @ v
        want = criterion.limit(com_velocity)
        assert (answer.status, answer.max_contact_velocity) == (
            want.status,
            want.max_contact_velocity,
        )
        want_interval = criterion.interval(com_velocity, want)
        assert (answer.safe_interval is None) == (want_interval is None)
        if want_interval is not None:
            np.testing.assert_allclose(answer.safe_interval, want_interval, rtol=0, atol=1e-12)
    assert {s for s, _ in seen} >= {"already_falling", "ok"}
