"""Robot files are read strictly: what urdfdom drops or accepts absurd is refused, naming the
file, the link or joint and the field; what the project repairs by its documented rule (a
massless link, a point mass, a zero axis on a fixed joint) still loads.

Each hostile URDF is the bundled G1 with one field corrupted, beside the unmodified copy.
"""

from __future__ import annotations

import math
import os
import re
import threading
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import RobotLoadError
from impact_balance.robot.robot import BUNDLED_ROBOTS, example_robot_data_root, load_robot
from impact_balance.robot.urdf_check import (
    MAX_LINK_MASS,
    check_urdf,
    read_robot_file,
)
from tests.helpers.cli import run_cli

G1 = example_robot_data_root() / BUNDLED_ROBOTS["g1"].urdf
G1_TEXT = G1.read_text()
G1_MASS = 33.34114202


def corrupt(pattern: str, value: str, text: str = G1_TEXT) -> str:
    """``text`` with the first group of the first match of ``pattern`` replaced by ``value``."""
    match = re.search(pattern, text, re.DOTALL)
    assert match is not None, pattern
    return text[: match.start(1)] + value + text[match.end(1) :]


def write(tmp_path: Path, text: str, name: str = "robot.urdf") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


PELVIS = r'<link name="pelvis">.*?'
HIP_JOINT = r'<joint name="left_hip_pitch_joint" type="revolute">.*?'


def test_the_unmodified_copy_loads_with_its_full_mass(tmp_path):
    robot = load_robot(urdf=write(tmp_path, G1_TEXT))
    assert math.isclose(robot.mass, G1_MASS, rel_tol=1e-12)


@pytest.mark.parametrize(
    "pattern, value, where, needle",
    [
        (PELVIS + r'<mass value="([^"]+)"', "nan", "link 'pelvis'", "mass = 'nan'"),
        (PELVIS + r'<mass value="([^"]+)"', "inf", "link 'pelvis'", "not a finite number"),
        (PELVIS + r'<mass value="([^"]+)"', "abc", "link 'pelvis'", "not a decimal number"),
        (PELVIS + r'<mass value="([^"]+)"', "0x10", "link 'pelvis'", "not a decimal number"),
        (PELVIS + r'<mass value="([^"]+)"', "-1", "link 'pelvis'", "outside [0, "),
        (PELVIS + r'<mass value="([^"]+)"', "1e308", "link 'pelvis'", "outside [0, "),
        (PELVIS + r'<mass value="([^"]+)"', "1e999", "link 'pelvis'", "out of range"),
        (PELVIS + r'ixx="([^"]+)"', "nan", "link 'pelvis'", "inertia ixx"),
        (PELVIS + r'ixx="([^"]+)"', "1e308", "link 'pelvis'", "inertia ixx"),
        (PELVIS + r'ixx="([^"]+)"', "-5", "link 'pelvis'", "negative principal moment"),
        (PELVIS + r'izz="([^"]+)"', "100", "link 'pelvis'", "triangle inequality"),
        (PELVIS + r'<origin xyz="([^"]+)"', "0 nan 0", "link 'pelvis' <inertial>", "origin xyz"),
        (PELVIS + r'<origin xyz="([^"]+)"', "0 0 1e9", "link 'pelvis' <inertial>", "farther"),
        (PELVIS + r'rpy="([^"]+)"', "0 inf 0", "link 'pelvis'", "origin rpy"),
        (HIP_JOINT + r'<axis xyz="([^"]+)"', "0 0 0", "joint 'left_hip_pitch_joint'", "zero axis"),
        (HIP_JOINT + r'<axis xyz="([^"]+)"', "nan 1 0", "joint 'left_hip_pitch_joint'", "axis"),
        (HIP_JOINT + r'<origin xyz="([^"]+)"', "0 nan 0", "joint 'left_hip_pitch_joint'", "xyz"),
        (HIP_JOINT + r'lower="([^"]+)"', "nan", "joint 'left_hip_pitch_joint'", "limit lower"),
    ],
)
def test_a_corrupted_field_is_refused_naming_file_element_and_field(
    tmp_path, pattern, value, where, needle
):
    path = write(tmp_path, corrupt(pattern, value))
    with pytest.raises(RobotLoadError) as caught:
        load_robot(urdf=path)
    message = str(caught.value)
    assert str(path) in message and where in message and needle in message, message


def test_a_value_urdfdom_refuses_is_an_error_not_a_massless_link(tmp_path):
    # " 3.5 " is a number to Python, not to urdfdom: it skipped the inertial (pelvis massless).
    path = write(tmp_path, corrupt(PELVIS + r'<mass value="([^"]+)"', " 3.5 "))
    with pytest.raises(RobotLoadError, match="urdfdom refused") as caught:
        load_robot(urdf=path)
    assert str(path) in str(caught.value) and "pelvis" in str(caught.value)


def test_the_cli_names_the_robot_file_in_one_line_exit_2(tmp_path, capsys):
    path = write(tmp_path, corrupt(PELVIS + r'<mass value="([^"]+)"', "nan"))
    rc, out, err = run_cli(capsys, "frames", str(path))
    assert rc == 2 and out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in err
    assert str(path) in lines[0] and "link 'pelvis'" in lines[0] and "mass" in lines[0]
    # control: the unmodified copy lists its frames
    assert run_cli(capsys, "frames", str(write(tmp_path, G1_TEXT, "g1.urdf")))[0] == 0


