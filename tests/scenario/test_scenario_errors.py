"""Bad scenario files: every mistake is a library exception naming the field and the value,
and ``impact-balance analyze FILE`` turns it into one line on stderr with exit status 2.

Infeasible but valid situations (a stance that cannot hold the robot, a CoM already falling,
an impact that cannot unbalance) are answers, not errors: exit 0 and a verdict.
"""

from __future__ import annotations

import copy
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import (
    ScenarioError,
    UnknownConfigurationError,
    UnknownFrameError,
    UnknownJointError,
    UnknownRobotError,
    UnknownScenarioError,
)
from impact_balance.scenario import bundled_scenarios, load_scenario
from tests.helpers.cli import assert_one_line_error, run_cli, strict_json

BASE = {
    "robot": "talos",
    "contacts": [
        {"frame": "left_sole_link", "friction": 0.7, "size": [0.2, 0.1]},
        {"frame": "right_sole_link", "friction": 0.7, "size": [0.2, 0.1]},
    ],
    "impact": {"frame": "gripper_right_base_link", "normal": [-1.0, 0.0, 0.0]},
}

DELETE = object()


def mutated(**changes) -> dict:
    """BASE with changes given as dotted paths (``contacts__0__friction=0``; DELETE removes)."""
    data = copy.deepcopy(BASE)
    for path, value in changes.items():
        keys = [int(k) if k.isdigit() else k for k in path.split("__")]
        node = data
        for k in keys[:-1]:
            node = node[k]
        if value is DELETE:
            del node[keys[-1]]
        else:
            node[keys[-1]] = value
    return data


