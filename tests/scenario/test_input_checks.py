"""Hostile and mistaken scenario input: bounded reading, bounded messages, quiet pipes, strict
JSON on a clean stdout, physical ranges, warnings and ``--strict``, nearest-key suggestions,
``impact-balance frames`` and ``--version``.

Each refusal is checked beside a control
that is accepted.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import pinocchio as pin
import pytest
import yaml

from impact_balance import cli
from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import (
    MESSAGE_CHARS,
    RobotLoadError,
    ScenarioError,
    SolverError,
    StrictWarningsError,
    UnknownFrameError,
    UnknownKeyError,
    short_repr,
)
from impact_balance.robot.robot import load_robot
from impact_balance.scenario import load_scenario, scenario_from_dict
from impact_balance.scenario.reader import MAX_BYTES, MAX_DEPTH, MAX_VALUES, parse_yaml
from tests.helpers.cli import assert_one_line_error, run_cli, run_process, strict_json
from tests.helpers.extras import needs_extra

TWO_FEET = {
    "robot": "talos",
    "contacts": [
        {"frame": "left_sole_link", "friction": 0.7, "size": [0.2, 0.1]},
        {"frame": "right_sole_link", "friction": 0.7, "size": [0.2, 0.1]},
    ],
}


def write(tmp_path: Path, data, name: str = "scenario.yaml") -> Path:
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return path


def one_error_line(rc: int, out: str, err: str) -> str:
    assert out == "", out[:200]
    return assert_one_line_error(rc, err)


def without_compile_notice(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if "compiling the projection kernel" not in line]


# -- bounded parse -------------------------------------------------------------------------
def alias_tree(fan: int, levels: int) -> str:
    lines = [f"l0: &l0 [{', '.join(['x'] * fan)}]"]
    lines += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * fan)}]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


def test_alias_bomb_is_refused_in_milliseconds(tmp_path):
    # 9**9 strings from ~400 bytes, as the value of the first field validated (`name`)
    text = "impact:\n" + "".join(
        f"  - {line.split(': ', 1)[1]}\n" for line in alias_tree(9, 9).splitlines()
    )
    text += "name: *l8\ncontacts: []\n"
    start = time.perf_counter()
    with pytest.raises(ScenarioError) as info:
        load_scenario(write(tmp_path, text))
    assert time.perf_counter() - start < 1.0
    assert f"expands to more than {MAX_VALUES} values" in str(info.value)
    assert len(str(info.value)) <= MESSAGE_CHARS


def test_small_alias_use_is_accepted(tmp_path):
    """Control: anchors and merge keys that expand to a few values are ordinary YAML."""
    text = (
        "robot: talos\nx-contact: &c {friction: 0.7, size: [0.2, 0.1]}\n"
        "contacts: [{<<: *c, frame: left_sole_link}, {<<: *c, frame: right_sole_link}]\n"
    )
    raw = parse_yaml(text)
    raw.pop("x-contact")
    scenario = scenario_from_dict(raw)
    assert [c.friction for c in scenario.contacts] == [0.7, 0.7]


def test_expanded_size_counts_aliases_as_copies():
    """100 aliases of a 1000-item list are 100 000 values: refused; 90 of them are not."""
    item = "[" + ", ".join(["1"] * 999) + "]"
    accepted = parse_yaml(f"a: &a {item}\nb: [{', '.join(['*a'] * 90)}]\n")
    assert len(accepted["b"]) == 90
    with pytest.raises(ScenarioError, match="expands to more than"):
        parse_yaml(f"a: &a {item}\nb: [{', '.join(['*a'] * 101)}]\n")


def test_recursive_alias_is_refused():
    with pytest.raises(ScenarioError, match="cycle"):
        parse_yaml("a: &a [1, *a]\n")


@pytest.mark.parametrize("style", ["flow", "block"])
def test_deep_nesting_is_refused_without_recursion_error(tmp_path, capsys, style):
    depth = 600
    if style == "flow":
        text = "contacts: " + "[" * depth + "]" * depth + "\n"
    else:
        text = "".join(f"{'  ' * i}k{i}:\n" for i in range(depth)) + f"{'  ' * depth}v: 1\n"
    line = one_error_line(*run_cli(capsys, "analyze", str(write(tmp_path, text))))
    assert f"nested deeper than {MAX_DEPTH} levels" in line


def test_nesting_at_the_limit_is_parsed():
    text = "a: " + "[" * (MAX_DEPTH - 1) + "]" * (MAX_DEPTH - 1) + "\n"
    assert parse_yaml(text)["a"] is not None


def test_deep_mapping_given_directly_is_refused():
    """The GUI and the library pass mappings, not YAML: the same limit applies."""
    deep: object = 1.0
    for _ in range(2000):
        deep = [deep]
    with pytest.raises(ScenarioError, match="nested deeper"):
        scenario_from_dict({**TWO_FEET, "com_velocity": deep})
    cyclic: list = [1.0]
    cyclic.append(cyclic)
    with pytest.raises(ScenarioError, match="cycle"):
        scenario_from_dict({**TWO_FEET, "com_velocity": cyclic})


def test_file_size_limit(tmp_path):
    big = tmp_path / "big.yaml"
    big.write_text("# " + "x" * MAX_BYTES + "\n" + yaml.safe_dump(TWO_FEET))
    with pytest.raises(ScenarioError, match="larger than"):
        load_scenario(big)
    assert load_scenario(write(tmp_path, TWO_FEET)).contacts  # control


@pytest.mark.parametrize("where", ["argument", "extends", "urdf"])
def test_names_longer_than_the_file_system_allows_are_clear_errors(tmp_path, capsys, where):
    long = "n" * 300
    if where == "argument":
        argv = ["analyze", long]
    elif where == "extends":
        argv = ["analyze", str(write(tmp_path, f"extends: {long}\n"))]
    else:
        argv = ["analyze", str(write(tmp_path, {**TWO_FEET, "robot": {"urdf": long + ".urdf"}}))]
    line = one_error_line(*run_cli(capsys, *argv))
    assert "at most 255 characters" in line and "this one has 30" in line
    assert len(line) < 400


def test_nul_in_a_name_is_a_clear_error(capsys):
    line = one_error_line(*run_cli(capsys, "analyze", "bad\x00name"))
    assert "NUL" in line


def test_extends_chain_limit(tmp_path):
    for i in range(20):
        write(
            tmp_path,
            f"extends: c{i + 1}.yaml\n" if i < 19 else "extends: palm_push_two_feet\n",
            f"c{i}.yaml",
        )
    with pytest.raises(ScenarioError, match="chain of more than"):
        load_scenario(tmp_path / "c0.yaml")
    assert load_scenario(tmp_path / "c10.yaml").impact is not None  # 10 levels: accepted


# -- bounded messages ------------------------------------------------------------------------
def test_short_repr_never_expands_a_shared_structure():
    x: object = ["x"] * 9
    for _ in range(12):  # 9**13 leaves if expanded
        x = [x] * 9
    start = time.perf_counter()
    text = short_repr(x)
    assert time.perf_counter() - start < 0.1
    assert len(text) <= 80 and text.startswith("[[")
    assert short_repr("s" * 10_000).count("s") < 80
    assert short_repr(10**400) == repr(10**400)[:77] + "..."
    assert short_repr(10**5000) == "<a very large integer>"  # Python refuses to convert it
    assert (
        short_repr(0.7) == "0.7" and short_repr([0.2, 0.1]) == "[0.2, 0.1]"
    )  # short values unchanged


def test_unknown_frame_message_is_short_with_closest_names_and_count(tmp_path):
    robot = load_robot("talos")
    with pytest.raises(UnknownFrameError) as info:
        analyze(
            write(
                tmp_path,
                {
                    **TWO_FEET,
                    "contacts": [{"frame": "left_sole", "friction": 0.7, "size": [0.2, 0.1]}],
                },
            )
        )
    message = str(info.value)
    assert len(message) < 400  # was 2.7 KB: every frame name
    assert "did you mean left_sole_link" in message
    assert (
        f"{robot.model.nframes} valid frames" in message
        and "impact-balance frames talos" in message
    )
    assert set(info.value.valid) == {
        f.name for f in robot.model.frames
    }  # the data still has them all


def test_huge_unknown_name_is_cut(tmp_path):
    with pytest.raises(UnknownFrameError) as info:
        analyze(
            write(
                tmp_path,
                {
                    **TWO_FEET,
                    "contacts": [{"frame": "f" * 100_000, "friction": 0.7, "size": [0.2, 0.1]}],
                },
            )
        )
    assert len(str(info.value)) <= MESSAGE_CHARS


@pytest.mark.parametrize(
    "path, typo, suggestion",
    [
        ((), "plane_hieght", "plane_height"),
        (("impact",), "frition", "friction"),
        (("contacts", 0), "frictoin", "friction"),
        ((), "contact", "contacts"),
        (("impact", "qp"), "solver_name", "solver"),
    ],
)
def test_unknown_key_suggests_the_nearest(tmp_path, capsys, path, typo, suggestion):
    data = json.loads(
        json.dumps(
            {
                **TWO_FEET,
                "impact": {"frame": "gripper_right_base_link", "normal": [-1, 0, 0], "qp": {}},
            }
        )
    )
    node = data
    for part in path:
        node = node[part]
    node[typo] = node.pop(suggestion, 0.5)
    with pytest.raises(UnknownKeyError) as info:
        load_scenario(write(tmp_path, data))
    assert info.value.suggestion == suggestion and info.value.key == typo
    assert suggestion in info.value.valid
    line = one_error_line(*run_cli(capsys, "analyze", str(tmp_path / "scenario.yaml")))
    assert f"unknown key (did you mean {suggestion}?)" in line


def test_unknown_key_without_a_close_match_has_no_suggestion(tmp_path):
    with pytest.raises(UnknownKeyError) as info:
        load_scenario(write(tmp_path, {**TWO_FEET, "zzzzzz": 1}))
    assert info.value.suggestion is None and "did you mean" not in str(info.value)


def test_solver_error_names_the_field():
    exc = SolverError("HiGHS", "kSolveError", "support LP of the projection").within("contacts")
    assert str(exc).startswith("contacts: HiGHS failed with status kSolveError")
    assert exc.within("impact.qp").field == "contacts"  # the first attribution is kept


# -- physical ranges ---------------------------------------------------------------------------
IMPACT = {"frame": "gripper_right_base_link", "normal": [-1.0, 0.0, 0.0]}
RANGES = [
    # (field path, refused value, accepted value, text of the range in the message)
    (("contacts", 0, "friction"), 2e6, 1e6, "(0, 1e+06]"),
    (("contacts", 0, "friction"), 0.0, 1e-6, "(0, 1e+06]"),
    (("impact", "friction"), 1e7, 0.0, "[0, 1e+06]"),
    (("contacts", 0, "size"), [11.0, 0.1], [10.0, 0.1], "(0, 10] m"),
    (("base",), {"position": [1e160, 0, 1]}, {"position": [1e4, 0, 1]}, "[-10000, 10000] m"),
    (
        ("impact", "offset"),
        {"position": [0, 0, -2e4]},
        {"position": [0, 0, 0.01]},
        "[-10000, 10000] m",
    ),
    (("contacts", 0, "offset"), {"rpy": [20.0, 0, 0]}, {"rpy": [0.1, 0, 0]}, "rad"),
    (("plane_height",), -1e160, -1.0, "[-10000, 10000] m"),
    (("gravity",), 1000.0, 1.62, "[0.1, 100] m/s^2"),
    (("impact", "duration"), 2.0, 1.0, "(0, 1] s"),
    (("impact", "reference_velocity"), [150.0, 0, 0], [0.8, 0, 0], "100 m/s"),
    (("com_velocity",), [80.0, 80.0], [0.1, 0.0], "100 m/s"),
    (("impact", "qp"), {"peak_factor": 1e4}, {"peak_factor": 2.0}, "(0, 1000]"),
]


def with_value(path, value) -> dict:
    data = json.loads(json.dumps({**TWO_FEET, "impact": IMPACT}))
    node = data
    for part in path[:-1]:
        node = node[part]
    node[path[-1]] = value
    return data


@pytest.mark.parametrize(
    "path, bad, good, text", RANGES, ids=[".".join(map(str, r[0])) for r in RANGES]
)
def test_out_of_range_value_is_refused_with_the_range(path, bad, good, text):
    with pytest.raises(ScenarioError) as info:
        scenario_from_dict(with_value(path, bad))
    assert info.value.field.startswith(
        ".".join(str(p) for p in path if not isinstance(p, int)).split(".")[0]
    )
    assert text in str(info.value)
    scenario_from_dict(with_value(path, good))  # control: the range's own boundary is accepted


@pytest.mark.parametrize(
    "path",
    [
        ("com_velocity",),
        ("plane_height",),
        ("base",),
        ("impact", "normal"),
        ("contacts", 0, "friction"),
        ("joints",),
        ("impact", "reference_velocity"),
    ],
)
def test_nan_is_refused_everywhere(path):
    value = {
        ("com_velocity",): [math.nan, 0.0],
        ("base",): {"position": [math.nan, 0, 1]},
        ("impact", "normal"): [math.nan, 0, 1],
        ("joints",): {"leg_left_4_joint": math.nan},
        ("impact", "reference_velocity"): [math.nan, 0, 0],
    }.get(path, math.nan)
    with pytest.raises(ScenarioError, match="finite"):
        scenario_from_dict(with_value(path, value))


# -- stdout: one strict JSON document, quiet pipes, no native chatter ---------------------------
def test_analyze_json_stdout_is_one_strict_document():
    proc = run_process("analyze", "talos_three_contacts", "--json", "--qp")
    assert proc.returncode == 0, proc.stderr
    document = strict_json(proc.stdout)
    assert document["verdict"] == "balanced" and document["warnings"] == []
    assert without_compile_notice(proc.stderr) == []


def test_closed_stdout_ends_quietly():
    """``analyze --json | head -c 10``: the reader is gone before the JSON is written."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "impact_balance", "analyze", "palm_push_two_feet", "--json"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.close()
    _, err = proc.communicate(timeout=120)
    assert without_compile_notice(err.decode()) == []  # was a BrokenPipeError traceback
    assert proc.returncode == cli.EXIT_BROKEN_PIPE


