"""Scoring of the balance trials: Wilson intervals, confusion, margins, the boundary impulse, the
journal, and resuming an interrupted push test."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance.exceptions import SimulationError
from impact_balance.geometry.polygon import Polygon
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.studies.push import PushOutcome, PushPrediction, boundary_impulse
from impact_balance.sim.studies.scores import confusion, wilson
from impact_balance.sim.trials.balance_trial import Push
from impact_balance.sim.trials.result import finite_or_null


@pytest.mark.parametrize(
    "k, n, lo, hi",
    [
        # Reference values (Wilson 1927 score interval, z = 1.96), e.g. Newcombe 1998, table I.
        (0, 10, 0.0, 0.2775),
        (1, 10, 0.0179, 0.4042),
        (5, 10, 0.2366, 0.7634),
        (10, 10, 0.7225, 1.0),
        (81, 263, 0.2553, 0.3662),
    ],
)
def test_wilson_interval(k, n, lo, hi):
    got = wilson(k, n)
    assert got[0] == pytest.approx(lo, abs=5e-4) and got[1] == pytest.approx(hi, abs=5e-4)
    assert wilson(0, 0) is None


def test_confusion_counts_and_rates():
    safe = [True, True, True, False, False, True]
    fell = [False, True, False, True, False, False]
    c = confusion(safe, fell)
    assert (c["safe_survived"], c["safe_fell"], c["unsafe_survived"], c["unsafe_fell"]) == (
        3,
        1,
        1,
        1,
    )
    assert c["accuracy"] == pytest.approx(4 / 6)
    assert c["safe_and_fell_share"] == pytest.approx(1 / 6)  # of all trials: not the headline
    assert c["fell_given_safe"]["rate"] == pytest.approx(1 / 4)
    assert (c["fell_given_safe"]["count"], c["fell_given_safe"]["of"]) == (1, 4)
    assert c["stood_given_unsafe"]["rate"] == pytest.approx(1 / 2)
    assert c["safe_given_stood"]["rate"] == pytest.approx(3 / 4)
    assert c["fell_given_safe"]["ci95"] == wilson(1, 4)
    assert c["accuracy_ci95"][0] < 4 / 6 < c["accuracy_ci95"][1]
    # The conditional rates come first in the JSON object.
    assert list(c)[:3] == ["fell_given_safe", "stood_given_unsafe", "safe_given_stood"]


def test_confusion_without_a_safe_call_has_no_false_safe_rate():
    c = confusion([False, False], [True, False])
    assert c["fell_given_safe"] == {"rate": None, "ci95": None, "count": 0, "of": 0}
    assert c["stood_given_unsafe"]["rate"] == 0.5
    with pytest.raises(ValueError, match="differ in length"):
        confusion([True], [True, False])


def test_boundary_impulse_puts_the_predicted_velocity_on_the_boundary():
    area = Polygon(np.array([[-0.3, -0.4], [0.3, -0.4], [0.3, 0.4], [-0.3, 0.4]]))
    m = 90.0
    for angle in np.linspace(0, 2 * np.pi, 17):
        J = boundary_impulse(area, m, angle)
        v = J / m * np.array([np.cos(angle), np.sin(angle)])
        assert area.margins(v)[0] == pytest.approx(0.0, abs=1e-12)
    assert boundary_impulse(area, m, 0.0, (0.1, 0.0)) == pytest.approx(m * 0.2)
    assert boundary_impulse(area, m, 0.0, (0.5, 0.0)) == 0.0  # already outside


def test_push_calls_at_a_margin_are_the_inset_area():
    """Safe at margin M exactly when the prediction lies in the area shrunk by M (omega M in CoM
    velocity)."""
    omega = 3.3
    summary = {
        "outcome": "balanced",
        "com_velocity_margin_at_end": 0.02,
        "min_zmp_margin_during": None,
    }
    o = PushOutcome(
        push=Push(0.0, 10.0),
        relative=None,
        summary=summary,
        prediction=PushPrediction(np.zeros(2), 0.033, np.zeros(2), 0.004),
    )
    assert (
        o.safe("com", 0.0, omega)
        and o.safe("com", 0.01, omega)
        and not o.safe("com", 0.0101, omega)
    )
    assert o.safe("zmp", 0.004, omega) and not o.safe("zmp", 0.005, omega)
    assert o.safe("com_in_trial", 0.006, omega) and not o.safe("com_in_trial", 0.007, omega)
    assert not o.safe("zmp_in_trial", 0.0, omega)  # no ZMP (a foot carried nothing): not safe


def test_non_finite_numbers_are_null_with_a_reason():
    nulls: dict = {}
    assert finite_or_null(nulls, "a", math.inf, "why") is None and nulls == {"a": "why"}
    assert finite_or_null(nulls, "b", [1.0, 2.0], "no") == [1.0, 2.0] and "b" not in nulls
    assert finite_or_null(nulls, "c", [1.0, math.nan], "nan") is None


def test_journal_round_trip_cut_line_and_foreign_digest(tmp_path):
    path = tmp_path / "j.jsonl"
    j = TrialJournal.open(path, "abc", {"command": "push-test"})
    j.add({"speed": 0.5}, {"summary": {"outcome": "fell"}, "trajectory": {}})
    j.add({"speed": 0.25}, {"summary": {"outcome": "balanced"}, "trajectory": {}})
    j.close()
    with open(path, "a") as fh:
        fh.write('{"key": {"speed": 0.375}, "entry": {"summ')  # a crash in the middle of a line
    again = TrialJournal.open(path, "abc")
    assert again.skipped_lines == 1 and again.get({"speed": 0.5})["summary"]["outcome"] == "fell"
    assert again.get({"speed": 0.375}) is None
    again.add({"speed": 0.375}, {"summary": {"outcome": "balanced"}, "trajectory": {}})
    again.close()
    third = TrialJournal.open(path, "abc")
    assert len(third.entries) == 3 and third.skipped_lines == 1
    third.close()
    lines = path.read_text().splitlines()
    assert all(json.loads(line) for line in lines if not line.endswith("summ"))
    with pytest.raises(SimulationError, match="digest"):
        TrialJournal.open(path, "another")


def test_an_interrupted_push_test_resumes_with_the_same_answers(tmp_path):
    from impact_balance.sim.studies.push import push_test
    from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

    options = BalanceTrialOptions(controller="id", after=0.5)
    setup = BalanceSetup.create("palm_push_two_feet", options=options)
    path = tmp_path / "push.jsonl"

    def crash_after_two(outcome, seen=[]):  # noqa: B006 - a counter across calls
        seen.append(outcome)
        if len(seen) == 2:
            raise KeyboardInterrupt

    journal = TrialJournal.open(path, "d")
    with pytest.raises(KeyboardInterrupt):
        push_test(
            "palm_push_two_feet",
            4,
            magnitudes=[5.0],
            options=options,
            setup=setup,
            journal=journal,
            progress=crash_after_two,
        )
    journal.close()
    resumed = push_test(
        "palm_push_two_feet",
        4,
        magnitudes=[5.0],
        options=options,
        setup=setup,
        journal=TrialJournal.open(path, "d"),
    )
    assert resumed.reused == 2 and len(resumed.outcomes) == 4
    fresh = push_test("palm_push_two_feet", 4, magnitudes=[5.0], options=options, setup=setup)
    assert [o.summary["outcome"] for o in resumed.outcomes] == [
        o.summary["outcome"] for o in fresh.outcomes
    ]
    assert [o.summary["com_velocity_margin_at_end"] for o in resumed.outcomes] == pytest.approx(
        [o.summary["com_velocity_margin_at_end"] for o in fresh.outcomes], abs=1e-12
    )


@settings(max_examples=100, deadline=None)
@given(
    st.floats(0.1, 2.0),
    st.floats(0.02, 1.0),
    st.floats(0.005, 0.1),
    st.lists(st.floats(0.05, 3.0), max_size=3),
)
def test_band_levels_cover_the_band_in_steps(lo, width, step, far):
    from impact_balance.sim.studies.push import band_levels

    hi = lo + width
    assume(step <= width)
    levels = band_levels((lo, hi), step, far)
    inside = [x for x in levels if lo - 1e-6 <= x <= hi + 1e-6]
    assert inside[0] == pytest.approx(lo, abs=1e-6) and inside[-1] == pytest.approx(hi, abs=1e-6)
    assert max(np.diff(inside), default=0.0) <= step + 2e-6  # no gap wider than the step
    assert levels == sorted(set(levels))
    for x in far:
        assert any(abs(x - y) <= 1e-6 for y in levels)


def test_the_documented_band_has_steps_of_at_most_003():
    from impact_balance.sim.studies.push import band_levels

    levels = band_levels((0.75, 1.05), 0.03, (0.5, 1.3))
    assert levels[0] == 0.5 and levels[-1] == 1.3 and len(levels) == 13
    assert np.allclose(np.diff(levels[1:-1]), 0.03)


@pytest.mark.parametrize(
    "band, step, far, field",
    [
        ((1.05, 0.75), 0.03, None, "--band"),
        ((0.75, 1.05), 0.0, None, "--band-step"),
        ((0.75, 1.05), 0.5, None, "--band-step"),
        ((0.75, 1.05), 0.03, (-1.0,), "--far"),
        (None, 0.03, (0.5,), "--far"),
    ],
)
def test_bad_band_arguments_name_the_option(band, step, far, field):
    from impact_balance.sim.studies.push import check_band_arguments

    with pytest.raises(SimulationError, match=field):
        check_band_arguments(band, step, far)


def test_predictions_start_at_rest_as_the_trials_do():
    """A scenario's com_velocity does not move the sim predictions: every trial starts at rest."""
    from impact_balance.scenario import load_scenario
    from impact_balance.sim.studies.validate import default_prediction, predictions

    scenario = load_scenario("palm_push_two_feet")
    moving = scenario.replace(com_velocity=(0.05, 0.02))
    assert predictions(moving) == predictions(scenario)
    assert default_prediction(moving, 0.01) == default_prediction(scenario, 0.01)
    assert (
        default_prediction(scenario, 0.01)
        == predictions(scenario, 0.01)["com_criterion"]["composite"]
    )