def write(tmp_path: Path, data, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


@pytest.fixture(scope="module")
def base_analysis():
    """The unmutated BASE is valid and balanced (the control for every case below)."""
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        return analyze(write(Path(d), BASE))


def test_base_scenario_is_valid(base_analysis):
    assert base_analysis.verdict == "balanced"
    assert base_analysis.impact is not None
    assert 0 < base_analysis.impact.max_contact_velocity < math.inf


# -- bad fields: (mutation, exception class, field, value) ----------------------------------
CASES = {
    "unknown_robot": (mutated(robot="atlas"), UnknownRobotError, "robot", "atlas"),
    "unknown_contact_frame": (
        mutated(contacts__0__frame="left_sole"),
        UnknownFrameError,
        "contacts[0].frame",
        "left_sole",
    ),
    "unknown_impact_frame": (
        mutated(impact__frame="nope_link"),
        UnknownFrameError,
        "impact.frame",
        "nope_link",
    ),
    "unknown_configuration": (
        mutated(configuration="squat"),
        UnknownConfigurationError,
        "configuration",
        "squat",
    ),
    "unknown_joint": (
        mutated(joints={"knee_joint": 0.3}),
        UnknownJointError,
        "joints.knee_joint",
        "knee_joint",
    ),
    "joint_out_of_limits": (
        mutated(joints={"leg_left_4_joint": 5.0}),
        ScenarioError,
        "joints.leg_left_4_joint",
        5.0,
    ),
    "friction_zero": (mutated(contacts__0__friction=0), ScenarioError, "contacts[0].friction", 0),
    "friction_negative": (
        mutated(contacts__1__friction=-0.7),
        ScenarioError,
        "contacts[1].friction",
        -0.7,
    ),
    "size_zero": (
        mutated(contacts__0__size=[0.0, 0.1]),
        ScenarioError,
        "contacts[0].size",
        [0.0, 0.1],
    ),
    "size_negative": (
        mutated(contacts__1__size=[0.2, -0.1]),
        ScenarioError,
        "contacts[1].size",
        [0.2, -0.1],
    ),
    "size_three_entries": (
        mutated(contacts__0__size=[0.2, 0.1, 0.3]),
        ScenarioError,
        "contacts[0].size",
        [0.2, 0.1, 0.3],
    ),
    "restitution_above_one": (
        mutated(impact__restitution=[0.0, 1.5]),
        ScenarioError,
        "impact.restitution",
        [0.0, 1.5],
    ),
    "restitution_negative": (
        mutated(impact__restitution=[-0.1, 0.2]),
        ScenarioError,
        "impact.restitution",
        [-0.1, 0.2],
    ),
    "restitution_reversed": (
        mutated(impact__restitution=[0.3, 0.1]),
        ScenarioError,
        "impact.restitution",
        [0.3, 0.1],
    ),
    "zero_normal": (mutated(impact__normal=[0, 0, 0]), ScenarioError, "impact.normal", [0, 0, 0]),
    "no_contacts": (mutated(contacts=[]), ScenarioError, "contacts", []),
    "plane_height_above_com": (mutated(plane_height=5.0), ScenarioError, "plane_height", 5.0),
    "friction_not_a_number": (
        mutated(contacts__0__friction="abc"),
        ScenarioError,
        "contacts[0].friction",
        "abc",
    ),
    "contacts_not_a_list": (mutated(contacts=3), ScenarioError, "contacts", 3),
    "com_velocity_not_a_pair": (mutated(com_velocity="abc"), ScenarioError, "com_velocity", "abc"),
    "com_velocity_three_entries": (
        mutated(com_velocity=[1, 2, 3]),
        ScenarioError,
        "com_velocity",
        [1, 2, 3],
    ),
    "unknown_key": (mutated(plane_hieght=0.0), ScenarioError, "plane_hieght", 0.0),
    "cone_edges_two": (mutated(impact__cone_edges=2), ScenarioError, "impact.cone_edges", 2),
    "duration_zero": (mutated(impact__duration=0), ScenarioError, "impact.duration", 0),
    "duration_negative": (
        mutated(impact__duration=-0.005),
        ScenarioError,
        "impact.duration",
        -0.005,
    ),
    "gravity_zero": (mutated(gravity=0), ScenarioError, "gravity", 0),
    "inertia_unknown": (
        mutated(impact__inertia="lumped"),
        ScenarioError,
        "impact.inertia",
        "lumped",
    ),
    "joint_value_not_a_number": (
        mutated(joints={"leg_left_4_joint": "bent"}),
        ScenarioError,
        "joints.leg_left_4_joint",
        "bent",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_bad_field_raises_and_names_it(tmp_path, case):
    data, cls, field, value = CASES[case]
    path = write(tmp_path, data)
    with pytest.raises(cls) as info:
        analyze(path)
    exc = info.value
    assert isinstance(exc, ScenarioError)
    assert exc.field == field
    assert exc.value == value
    assert f"{field} = {value!r}" in str(exc)


@pytest.mark.parametrize("case", list(CASES))
def test_bad_field_cli_one_line_exit_2(tmp_path, capsys, case):
    data, _, field, value = CASES[case]
    path = write(tmp_path, data)
    rc, out, err = run_cli(capsys, "analyze", str(path))
    assert out == ""
    assert_one_line_error(rc, err, field, str(value))


# -- details of the unknown-name errors -------------------------------------------------------
def test_unknown_robot_lists_valid_robots(tmp_path):
    with pytest.raises(UnknownRobotError) as info:
        analyze(write(tmp_path, mutated(robot="atlas")))
    assert {"talos", "g1"} <= set(info.value.valid)
    assert "talos" in str(info.value) and "g1" in str(info.value)


def test_unknown_contact_frame_lists_valid_frames(tmp_path):
    with pytest.raises(UnknownFrameError) as info:
        analyze(write(tmp_path, mutated(contacts__0__frame="left_sole")))
    assert "left_sole_link" in info.value.valid
    assert "left_sole_link" in str(info.value)
    assert "did you mean left_sole_link" in str(info.value)  # close match offered first


def test_unknown_impact_frame_lists_valid_frames(tmp_path):
    with pytest.raises(UnknownFrameError) as info:
        analyze(write(tmp_path, mutated(impact__frame="nope_link")))
    assert "gripper_right_base_link" in info.value.valid


def test_unknown_configuration_lists_valid_ones(tmp_path):
    with pytest.raises(UnknownConfigurationError) as info:
        analyze(write(tmp_path, mutated(configuration="squat")))
    assert "half_sitting" in info.value.valid
    assert "half_sitting" in str(info.value)


def test_unknown_joint_lists_valid_joints(tmp_path):
    with pytest.raises(UnknownJointError) as info:
        analyze(write(tmp_path, mutated(joints={"knee_joint": 0.3})))
    assert "leg_left_4_joint" in info.value.valid
    # 32 names are too many for one line: a count and the command that lists them all.
    assert "32 valid joints" in str(info.value) and "impact-balance frames talos" in str(info.value)


def test_joint_out_of_limits_gives_the_limits(tmp_path):
    with pytest.raises(ScenarioError) as info:
        analyze(write(tmp_path, mutated(joints={"leg_left_4_joint": 5.0})))
    assert "limit" in info.value.reason


def test_plane_height_at_the_com_is_refused(tmp_path, base_analysis):
    com_z = float(base_analysis.stance.com[2])
    with pytest.raises(ScenarioError) as info:
        analyze(write(tmp_path, mutated(plane_height=com_z)))
    assert info.value.field == "plane_height"
    assert info.value.value == com_z
    assert "CoM" in info.value.reason


# -- cases where the library's current message misleads (see the lead's report) ---------------
def test_missing_contacts_names_the_key_not_the_whole_file(tmp_path, capsys):
    path = write(tmp_path, mutated(contacts=DELETE))
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    exc = info.value
    assert exc.field == "contacts"
    assert "missing" in exc.reason
    # A missing key has no value: the containing mapping (with internal keys) is not it.
    assert not isinstance(exc.value, dict), f"value is the whole mapping: {exc.value!r}"
    rc, _, err = run_cli(capsys, "analyze", str(path))
    line = assert_one_line_error(rc, err, "contacts", "missing")
    assert "'source'" not in line and "'impact'" not in line, line


def test_typo_key_is_reported_as_unknown_key(tmp_path, capsys):
    """`contact:` for `contacts:` -- the typo is the cause, not the missing `contacts`."""
    data = mutated()
    data["contact"] = data.pop("contacts")
    path = write(tmp_path, data)
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    assert info.value.field == "contact"
    assert info.value.value == BASE["contacts"]
    assert "unknown key" in info.value.reason
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, "contact =", "unknown key")


def test_nested_typo_key_is_reported_as_unknown_key(tmp_path):
    data = mutated()
    data["contacts"][0]["frictoin"] = data["contacts"][0].pop("friction")
    with pytest.raises(ScenarioError) as info:
        analyze(write(tmp_path, data))
    assert info.value.field == "contacts[0].frictoin"
    assert info.value.value == 0.7
    assert "unknown key" in info.value.reason


def test_com_velocity_with_one_entry(tmp_path, capsys):
    path = write(tmp_path, mutated(com_velocity=[1]))
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    exc = info.value
    assert exc.field.startswith("com_velocity")
    assert exc.value == [1]
    # A pair with one entry is a wrong length, not a "missing required key".
    assert "key" not in exc.reason, exc.reason
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, "com_velocity", "[1]")


# -- file-level problems -----------------------------------------------------------------------
def test_not_yaml(tmp_path, capsys):
    path = write(tmp_path, "a: [1, 2\n")
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    assert info.value.field == "scenario"
    assert info.value.value == str(path)
    assert "YAML" in info.value.reason
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, str(path), "YAML")