def test_urdf_errors_are_one_line_with_the_cause(tmp_path):
    (tmp_path / "bad.urdf").write_text(
        '<robot name="r"><link name="a"/><joint name="j" type="revolute">'
        '<parent link="a"/><child link="b"/></joint></robot>'
    )
    path = write(tmp_path, {**TWO_FEET, "robot": {"urdf": "bad.urdf"}})
    with pytest.raises(RobotLoadError, match="does not specify limits"):
        analyze(path)
    proc = run_process("analyze", str(path))
    lines = without_compile_notice(proc.stderr)
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr  # urdfdom printed 4 more lines
    assert "REVOLUTE but it does not specify limits" in lines[0]


# -- warnings and --strict -----------------------------------------------------------------------
def scenario_with(**changes) -> dict:
    data = json.loads(json.dumps({**TWO_FEET, "impact": IMPACT}))
    data.update(changes)
    return data


def codes(analysis) -> list[str]:
    return [w.code for w in analysis.warnings]


def test_no_warnings_on_plain_and_wall_stances():
    assert codes(analyze("palm_push_two_feet")) == []
    assert codes(analyze("palm_push_ramp")) == []  # a 30 degree ramp is a floor
    assert codes(analyze("talos_three_contacts")) == []  # a hand on a wall is a wall


