"""The examples run, and say what an independent computation says."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

import impact_balance as ib
from tests.helpers.extras import needs_extra

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@needs_extra("logs")
def test_robot_log_example_finds_the_exit_of_the_area(tmp_path, capsys):
    """The synthetic log's forward speed grows linearly: it leaves the CoM velocity area at the
    first sample beyond the area's extent along x (from analyze, not from the log checker)."""
    example = _load("robot_log")
    assert example.main(["--out", str(tmp_path / "sway.csv")]) == 0
    out = capsys.readouterr().out
    scenario = ib.load_scenario("palm_push_two_feet")
    time, _, v = example.record(scenario)
    area = ib.analyze(scenario).areas.com_velocity_area
    exit_time = time[np.argmax(v[:, 0] > area.vertices[:, 0].max())]
    assert f"com_velocity outside its area from {exit_time:.3f} s to {time[-1]:.3f} s" in out
    worst = v[-1, 0] - area.vertices[:, 0].max()
    assert f"worst margin {-worst:.3f} m/s" in out


def test_governor_in_a_pink_loop_caps_the_speed_at_the_criterion(capsys):
    """The commanded approach speed is min(reference, the cap), the cap is the analysis' maximum at
    the start, and pink's IK tracks the commanded speed."""
    example = _load("governor_pink")
    fast = example.run("palm_push_two_feet", reference=0.8, ticks=80)
    start = ib.analyze("palm_push_two_feet").impact.max_contact_velocity
    assert fast["cap"][0] == np.float64(start) or abs(fast["cap"][0] - start) < 1e-9
    assert np.allclose(fast["commanded"], np.minimum(0.8, fast["cap"]), atol=1e-12)
    assert np.all(fast["commanded"] < 0.8)  # the cap binds: 0.48 m/s at most here
    assert abs(np.median(fast["measured"][40:]) - np.median(fast["commanded"][40:])) < 0.05
    slow = example.run("palm_push_two_feet", reference=0.2, ticks=40)
    assert np.allclose(slow["commanded"], 0.2)  # below the cap: the reference as it is
    assert example.main(["--ticks", "20"]) == 0
    assert "com governor" in capsys.readouterr().out


def _approach_checks(r: dict, reference: float) -> None:
    """The cap is a constraint of the QP: at every tick the commanded approach speed (the QP's
    -n . J v) and the speed the point travelled stay within 1 % of the cap, and at the wall they
    reach at least 95 % of it (the reference is higher)."""
    assert r["distance"][-1] <= 0.0  # the point reached the wall
    assert np.all(r["cap"] < reference)  # the cap binds
    assert np.all(r["commanded"] <= 1.01 * r["cap"])
    assert np.all(r["measured"] <= 1.01 * r["cap"])
    assert r["commanded"][-1] >= 0.95 * r["cap"][-1]
    assert r["measured"][-1] >= 0.95 * r["cap"][-1]


def test_pink_loop_with_the_cap_as_a_limit(capsys):
    example = _load("pink_limit")
    r = example.run("palm_push_two_feet", reference=1.5, wall=0.05, steps=100)
    _approach_checks(r, 1.5)
    start = ib.analyze("palm_push_two_feet").impact.max_contact_velocity
    assert abs(r["cap"][0] - start) < 1e-9  # the governor's answer at the scenario's state
    free = example.run("palm_push_two_feet", reference=1.5, wall=0.05, steps=100, limited=False)
    assert free["commanded"].max() > 1.5 * free["cap"].max()  # without the limit: no cap
    slow = example.run("palm_push_two_feet", reference=0.2, wall=0.05, steps=20)
    assert np.allclose(slow["commanded"], 0.2, atol=0.01)
    assert example.main(["--steps", "10"]) == 0
    assert "pink IK with the cap as a limit" in capsys.readouterr().out
    for bad in (["--steps", "0"], ["--reference", "nan"], ["--wall", "-1"]):
        with pytest.raises(SystemExit) as exit_:
            example.main(bad)
        assert exit_.value.code == 2 and bad[0] in capsys.readouterr().err


@needs_extra("sim")
def test_mink_loop_on_mujoco_with_the_cap_as_a_limit(capsys):
    pytest.importorskip("mink", reason="needs the mink extra (pip install 'impact-balance[mink]')")
    example = _load("mink_limit")
    r = example.run("palm_push_two_feet", reference=1.5, wall=0.05, steps=100)
    _approach_checks(r, 1.5)
    free = example.run("palm_push_two_feet", reference=1.5, wall=0.05, steps=100, limited=False)
    assert free["commanded"].max() > 1.5 * free["cap"].max()
    slow = example.run("palm_push_two_feet", reference=0.2, wall=0.05, steps=20)
    # Below the cap the limit is inactive: the task's speed (the posture task holds it back 3 %).
    assert np.allclose(slow["commanded"], 0.2, atol=0.01)
    assert np.all(slow["commanded"] < 0.9 * slow["cap"])
    assert example.main(["--steps", "10"]) == 0
    assert "mink IK (MuJoCo) with the cap as a limit" in capsys.readouterr().out
