"""The trial commands (validate, push-test, approach) take their margins the one validated way.

The studies are replaced by stand-ins that record what the command hands them and stop: what
is checked is the command's plumbing (no simulation runs).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from impact_balance import cli
from impact_balance.exceptions import SimulationError

pytest.importorskip("mujoco")


class Stop(SimulationError):
    """Raised by a stand-in once it has recorded its call."""

    def __init__(self) -> None:
        super().__init__("stand-in", None, "stopped before any trial")


def record(calls: list[dict[str, Any]]):
    """A stand-in for a study: records its scenario and keyword arguments, then stops."""

    def stand_in(scenario, *args: Any, **kwargs: Any):
        calls.append({"scenario": scenario, **kwargs})
        raise Stop()

    return stand_in


@pytest.fixture
def studies(monkeypatch) -> dict[str, list[dict[str, Any]]]:
    import impact_balance.sim.studies.push as push
    import impact_balance.sim.studies.validate as validate

    calls: dict[str, list[dict[str, Any]]] = {"validate": [], "push-test": []}
    monkeypatch.setattr(validate, "validate", record(calls["validate"]))
    monkeypatch.setattr(push, "push_test", record(calls["push-test"]))
    return calls


@pytest.mark.parametrize("command", ["validate", "push-test"])
def test_the_option_reaches_the_study(studies, command, capsys):
    argv = [command, "palm_push_two_feet", "--no-journal", "--zmp-margin", "0.02"]
    assert cli.main(argv) == 2
    assert "stopped before any trial" in capsys.readouterr().err
    (call,) = studies[command]
    assert call["scenario"].zmp_margin == 0.02
    assert call["zmp_margin"] == 0.02


@pytest.mark.parametrize("command", ["validate", "push-test"])
@pytest.mark.parametrize("value", ["-0.01", "10.5", "nan"])
def test_a_refused_margin_stops_before_any_trial(studies, command, value, capsys):
    assert cli.main([command, "palm_push_two_feet", "--no-journal", "--zmp-margin", value]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--zmp-margin = " in err
    assert studies[command] == []


def test_approach_gives_the_governor_both_margins(monkeypatch, tmp_path: Path, capsys):
    import impact_balance.governor as governor_module
    from impact_balance.sim.trials.balance_trial import BalanceSetup

    calls: list[dict[str, Any]] = []
    monkeypatch.setattr(BalanceSetup, "create", classmethod(lambda cls, *a, **k: None))
    monkeypatch.setattr(governor_module, "Governor", record(calls))
    argv = ["approach", "palm_push_two_feet", "--reference", "0.8"]
    assert cli.main([*argv, "--zmp-margin", "0.02", "--velocity-margin", "0.01"]) == 2
    (call,) = calls
    assert call["scenario"].zmp_margin == 0.02
    assert call["scenario"].velocity_margin == 0.01
    assert cli.main([*argv, "--velocity-margin", "11"]) == 2
    assert "--velocity-margin = 11.0: must be in [0, 10] m/s" in capsys.readouterr().err
    assert len(calls) == 1


@pytest.mark.parametrize("command", ["validate", "push-test"])
def test_the_scenario_files_margin_reaches_the_study(studies, command, tmp_path: Path):
    path = tmp_path / "margin.yaml"
    path.write_text("extends: palm_push_two_feet\nzmp_margin: 0.03\n")
    assert cli.main([command, str(path), "--no-journal"]) == 2
    assert cli.main([command, str(path), "--no-journal", "--zmp-margin", "0.02"]) == 2
    assert cli.main([command, "palm_push_two_feet", "--no-journal"]) == 2
    from_file, from_option, unset = studies[command]
    assert from_file["zmp_margin"] == 0.03  # the file's key, as analyze honours it
    assert from_option["zmp_margin"] == 0.02  # the option wins over the file
    assert unset["zmp_margin"] is None  # neither: the controller's own margin


def test_approach_honours_the_scenario_files_margins(monkeypatch, tmp_path: Path):
    import impact_balance.governor as governor_module
    from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions
    from impact_balance.sim.trials.setup import controller_margin

    calls: list[dict[str, Any]] = []
    monkeypatch.setattr(BalanceSetup, "create", classmethod(lambda cls, *a, **k: None))
    monkeypatch.setattr(governor_module, "Governor", record(calls))
    path = tmp_path / "margins.yaml"
    path.write_text("extends: palm_push_two_feet\nzmp_margin: 0.03\nvelocity_margin: 0.01\n")
    assert cli.main(["approach", str(path), "--reference", "0.8"]) == 2
    assert cli.main(["approach", "palm_push_two_feet", "--reference", "0.8"]) == 2
    from_file, unset = calls
    assert from_file["scenario"].zmp_margin == 0.03
    assert from_file["scenario"].velocity_margin == 0.01
    own = controller_margin(BalanceTrialOptions(controller="id"))  # approach's default controller
    assert unset["scenario"].zmp_margin == own and unset["scenario"].velocity_margin == 0.0
