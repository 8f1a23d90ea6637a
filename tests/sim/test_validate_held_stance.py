"""``validate --impact-model held-stance``: the held-stance maximum computed once before the
trials, kept in ``predicted.held_stance``, each trial called against it; the floating default
unchanged."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from impact_balance import analyze, load_scenario
from impact_balance.analysis.held_stance import held_stance_max_contact_velocity
from impact_balance.cli import main
from impact_balance.exceptions import SimulationError
from impact_balance.sim.studies import validate as validate_module
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.studies.validate import IMPACT_MODELS, held_stance_prediction, validate
from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

SCENARIO = "palm_push_two_feet"


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One search (at most 0.3 m/s: one trial) with the held stance, then again without it."""
    options = BalanceTrialOptions(after=1.0, controller="id", rigid_impact=True)
    setup = BalanceSetup.create(SCENARIO, options=options)
    path = tmp_path_factory.mktemp("validate") / "v.jsonl"
    kwargs = {"tolerance": 0.5, "max_speed": 0.3, "options": options, "setup": setup}
    docs = []
    for model in ("held-stance", "floating"):
        journal = TrialJournal.open(path, "digest")
        result = validate(SCENARIO, zmp_margin=0.01, journal=journal, impact_model=model, **kwargs)
        journal.close()
        docs.append(json.loads(json.dumps(result.to_dict(), allow_nan=False)))
    return docs


def test_the_held_stance_is_that_of_the_analysis_at_the_scoring_margin(runs):
    held, _ = runs
    scenario = load_scenario(SCENARIO).replace(zmp_margin=0.01, com_velocity=(0.0, 0.0))
    independent = held_stance_max_contact_velocity(analyze(scenario))
    block = held["predicted"]["held_stance"]
    assert block == json.loads(json.dumps(independent.to_dict()))
    assert block["converged"] and not block["fell_back"]
    # A different answer from the paper's at the same margin (what the option is for).
    assert (
        block["max_contact_velocity"] != held["predicted_with_margin"]["com_criterion"]["composite"]
    )
    assert held["trials"]
    for t in held["trials"]:
        measured = t["approach_speed_measured"]
        assert t["held_stance_safe"] == (measured <= block["max_contact_velocity"])


def test_the_floating_default_is_the_same_document_less_the_held_stance(runs):
    held, floating = runs
    assert "held_stance" not in floating["predicted"]
    assert all("held_stance_safe" not in t for t in floating["trials"])
    del held["predicted"]["held_stance"]
    for t in held["trials"]:
        del t["held_stance_safe"]
    for doc in (held, floating):
        for key in ("wall_time", "reused_trials"):
            doc.pop(key)
    assert held == floating  # the verdict too: it is not scored against the held stance


def test_the_fallback_is_the_composite_papers_answer_at_the_margin(monkeypatch):
    """A fixed point not reached: the held stance is the paper's composite answer with margin."""
    real = validate_module.held_stance_max_contact_velocity

    def cut(analysis):
        return real(analysis, max_iterations=1)

    monkeypatch.setattr(validate_module, "held_stance_max_contact_velocity", cut)
    scenario = load_scenario(SCENARIO)
    joint_space = scenario.model_copy(
        update={"impact": scenario.impact.model_copy(update={"inertia": "joint_space"})}
    )
    answer = held_stance_prediction(joint_space, 0.01)  # the composite model even so
    paper = validate_module.predictions(scenario, 0.01)["com_criterion"]["composite"]
    assert answer.fell_back and answer.max_contact_velocity == paper


def test_a_bad_impact_model_is_refused_before_any_trial():
    with pytest.raises(SimulationError) as info:
        validate(SCENARIO, impact_model="held_stance", setup=None, max_speed=0.3)
    assert info.value.field == "impact_model"
    assert "held_stance" in str(info.value) and "held-stance" in str(info.value)


def test_the_command_lines_choices_are_the_librarys(capsys):
    with pytest.raises(SystemExit):
        main(["validate", SCENARIO, "--impact-model", "x"])
    err = capsys.readouterr().err
    assert str(IMPACT_MODELS)[1:-1] in err


def test_validate_impact_model_cli_json_and_text(capsys, tmp_path):
    argv = [
        "validate",
        SCENARIO,
        "--controller",
        "id",
        "--rigid-impact",
        "--max-speed",
        "0.3",
        "--impact-model",
        "held-stance",
        "--journal",
        str(tmp_path / "v.jsonl"),
    ]
    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))
    block = out["predicted"]["held_stance"]
    assert set(block) == {
        "max_contact_velocity",
        "status",
        "restitution",
        "jumps",
        "converged",
        "fell_back",
        "binding_restitution",
        "iterations",
    }
    assert all("held_stance_safe" in t for t in out["trials"])
    assert main(argv) == 0
    text = capsys.readouterr().out
    assert text.count("held stance (10 mm)") == 1 and "held stance: safe" in text


def test_with_the_controllers_tau_the_prediction_carries_the_angular_momentum():
    """``--angular-momentum-damping-time controller``: the scenario the predictions use has
    tau = 1 / K_L, and the held-stance prediction then has its ``angular_momentum`` block."""
    from impact_balance.cli.angular_momentum import for_trials

    options = BalanceTrialOptions(controller="id")
    judged = for_trials(load_scenario(SCENARIO), "controller", options)
    tau = judged.angular_momentum_damping_time
    assert tau is not None and 0.05 < tau < 0.2
    held = held_stance_prediction(judged, 0.01)
    expected = held_stance_max_contact_velocity(
        analyze(judged.replace(zmp_margin=0.01, com_velocity=(0.0, 0.0)))
    )
    assert held.to_dict() == expected.to_dict()
    assert held.angular_momentum.damping_time == tau
    assert held.angular_momentum.max_contact_velocity <= held.max_contact_velocity
    plain = held_stance_prediction(load_scenario(SCENARIO), 0.01)
    assert plain.angular_momentum is None
    assert plain.max_contact_velocity == held.max_contact_velocity
