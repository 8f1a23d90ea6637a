"""The wall experiment (``impact-balance approach``): the impact point sent at an unknown wall,
its speed capped every tick by a governor fed the simulated state."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

import impact_balance as ib
from impact_balance.cli import main
from impact_balance.scenario import load_scenario

KEYS = {
    "governor",
    "reference",
    "speed_at_contact",
    "cap_at_contact",
    "time_to_contact",
    "outcome",
    "reason",
    "tick_us",
}


def run_json(capsys, *argv):
    assert main(["approach", *argv, "--json"]) == 0
    return json.loads(capsys.readouterr().out, parse_constant=lambda c: pytest.fail(c))


def test_com_governor_caps_the_speed_at_contact(capsys, tmp_path):
    out = run_json(
        capsys,
        "palm_push_two_feet",
        "--reference",
        "0.8",
        "--governor",
        "com",
        "--rigid-impact",
        "--plots",
        str(tmp_path),
    )
    assert KEYS <= set(out) and set(out["tick_us"]) >= {"median", "p99"}
    margin = load_scenario("palm_push_two_feet").model_copy(
        update={"zmp_margin": out["zmp_margin"]}
    )
    at_stance = ib.analyze(margin).impact.max_contact_velocity
    # The cap in force at contact is the criterion's maximum at the posture of the contact (close to
    # the stance's).
    assert out["cap_at_contact"] == pytest.approx(at_stance, rel=0.05)
    assert out["speed_at_contact"] == pytest.approx(
        out["cap_at_contact"], rel=0.1
    )  # tracked, not conservative for nothing
    assert out["outcome"] in ("balanced", "contact_broken") and out["time_to_contact"] > 0
    assert out["tick_us"]["median"] > 0 and out["tick_us"]["count"] > 10
    assert len(out["ticks_us"]) == out["tick_us"]["count"]
    assert np.median(out["ticks_us"]) == pytest.approx(out["tick_us"]["median"], abs=1e-3)
    assert out["strict_fail"] == (
        out["outcome"] == "fell" or out["trial"]["stance_changed_time"] is not None
    )
    assert out["strict_reason"] == out["trial"]["strict_reason"]
    assert any(p.name.endswith("_approach_com_0.8_15cm.png") for p in tmp_path.iterdir())


def test_the_id_controller_holds_the_point_under_a_falling_cap():
    """On the ramp the cap falls as the arm extends; with the cap as a bound in the controller's
    QP the point hits at the cap in force (to the next tick's change of it), where the reference
    alone lets the torque controller's lag carry it past."""
    from impact_balance.governor import Governor
    from impact_balance.sim.studies.wall import WallOptions, run_wall_trial
    from impact_balance.sim.trials.balance_trial import (
        BalanceSetup,
        BalanceTrialOptions,
        controller_margin,
    )

    options = BalanceTrialOptions(controller="id", rigid_impact=True)
    scenario = load_scenario("palm_push_ramp")
    governor = Governor(scenario.model_copy(update={"zmp_margin": controller_margin(options)}))
    setup = BalanceSetup.create(scenario, "servo", options)
    ratio = {}
    for bound in (True, False):
        trial = run_wall_trial(
            setup,
            WallOptions(reference=1.0, wall_distance=0.12, cap_constraint=bound),
            options,
            governor=governor,
        )
        ratio[bound] = trial.speed_at_contact / trial.cap_at_contact
    assert ratio[True] <= 1.003
    assert ratio[False] > ratio[True] + 0.01  # the lag the bound removes


def test_tick_percentiles_are_pooled_over_the_trials():
    from types import SimpleNamespace

    from impact_balance.sim.studies.wall import pooled_tick_statistics

    rng = np.random.default_rng(3)
    ticks = [list(rng.uniform(1e-4, 2e-4, 90)) for _ in range(3)]
    ticks[1][5] = 5e-3  # one slow tick in one trial
    trials = [SimpleNamespace(ticks=t) for t in ticks]
    pooled = pooled_tick_statistics(trials)
    everything = 1e6 * np.concatenate(ticks)
    assert pooled["count"] == 270
    assert pooled["p99"] == pytest.approx(np.percentile(everything, 99))
    assert pooled["median"] == pytest.approx(np.median(everything))
    assert pooled_tick_statistics([]) == {"median": None, "p99": None, "count": 0}
    # From the trials' JSON (what a study's journal keeps): the same statistics.
    docs = [{"ticks_us": [1e6 * x for x in t]} for t in ticks]
    again = pooled_tick_statistics(docs)
    assert again["count"] == 270 and again["p99"] == pytest.approx(pooled["p99"])


def test_without_a_governor_the_reference_is_reached(capsys):
    out = run_json(
        capsys,
        "palm_push_two_feet",
        "--reference",
        "0.5",
        "--governor",
        "none",
        "--wall-distance-range",
        "0.12",
        "0.18",
    )
    assert out["governor"] == "none" and len(out["trials"]) == 3
    assert out["tick_us"] == {"median": None, "p99": None, "count": 0}  # pooled: no governor
    for trial in out["trials"]:
        assert trial["cap_at_contact"] is None and trial["tick_us"]["median"] is None
        assert trial["speed_at_contact"] == pytest.approx(0.5, rel=0.1)
    times = [t["time_to_contact"] for t in out["trials"]]
    assert times == sorted(times)  # a farther wall is reached later
    assert np.diff(times) == pytest.approx([0.03 / 0.5] * 2, rel=0.25)  # 3 cm more at 0.5 m/s


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--reference", "0.5", "--wall-distance-range", "0.2", "0.1"], "--wall-distance-range"),
        (
            ["--reference", "0.5", "--wall-distance-range", "0.1", "0.2", "--video", "v.mp4"],
            "--video",
        ),
        (["--reference", "9"], "--reference"),
        (["--reference", "nan"], "--reference"),
        (["--reference", "0.5", "--wall-distance", "0"], "--wall-distance"),
        (["--reference", "0.5", "--max-time", "1e9"], "--max-time"),
        (["--reference", "0.5", "--video", "v.avi"], "--video"),
        (["--reference", "0.5", "--plots", "/etc/passwd"], "--plots"),
        (["--reference", "0.5", "--governor", "fast"], "--governor"),
    ],
)
def test_bad_options_are_one_line(capsys, argv, needle):
    try:
        rc = main(["approach", "palm_push_two_feet", *argv])
    except SystemExit as exc:  # argparse's own usage errors exit (one line, status 2)
        rc = exc.code
    assert rc == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err and "Traceback" not in err