def _push(margin: float, outcome: str, strict: bool, relative: float) -> PushOutcome:
    summary = {"outcome": outcome, "fell": outcome == "fell", "strict_fail": strict, "events": []}
    return PushOutcome(
        push=Push(0.0, 10.0),
        relative=relative,
        prediction=PushPrediction(np.zeros(2), margin, np.zeros(2), 0.05),
        summary=summary,
    )


@settings(max_examples=50, deadline=None)
@given(
    st.lists(
        st.tuples(st.floats(-0.05, 0.2), st.sampled_from(["balanced", "contact_broken", "fell"])),
        min_size=1,
        max_size=25,
    )
)
def test_margin_study_finds_the_smallest_margin_by_the_false_safe_rate(rows):
    from impact_balance.sim.studies.push import PushTestResult
    from impact_balance.sim.studies.scores import MARGIN_GRID

    omega = 3.0
    pushes = [
        _push(m, outcome, outcome == "fell" or (outcome == "contact_broken" and k % 2 == 0), 1.0)
        for k, (m, outcome) in enumerate(rows)
    ]
    result = PushTestResult("s", pushes, {}, {}, None, 0.01, 0.01, omega, 0.0)
    study = result.margin_study()

    def brute(failed):
        for margin in MARGIN_GRID:
            safe = [p for p in pushes if p.prediction.com_velocity_margin >= omega * margin]
            if safe and sum(failed(p) for p in safe) / len(safe) <= 0.05:
                return margin
        return None

    assert study["smallest_margin"]["com"] == brute(lambda p: p.fell)
    assert study["smallest_margin_strict"]["com"] == brute(lambda p: p.strict_fail)
    # Strict failures include the falls: the strict margin is never the smaller one.
    lenient, strict = study["smallest_margin"]["com"], study["smallest_margin_strict"]["com"]
    if strict is not None:
        assert lenient is not None and lenient <= strict
    scores = result.scores()
    assert (
        scores["com"]["strict"]["fell_given_safe"]["count"]
        >= scores["com"]["fell_given_safe"]["count"]
    )
