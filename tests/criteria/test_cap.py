"""The approach-speed clamps: one core, the behaviours where no speed is safe or none approaches."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.criteria.cap import (
    cap_approach,
    capped_velocity,
    clamp_approach_speed,
    safe_contact_velocity,
)
from impact_balance.exceptions import GovernorError

finite = st.floats(-5.0, 5.0, allow_nan=False)
vectors = st.tuples(finite, finite, finite)


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v)


def _approach(v, n):
    return -float(np.dot(n, v))


@settings(max_examples=200, deadline=None)
@given(vectors, vectors, st.floats(0.0, 3.0), st.floats(0.0, 3.0))
def test_clamp_moves_along_the_normal_only_into_the_bounds(reference, direction, a, b):
    if np.linalg.norm(direction) < 1e-3:
        return
    n = _unit(direction)
    lo, hi = min(a, b), max(a, b)
    v = clamp_approach_speed(reference, n, lo, hi)
    s_ref = _approach(reference, n)
    # the tangential part is kept
    tangential = lambda u: np.asarray(u) + _approach(u, n) * n  # noqa: E731
    np.testing.assert_allclose(tangential(v), tangential(reference), atol=1e-9)
    # the approach speed is the nearest one in [lo, hi] (a 1-D projection)
    assert _approach(v, n) == pytest.approx(min(max(s_ref, lo), hi), abs=1e-9)
    if lo <= s_ref <= hi:
        np.testing.assert_array_equal(v, np.asarray(reference, dtype=float))


@settings(max_examples=200, deadline=None)
@given(vectors, vectors, st.floats(0.0, 3.0))
def test_capped_velocity_is_the_minimiser_of_the_distance_under_the_cap(reference, direction, m):
    if np.linalg.norm(direction) < 1e-3:
        return
    n = _unit(direction)
    v = capped_velocity(reference, n, m)
    assert _approach(v, n) <= m + 1e-9
    # no velocity meeting the cap is nearer the reference: v is the projection on a half-space
    distance = np.linalg.norm(v - np.asarray(reference))
    excess = max(0.0, _approach(reference, n) - m)
    assert distance == pytest.approx(excess, abs=1e-9)


N = np.array([-1.0, 0.0, 0.0])  # a wall at +x: approach speed is +x


def test_the_three_clamps_agree_from_inside():
    for reference in ([0.8, 0.3, 0.0], [0.2, 0.3, 0.1], [-0.5, 0.0, 0.0]):
        expected = capped_velocity(reference, N, 0.5)
        np.testing.assert_array_equal(safe_contact_velocity(reference, N, (0.0, 0.5)), expected)
        np.testing.assert_array_equal(cap_approach(reference, N, (0.0, 0.5)), expected)
    np.testing.assert_allclose(capped_velocity([0.8, 0.3, 0.0], N, 0.5), [0.5, 0.3, 0.0])


def test_without_a_safe_speed_the_analysis_has_no_answer_and_the_governor_stops_approaching():
    reference = [0.8, 0.3, 0.2]
    assert safe_contact_velocity(reference, N, None) is None
    np.testing.assert_allclose(cap_approach(reference, N, None), [0.0, 0.3, 0.2])
    # moving away: the governor keeps it (no impact)
    np.testing.assert_array_equal(cap_approach([-0.4, 0.3, 0.2], N, None), [-0.4, 0.3, 0.2])


def test_from_a_falling_start_the_analysis_hits_even_from_a_reference_moving_away():
    interval = (0.2, 0.6)
    away = [-0.4, 0.3, 0.0]
    np.testing.assert_allclose(safe_contact_velocity(away, N, interval), [0.2, 0.3, 0.0])
    np.testing.assert_array_equal(cap_approach(away, N, interval), away)
    # a slow approach is raised to lo by both, a fast one capped at hi by both
    for reference, expected in (([0.1, 0.0, 0.0], 0.2), ([0.9, 0.0, 0.0], 0.6)):
        assert safe_contact_velocity(reference, N, interval)[0] == pytest.approx(expected)
        assert cap_approach(reference, N, interval)[0] == pytest.approx(expected)


def test_an_unbounded_cap_keeps_the_reference():
    reference = [3.0, -1.0, 2.0]
    np.testing.assert_array_equal(capped_velocity(reference, N, math.inf), reference)
    np.testing.assert_array_equal(safe_contact_velocity(reference, N, (0.0, math.inf)), reference)


@pytest.mark.parametrize("bad", [[1.0, 2.0], [1.0, float("nan"), 0.0], "fast"])
def test_the_governor_clamp_refuses_a_bad_reference(bad):
    with pytest.raises(GovernorError):
        cap_approach(bad, N, (0.0, 1.0))


def test_the_clamps_accept_arrays_and_do_not_modify_them():
    reference = np.array([0.8, 0.3, 0.0])
    for out in (
        capped_velocity(reference, N, 0.5),
        safe_contact_velocity(reference, N, (0.0, 0.5)),
        cap_approach(reference, N, (0.0, 0.5)),
    ):
        assert out is not reference
    np.testing.assert_array_equal(reference, [0.8, 0.3, 0.0])
