"""The examples run, and say what an independent computation says."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

import impact_balance as ib

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _load(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


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
