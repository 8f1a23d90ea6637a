"""The trials journal's digest: what judges the trials is not an input of the trials."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

pytest.importorskip("mujoco")

from impact_balance.cli._options import open_journal
from impact_balance.scenario import load_scenario
from impact_balance.sim.trials.balance_trial import BalanceTrialOptions


def _digest(scenario: object, tmp_path: Path) -> str:
    args = argparse.Namespace(no_journal=True, journal=None, fresh=False)
    journal = open_journal(args, "push-test", scenario, "servo", BalanceTrialOptions(), {})  # type: ignore[arg-type]
    return journal.digest


def test_criterion_settings_leave_the_digest_alone(tmp_path: Path) -> None:
    base = load_scenario("palm_push_two_feet")
    d0 = _digest(base, tmp_path)
    for change in (
        {"zmp_margin": 0.02},
        {"velocity_margin": 0.05},
        {"angular_momentum_damping_time": 0.1},
        {"angular_momentum_damping_time": 0.0},
    ):
        assert _digest(base.replace(**change), tmp_path) == d0, change
    # ...while an input of the trials changes it.
    assert _digest(base.replace(com_velocity=[0.1, 0.0]), tmp_path) != d0
