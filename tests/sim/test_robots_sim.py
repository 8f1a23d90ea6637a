"""Every robot simulates: the four bundled ones, simple_humanoid and the Solo12 quadruped.

Romeo (24 massless finger links) and iCub (point-mass legs, singular ankle inertias) are
refused by MuJoCo as their URDFs stand; :mod:`impact_balance.sim.model.inertia` repairs them. The
checks here are independent of that repair: the compiled MuJoCo model's total mass and
composite inertia are compared with pinocchio's (which reads the URDF unrepaired), and the
rigid robot's measured CoM velocity jump with the impact model's prediction.

The trials assert that they run and return sane fields, not a fall outcome (the outcomes per
robot are tests/sim/test_robots_standing.py's and docs/studies/robots-standing.md's).
"""

from __future__ import annotations

import json
import math
import warnings

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance.cli import main
from impact_balance.exceptions import ModelRepairWarning
from impact_balance.robot.robot import example_robot_data_root
from impact_balance.sim import SimOptions, build_model
from impact_balance.sim.studies.push import push_test
from impact_balance.sim.studies.validate import validate
from impact_balance.sim.trials.balance_trial import BalanceTrialOptions
from impact_balance.sim.trials.outcomes import (
    EVENT_KINDS,
    FALL_REASONS,
    OUTCOMES,
    OutcomeCriteria,
)
from tests.helpers.sim import mujoco_composite_inertia

ROOT = example_robot_data_root()
BUNDLED = {
    "talos": "palm_push_two_feet",
    "g1": "g1_two_feet",
    "romeo": "romeo_two_feet",
    "icub": "icub_two_feet",
}
LIGHT = SimOptions(meshes=False)
# Short trials: 0.2 s standing, 0.6 s after the disturbance.
SHORT = BalanceTrialOptions(after=0.6, settle=0.2)
DEFAULT_CRITERIA = SHORT.criteria


def _draft(path, robot: str, contacts: str, impact: str) -> None:
    path.write_text(f"robot: {robot}\ntorque_limits: false\ncontacts:\n{contacts}impact:\n{impact}")


@pytest.fixture(scope="module")
def extra_scenarios(tmp_path_factory):
    """simple_humanoid and Solo12 scenarios, posed with the `pose` command from drafts."""
    folder = tmp_path_factory.mktemp("robots")
    simple = ROOT / "simple_humanoid_description"
    _draft(
        folder / "simple_draft.yaml",
        f"{{urdf: {simple / 'urdf' / 'simple_humanoid.urdf'},"
        f" srdf: {simple / 'srdf' / 'simple_humanoid.srdf'}, "
        "standing: neutral}",  # its SRDF half_sitting is outside its own joint limits
        "  - {frame: l_ankle, friction: 0.7, size: [0.2, 0.1]}\n"
        "  - {frame: r_ankle, friction: 0.7, size: [0.2, 0.1]}\n",
        "  {frame: r_wrist, normal: [-1, 0, 0], reference_velocity: [0.5, 0, 0]}\n",
    )
    solo = ROOT / "solo_description"
    feet = "".join(
        f"  - {{frame: {f}_FOOT, friction: 0.7, size: [0.02, 0.02], normal: [0, 0, 1]}}\n"
        for f in ("FR", "HL", "HR")
    )  # the *_FOOT frames are tilted 45 degrees: give the normal
    _draft(
        folder / "solo_draft.yaml",
        f"{{urdf: {solo / 'robots' / 'solo12.urdf'}, srdf: {solo / 'srdf' / 'solo.srdf'},"
        " standing: straight_standing}",
        feet,
        "  {frame: FL_FOOT, normal: [-1, 0, 0], reference_velocity: [0.5, 0, 0]}\n",
    )
    # The arm forward (the neutral arm hangs straight, a singular start); the front left foot
    # lifted for a kick, the CoM inside the three other feet.
    assert (
        main(
            [
                "pose",
                str(folder / "simple_draft.yaml"),
                "--place",
                "r_wrist",
                "0.25",
                "-0.25",
                "0.9",
                "--out",
                str(folder / "simple_humanoid.yaml"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "pose",
                str(folder / "solo_draft.yaml"),
                "--place",
                "FL_FOOT",
                "0.22",
                "0.147",
                "0.05",
                "--com",
                "-0.04",
                "-0.04",
                "--out",
                str(folder / "solo12.yaml"),
            ]
        )
        == 0
    )
    return {
        "simple_humanoid": str(folder / "simple_humanoid.yaml"),
        "solo12": str(folder / "solo12.yaml"),
    }


ROBOTS = [*BUNDLED, "simple_humanoid", "solo12"]


def scenario_of(robot: str, extra: dict) -> str:
    return BUNDLED.get(robot) or extra[robot]


@pytest.mark.parametrize("robot", ROBOTS)
def test_model_is_pinocchios_robot_within_1e6(extra_scenarios, robot):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelRepairWarning)
        sim = build_model(scenario_of(robot, extra_scenarios), "servo", LIGHT)
    stance = sim.stance
    mass, com, inertia = mujoco_composite_inertia(sim)
    assert abs(mass / stance.mass - 1.0) < 1e-6
    assert np.linalg.norm(com - stance.com) < 1e-6 * np.linalg.norm(stance.com)
    reference = stance.com_inertia
    assert np.linalg.norm(inertia - reference, 2) < 1e-6 * np.linalg.eigvalsh(reference)[0]
    if robot in ("talos", "g1", "simple_humanoid", "solo12"):
        assert sim.inertia_repair is None
        assert mass == pytest.approx(stance.mass, rel=1e-12)  # nothing repaired: exact