def test_yaml_list_not_mapping(tmp_path, capsys):
    path = write(tmp_path, "- 1\n- 2\n")
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    assert info.value.field == "scenario"
    assert info.value.value == str(path)
    assert "mapping" in info.value.reason
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, str(path), "mapping")


def test_empty_file(tmp_path, capsys):
    path = write(tmp_path, "")
    with pytest.raises(ScenarioError) as info:
        analyze(path)
    assert info.value.value == str(path)
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, str(path))


def test_missing_file_says_so(tmp_path, capsys):
    path = tmp_path / "does_not_exist.yaml"
    with pytest.raises(ScenarioError) as info:
        analyze(str(path))
    assert info.value.field == "scenario"
    assert info.value.value == str(path)
    rc, _, err = run_cli(capsys, "analyze", str(path))
    line = assert_one_line_error(rc, err, str(path))
    # A path that does not exist should be reported as such, not only as an unknown bundled name.
    assert any(s in line.lower() for s in ("no such file", "not found", "does not exist")), line


def test_unknown_bundled_name_lists_bundled_names(capsys):
    with pytest.raises(UnknownScenarioError) as info:
        analyze("no_such_scenario")
    assert info.value.field == "scenario"
    assert info.value.value == "no_such_scenario"
    assert set(bundled_scenarios()) <= set(info.value.valid)
    rc, _, err = run_cli(capsys, "analyze", "no_such_scenario")
    # More bundled scenarios than a line lists: the line says where the list is.
    assert_one_line_error(rc, err, "no_such_scenario", "`impact-balance scenarios` lists them")


