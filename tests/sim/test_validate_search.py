"""The threshold searches of `validate` on a synthetic robot (no simulation): the fall, the strict
failure and the first contact break are each bisected to the tolerance, in measured speed."""

from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance.sim.studies.validate import (
    ValidationResult,
    ValidationTrial,
    _broke,
    _fell,
    _Search,
    _strict,
)


class _Robot:
    """Trials of a robot that breaks a contact from ``brk``, fails strictly from ``strict`` and
    falls from ``fall`` (commanded m/s); the measured speed is 2 % above the commanded one."""

    def __init__(self, brk: float, strict: float, fall: float):
        self.brk, self.strict, self.fall = brk, strict, fall
        self.trials: list[ValidationTrial] = []

    def __call__(self, speed: float) -> str:
        fell = speed >= self.fall
        events = [{"contact": "palm", "kind": "slipped", "time": 2.0, "value": 0.02}]
        outcome = "fell" if fell else ("contact_broken" if speed >= self.brk else "balanced")
        summary = {
            "outcome": outcome,
            "fell": fell,
            "strict_fail": speed >= self.strict,
            "strict_reason": "palm slipped" if speed >= self.strict else None,
            "reason": None,
            "detail": "",
            "events": events if speed >= self.brk else [],
            "approach_speed_measured": 1.02 * speed,
        }
        self.trials.append(ValidationTrial(speed=speed, summary=summary))
        return outcome


@settings(max_examples=60, deadline=None)
@given(
    st.floats(0.05, 1.0),
    st.floats(0.0, 1.0),
    st.floats(0.0, 1.0),
    st.sampled_from([0.05, 0.1, 0.2]),
)
def test_every_threshold_is_bisected_to_the_tolerance(brk, a, b, tolerance):
    strict = brk * (1 + 2 * a)
    fall = strict * (1 + 2 * b)
    robot = _Robot(brk, strict, fall)
    search = _Search(robot, tolerance, 0.02, 4.0, None)
    stood, fell = search.bracket(0.5)
    if stood is not None and fell is not None:
        search.bisect(stood, fell)
    search.threshold(_strict)
    search.threshold(_broke)
    for failed, threshold in ((_fell, fall), (_strict, strict), (_broke, brk)):
        bad = [t.speed for t in robot.trials if failed(t)]
        if threshold > 4.0:
            continue
        hi = min(bad)
        good = [t.speed for t in robot.trials if not failed(t) and t.speed < hi]
        assert hi >= threshold
        if threshold > 0.02:
            assert good, "no trial below the threshold"
            lo = max(good)
            assert lo < threshold <= hi and hi - lo <= tolerance * hi + 1e-12


def test_the_result_reports_the_thresholds_in_measured_speed():
    robot = _Robot(0.3, 0.45, 0.6)
    search = _Search(robot, 0.05, 0.02, 4.0, None)
    stood, fell = search.bracket(0.5)
    search.bisect(stood, fell)
    search.threshold(_strict)
    search.threshold(_broke)
    result = ValidationResult(
        "synthetic", "servo", True, {}, {}, 0.01, 3.0, robot.trials, {}, {}, 0.05, 4.0
    )
    b = result.bracket()
    assert b["fell"] == pytest.approx(1.02 * b["fell_commanded"])
    assert 0.45 <= b["strict_failed_commanded"] <= 0.45 / 0.95
    assert b["strict_failed"] == pytest.approx(1.02 * b["strict_failed_commanded"])
    assert b["strict_stood_commanded"] < 0.45 <= b["strict_failed_commanded"]
    brk = b["first_contact_break"]
    assert brk["no_break_below_commanded"] < 0.3 <= brk["commanded"]
    assert brk["commanded"] - brk["no_break_below_commanded"] <= 0.05 * brk["commanded"]
    assert brk["measured"] == pytest.approx(1.02 * brk["commanded"])
    assert brk["contact"] == "palm" and brk["kind"] == "slipped"


class _Runner(_Robot):
    """The search's runner on the synthetic robot, aborting below ``abort`` (commanded m/s), and
    running each speed once, as :class:`~impact_balance.sim.studies.validate._TrialRunner` does."""

    def __init__(self, brk: float, strict: float, fall: float, abort: float):
        super().__init__(brk, strict, fall)
        self.abort, self.runs = abort, 0

    def __call__(self, speed: float) -> str:
        for done in self.trials:
            if round(done.speed, 9) == round(speed, 9):
                return done.outcome
        self.runs += 1
        if speed < self.abort:
            summary = {"outcome": "aborted", "reason": "before_disturbance", "events": []}
            self.trials.append(ValidationTrial(speed=speed, summary=summary))
            return "aborted"
        return super().__call__(speed)


def test_searches_stop_above_an_aborted_speed_and_never_run_one_twice():
    robot = _Runner(0.2, 0.2, 0.4, abort=0.15)
    search = _Search(robot, 0.05, 0.02, 4.0, None)
    stood, fell = search.bracket(0.4)  # falls at once: halves to 0.2 (broke, stood), bisects
    search.bisect(stood, fell)
    search.threshold(_strict)  # fails at 0.2 already: halves to 0.1, aborted, stops
    before = robot.runs
    search.threshold(_broke)  # the same: the aborted 0.1 is not run again
    assert robot.runs == before
    speeds = [round(t.speed, 9) for t in robot.trials]
    assert len(speeds) == len(set(speeds)) and 0.1 in speeds
    assert min(speeds) == 0.1  # nothing below the aborted speed