def test_flipped_sole_warns_normal_down(tmp_path):
    contacts = json.loads(json.dumps(TWO_FEET["contacts"]))
    contacts[0]["offset"] = {"rpy": [3.14159, 0.0, 0.0]}
    analysis = analyze(write(tmp_path, scenario_with(contacts=contacts)))
    (warning,) = analysis.warnings
    assert (warning.code, warning.field) == ("contact_normal_down", "contacts[0]")
    assert analysis.stance.contacts[0].normal[2] < -0.99  # independent: the frame's z axis


@pytest.mark.parametrize(
    "roll, warned", [(0.0, False), (0.6, False), (math.radians(45), True), (1.3, False)]
)
def test_tilted_contact_warns_between_floor_and_wall(tmp_path, roll, warned):
    contacts = json.loads(json.dumps(TWO_FEET["contacts"]))
    contacts[1]["offset"] = {"rpy": [roll, 0.0, 0.0]}
    analysis = analyze(write(tmp_path, scenario_with(contacts=contacts)))
    tilt = math.degrees(math.acos(analysis.stance.contacts[1].normal[2]))
    assert ("contact_normal_tilted" in codes(analysis)) == warned == (40 < tilt < 70)


def test_impact_moving_away_warns(tmp_path, capsys):
    path = write(
        tmp_path,
        scenario_with(
            impact=dict(IMPACT, normal=[1.0, 0.0, 0.0], reference_velocity=[0.8, 0.0, 0.0])
        ),
    )
    analysis = analyze(path)
    assert codes(analysis) == ["impact_moving_away"]
    assert analysis.impact.model.approach_speed([0.8, 0.0, 0.0]) < 0  # independent: -n.v = -0.8
    rc, out, _err = run_cli(capsys, "analyze", str(path))
    assert (
        rc == 0 and "warning: impact.reference_velocity:" in out and "[impact_moving_away]" in out
    )
    rc, out, _err = run_cli(capsys, "analyze", str(path), "--json")
    assert rc == 0 and strict_json(out)["warnings"][0]["code"] == "impact_moving_away"
    # control: the same reference towards the surface is capped, no warning
    control = write(
        tmp_path,
        scenario_with(impact=dict(IMPACT, reference_velocity=[0.8, 0.0, 0.0])),
        "control.yaml",
    )
    assert codes(analyze(control)) == []


