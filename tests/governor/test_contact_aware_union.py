"""The contact-aware option's union of the frictional impact LCP's solutions (governor/support.py,
``starts="union"``): every distinct solution reached from the kept solutions and the cold start
is kept, the limit is the smallest over them, the interval their intersection.

The postures: ``palm_push_two_feet`` (a training stance) along a straight path in configuration
space from the approach's start posture (the palm backed off 15 cm) to the scenario's posture.
Along it the LCP has two solutions over part of the way (the continuation of the start's answer
and the cold start's), found by the structure of the path, not by a trial's outcome."""

from __future__ import annotations

import numpy as np
import pytest

import impact_balance as ib
from impact_balance.exceptions import GovernorError
from impact_balance.governor import ContactAwareOptions, Governor
from impact_balance.governor.support import (
    SAME_SOLUTION,
    ContactAwareLimit,
    contact_aware_rates,
    contact_aware_solutions,
)
from impact_balance.impact.contact_aware import contact_impact

#: The start posture comes from the sim package (its retracted stance).
pytestmark = pytest.mark.sim
pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

NAME = "palm_push_two_feet"
STEPS = 11
#: Two runs of the fixed point to one solution agree to its tolerance (1e-9 m/s per m/s on the
#: gauges); the union keeps the first run's row, so its limit may exceed a single start's by that.
FIXED_POINT = 1e-8  # m/s


@pytest.fixture(scope="module")
def path():
    """``(governor, [(posture, stance)...])``: the postures of the straight path (pinocchio's
    interpolation) from the 15 cm start posture to the scenario's, each evaluated once."""
    import pinocchio as pin

    from impact_balance.sim.control.kinematic import retracted_stance

    analysis = ib.analyze(NAME)
    governor = Governor(NAME)
    q0, q1 = retracted_stance(analysis, 0.15), analysis.stance.q.copy()
    out = []
    for s in np.linspace(0.0, 1.0, STEPS):
        governor.limit_com(pin.interpolate(governor.robot.model, q0, q1, float(s)), np.zeros(3))
        out.append(governor.posture)
    return governor, out


@pytest.fixture(scope="module")
def answers(path):
    """Per posture of the path, the answers of the three starts (every posture a recomputation)."""
    governor, postures = path
    spec = governor.scenario.impact.spec()
    limits = {s: ContactAwareLimit(spec, every=1, starts=s) for s in ("warm", "cold", "union")}
    out = []
    for posture in postures:
        row = {}
        for name, limit in limits.items():
            limit.new_posture(lambda posture=posture: posture.stance)
            row[name] = limit.answer(posture.com_criterion, np.zeros(3))
        out.append(row)
    return out


def _contains(rows: np.ndarray, rate: np.ndarray, tol: float = 1e-6) -> bool:
    return bool(np.any(np.abs(rows - rate).max(axis=1) <= tol))


def test_union_limit_is_at_most_each_single_start(answers):
    """The union's rows contain the warm and the cold start's (same restitution bound), so its
    limit is at most each one's and its interval inside both."""
    for row in answers:
        union = row["union"]
        for single in (row["warm"], row["cold"]):
            assert (
                union.limit.max_contact_velocity <= single.limit.max_contact_velocity + FIXED_POINT
            )
            for k, c_r in enumerate(single.restitution):
                assert _contains(union.rates[union.restitution == c_r], single.rates[k])
            lo, hi = union.interval
            assert single.interval[0] <= lo + FIXED_POINT and hi <= single.interval[1] + FIXED_POINT
        assert union.limit.max_contact_velocity == pytest.approx(
            min(row["warm"].limit.max_contact_velocity, row["cold"].limit.max_contact_velocity),
            abs=FIXED_POINT,
        )


def test_two_branches_are_both_kept(answers):
    """Where the continued answer and the cold start's differ (two LCP solutions), the union has
    both at each restitution bound, and the rate bound is the worse of the two."""
    split = [
        row
        for row in answers
        if np.abs(row["warm"].rates - row["cold"].rates).max() > 100 * SAME_SOLUTION
    ]
    assert split, "the path has postures with two solutions"
    for row in split:
        union = row["union"]
        for c_r in np.unique(union.restitution):
            assert np.sum(union.restitution == c_r) >= 2
        assert len(union.rates) >= 4 and union.converged
    # Where the two agree, the union is that one solution per bound (no duplicate rows).
    single = [
        row
        for row in answers
        if np.abs(row["warm"].rates - row["cold"].rates).max() <= SAME_SOLUTION
    ]
    assert single
    for row in single:
        assert len(row["union"].rates) == len(np.unique(row["union"].restitution))


def test_each_kept_row_is_a_fixed_point(path):
    """Every row of the union is a solution, not a transient: the fixed point started at its own
    body velocity change stays there (to the solver's tolerance), and rows of one bound are
    distinct by more than SAME_SOLUTION."""
    governor, postures = path
    spec = governor.scenario.impact.spec()
    previous, checked = None, 0
    for posture in postures:
        previous = contact_aware_solutions(posture.stance, spec, previous)
        if len(previous.rates) > len(spec.restitution):
            for rate, c_r, state in zip(
                previous.rates, previous.restitution, previous.states, strict=True
            ):
                again = contact_impact(
                    posture.stance, spec, 1.0, restitution=float(c_r), initial_dxi=state
                )
                assert again.converged
                assert np.abs(again.com_velocity_jump - rate).max() <= 1e-7
            for c_r in np.unique(previous.restitution):
                s = previous.states[previous.restitution == c_r]
                gaps = [np.abs(a - b).max() for i, a in enumerate(s) for b in s[i + 1 :]]
                assert min(gaps) > SAME_SOLUTION
            checked += 1
    assert checked


def test_union_starts_with_the_frozen_answers(path):
    """On the first posture the union is the cold start alone, i.e. the frozen warm option's
    first answer (the same fixed points as contact_aware_rates)."""
    governor, postures = path
    spec = governor.scenario.impact.spec()
    rates, _, converged = contact_aware_rates(postures[0].stance, spec)
    first = contact_aware_solutions(postures[0].stance, spec)
    assert converged and first.converged.all()
    assert first.restitution.tolist() == [float(c) for c in spec.restitution]
    assert np.array_equal(first.rates, rates)


def test_the_governor_defaults_to_the_union(path):
    """``Governor(contact_aware=True)`` uses the union; ``starts="warm"`` is the
    frozen option; along the path (every posture a recomputation) the union's cap is never above
    the warm one's."""
    _governor, postures = path
    union = Governor(NAME, contact_aware=ContactAwareOptions(every=1))
    warm = Governor(NAME, contact_aware=ContactAwareOptions(every=1, starts="warm"))
    assert union._support.starts == "union" and warm._support.starts == "warm"
    for posture in postures:
        a, b = union.limit_com(posture.q, np.zeros(3)), warm.limit_com(posture.q, np.zeros(3))
        assert a.max_contact_velocity <= b.max_contact_velocity + FIXED_POINT
    with pytest.raises(GovernorError) as info:
        Governor(NAME, contact_aware=ContactAwareOptions(starts="several"))  # type: ignore[arg-type]
    assert info.value.field == "contact_aware.starts"
