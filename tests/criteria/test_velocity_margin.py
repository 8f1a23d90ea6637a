"""The velocity margin: every post-impact CoM velocity at least d (m/s) inside the CoM velocity
area."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.criteria.com import ComCriterion
from impact_balance.exceptions import GovernorError
from impact_balance.governor import ContactAwareOptions, Governor

ANALYSES = {name: ib.analyze(name) for name in ("palm_push_two_feet", "palm_push_ramp")}


def inside_distance(vertices: np.ndarray, x: np.ndarray) -> float:
    """Signed distance from ``x`` to the boundary of the convex CCW polygon ``vertices``
    (positive inside), from the vertices alone: the smallest distance to an edge's line."""
    best = math.inf
    for a, b in zip(vertices, np.roll(vertices, -1, axis=0), strict=True):
        edge = b - a
        best = min(
            best, float(edge[0] * (x[1] - a[1]) - edge[1] * (x[0] - a[0])) / float(np.hypot(*edge))
        )
    return best


@settings(max_examples=40, deadline=None)
@given(
    name=st.sampled_from(sorted(ANALYSES)),
    d=st.floats(0.0, 0.05),
    cx=st.floats(-0.05, 0.05),
    cy=st.floats(-0.05, 0.05),
)
def test_the_limit_puts_the_worst_vertex_d_inside(name, d, cx, cy):
    analysis = ANALYSES[name]
    area, model = analysis.areas.com_velocity_area, analysis.impact.model
    c0 = np.array([cx, cy])
    if inside_distance(area.vertices, c0) <= d:
        return  # already within d of the edge: no speed is safe with that margin
    limit = ComCriterion(area, model, d).limit(c0)
    assert limit.status == "ok"
    s = limit.max_contact_velocity
    worst = min(inside_distance(area.vertices, p) for p in model.post_impact_com_velocities(c0, s))
    assert worst == pytest.approx(d, abs=1e-9)
    beyond = min(
        inside_distance(area.vertices, p)
        for p in model.post_impact_com_velocities(c0, s * 1.001 + 1e-6)
    )
    assert beyond < d
    assert s <= ComCriterion(area, model).limit(c0).max_contact_velocity + 1e-12


def test_the_governor_applies_it_to_both_models():
    warm = ContactAwareOptions(starts="warm")
    plain = Governor("palm_push_two_feet", contact_aware=warm)
    margin = Governor("palm_push_two_feet", contact_aware=warm, velocity_margin=0.02)
    q, v = plain.configuration, np.zeros(plain.nv)
    a, b = plain.limit(q, v), margin.limit(q, v)
    assert b.max_contact_velocity < a.max_contact_velocity
    posture = margin.posture
    floating = ComCriterion(posture.com_criterion.area, posture.impact, 0.02).limit(b.com_velocity)
    assert b.max_contact_velocity <= floating.max_contact_velocity + 1e-12
    # The contact-aware jump with the margin: the point it predicts at the limit is 0.02 inside (or
    # the floating set binds).
    aware = margin._support.answer(posture.com_criterion, b.com_velocity)
    assert b.max_contact_velocity == pytest.approx(
        min(floating.max_contact_velocity, aware.limit.max_contact_velocity)
    )
    rates = aware.rates
    vertices = posture.com_criterion.area.vertices
    s = aware.limit.max_contact_velocity
    worst = min(inside_distance(vertices, b.com_velocity[:2] + s * r) for r in rates)
    assert worst == pytest.approx(0.02, abs=1e-9)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"velocity_margin": -0.01},
        {"velocity_margin": float("nan")},
        {"velocity_margin": "fast"},
        {"velocity_margin": 0.02, "criterion": "zmp"},
    ],
)
def test_bad_margins_name_the_field(kwargs):
    with pytest.raises(GovernorError, match="velocity_margin"):
        Governor("palm_push_two_feet", **kwargs)


def test_async_rates_are_the_workers_answer_for_the_posture_it_was_sent():
    """With contact_aware_async the tick adopts the worker's rates for an earlier posture: the
    same numbers a synchronous solve gives there (cold start: nothing carried)."""
    from impact_balance.contacts.stance import Stance
    from impact_balance.governor.support import ContactAwareLimit

    with Governor(
        "g1_two_feet",
        contact_aware=ContactAwareOptions(starts="cold", asynchronous=True),
        velocity_margin=0.01,
    ) as governor:
        worker = governor._worker
        assert worker is not None and worker.alive
        q1 = governor.configuration.copy()
        q1[7:] += 0.01
        v = np.zeros(governor.nv)
        first = governor.limit(q1, v)  # the scenario posture's rates; q1 sent to the worker
        assert worker.submitted == governor.posture.key
        solutions = worker.wait(120.0)
        assert solutions is not None
        expected = ContactAwareLimit(governor.scenario.impact.spec(), 1, "cold").solve(
            Stance(governor.robot, q1, tuple(c.spec() for c in governor.scenario.contacts))
        )
        np.testing.assert_allclose(solutions.rates, expected.rates, rtol=0, atol=1e-12)
        governor._support.adopt(solutions)  # what the next tick's poll does
        q2 = q1.copy()
        q2[7:] += 0.005
        second = governor.limit(q2, v)
        aware = governor._support.answer(governor.posture.com_criterion, second.com_velocity)
        floating = governor.posture.com_criterion.limit(second.com_velocity)
        assert second.max_contact_velocity == pytest.approx(
            min(aware.limit.max_contact_velocity, floating.max_contact_velocity)
        )
        assert first.binding == "contact_aware"
    assert governor._worker is None and not worker.alive  # closed by the with block


def test_the_contact_aware_option_is_its_options():
    """Asynchronous rates are a contact-aware option: there is no way to ask for them alone."""
    with pytest.raises(GovernorError, match="contact_aware"):
        Governor("palm_push_two_feet", contact_aware="async")  # type: ignore[arg-type]