def test_extends_unknown_name_names_extends(tmp_path, capsys):
    path = write(tmp_path, mutated(extends="no_such_scenario"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.field == "extends"
    assert info.value.value == "no_such_scenario"
    rc, _, err = run_cli(capsys, "analyze", str(path))
    assert_one_line_error(rc, err, "extends", "no_such_scenario")


def test_extends_bundled_name_works(tmp_path):
    """Control for the case above: a valid ``extends`` merges mappings."""
    path = write(tmp_path, {"extends": "palm_push_two_feet", "impact": {"friction": 0.1}})
    sc = load_scenario(path)
    assert sc.impact.friction == 0.1
    assert sc.impact.frame == "gripper_right_base_link"


# -- real processes: exit status and no traceback ----------------------------------------------
@pytest.mark.parametrize(
    "case",
    [
        "unknown_contact_frame",
        "friction_zero",
        "size_three_entries",
        "plane_height_above_com",
        "unknown_robot",
    ],
)
def test_subprocess_exit_2_no_traceback(tmp_path, case):
    data, _, field, value = CASES[case]
    path = write(tmp_path, data)
    proc = subprocess.run(
        [sys.executable, "-m", "impact_balance", "analyze", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.stdout == ""
    assert_one_line_error(proc.returncode, proc.stderr, field, str(value))


def test_subprocess_not_yaml_exit_2(tmp_path):
    path = write(tmp_path, "a: [1, 2\n")
    proc = subprocess.run(
        [sys.executable, "-m", "impact_balance", "analyze", str(path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert_one_line_error(proc.returncode, proc.stderr, str(path))


# -- infeasible but valid: answers, not errors -------------------------------------------------
INFEASIBLE = {
    # One sole contact moved 1 m ahead of the foot, low friction: the CoM is far outside.
    "far_contact": [
        {
            "frame": "left_sole_link",
            "friction": 0.1,
            "size": [0.2, 0.1],
            "offset": {"position": [1.0, 0.0, 0.0]},
        }
    ],
    # The left hand alone, slippery.
    "hand_only": [{"frame": "gripper_left_base_link", "friction": 0.05, "size": [0.05, 0.05]}],
}


@pytest.mark.parametrize("case", list(INFEASIBLE))
def test_cannot_balance_is_an_answer(tmp_path, capsys, case):
    path = write(tmp_path, mutated(contacts=INFEASIBLE[case]))
    a = analyze(path)
    assert a.verdict.startswith("cannot balance")
    d = a.to_dict()
    assert d["can_balance"] is False
    assert d["com_velocity_inside"] is False
    assert d["impact"]["max_contact_velocity"] == 0
    assert d["impact"]["status"] == "cannot_balance"

    rc, out, err = run_cli(capsys, "analyze", str(path), "--json")
    assert rc == 0 and err == ""
    j = strict_json(out)
    assert j["can_balance"] is False
    assert j["verdict"].startswith("cannot balance")
    assert j["impact"]["max_contact_velocity"] == 0

    rc, out, err = run_cli(capsys, "analyze", str(path))
    assert rc == 0 and err == ""
    assert "CANNOT BALANCE" in out


def test_already_falling_is_an_answer(tmp_path, capsys):
    path = write(tmp_path, mutated(com_velocity=[3.0, 0.0]))
    a = analyze(path)
    assert a.verdict.startswith("falling")
    assert a.areas.can_balance
    assert a.impact.max_contact_velocity == 0
    assert a.impact.com.status == "already_falling"

    rc, out, err = run_cli(capsys, "analyze", str(path), "--json")
    assert rc == 0 and err == ""
    j = strict_json(out)
    assert j["can_balance"] is True
    assert j["com_velocity_inside"] is False
    assert j["verdict"].startswith("falling")
    assert j["impact"]["status"] == "already_falling"
    assert j["impact"]["max_contact_velocity"] == 0

    rc, out, _ = run_cli(capsys, "analyze", str(path))
    assert rc == 0 and "falling" in out


@pytest.mark.parametrize("normal", [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0]])
def test_frictionless_vertical_impact_is_unbounded(tmp_path, capsys, normal):
    """Friction 0 and a vertical normal: the impulse is vertical, the planar CoM jump zero."""
    data = mutated(impact={"frame": "gripper_left_base_link", "normal": normal, "friction": 0.0})
    path = write(tmp_path, data)
    a = analyze(path)
    assert a.verdict == "balanced"
    assert a.impact.max_contact_velocity == math.inf
    assert a.impact.com.status == "unbounded"
    np.testing.assert_allclose(a.impact.model.com_jump_rates, 0.0, atol=1e-12)

    rc, out, err = run_cli(capsys, "analyze", str(path), "--json")
    assert rc == 0 and err == ""
    j = strict_json(out)  # no Infinity in the JSON
    assert j["impact"]["max_contact_velocity"] is None
    assert j["impact"]["status"] == "unbounded"
    np.testing.assert_allclose(j["impact"]["post_impact_com_velocities"], 0.0, atol=1e-12)

    rc, out, _ = run_cli(capsys, "analyze", str(path))
    assert rc == 0 and "unbounded" in out