def test_qp_capped_by_the_reference_warns():
    analysis = analyze("kick_one_foot", solve_qp=True)
    assert codes(analysis) == ["qp_capped_by_reference"]
    qp, limit = analysis.impact.qp.approach_speed, analysis.impact.max_contact_velocity
    assert (
        qp == pytest.approx(1.0, abs=1e-6) and limit > 1.2
    )  # the reference (1 m/s) below the maximum
    assert codes(analyze("kick_one_foot")) == []  # without the QP, nothing to say


@needs_extra("plots")
def test_skipped_figure_warns(tmp_path, capsys):
    path = write(
        tmp_path, {"robot": "talos", "contacts": [TWO_FEET["contacts"][0]]}
    )  # CoM beside the only sole
    rc, out, err = run_cli(
        capsys, "analyze", str(path), "--json", "--plots", str(tmp_path / "figures")
    )
    assert rc == 0, err
    (warning,) = strict_json(out)["warnings"]
    assert warning["code"] == "figure_skipped" and "phase_portrait" in warning["message"]
    assert not (tmp_path / "figures" / "scenario_phase_portrait.png").exists()
    assert (tmp_path / "figures" / "scenario_areas.png").exists()


def test_strict_turns_warnings_into_one_error_line(tmp_path, capsys):
    path = write(
        tmp_path,
        scenario_with(
            impact=dict(IMPACT, normal=[1.0, 0.0, 0.0], reference_velocity=[0.8, 0.0, 0.0])
        ),
    )
    line = one_error_line(*run_cli(capsys, "analyze", str(path), "--json", "--strict"))
    assert "(--strict)" in line and "impact_moving_away" in line
    exc = StrictWarningsError(analyze(path).warnings)
    assert exc.warnings[0].code == "impact_moving_away" and str(exc) in line
    rc, out, _err = run_cli(
        capsys, "analyze", "palm_push_two_feet", "--json", "--strict"
    )  # control
    assert rc == 0 and strict_json(out)["warnings"] == []


