"""``--angular-momentum-damping-time`` on the trial commands: ``controller`` needs a K_L."""

from __future__ import annotations

import pytest

from impact_balance.cli.angular_momentum import CONTROLLER, for_trials, with_angular_momentum
from impact_balance.exceptions import ScenarioError
from impact_balance.scenario import load_scenario
from tests.helpers.cli import assert_one_line_error, run_cli
from tests.helpers.extras import needs_extra


@needs_extra("sim")
@pytest.mark.parametrize("command", ["push-test", "validate", "approach"])
def test_controller_is_refused_for_the_ik_controller_before_any_trial(command, capsys, tmp_path):
    journal = tmp_path / "j.jsonl"
    extra = ["--reference", "0.5"] if command == "approach" else ["--journal", str(journal)]
    rc, _, err = run_cli(
        capsys,
        command,
        "palm_push_two_feet",
        "--controller",
        "ik",
        "--angular-momentum-damping-time",
        CONTROLLER,
        *extra,
    )
    assert_one_line_error(rc, err, "--angular-momentum-damping-time", "K_L")
    assert not journal.exists()


@needs_extra("sim")
@pytest.mark.parametrize("name", ["palm_push_two_feet", "g1_two_feet"])
def test_controller_is_one_over_the_gain_the_trials_controller_runs_with(name):
    # The controller's K_L is derived from the robot (G1: 11.25 /s, not the default 10 /s):
    # the prediction's tau is 1 / the gain of the controller built for the trial.
    from dataclasses import replace

    from impact_balance.sim.control.gains import trial_gains
    from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions

    options = BalanceTrialOptions(controller="id")
    scenario = load_scenario(name)
    judged = for_trials(scenario, CONTROLLER, options)
    setup = BalanceSetup.create(scenario, "servo", options)
    running = trial_gains(options, setup.sim)[1].angular_momentum_damping
    assert judged.angular_momentum_damping_time == pytest.approx(1.0 / running, rel=1e-12)
    fixed = replace(options, robot_gains=False)
    assert for_trials(scenario, CONTROLLER, fixed).angular_momentum_damping_time == (
        pytest.approx(1.0 / fixed.id_gains.angular_momentum_damping, rel=1e-15)
    )


def test_off_removes_the_key_and_a_bad_value_names_the_option():
    on = load_scenario("palm_push_two_feet").replace(angular_momentum_damping_time=0.2)
    assert with_angular_momentum(on, "off").angular_momentum_damping_time is None
    assert with_angular_momentum(on, None) is on
    with pytest.raises(ScenarioError) as caught:
        with_angular_momentum(on, 1e9)
    assert caught.value.field == "--angular-momentum-damping-time"
