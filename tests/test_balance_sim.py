"""Balance trials in MuJoCo (a few simulated seconds each): pushes, an impact bisection, logs, CLI."""

from __future__ import annotations

import json

import numpy as np
import pytest

from impact_balance.cli import main
from impact_balance.logs import check_log, read_log, write_log
from impact_balance.sim.balance_trial import BalanceSetup, BalanceTrialOptions, Push, run_balance_trial
from impact_balance.sim.validate import validate

SCENARIO = "palm_push_two_feet"


@pytest.fixture(scope="module")
def setup():
    return BalanceSetup.create(SCENARIO)


def test_small_push_is_recovered_and_logged(setup, tmp_path):
    result = run_balance_trial(setup, push=Push(0.0, 5.0, 0.05), options=BalanceTrialOptions(after=1.0, record=True))
    assert not result.fell, result.detail
    assert result.com_criterion_safe and result.min_com_velocity_margin > 0
    # A 5 N s push changes the CoM velocity by about 5 / 90 m/s; the controller brings it back.
    peak = np.abs(result.series["com_velocity"][:, 0]).max()
    assert 0.03 < peak < 0.12
    path = write_log(result.log, tmp_path / "push.parquet")
    frame = read_log(path)
    check = check_log(frame, SCENARIO)
    # The checker's CoM velocity (pinocchio, from base and joint columns) against MuJoCo's own (logged).
    ours = check.samples[["comd_x", "comd_y", "comd_z"]].to_numpy()
    mujoco_com = frame[["comd_x", "comd_y", "comd_z"]].to_numpy()
    assert np.abs(ours - mujoco_com).max() < 1e-6
    assert np.abs(check.samples[["com_x", "com_y", "com_z"]].to_numpy() - frame[["com_x", "com_y", "com_z"]].to_numpy()).max() < 1e-6
    late = check.samples["time"] > 0.2
    assert check.samples.loc[late, "com_velocity_inside"].all()


def test_large_push_falls_and_the_com_criterion_saw_it(setup):
    result = run_balance_trial(setup, push=Push(0.0, 100.0, 0.05), options=BalanceTrialOptions(after=1.5))
    assert result.fell and result.reason is not None
    assert result.com_criterion_safe is False  # ~1.1 m/s is far outside the CoM velocity area


def test_validate_brackets_the_threshold(setup):
    result = validate(SCENARIO, tolerance=0.5, options=BalanceTrialOptions(after=0.6), setup=setup)
    out = json.loads(json.dumps(result.to_dict()))
    assert set(out["predicted"]) == {"com_criterion", "zmp_criterion"}
    assert set(out["predicted"]["com_criterion"]) == {"composite", "joint_space"}
    s, f = out["empirical"]["survived"], out["empirical"]["fell"]
    assert s is not None and f is not None and s < f and f - s <= 0.5 * f
    assert all({"speed", "fell", "reason", "max_zmp_excursion", "max_com_velocity_excursion"} <= set(t) for t in out["trials"])
    assert any(t["fell"] for t in out["trials"]) and any(not t["fell"] for t in out["trials"])
    assert out["controller"]["name"] and out["controller"]["gains"]["rate"] == 500.0


def test_cli_errors_are_one_line(capsys, tmp_path):
    no_impact = tmp_path / "no_impact.yaml"
    no_impact.write_text("extends: palm_push_two_feet\nimpact: null\n")
    assert main(["validate", str(no_impact)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "has no impact" in err[0]
    assert main(["push-test", SCENARIO, "--magnitudes", "-3"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--magnitudes" in err[0]


def test_push_test_json(capsys):
    assert main(["push-test", SCENARIO, "--controller", "ik", "--directions", "1", "--magnitudes", "5", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    (push,) = out["pushes"]
    assert set(push) >= {"direction", "magnitude", "fell", "reason", "com_criterion_safe", "zmp_criterion_safe"}
    assert push["magnitude"] == 5.0 and push["fell"] is False
    assert out["confusion"]["com"]["total"] == 1 and out["confusion"]["com"]["safe_survived"] == 1


def test_checker_reads_simulate_logs(tmp_path, capsys):
    """`simulate --log` (servo joints, a palm impact) writes a log the checker reads; its CoM is MuJoCo's."""
    path = tmp_path / "simulate.csv"
    assert main(["simulate", SCENARIO, "--speed", "0.2", "--joints", "servo", "--log", str(path)]) == 0
    capsys.readouterr()
    frame = read_log(path)
    check = check_log(frame, SCENARIO)
    ours = check.samples[["comd_x", "comd_y", "comd_z"]].to_numpy()
    assert np.abs(ours - frame[["comd_x", "comd_y", "comd_z"]].to_numpy()).max() < 1e-9
    assert main(["check-log", str(path), "--scenario", SCENARIO, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["samples"] == len(frame) and "violations" in out
