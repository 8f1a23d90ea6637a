"""Stance authoring from the command line: `frames` (poses and axes), contacts given by their
world normal, and `pose` (whole-body IK that writes a scenario).

Two stances are written with `frames` and `pose` alone: a hand flat on a table
beside two feet, and a one-foot kick. Each result is checked independently: frame poses with
pinocchio's forward kinematics of the written configuration, the analysis of the written file.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pinocchio as pin
import pytest

import impact_balance as ib
from impact_balance.exceptions import ScenarioError
from impact_balance.scenario import load_scenario, scenario_from_dict
from tests.helpers.cli import run_cli as run


def frames_json(capsys, target: str, *names: str) -> dict:
    rc, out, _ = run(
        capsys, "frames", target, *[a for n in names for a in ("--frame", n)], "--json"
    )
    assert rc == 0
    return json.loads(out)


def fk(scenario_path: str, frame: str) -> pin.SE3:
    """Independent: the frame's pose by pinocchio's forward kinematics at the scenario's q."""
    scenario = load_scenario(scenario_path)
    stance = scenario.build_stance()
    model = stance.robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, stance.q)
    return data.oMf[model.getFrameId(frame)]


def test_frames_give_world_position_and_axes(capsys):
    doc = frames_json(capsys, "kick_one_foot", "left_sole_link", "gripper_right_base_link")
    assert doc["configuration"].startswith("stance of scenario")
    for entry in doc["frames"]:
        M = fk("kick_one_foot", entry["name"])
        np.testing.assert_allclose(entry["position"], M.translation, atol=1e-12)
        R = np.column_stack([entry["axes"][k] for k in "xyz"])
        np.testing.assert_allclose(R, M.rotation, atol=1e-12)
        assert entry["z_tilt_deg"] == pytest.approx(
            math.degrees(math.acos(M.rotation[2, 2])), abs=1e-9
        )
    assert [c["frame"] for c in doc["contacts"]] == ["right_sole_link"]
    rc, out, _ = run(capsys, "frames", "romeo", "--frame", "l_sole")
    assert rc == 0 and "z tilt" in out and "l_sole" in out and "configuration half_sitting" in out
    rc, _, err = run(capsys, "frames", "romeo", "--frame", "l_sol")
    assert rc == 2 and err.count("\n") == 1 and "l_sole" in err  # the closest names


def _scenario(**contact) -> dict:
    base = {
        "robot": "talos",
        "contacts": [
            {"frame": "left_sole_link", "friction": 0.7, "size": [0.2, 0.1]},
            {"frame": "gripper_right_base_link", "friction": 0.5, "size": [0.08, 0.06], **contact},
        ],
    }
    return base


def test_a_contact_given_by_its_world_normal():
    # At half_sitting the right gripper's z axis is far from vertical: the offset form would
    # need a hand-computed rpy for a horizontal table; the normal form needs none.
    stance = scenario_from_dict(_scenario()).build_stance()
    assert stance.contacts[1].normal[2] < 0.9
    for angle in (0.0, 0.7):
        s = scenario_from_dict(
            _scenario(normal=[0, 0, 2.0], angle=angle, offset={"position": [0.05, 0, 0]})
        )
        c = s.build_stance().contacts[1]
        np.testing.assert_allclose(c.normal, [0, 0, 1], atol=1e-12)
        # x axis: the frame's x axis projected on the surface, turned by the angle about the normal.
        x = stance.contacts[1].rotation[:, 0] * [1, 1, 0]
        x /= np.linalg.norm(x)
        expected = math.cos(angle) * x + math.sin(angle) * np.cross([0, 0, 1], x)
        np.testing.assert_allclose(c.rotation[:, 0], expected, atol=1e-12)
        # The offset position stays in the frame: the centre is where the offset form puts it.
        offset_form = scenario_from_dict(
            _scenario(offset={"position": [0.05, 0, 0]})
        ).build_stance()
        np.testing.assert_allclose(c.position, offset_form.contacts[1].position, atol=1e-12)
    bad = [
        ({"normal": [0, 0, 1], "offset": {"rpy": [0.1, 0, 0]}}, "contacts[1].normal", "not both"),
        ({"angle": 0.3}, "contacts[1].angle", "give normal too"),
        ({"normal": [0, 0, 0]}, "contacts[1].normal", "non-zero"),
    ]
    for contact, field, reason in bad:
        with pytest.raises(ScenarioError) as info:
            scenario_from_dict(_scenario(**contact))
        assert field in str(info.value) and reason in str(info.value)


