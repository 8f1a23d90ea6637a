"""A compiled posture makes its areas, impact model and criterion when first read: the same
objects as the steps' (to the last digit), the tick's arrays equal to theirs, and a tick that
reads none of them."""

from __future__ import annotations

import pickle
import threading

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from impact_balance.governor import Governor
from impact_balance.governor.posture import PostureEvaluator
from tests.helpers.postures import postures

_CACHE: dict[tuple[str, float], tuple[Governor, PostureEvaluator, PostureEvaluator]] = {}


def evaluators(
    name: str, margin: float = 0.0
) -> tuple[Governor, PostureEvaluator, PostureEvaluator]:
    """A governor, an evaluator for the compiled call and one for the steps."""
    key = (name, margin)
    if key not in _CACHE:
        g = Governor(name, velocity_margin=margin)
        compiled = PostureEvaluator(g.robot, g._evaluator.settings)
        steps = PostureEvaluator(g.robot, g._evaluator.settings)
        assert compiled._compiled
        _CACHE[key] = (g, compiled, steps)
    return _CACHE[key]


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(["palm_push_two_feet", "kick_one_foot"]),
    margin=st.sampled_from([0.0, 0.03]),
    seed=st.integers(0, 2**32 - 1),
)
def test_tick_arrays_are_the_criterion_and_model_made_later(name, margin, seed):
    g, compiled, steps = evaluators(name, margin)
    for q in postures(g, 3, seed, 0.01):
        lazy = compiled.evaluate(q)
        assert "_made" in vars(lazy) and "impact" not in vars(lazy)  # nothing made yet
        J, G, h, rates = lazy.exit_arrays
        point, normal = lazy.impact_point_normal
        want = steps.evaluate(q, steps=True)  # an independent path: the steps one by one
        wc = want.com_criterion
        assert wc is not None and wc.G is not None and wc.h is not None and wc.rates is not None
        for got, expected in ((J, want.com_jacobian), (G, wc.G), (h, wc.h), (rates, wc.rates)):
            np.testing.assert_array_equal(got, expected)
        np.testing.assert_array_equal(point, want.impact.point)
        np.testing.assert_array_equal(normal, want.impact.normal)
        # Made on first access, all three at once, and kept (the same objects after).
        model = lazy.impact
        assert {"projected", "impact", "com_criterion"} <= set(vars(lazy))
        assert lazy.impact is model and lazy.com_criterion is lazy.com_criterion
        assert model.point is point and model.normal is normal  # the answers' arrays
        criterion = lazy.com_criterion
        assert criterion is not None and criterion.velocity_margin == margin
        np.testing.assert_array_equal(criterion.h, h)
        np.testing.assert_array_equal(model.W, want.impact.W)
        for field in ("force_area", "zmp_area", "com_velocity_area"):
            np.testing.assert_array_equal(
                getattr(lazy.areas, field).vertices, getattr(want.areas, field).vertices
            )


def test_a_tick_makes_none_of_the_objects_and_answers_with_the_models_arrays():
    g = Governor("palm_push_two_feet")
    q = g.configuration.copy()
    q[10] += 0.004
    v = np.zeros(g.nv)
    v[0] = 0.05
    answer = g.limit(q, v)
    posture = g.posture
    assert not answer.posture_reused and "impact" not in vars(posture)
    again = g.limit(q, v)
    assert again.posture_reused and "impact" not in vars(posture)
    # Reading the model afterwards gives the arrays the answers hold, and its own answer.
    assert posture.impact.normal is answer.normal and posture.impact.point is answer.point
    criterion = posture.com_criterion
    assert criterion is not None
    assert criterion.limit(answer.com_velocity).max_contact_velocity == answer.max_contact_velocity


def test_objects_made_after_other_postures_are_their_own_postures():
    # The evaluator's Data and buffers move on; a posture read later keeps its own arrays.
    g, compiled, steps = evaluators("palm_push_two_feet")
    qs = postures(g, 4, 3, 0.02)
    lazy = [compiled.evaluate(q) for q in qs]
    for q, posture in zip(qs, lazy, strict=True):
        want = steps.evaluate(q, steps=True)
        for field in ("point", "normal", "cone", "W", "jacobian", "impulse_rates"):
            np.testing.assert_array_equal(
                getattr(posture.impact, field), getattr(want.impact, field)
            )
        assert posture.impact.mass == want.impact.mass
        np.testing.assert_array_equal(posture.areas.zmp_area.vertices, want.areas.zmp_area.vertices)
        assert posture.areas.omega == want.areas.omega
    # The cone is the model's own copy, not the evaluator's.
    assert lazy[0].impact.cone is not compiled._cone


def test_unknown_attributes_and_the_steps_posture_raise_attribute_error():
    g, compiled, steps = evaluators("kick_one_foot")
    lazy = compiled.evaluate(g.configuration)
    with pytest.raises(AttributeError, match="no attribute 'impcat'"):
        lazy.impcat  # noqa: B018
    stepped = steps.evaluate(g.configuration, steps=True)
    assert "_made" not in vars(stepped)
    with pytest.raises(AttributeError, match="no attribute '_made'"):
        stepped._made  # noqa: B018


def test_a_compiled_posture_survives_pickling_before_and_after_its_objects():
    g, compiled, _ = evaluators("kick_one_foot")
    fresh = pickle.loads(pickle.dumps(compiled.evaluate(g.configuration)))
    made = compiled.evaluate(g.configuration)
    made.impact  # noqa: B018
    for posture in (fresh, pickle.loads(pickle.dumps(made))):
        np.testing.assert_array_equal(posture.impact.W, made.impact.W)
        np.testing.assert_array_equal(posture.areas.zmp_area.vertices, made.areas.zmp_area.vertices)


def test_threads_reading_a_new_posture_see_equal_objects():
    g, compiled, _ = evaluators("palm_push_two_feet")
    q = g.configuration.copy()
    q[9] += 0.003
    for _ in range(5):
        posture = compiled.evaluate(q)
        seen: list[object] = []
        barrier = threading.Barrier(4)

        def read(posture=posture, seen=seen, barrier=barrier):
            barrier.wait()
            seen.append(posture.com_criterion)

        threads = [threading.Thread(target=read) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        rates = [c.rates for c in seen]  # type: ignore[attr-defined]
        assert len(rates) == 4 and all(np.array_equal(r, rates[0]) for r in rates)
        assert posture.com_criterion is posture.com_criterion  # one object kept in the end