# -- frames command and --version ------------------------------------------------------------------
def test_frames_lists_every_frame_and_joint(capsys):
    rc, out, err = run_cli(capsys, "frames", "talos", "--json")
    assert rc == 0, err
    listing = strict_json(out)
    model = load_robot("talos").model
    assert [f["name"] for f in listing["frames"]] == [f.name for f in model.frames]
    assert len(listing["joints"]) == model.njoints - 2  # minus universe and the free-flyer root
    knee = next(j for j in listing["joints"] if j["name"] == "leg_left_4_joint")
    jid = model.getJointId("leg_left_4_joint")
    assert knee["upper"] == pytest.approx(model.upperPositionLimit[model.joints[jid].idx_q])
    assert knee["effort"] == pytest.approx(model.effortLimit[model.joints[jid].idx_v])
    rc, out, _ = run_cli(capsys, "frames", "talos")
    assert rc == 0 and "left_sole_link" in out and "leg_left_4_joint" in out


def test_frames_of_a_scenario_and_of_an_unknown_robot(capsys):
    rc, out, _ = run_cli(capsys, "frames", "g1_two_feet", "--json")
    assert rc == 0 and strict_json(out)["robot"] == "g1"
    line = one_error_line(*run_cli(capsys, "frames", "atlas"))
    assert "robot = 'atlas': unknown robot" in line and "talos" in line


