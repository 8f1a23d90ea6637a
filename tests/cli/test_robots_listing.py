"""``impact-balance robots [--all]`` and ``frames NAME`` for robots by name."""

from __future__ import annotations

import re
import time

from impact_balance.robot.robot import EXAMPLE_ROBOTS, robot_names
from tests.helpers.cli import run_cli as run


def test_robots_all_lists_go2_with_its_mass_feet_and_standing(capsys):
    start = time.perf_counter()
    rc, out, err = run(capsys, "robots", "--all")
    assert time.perf_counter() - start < 5.0
    assert rc == 0 and err == ""
    lines = out.splitlines()
    assert lines[0].split()[:3] == ["robot", "mass", "standing"]
    rows = {line.split()[0]: line for line in lines[1:]}
    assert set(rows) == set(robot_names())
    assert re.search(
        r"^go2\s+16\.09 kg\s+standing\s+FL_foot, FR_foot, RL_foot, RR_foot\s+unknown", rows["go2"]
    )
    assert re.search(
        r"^talos\s+90\.27 kg\s+half_sitting\s+left_sole_link, right_sole_link\s+0\.211 x 0\.124 m",
        rows["talos"],
    )
    assert re.search(r"^quadruped\s+2\.77 kg\s+neutral\s+unknown\s+unknown", rows["quadruped"])


def test_robots_without_all_lists_the_bundled_and_says_how_to_see_the_rest(capsys):
    rc, out, err = run(capsys, "robots")
    assert rc == 0 and err == ""
    assert "go2" not in out.split()
    assert f"{len(EXAMPLE_ROBOTS)} more by name" in out and "robots --all" in out


def test_frames_takes_a_robot_by_name(capsys):
    rc, out, err = run(capsys, "frames", "go2", "--frame", "FL_foot")
    assert rc == 0 and err == ""
    assert out.startswith("go2:") and "configuration standing" in out
    assert re.search(r"^\s+FL_foot\s+BODY", out, re.M)
