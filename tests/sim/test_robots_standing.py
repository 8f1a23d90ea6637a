"""Every robot of the issue stands and recovers with the gains derived from it.

go2, anymal_c and solo12 on point feet (three, the bundled kicks; four, written here), and the
humanoids jvrc1, talos, g1, romeo and icub: each stands unpushed (a push of 1 micro-N s marks the
start) with the default ``id`` controller, then the commands that run trials run on the
quadrupeds with no aborted trial. ``scripts/robots_standing.py`` runs the longer version (5 s
standing, a push grid per robot; docs/studies/robots-standing.md).
"""

from __future__ import annotations

import json
import warnings

import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.exceptions import ModelRepairWarning
from impact_balance.scenario.validate import scenario_from_dict
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push
from tests.helpers.cli import run_cli
from tests.helpers.quadrupeds import four_point_feet

STANCES = {
    "go2": "go2_kick_three_feet",
    "anymal_c": "anymal_c_kick_three_feet",
    "solo12": "solo12_kick_three_feet",
    "jvrc1": "jvrc1_palm_push_two_feet",
    "talos": "palm_push_two_feet",
    "g1": "g1_two_feet",
    "romeo": "romeo_two_feet",
    "icub": "icub_two_feet",
}
KICKS = ("go2_kick_three_feet", "anymal_c_kick_three_feet", "solo12_kick_three_feet")


def _stands(scenario, seconds: float, magnitude: float = 1e-6) -> None:
    options = BalanceTrialOptions(controller="id", after=seconds, settle=0.2)
    setup = BalanceSetup.create(scenario, options=options)
    result = run_balance_trial(setup, push=Push(0.0, magnitude), options=options)
    assert result.outcome == "balanced", (result.reason, result.detail)
    assert result.max_drop < 0.02 and result.max_slip < 0.01


def test_go2_stands_on_four_point_feet_and_takes_a_push():
    scenario = scenario_from_dict(four_point_feet("go2"))
    _stands(scenario, 1.0, magnitude=0.1 * scenario.build_stance().mass)  # 0.1 m/s


@pytest.mark.slow
@pytest.mark.parametrize("robot", sorted(STANCES))
def test_every_robot_stands_unpushed(robot):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelRepairWarning)  # anymal_c, romeo, icub: repaired
        _stands(STANCES[robot], 3.0)


@pytest.mark.slow
@pytest.mark.parametrize("name", KICKS)
def test_the_trial_commands_run_on_the_quadrupeds(capsys, name):
    rc, out, err = run_cli(
        capsys,
        "push-test",
        name,
        "--directions",
        "2",
        "--magnitudes",
        "0.5",
        "--no-journal",
        "--json",
    )
    assert rc == 0, err
    doc = json.loads(out)
    assert doc["counts"]["outcomes"]["aborted"] == 0
    rc, out, err = run_cli(capsys, "approach", name, "--reference", "0.8", "--json")
    assert rc == 0, err
    assert json.loads(out)["outcome"] != "aborted"
    rc, out, err = run_cli(capsys, "simulate", name, "--speed", "0.3", "--json")
    assert rc == 0, err
    assert json.loads(out)["com_velocity_jump_measured"] is not None


@pytest.mark.slow
@pytest.mark.parametrize("name", KICKS)
def test_a_rigid_impact_on_the_quadrupeds_is_a_trial(name):
    """One ``validate --rigid-impact`` trial: the kick at 0.3 m/s touches and is not aborted."""
    options = BalanceTrialOptions(controller="id", after=1.0, settle=0.2, rigid_impact=True)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelRepairWarning)
        setup = BalanceSetup.create(name, options=options)
    result = run_balance_trial(setup, impact_speed=0.3, options=options)
    assert result.outcome != "aborted", result.detail
    assert result.impact is not None and result.approach_speed == pytest.approx(0.3)
