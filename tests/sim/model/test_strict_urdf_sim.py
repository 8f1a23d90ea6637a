"""The simulation's URDF -> MuJoCo path applies the robot layer's strict check: a robot file
edited after pinocchio loaded it, or a specification with a non-finite inertial, is refused with
the file named; the intact file still builds."""

from __future__ import annotations

import re

import numpy as np
import pytest

pytest.importorskip("mujoco")

from impact_balance.exceptions import RobotLoadError
from impact_balance.robot.robot import BUNDLED_ROBOTS, example_robot_data_root, load_robot
from impact_balance.sim.model.inertia import repair_inertias
from impact_balance.sim.model.urdf import robot_spec

G1 = example_robot_data_root() / BUNDLED_ROBOTS["g1"].urdf


@pytest.fixture
def copied(tmp_path):
    path = tmp_path / "g1.urdf"
    path.write_text(G1.read_text())
    return path, load_robot(urdf=path)


def test_the_intact_copy_builds(copied):
    _, robot = copied
    spec, _ = robot_spec(robot, meshes=False)
    assert spec.compile().nbody > 20


@pytest.mark.parametrize(
    "pattern, value, needle",
    [
        (r'<link name="pelvis">.*?<mass value="([^"]+)"', "nan", "mass"),
        (r'<link name="pelvis">.*?ixx="([^"]+)"', "-5", "negative principal moment"),
        (r'type="revolute">.*?<axis xyz="([^"]+)"', "0 0 0", "zero axis"),
    ],
)
def test_a_file_corrupted_after_loading_is_refused(copied, pattern, value, needle):
    path, robot = copied
    text = path.read_text()
    match = re.search(pattern, text, re.DOTALL)
    assert match is not None
    path.write_text(text[: match.start(1)] + value + text[match.end(1) :])
    with pytest.raises(RobotLoadError) as caught:
        robot_spec(robot, meshes=False)
    assert str(path) in str(caught.value) and needle in str(caught.value)


def test_a_non_finite_inertial_is_never_repaired(copied):
    _, robot = copied
    spec, _ = robot_spec(robot, meshes=False)
    body = next(b for b in spec.bodies if b.name == "pelvis")
    body.mass = float("nan")
    with pytest.raises(RobotLoadError, match="pelvis"):
        repair_inertias(spec, robot)
    body.mass = 3.813
    body.inertia = np.array([np.inf, 1.0, 1.0])
    body.fullinertia = [np.nan, 0, 0, 0, 0, 0]
    with pytest.raises(RobotLoadError, match="not finite"):
        repair_inertias(spec, robot)
