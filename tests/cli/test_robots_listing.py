"""``impact-balance robots [--all]`` and ``frames NAME`` for robots by name."""

from __future__ import annotations

import re
import time

from impact_balance.cli.listing import KNOWN_SOLES, POINT_SOLE, robot_rows
from impact_balance.robot.robot import EXAMPLE_ROBOTS, load_robot, robot_names
from tests.helpers.cli import run_cli as run
from tests.helpers.quadrupeds import FEET


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
        r"^go2\s+16\.09 kg\s+standing\s+FL_foot, FR_foot, RL_foot, RR_foot\s+point\s", rows["go2"]
    )
    assert re.search(
        r"^talos\s+90\.27 kg\s+half_sitting\s+left_sole_link, right_sole_link\s+0\.211 x 0\.124 m",
        rows["talos"],
    )
    assert re.search(r"^quadruped\s+2\.77 kg\s+neutral\s+unknown\s+unknown", rows["quadruped"])
    assert re.search(
        r"^jvrc1\s+62\.40 kg\s+neutral\s+l_ankle, r_ankle\s+0\.225 x 0\.084 m", rows["jvrc1"]
    )


def _leg_dofs(name: str, frame: str) -> int:
    """Velocity dimension of the joints supporting ``frame``, the floating base's 6 left out."""
    model = load_robot(name).model
    joint = model.frames[model.getFrameId(frame)].parentJoint
    return sum(model.joints[j].nv for j in model.supports[joint]) - 6


def test_robots_all_says_point_exactly_where_every_foot_hangs_on_fewer_than_6_joints():
    rows = {row[0]: row for row in robot_rows()}
    points = {name for name, row in rows.items() if row[4] == POINT_SOLE}
    assert set(FEET) <= points  # the quadrupeds the tests stand on point feet
    assert not points & set(KNOWN_SOLES)  # a measured sole is never a point
    for name, row in rows.items():
        feet = [] if row[3] == "unknown" else row[3].split(", ")
        expected = bool(feet) and all(_leg_dofs(name, foot) < 6 for foot in feet)
        assert (name in points) == expected, (name, row[3], row[4])
        if name not in points and name not in KNOWN_SOLES:
            assert row[4] == "unknown", row  # nothing guessed (alexander, human: 6-joint legs)


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
