"""Aborted trials say why (once per reason, with a count), and a run of aborted trials exits 1."""

from __future__ import annotations

import json

import pytest
import yaml

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.exit_status import EXIT_ENVIRONMENT, describe_error
from impact_balance.sim.trials import outcomes
from impact_balance.sim.trials.aborts import (
    AllTrialsAbortedError,
    aborted_lines,
    aborted_reasons,
    check_not_all_aborted,
)
from tests.helpers.cli import run_cli
from tests.helpers.quadrupeds import four_point_feet

GO2_FOUR = four_point_feet("go2")


def _trial(outcome, reason=None, detail=""):
    return {"outcome": outcome, "reason": reason, "detail": detail}


def test_reasons_are_counted_once_each_most_frequent_first():
    trials = [
        _trial("aborted", "before_disturbance", "FL_foot slipped before the disturbance"),
        _trial("fell", "trunk_tipped", "trunk turned 25 deg"),
        _trial("aborted", "no_disturbance", ""),
        _trial("aborted", "before_disturbance", "FL_foot slipped before the disturbance"),
    ]
    assert aborted_reasons(trials) == [
        ("FL_foot slipped before the disturbance", 2),
        ("no_disturbance", 1),
    ]
    assert aborted_lines(trials) == [
        "  aborted (2): FL_foot slipped before the disturbance",
        "  aborted (1): no_disturbance",
    ]
    check_not_all_aborted("push-test", "x", trials)  # one fell: something was tested
    check_not_all_aborted("push-test", "x", [])  # no trial: nothing to say


def test_all_aborted_is_one_line_and_exit_status_1():
    trials = [_trial("aborted", "before_disturbance", "RR_foot lifted before the disturbance")] * 3
    with pytest.raises(AllTrialsAbortedError) as err:
        check_not_all_aborted("validate", "go2_kick", trials)
    line, status = describe_error(err.value)
    assert status == EXIT_ENVIRONMENT == 1
    assert "\n" not in line
    assert "all 3 trials of validate were aborted" in line
    assert "RR_foot lifted before the disturbance (3)" in line
    assert "'go2_kick'" in line


@pytest.fixture
def forced_abort(monkeypatch):
    """Every trial's disturbance starts after a (forced) contact event: the trial is aborted."""
    start = outcomes.OutcomeMonitor.start_disturbance

    def aborting(self, t):
        start(self, t)
        self.abort("before_disturbance", t, "FL_foot slipped before the disturbance (forced)")

    monkeypatch.setattr(outcomes.OutcomeMonitor, "start_disturbance", aborting)


@pytest.mark.slow
@pytest.mark.parametrize("as_json", [False, True])
def test_push_test_all_aborted_prints_why_and_exits_1(capsys, tmp_path, forced_abort, as_json):
    path = tmp_path / "go2_four.yaml"
    path.write_text(yaml.safe_dump(GO2_FOUR))
    argv = ["push-test", str(path), "--directions", "2", "--magnitudes", "1", "--no-journal"]
    rc, out, err = run_cli(capsys, *argv, *(["--json"] if as_json else []))
    assert rc == 1
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("impact-balance: error: "), err
    assert "all 2 trials of push-test were aborted" in lines[0]
    if as_json:
        doc = json.loads(out)
        assert doc["counts"]["outcomes"]["aborted"] == 2
    else:
        assert "aborted (2): FL_foot slipped before the disturbance (forced)" in out


@pytest.mark.slow
def test_approach_all_aborted_prints_why_and_exits_1(capsys, forced_abort):
    rc, out, err = run_cli(capsys, "approach", "go2_kick_three_feet", "--reference", "0.5")
    assert rc == 1
    assert "aborted (1): FL_foot slipped before the disturbance (forced)" in out
    assert "all 1 trials of approach were aborted" in err and len(err.strip().splitlines()) == 1


@pytest.mark.slow
def test_validate_all_aborted_prints_why_and_exits_1(capsys, forced_abort):
    argv = ["validate", "go2_kick_three_feet", "--no-journal", "--tolerance", "0.2"]
    rc, out, err = run_cli(capsys, *argv)
    assert rc == 1
    n = sum(": aborted before_disturbance" in line for line in out.splitlines())
    assert n > 0 and f"aborted ({n}): FL_foot slipped before the disturbance (forced)" in out
    assert f"all {n} trials of validate were aborted" in err


def test_an_unreachable_approach_start_is_an_aborted_trial_not_a_crash(monkeypatch):
    """A speed whose retracted start the arm cannot reach is untestable: aborted, with why."""
    import numpy as np

    from impact_balance.robot.ik import IKError
    from impact_balance.sim.trials.balance_trial import BalanceTrialOptions, run_balance_trial
    from impact_balance.sim.trials.setup import BalanceSetup

    setup = BalanceSetup.create("palm_push_two_feet", "servo", BalanceTrialOptions())

    def unreachable(standoff: float = 0.0) -> np.ndarray:
        raise IKError("not converged", {}, 300, np.zeros(1))

    monkeypatch.setattr(setup, "start_configuration", unreachable)
    result = run_balance_trial(setup, impact_speed=3.0, options=BalanceTrialOptions())
    assert result.outcome == "aborted" and result.reason == "no_start"
    assert "cannot start" in result.detail and "not converged" in result.detail
    assert result.summary()["outcome"] == "aborted"