def test_hand_on_table_with_frames_and_pose(tmp_path, capsys):
    """Talos' right palm (the gripper's flat +x face) flat on a table at 1 m, on its right."""
    feet = frames_json(capsys, "palm_push_two_feet", "left_sole_link", "right_sole_link")["frames"]
    between = np.mean([f["position"] for f in feet], axis=0)
    draft = tmp_path / "table_draft.yaml"
    # The palm contact: centre of the +x face, its normal (surface into the robot) along the
    # gripper's -x axis (rpy: -90 degrees about y), as docs/robots.md lists for Talos.
    draft.write_text(
        "extends: palm_push_two_feet\nimpact: null\ncontacts:\n"
        "  - {frame: left_sole_link, friction: 0.7, size: [0.2, 0.1]}\n"
        "  - {frame: right_sole_link, friction: 0.7, size: [0.2, 0.1]}\n"
        "  - {frame: gripper_right_base_link, friction: 0.5, size: [0.08, 0.08],\n"
        "     offset: {position: [0.051, 0.0, -0.045], rpy: [0.0, -1.5708, 0.0]}}\n"
    )
    out = tmp_path / "table.yaml"
    rc, text, err = run(
        capsys,
        "pose",
        str(draft),
        "--place",
        "gripper_right_base_link",
        "0.3",
        "-0.4",
        "1.0",
        "--normal",
        "0",
        "0",
        "1",
        "--com",
        f"{between[0]}",
        f"{between[1]}",
        "--out",
        str(out),
    )
    assert rc == 0, err
    assert "wrote" in text and "contacts kept: left_sole_link, right_sole_link" in text
    analysis = ib.analyze(str(out))
    hand = analysis.stance.contacts[2]
    np.testing.assert_allclose(hand.normal, [0, 0, 1], atol=1e-5)  # not 127 degrees off
    np.testing.assert_allclose(hand.position, [0.3, -0.4, 1.0], atol=1e-5)
    for before, contact in zip(feet, analysis.stance.contacts[:2], strict=True):
        np.testing.assert_allclose(
            contact.position, before["position"], atol=1e-5
        )  # the feet stayed
    assert analysis.areas.can_balance and analysis.com_velocity_inside
    assert analysis.areas.zmp_area.area > 0 and analysis.areas.com_velocity_area.area > 0
    assert analysis.warnings == ()
    # Independent: the written joints put the frame where `pose` says (pinocchio FK of the file).
    M = fk(str(out), "gripper_right_base_link")
    np.testing.assert_allclose(M.rotation[:, 0], [0, 0, -1], atol=1e-5)  # the palm faces down
    # The file is not replaced without --force.
    rc, _, err = run(capsys, "pose", str(draft), "--com", "0", "0", "--out", str(out))
    assert rc == 2 and "--force" in err and err.count("\n") == 1


def test_kick_one_foot_with_frames_and_pose(tmp_path, capsys):
    """Talos on its right foot, the left foot lifted forward, kicking with its toe."""
    soles = {
        f["name"]: f
        for f in frames_json(capsys, "palm_push_two_feet", "left_sole_link", "right_sole_link")[
            "frames"
        ]
    }
    right, left = soles["right_sole_link"]["position"], soles["left_sole_link"]["position"]
    draft = tmp_path / "kick_draft.yaml"
    draft.write_text(
        "extends: palm_push_two_feet\n"
        "contacts:\n  - {frame: right_sole_link, friction: 0.7, size: [0.2, 0.1]}\n"
        "impact:\n  frame: left_sole_link\n  offset: {position: [0.105, 0.0, 0.0]}\n"
        "  normal: [-1.0, 0.0, 0.0]\n"
        "  reference_velocity: [1.0, 0.0, 0.0]\n"
    )
    out = tmp_path / "kick.yaml"
    target = [left[0] + 0.2, left[1], left[2] + 0.12]
    rc, _, err = run(
        capsys,
        "pose",
        str(draft),
        "--place",
        "left_sole_link",
        *map(str, target),
        "--com",
        str(right[0]),
        str(right[1]),
        "--out",
        str(out),
        "--json",
    )
    assert rc == 0, err
    analysis = ib.analyze(str(out))
    M = fk(str(out), "left_sole_link")
    np.testing.assert_allclose(M.translation, target, atol=1e-5)
    np.testing.assert_allclose(M.rotation, np.eye(3), atol=1e-4)  # the foot stays flat
    np.testing.assert_allclose(analysis.stance.com[:2], right[:2], atol=1e-5)
    np.testing.assert_allclose(analysis.stance.contacts[0].normal, [0, 0, 1], atol=1e-5)
    assert len(analysis.stance.contacts) == 1 and analysis.com_velocity_inside
    assert analysis.areas.com_velocity_area.area > 0
    np.testing.assert_allclose(
        analysis.impact.model.point, M.act(np.array([0.105, 0.0, 0.0])), atol=1e-9
    )
    assert 0 < analysis.impact.max_contact_velocity < 10


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--place", "left_sole", "0", "0", "0"], "left_sole_link"),
        (["--place", "left_sole_link", "0", "0", "0", "--normal", "0", "0", "0"], "non-zero"),
        (["--normal", "0", "0", "1"], "after the --place"),
        (["--place", "left_sole_link", "a", "0", "0"], "expected numbers"),
        ([], "nothing to do"),
    ],
)
def test_pose_bad_input_is_one_line(tmp_path, capsys, argv, needle):
    rc, _, err = run(capsys, "pose", "palm_push_two_feet", *argv, "--out", str(tmp_path / "x.yaml"))
    assert rc == 2 and err.count("\n") == 1 and needle in err and "Traceback" not in err
