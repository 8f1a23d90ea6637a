"""The scores a safety criterion is judged by: Wilson intervals checked against scipy, and the
conditional rates of a confusion matrix checked against counts made by hand."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance.sim.studies.scores import confusion, rate, wilson

scipy_stats = pytest.importorskip("scipy.stats")


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 2000).flatmap(lambda n: st.tuples(st.integers(0, n), st.just(n))))
def test_wilson_matches_scipy(kn):
    k, n = kn
    ci = scipy_stats.binomtest(k, n).proportion_ci(confidence_level=0.95, method="wilson")
    lo, hi = wilson(k, n)
    assert lo == pytest.approx(ci.low, abs=1e-9) and hi == pytest.approx(ci.high, abs=1e-9)
    assert 0.0 <= lo <= k / n <= hi <= 1.0


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(st.booleans(), st.booleans()), min_size=0, max_size=60))
def test_conditional_rates_are_counts_over_their_condition(pairs):
    safe = [p for p, _ in pairs]
    fell = [f for _, f in pairs]
    c = confusion(safe, fell)
    called_safe = [f for p, f in pairs if p]
    called_unsafe = [f for p, f in pairs if not p]
    stood = [p for p, f in pairs if not f]
    assert c["fell_given_safe"] == rate(sum(called_safe), len(called_safe))
    assert c["stood_given_unsafe"] == rate(
        len(called_unsafe) - sum(called_unsafe), len(called_unsafe)
    )
    assert c["safe_given_stood"] == rate(sum(stood), len(stood))
    assert c["total"] == len(pairs)
    assert c["safe_fell"] + c["safe_survived"] == len(called_safe)
    if called_safe:
        r = c["fell_given_safe"]
        assert r["ci95"][0] <= r["rate"] <= r["ci95"][1]
        # Conditional on a safe call: never smaller than the share of all trials that were
        # called safe and fell (the old headline, which dilutes it by the unsafe calls).
        assert r["rate"] >= c["safe_and_fell_share"]