def test_repairs_are_named_in_one_warning():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("default")
        romeo = build_model("romeo_two_feet", "servo", LIGHT)
        build_model("romeo_two_feet", "rigid", LIGHT)  # the same repair again: no second warning
        icub = build_model("icub_two_feet", "rigid", LIGHT)
    repairs = [w.message for w in caught if issubclass(w.category, ModelRepairWarning)]
    assert [w.robot for w in repairs] == ["romeo", "icub"]
    assert "LFinger11Link" in str(repairs[0]) and len(romeo.inertia_repair.floored) == 24
    assert "l_ankle_2" in str(repairs[1]) and "l_ankle_2" in dict(icub.inertia_repair.merged)
    # Floors: all together below 1e-7 of the mass, yet far above MuJoCo's 1e-15.
    r = romeo.inertia_repair
    assert 0 < r.added_mass < 1e-7 * romeo.stance.mass
    assert r.mass_floor > 1e-12 and r.inertia_floor > 1e-12
    fingers = [romeo.model.body(name).id for name in r.floored]
    assert np.all(romeo.model.body_mass[fingers] >= r.mass_floor)
    assert np.all(romeo.model.body_inertia[fingers] >= r.inertia_floor * (1 - 1e-9))


@pytest.mark.parametrize("robot", ROBOTS)
def test_simulate_rigid_impact_matches_the_composite_model(extra_scenarios, robot, capsys):
    rc = main(
        [
            "simulate",
            scenario_of(robot, extra_scenarios),
            "--speed",
            "0.3",
            "--duration",
            "0.05",
            "--json",
        ]
    )
    out = capsys.readouterr().out
    assert rc == 0
    result = json.loads(out)
    jump = np.asarray(result["com_velocity_jump_measured"])
    assert np.all(np.isfinite(jump)) and np.linalg.norm(jump) > 1e-3
    # A rigid robot obeys the paper's model: the jump lies on the composite set (README: within 2
    # %).
    assert result["predicted"]["composite"]["distance"] < 0.02 * np.linalg.norm(jump)


def _finite(x) -> bool:
    return x is None or math.isfinite(x)


def assert_real_outcome(summary: dict, criteria: OutcomeCriteria = DEFAULT_CRITERIA) -> None:
    """A scored trial (not ``aborted``) whose outcome is what the robot did.

    ``balanced``: no event, no reason, base drop and trunk tilt within the fall thresholds;
    ``contact_broken``: the reason is one of its contact events, every event after the disturbance;
    ``fell``: a fall reason, and the measured drop or tilt past its threshold when that is the
    reason. In every case the disturbance happened (an aborted trial tests nothing).
    """
    json.dumps(summary, allow_nan=False)  # every number finite or null
    outcome, reason, events = summary["outcome"], summary["reason"], summary["events"]
    assert outcome in OUTCOMES and summary["fell"] == (outcome == "fell")
    assert outcome != "aborted", f"aborted: {reason}: {summary['detail']}"
    assert summary["disturbance_time"] is not None and summary["sim_time"] > 0
    assert all(e["time"] >= summary["disturbance_time"] - 1e-9 for e in events), events
    assert _finite(summary["worst_com_velocity_margin"])
    if outcome == "balanced":
        assert reason is None and not events, summary
        assert summary["max_drop"] <= criteria.max_drop
        assert summary["max_trunk_tilt_deg"] <= math.degrees(criteria.max_trunk_tilt)
    elif outcome == "contact_broken":
        assert events and reason in EVENT_KINDS, summary
        assert reason in {e["kind"] for e in events}
    else:
        assert reason in FALL_REASONS, summary
        if reason == "base_dropped":
            assert summary["max_drop"] > criteria.max_drop
        if reason == "trunk_tipped":
            assert summary["max_trunk_tilt_deg"] > math.degrees(criteria.max_trunk_tilt)


@pytest.mark.slow
@pytest.mark.parametrize("robot", ROBOTS)
def test_push_and_validate_run(extra_scenarios, robot):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ModelRepairWarning)
        pushed = push_test(
            scenario_of(robot, extra_scenarios), directions=1, magnitudes=[5.0], options=SHORT
        )
        bracket = validate(
            scenario_of(robot, extra_scenarios), tolerance=0.5, max_speed=0.4, options=SHORT
        )
    (outcome,) = pushed.outcomes
    assert_real_outcome(outcome.summary)
    b = bracket.bracket()
    assert bracket.trials
    assert b["survived_commanded"] is not None or b["fell_commanded"] is not None, b
    real = [t for t in bracket.trials if t.outcome != "aborted"]
    assert real
    for trial in bracket.trials:
        assert 0 < trial.speed <= 0.4
        if trial.outcome == "aborted":
            # Only the slower approaches the threshold searches probe below every scored trial may
            # abort (a long approach lifts simple_humanoid's foot before the contact).
            assert trial.speed < min(t.speed for t in real)
            assert trial.summary["reason"] == "before_disturbance"
            continue
        assert_real_outcome(trial.summary)
        assert "impact" in trial.summary  # the impact point touched the surface
    assert len({round(t.speed, 9) for t in bracket.trials}) == len(bracket.trials)  # none twice


def test_push_test_cli_on_romeo(capsys):
    rc = main(["push-test", "romeo_two_feet", "--directions", "1", "--magnitudes", "5", "--json"])
    captured = capsys.readouterr()
    assert rc == 0
    document = json.loads(captured.out)
    assert document and "impact-balance: warning: robot romeo" in captured.err
    assert "LFinger11Link" in document["controller"]["inertia_repair"]["floored"]  # in the JSON too
    assert captured.err.count("warning: robot romeo") <= 1