def test_what_the_documented_repair_covers_still_loads(tmp_path):
    # A massless link (Romeo's fingers), a point mass (iCub's ankles) and a zero axis on a
    # fixed joint load as they are.
    text = corrupt(PELVIS + r'<mass value="([^"]+)"', "0")
    text = corrupt(
        PELVIS + r"(<inertia [^/]*)/>",
        '<inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"',
        text,
    )
    text = corrupt(
        r'(<joint name="pelvis_contour_joint" type="fixed">)',
        '<joint name="pelvis_contour_joint" type="fixed"><axis xyz="0 0 0"/>',
        text,
    )
    robot = load_robot(urdf=write(tmp_path, text))
    assert math.isclose(robot.mass, G1_MASS - 3.813, rel_tol=1e-9)


@pytest.mark.parametrize("name", sorted(BUNDLED_ROBOTS))
def test_bundled_robots_pass_the_check(name):
    data = read_robot_file(example_robot_data_root() / BUNDLED_ROBOTS[name].urdf)
    masses = check_urdf(data, name).masses
    assert math.isclose(sum(masses.values()), load_robot(name).mass, rel_tol=1e-9)


def test_xml_entities_are_refused_never_expanded(tmp_path):
    bomb = (
        '<?xml version="1.0"?>\n<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa">'
        '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;">]>\n<robot name="&b;"><link name="x"/></robot>'
    )
    with pytest.raises(RobotLoadError, match="entit"):
        load_robot(urdf=write(tmp_path, bomb))


def test_not_xml_and_wrong_root_are_refused(tmp_path):
    with pytest.raises(RobotLoadError, match="not valid XML"):
        load_robot(urdf=write(tmp_path, "<robot><link></robot>", "a.urdf"))
    with pytest.raises(RobotLoadError, match="not <robot>"):
        load_robot(urdf=write(tmp_path, "<sdf/>", "b.urdf"))


def test_a_fifo_is_refused_without_waiting(tmp_path):
    fifo = tmp_path / "robot.urdf"
    os.mkfifo(fifo)
    done: list[BaseException] = []

    def load() -> None:
        try:
            load_robot(urdf=fifo)
        except BaseException as exc:
            done.append(exc)

    thread = threading.Thread(target=load, daemon=True)
    thread.start()
    thread.join(10)
    assert not thread.is_alive(), "load_robot blocked on a FIFO"
    assert isinstance(done[0], RobotLoadError) and "not a regular file" in str(done[0])


def test_a_file_over_the_byte_bound_is_refused(tmp_path):
    path = write(tmp_path, G1_TEXT)
    with pytest.raises(RobotLoadError, match="larger than 1000 bytes"):
        read_robot_file(path, max_bytes=1000)
    assert read_robot_file(path) == G1_TEXT.encode()


LINK = (
    '<link name="{name}"><inertial><origin xyz="{x} 0 0" rpy="0 0 0"/><mass value="{m}"/>'
    '<inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial></link>'
)


@settings(max_examples=60, deadline=None)
@given(
    field=st.sampled_from(["m", "i", "x"]),
    bad=st.sampled_from(["nan", "-nan", "inf", "-inf", "NaN", "1e400", "--1", "1e", "", "1.0.0"])
    | st.floats(min_value=MAX_LINK_MASS * 1.01, max_value=1e300).map(repr),
    index=st.integers(0, 3),
)
def test_any_non_finite_or_absurd_number_in_any_link_is_refused(field, bad, index):
    values = [{"name": f"l{k}", "m": "1.0", "i": "0.01", "x": "0.1"} for k in range(4)]
    values[index][field] = bad
    joints = "".join(
        f'<joint name="j{k}" type="revolute"><parent link="l{k - 1}"/><child link="l{k}"/>'
        f'<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>'
        for k in range(1, 4)
    )
    text = "<robot name='r'>" + "".join(LINK.format(**v) for v in values) + joints + "</robot>"
    with pytest.raises(RobotLoadError) as caught:
        check_urdf(text.encode(), "r.urdf")
    assert f"link 'l{index}'" in str(caught.value) and "r.urdf" in str(caught.value)
    values[index][field] = "0.5"  # control: a good number there is accepted
    text = "<robot name='r'>" + "".join(LINK.format(**v) for v in values) + joints + "</robot>"
    assert check_urdf(text.encode(), "r.urdf").masses[f"l{index}"] > 0.0


TALOS = BUNDLED_ROBOTS["talos"]
TALOS_SRDF = (example_robot_data_root() / str(TALOS.srdf)).read_text()
KNEE = r'<group_state name="half_sitting".*?<joint name="leg_left_4_joint" value="([^"]+)"'
ROTOR = r'<rotor_params>.*?gear_ratio="([^"]+)"'


@pytest.mark.parametrize(
    "pattern, value, needle",
    [
        (KNEE, "nan", "group_state 'half_sitting' joint 'leg_left_4_joint'"),
        (KNEE, "abc", "not a decimal number"),  # pinocchio read it as 0: the knee straight
        (ROTOR, "-100", "negative"),
        (ROTOR, "inf", "not a finite number"),
    ],
)
def test_a_corrupted_srdf_value_is_refused(tmp_path, pattern, value, needle):
    urdf = example_robot_data_root() / TALOS.urdf
    srdf = write(tmp_path, corrupt(pattern, value, TALOS_SRDF), "talos.srdf")
    with pytest.raises(RobotLoadError) as caught:
        load_robot(urdf=urdf, srdf=srdf)
    assert str(srdf) in str(caught.value) and needle in str(caught.value), str(caught.value)
    # control: the unmodified copy gives the knee its half-sitting angle
    good = write(tmp_path, TALOS_SRDF, "good.srdf")
    knee = load_robot(urdf=urdf, srdf=good).configuration()[
        load_robot("talos").joint_slot("leg_left_4_joint").idx_q
    ]
    assert knee > 0.5