def test_a_video_loads_the_robots_meshes_and_picks_egl_first(monkeypatch, tmp_path, capsys):
    """The video's robot is drawn from its meshes (visual only), and MuJoCo's offscreen backend is
    chosen before anything imports MuJoCo (``MUJOCO_GL`` left as the user set it)."""
    from impact_balance.exceptions import SimulationError
    from impact_balance.sim.trials.setup import BalanceSetup

    seen = {}

    def spy(cls, *args, **kwargs):
        seen.update(kwargs)
        raise SimulationError("spy", None, "stopped before the trial")

    monkeypatch.setattr(BalanceSetup, "create", classmethod(spy))
    monkeypatch.setenv("MUJOCO_GL", "egl")
    assert (
        main(
            [
                "approach",
                "kick_one_foot",
                "--reference",
                "0.5",
                "--wall-distance",
                "0.15",
                "--video",
                str(tmp_path / "v.mp4"),
            ]
        )
        == 2
    )
    assert seen.get("meshes") is True and "spy" in capsys.readouterr().err
    assert main(["approach", "kick_one_foot", "--reference", "0.5"]) == 2
    assert seen.get("meshes") is False


def test_meshes_are_visual_only():
    from impact_balance.sim.trials.setup import BalanceSetup

    bare = BalanceSetup.create("kick_one_foot")
    drawn = BalanceSetup.create("kick_one_foot", meshes=True)
    assert drawn.sim.model.ngeom > bare.sim.model.ngeom
    extra = drawn.sim.model.geom_contype[
        drawn.sim.model.geom_group == drawn.sim.model.geom_group.max()
    ]
    assert (extra == 0).all() and drawn.sim.model.nv == bare.sim.model.nv


def test_the_contact_aware_governor_off_the_tick_stands_g1_and_leaves_no_process(capsys):
    """End to end: G1's governed approach with the contact-aware rates from a worker process and
    the velocity margin stands where the default governor lets it fall (docs/velocity_margin.md),
    and the worker is gone when the command returns."""
    from pathlib import Path

    out = run_json(
        capsys,
        "g1_two_feet",
        "--reference",
        "1",
        "--governor",
        "com",
        "--rigid-impact",
        "--contact-aware",
        "--contact-aware-async",
        "--velocity-margin",
        "0.022",
        "--wall-distance",
        "0.15",
    )
    assert out["contact_aware_async"] is True and out["velocity_margin"] == 0.022
    assert out["outcome"] != "fell" and out["speed_at_contact"] <= out["cap_at_contact"] * 1.003
    assert out["tick_us"]["count"] > 10

    def workers() -> list[str]:
        """This test process's worker children (other test runs on the machine have their own)."""
        found = []
        for proc in Path("/proc").glob("[0-9]*"):
            try:
                if b"impact_balance.governor.worker" not in (proc / "cmdline").read_bytes():
                    continue
                parent = int((proc / "stat").read_text().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):  # a process that ended while we looked
                continue
            if parent == os.getpid():
                found.append(proc.name)
        return found

    if Path("/proc/self/cmdline").exists():  # Linux: no worker process left behind
        assert workers() == []


def test_off_the_tick_needs_the_contact_aware_option(capsys):
    assert main(["approach", "g1_two_feet", "--reference", "1", "--contact-aware-async"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--contact-aware-async" in err