def test_version(capsys):
    with pytest.raises(SystemExit) as info:
        cli.main(["--version"])
    assert info.value.code == 0
    assert (
        capsys.readouterr().out.strip()
        == f"impact-balance {importlib.metadata.version('impact-balance')}"
    )


def test_pinocchio_frame_count_is_independent():
    """The frame count in messages is pinocchio's, not a count of the message's own list."""
    model = pin.buildModelFromUrdf(str(load_robot("talos").urdf_path), pin.JointModelFreeFlyer())
    assert model.nframes == len(load_robot("talos").frame_names)


@needs_extra("gui")
def test_gui_shows_the_warnings(tmp_path):
    from impact_balance.gui.app import GuiApp

    path = write(
        tmp_path,
        scenario_with(
            impact=dict(IMPACT, normal=[1.0, 0.0, 0.0], reference_velocity=[0.8, 0.0, 0.0])
        ),
    )
    app = GuiApp(str(path), port=0)
    try:
        assert (
            app.session.summary.warnings
            and "[impact_moving_away]" in app.session.summary.warnings[0]
        )
        assert (
            'class="ib-warning"' in app.w_results.content
            and "impact_moving_away" in app.w_results.content
        )
        app.edit(lambda: app.session.load("palm_push_two_feet"))  # control: no warning, no line
        assert 'class="ib-warning"' not in app.w_results.content
    finally:
        app.stop()


def test_phase_portrait_refuses_non_finite_gravity(capsys):
    line = one_error_line(
        *run_cli(
            capsys,
            "phase-portrait",
            "--com-height",
            "0.8",
            "--zmp-range",
            "-0.1",
            "0.1",
            "--gravity",
            "inf",
            "--json",
        )
    )
    assert "gravity = inf" in line and "[0.1, 100]" in line
    rc, out, _ = run_cli(
        capsys, "phase-portrait", "--com-height", "0.78", "--zmp-range", "-0.13", "0.13", "--json"
    )
    assert rc == 0 and strict_json(out)["com_velocity_bounds"][1] == pytest.approx(
        0.13 * math.sqrt(9.81 / 0.78)
    )


def test_solo12_foot_frames_are_tilted(tmp_path):
    """The case a user met: solo12's *_FOOT frames have their z axis 45 degrees off the vertical."""
    from impact_balance.robot.robot import example_robot_data_root

    root = example_robot_data_root() / "solo_description"
    feet = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"]
    data = {
        "robot": {
            "urdf": str(root / "robots" / "solo12.urdf"),
            "srdf": str(root / "srdf" / "solo.srdf"),
            "standing": "straight_standing",
        },
        "torque_limits": False,
        "contacts": [{"frame": f, "friction": 0.7, "size": [0.02, 0.02]} for f in feet],
    }
    analysis = analyze(write(tmp_path, data))
    assert codes(analysis) == ["contact_normal_tilted"] * 4
    # independent: the frames' z axes from pinocchio's forward kinematics at the same q
    robot, q = analysis.stance.robot, analysis.stance.q
    frame_data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, frame_data, q)
    for foot in feet:
        z = frame_data.oMf[robot.model.getFrameId(foot)].rotation[:, 2]
        assert 40 < math.degrees(math.acos(z[2])) < 70
