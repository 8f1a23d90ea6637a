"""``validate --com-reach``: the reach computed once, kept in ``predicted``, scored against."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance import analyze, load_scenario
from impact_balance.analysis.reach import ReachAnswer, reach_answer
from impact_balance.balance.reach import ReachOptions
from impact_balance.cli import main
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.studies.validate import ValidationResult, validate
from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions
from tests.helpers.reach import evenly_spaced_reach

SCENARIO = "palm_push_two_feet"
#: A cheap search (4 azimuths, 3 bisections, 150 IK steps): the same code as the default's.
CHEAP = ReachOptions(directions=4, bisections=3, iterations=150)


def _synthetic(reach: ReachAnswer | None, default: float) -> ValidationResult:
    """A result without trials (the verdict names its prediction), with or without a reach."""
    return ValidationResult(
        "synthetic",
        "servo",
        True,
        {},
        {"com_criterion": {"composite": default}},
        0.01,
        3.0,
        [],
        {},
        {},
        0.05,
        4.0,
        default=default,
        reach=reach,
    )


@pytest.mark.parametrize("within", [0.0, 0.21, 0.5])
def test_the_verdict_is_scored_against_the_maximum_within_reach(within):
    n = 4
    reach = evenly_spaced_reach(np.full(n, 0.05), nq=3)
    answer = ReachAnswer(reach, np.full(n, 0.3), within, 0.5)
    doc = _synthetic(answer, 0.5).to_dict()
    assert doc["predicted"]["default"] == 0.5
    assert doc["predicted"]["com_reach"] == answer.to_dict()
    assert doc["verdict"]["predicted"] == within
    plain = _synthetic(None, 0.5).to_dict()
    assert "com_reach" not in plain["predicted"] and plain["verdict"]["predicted"] == 0.5


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One search (at most 0.3 m/s: one trial) with the cheap reach, then again without it."""
    options = BalanceTrialOptions(after=1.0, controller="id", rigid_impact=True)
    setup = BalanceSetup.create(SCENARIO, options=options)
    path = tmp_path_factory.mktemp("validate") / "v.jsonl"
    kwargs = {"tolerance": 0.5, "max_speed": 0.3, "options": options, "setup": setup}
    docs = []
    for reach in (CHEAP, False):
        journal = TrialJournal.open(path, "digest")
        result = validate(SCENARIO, zmp_margin=0.01, journal=journal, com_reach=reach, **kwargs)
        journal.close()
        docs.append(json.loads(json.dumps(result.to_dict(), allow_nan=False)))
    return docs


def test_the_reach_is_reach_answer_of_the_default_analysis(runs):
    with_reach, _ = runs
    scenario = load_scenario(SCENARIO).replace(zmp_margin=0.01, com_velocity=(0.0, 0.0))
    independent = reach_answer(analyze(scenario), CHEAP)
    block = with_reach["predicted"]["com_reach"]
    assert block == json.loads(json.dumps(independent.to_dict()))
    assert block["default_max_contact_velocity"] == with_reach["predicted"]["default"]
    assert with_reach["verdict"]["predicted"] == block["max_contact_velocity"]
    for t in with_reach["trials"]:
        measured = t["approach_speed_measured"]
        assert t["com_reach_safe"] == (measured <= block["max_contact_velocity"])


def test_without_the_option_the_document_is_the_same_less_the_reach(runs):
    with_reach, without = runs
    assert "com_reach" not in without["predicted"]
    assert all("com_reach_safe" not in t for t in without["trials"])
    assert without["verdict"]["predicted"] == without["predicted"]["default"]
    del with_reach["predicted"]["com_reach"]
    for t in with_reach["trials"]:
        del t["com_reach_safe"]
    for doc in (with_reach, without):
        for key in ("wall_time", "reused_trials", "verdict"):
            doc.pop(key)
    assert with_reach == without


@pytest.mark.slow
def test_validate_com_reach_cli_json_and_text(capsys, tmp_path):
    argv = [
        "validate",
        SCENARIO,
        "--controller",
        "id",
        "--rigid-impact",
        "--max-speed",
        "0.3",
        "--com-reach",
        "--journal",
        str(tmp_path / "v.jsonl"),
    ]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    block = out["predicted"]["com_reach"]
    assert len(block["radii"]) == ReachOptions().directions
    assert block["max_contact_velocity"] <= block["default_max_contact_velocity"]
    assert out["verdict"]["predicted"] == block["max_contact_velocity"]
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert text.count("within the CoM's reach") == 1 and "within reach: safe" in text
