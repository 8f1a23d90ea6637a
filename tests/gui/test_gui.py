"""The web GUI without a browser: state, edits, scene objects, 2D view, drags, server wiring.

The browser end-to-end test is ``test_gui_e2e.py``.
"""

from __future__ import annotations

import math
import os
import signal
import statistics
import subprocess
import sys
import time
import urllib.request
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
import yaml

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from impact_balance import cli
from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import ScenarioError
from impact_balance.gui import (
    DEFAULT_SCENARIO,
    Arrows,
    DragTarget,
    GuiState,
    Label,
    Points,
    Segments,
    Session,
    Surface,
    handle_pose,
    joint_groups,
    scene_objects,
    svg_view,
)
from impact_balance.gui.contact_orientation import RPY_MODE, WORLD_NORMAL_MODE
from impact_balance.gui.scene import CONE_LENGTH, PLANE_LIFT
from impact_balance.robot.robot import example_robot_data_root, load_robot
from impact_balance.scenario import load_scenario

TOL = 1e-9


@pytest.fixture()
def session(tmp_path) -> Session:
    return Session(DEFAULT_SCENARIO, workspace=tmp_path)


def by_name(objects) -> dict:
    return {o.name: o for o in objects}


# -- state: edits, validation, load and save ------------------------------------------------
def test_default_scenario_is_the_demo_two_foot_push(session):
    assert session.state.scenario.name == "palm_push_two_feet"
    assert [c.frame for c in session.state.scenario.contacts] == [
        "left_sole_link",
        "right_sole_link",
    ]
    assert session.summary.headline == "balanced"
    # README's demo table: 0.481 m/s by the CoM criterion.
    assert session.summary.max_contact_velocity == pytest.approx(0.481, abs=5e-4)


def test_recompute_changes_the_numbers(session):
    before = session.summary.max_contact_velocity
    assert session.set(("impact", "friction"), 0.4)
    after = session.summary.max_contact_velocity
    # The same edit as the bundled friction sweep's mu = 0.4 file.
    assert after == pytest.approx(analyze("palm_push_mu040").impact.max_contact_velocity, rel=1e-9)
    assert after < before - 0.05
    assert session.state.scenario.impact.friction == 0.4
    assert session.revision == 1 and not session.refused


def test_joint_edit_moves_the_robot(session):
    q0 = session.analysis.stance.q.copy()
    joint = session.analysis.stance.robot.model.joints[
        session.analysis.stance.robot.model.getJointId("arm_right_1_joint")
    ]
    assert session.set(("joints", "arm_right_1_joint"), 0.8)
    assert session.analysis.stance.q[joint.idx_q] == 0.8
    assert not np.allclose(
        session.analysis.impact.model.point, analyze(DEFAULT_SCENARIO).impact.model.point
    )
    assert np.linalg.norm(session.analysis.stance.q - q0) > 0.1


@pytest.mark.parametrize(
    "path, value, needle",
    [
        (("impact", "friction"), -1.0, "impact.friction"),
        (("impact", "friction"), float("nan"), "impact.friction"),
        (("impact", "friction"), "abc", "impact.friction"),
        (("contacts", 0, "friction"), 0.0, "contacts[0].friction"),
        (("contacts", 1, "size"), [0.2, -0.1], "contacts[1].size"),
        (("impact", "restitution"), [0.5, 0.2], "lo <= hi"),
        (("impact", "cone_edges"), 2, "impact.cone_edges"),
        (("contacts", 0, "frame"), "left_sole", "did you mean"),
        (("joints", "leg_left_4_joint"), 9.0, "outside the joint limits"),
        (("plane_height",), 5.0, "below the CoM"),
        (("impact", "normal"), [0.0, 0.0, 0.0], "non-zero"),
        (("contacts", 0), None, None),  # removing one of two contacts is fine
    ],
)
def test_bad_value_is_refused_with_a_message_and_keeps_the_state(session, path, value, needle):
    state, analysis = session.state, session.analysis
    ok = session.set(path, value)
    if needle is None:
        assert ok and len(session.state.scenario.contacts) == 1
        return
    assert not ok
    assert session.refused and needle in session.message
    assert session.state is state and session.analysis is analysis  # nothing changed
    assert session.revision == 0
    # The session still works after a refusal.
    assert session.set(("impact", "friction"), 0.3) and session.message is None


def test_removing_the_last_contact_is_refused(session):
    assert session.set(("contacts", 1), None)
    assert not session.set(("contacts", 0), None)
    assert "contacts" in session.message and len(session.state.scenario.contacts) == 1


def test_state_edits_do_not_mutate_the_previous_state():
    state = GuiState.from_file(DEFAULT_SCENARIO)
    edited = state.with_changes({("contacts", 0, "offset", "position"): np.array([0.01, 0.0, 0.0])})
    assert state.get(("contacts", 0, "offset")) is None
    assert edited.get(("contacts", 0, "offset", "position")) == [
        0.01,
        0.0,
        0.0,
    ]  # numpy became plain data
    assert edited.scenario.contacts[0].offset.position == (0.01, 0.0, 0.0)
    assert edited.with_value(("base",), None).get(("base",)) is None
    with pytest.raises(ScenarioError, match="gravity"):
        state.with_value(("gravity",), float("inf"))


@pytest.mark.parametrize(
    "name", ["palm_push_two_feet", "palm_push_mu040", "talos_three_contacts", "g1_two_feet"]
)
def test_save_load_round_trip_equals_the_original(tmp_path, name):
    original = load_scenario(name)
    state = GuiState.from_file(name)
    path = state.save(tmp_path / "saved.yaml")
    again = load_scenario(path)
    assert again.model_dump() == original.model_dump()  # `extends` flattened, every value kept
    assert "extends" not in yaml.safe_load(path.read_text())
    assert GuiState.from_file(path) == state


def test_saved_edits_are_analysed_like_the_gui(tmp_path):
    session = Session(DEFAULT_SCENARIO, workspace=tmp_path)
    assert session.apply(
        {("impact", "friction"): 0.1, ("com_velocity",): [0.05, -0.02], ("torque_limits",): False}
    )
    (tmp_path / "tuned").mkdir()
    path = session.save("tuned/stance.yaml")
    assert (
        path == tmp_path / "tuned" / "stance.yaml" and session.message == "saved tuned/stance.yaml"
    )
    loaded = analyze(str(path))
    assert loaded.impact.max_contact_velocity == pytest.approx(
        session.summary.max_contact_velocity, rel=1e-12
    )
    assert loaded.scenario.torque_limits is False and loaded.scenario.com_velocity == (0.05, -0.02)
    # Upload path: the same text loads back into a session.
    other = Session("kick_one_foot")
    assert other.load_yaml(path.read_text(), "stance.yaml")
    assert other.state == session.state


def test_save_refuses_a_bad_file_name(tmp_path):
    session = Session(DEFAULT_SCENARIO, workspace=tmp_path)
    assert session.save("stance.txt") is None
    assert session.refused and ".yaml" in session.message
    (tmp_path / "blocker").write_text("")
    assert session.save("blocker/x.yaml") is None
    assert "blocker is not a folder" in session.message
    assert session.save("no_folder/x.yaml") is None  # folders are not created
    assert "no such folder" in session.message and not (tmp_path / "no_folder").exists()


def test_load_bad_yaml_is_refused(session):
    state = session.state
    assert not session.load_yaml("contacts: [\n", "broken.yaml")
    assert "broken.yaml" in session.message and "not valid YAML" in session.message
    assert not session.load_yaml("robot: talos\n", "nocontacts.yaml")
    assert "contacts" in session.message
    assert not session.load("no_such_scenario")
    assert "unknown scenario" in session.message
    assert session.state is state


def test_robot_files_made_absolute_so_a_saved_state_still_finds_them(tmp_path):
    urdf = example_robot_data_root() / "talos_data/robots/talos_reduced.urdf"
    srdf = example_robot_data_root() / "talos_data/srdf/talos.srdf"
    src = tmp_path / "a"
    src.mkdir()
    raw = yaml.safe_load(load_scenario("palm_push_two_feet").model_dump_json(exclude_unset=True))
    raw["robot"] = {
        "urdf": os.path.relpath(urdf, src),
        "srdf": os.path.relpath(srdf, src),
        "standing": "half_sitting",
    }
    (src / "files.yaml").write_text(yaml.safe_dump(raw))
    state = GuiState.from_file(src / "files.yaml")
    saved = state.save(tmp_path / "elsewhere" / "b" / "files.yaml")
    assert Path(yaml.safe_load(saved.read_text())["robot"]["urdf"]).is_absolute()
    assert analyze(str(saved)).impact.max_contact_velocity == pytest.approx(0.481, abs=5e-4)


# -- infeasible stances ---------------------------------------------------------------------
@pytest.mark.parametrize(
    "contacts",
    [
        [
            {"frame": "gripper_left_base_link", "friction": 0.7, "size": [0.1, 0.08]}
        ],  # one hand, nothing under the feet
        [
            {
                "frame": "left_sole_link",
                "friction": 0.7,
                "size": [0.2, 0.1],
                "offset": {"rpy": [math.pi, 0.0, 0.0]},
            }
        ],
    ],
)
def test_infeasible_stance_shows_cannot_balance(session, contacts):
    assert session.set(("contacts",), contacts)  # an answer, not a refusal
    s = session.summary
    assert s.headline == "cannot balance" and not s.can_balance
    assert s.max_contact_velocity == 0.0
    names = by_name(scene_objects(session.analysis))
    assert not any(n.startswith("zmp_area") for n in names) and "com/point" in names
    svg = svg_view(session.analysis)
    ET.fromstring(svg)
    assert "cannot balance" in svg and "CANNOT BALANCE" in svg
    # Back to a good stance: the GUI goes on.
    assert session.load(DEFAULT_SCENARIO) and session.summary.headline == "balanced"


def test_tiny_friction_is_still_an_answer(session):
    assert session.apply({("contacts", 0, "friction"): 1e-4, ("contacts", 1, "friction"): 1e-4})
    assert session.summary.max_contact_velocity < 0.01


# -- scene objects ----------------------------------------------------------------------------
def test_scene_objects_of_the_default_stance(session):
    analysis = session.analysis
    objects = by_name(scene_objects(analysis))
    kinds = {
        "contacts/0/outline": Segments,
        "com/label": Label,
        "impact/label": Label,
        "contacts/1/outline": Segments,
        "contacts/0/normal": Arrows,
        "com/point": Points,
        "com/projection": Points,
        "zmp_area/outline": Segments,
        "zmp_area/fill": Surface,
        "impact/point": Points,
        "impact/normal": Arrows,
        "impact/cone": Surface,
        "impact/impulses": Segments,
    }
    for name, kind in kinds.items():
        assert isinstance(objects[name], kind), name
    # Contact rectangles: their 4 corners, closed.
    for i, contact in enumerate(analysis.stance.contacts):
        seg = objects[f"contacts/{i}/outline"].segments
        assert seg.shape == (4, 2, 3)
        np.testing.assert_allclose(seg[:, 0], contact.corners(), atol=TOL)
        np.testing.assert_allclose(seg[:, 1], np.roll(contact.corners(), -1, axis=0), atol=TOL)
    # CoM and its projection on the ZMP plane.
    com = analysis.stance.com
    np.testing.assert_allclose(objects["com/point"].points[0], com, atol=TOL)
    np.testing.assert_allclose(
        objects["com/projection"].points[0], [com[0], com[1], PLANE_LIFT], atol=TOL
    )
    # ZMP area on its plane, with the area's vertices.
    outline = objects["zmp_area/outline"].segments
    np.testing.assert_allclose(outline[:, 0, :2], analysis.areas.zmp_area.vertices, atol=TOL)
    np.testing.assert_allclose(outline[:, :, 2], PLANE_LIFT, atol=TOL)
    # Impact: point, normal into the robot, cone of half-angle atan(mu) around it.
    model = analysis.impact.model
    np.testing.assert_allclose(objects["impact/point"].points[0], model.point, atol=TOL)
    normal = objects["impact/normal"]
    direction = normal.ends[0] - normal.starts[0]
    np.testing.assert_allclose(direction / np.linalg.norm(direction), [-1.0, 0.0, 0.0], atol=TOL)
    rim = objects["impact/cone"].vertices[1:] - model.point
    assert len(rim) == 16
    np.testing.assert_allclose(rim @ model.normal, CONE_LENGTH, atol=TOL)
    radial = np.linalg.norm(rim - np.outer(rim @ model.normal, model.normal), axis=1)
    np.testing.assert_allclose(radial / CONE_LENGTH, 0.24, atol=TOL)
    # 2N impulse directions, along the impulse vertices.
    imp = objects["impact/impulses"].segments
    assert imp.shape == (32, 2, 3)
    d = imp[:, 1] - imp[:, 0]
    rates = model.impulse_rates
    cos = np.sum(d * rates, axis=1) / (np.linalg.norm(d, axis=1) * np.linalg.norm(rates, axis=1))
    np.testing.assert_allclose(cos, 1.0, atol=1e-9)


def test_scene_objects_follow_the_state(session):
    assert session.apply({("impact",): None, ("com_velocity",): [0.1, 0.0]})
    names = by_name(scene_objects(session.analysis))
    assert not any(n.startswith("impact/") for n in names)
    vel = names["com/velocity"]
    np.testing.assert_allclose(vel.ends[0] - vel.starts[0], [0.1, 0.0, 0.0], atol=TOL)
    assert session.apply(
        {
            ("contacts",): [
                *session.state.get(("contacts",)),
                {"frame": "gripper_left_base_link", "friction": 0.5, "size": [0.1, 0.08]},
            ]
        }
    )
    assert "contacts/2/outline" in by_name(scene_objects(session.analysis))


def test_svg_view_shows_the_sets_and_the_verdict(session):
    svg = svg_view(session.analysis)
    root = ET.fromstring(svg)  # well-formed
    polygons = [e for e in root.iter() if e.tag.endswith("polygon")]
    # CoM velocity area, set at the maximum, set at the reference, ZMP area, 2 contacts.
    assert len(polygons) >= 6
    assert "0.481 m/s" in svg and "falls" in svg and "#d62728" in svg
    # A reference below the maximum does not fall: drawn in the other colour.
    assert session.set(("impact", "reference_velocity"), [0.2, 0.0, 0.0])
    svg = svg_view(session.analysis)
    assert "does not fall" in svg and "#2ca02c" in svg


# -- limbs ------------------------------------------------------------------------------------
def test_joint_groups_by_limb():
    robot = load_robot("talos")
    groups = joint_groups(robot)
    assert list(groups) == ["left leg", "right leg", "torso", "left arm", "right arm", "head"]
    assert [s.name for s in groups["left leg"]] == [f"leg_left_{i}_joint" for i in range(1, 7)]
    names = [s.name for sliders in groups.values() for s in sliders]
    assert sorted(names) == sorted(robot.joint_names)  # every joint once
    knee = next(s for s in groups["left leg"] if s.name == "leg_left_4_joint")
    model = robot.model
    idx = model.joints[model.getJointId("leg_left_4_joint")].idx_q
    assert (knee.lower, knee.upper) == (
        model.lowerPositionLimit[idx],
        model.upperPositionLimit[idx],
    )
    assert list(joint_groups(load_robot("g1"))) == [
        "left leg",
        "right leg",
        "torso",
        "left arm",
        "right arm",
    ]


# -- gizmo drags (IK) ---------------------------------------------------------------------------
def test_drag_a_foot_moves_it_and_keeps_the_other(session):
    before = session.analysis.stance
    left = before.contacts[0]
    target = DragTarget("contact", 1)
    pose = handle_pose(session.state, before, target)
    goal = pin.SE3(pose.rotation, pose.translation + np.array([0.06, -0.04, 0.03]))
    assert session.drag(target, goal), session.message
    after = session.analysis.stance
    np.testing.assert_allclose(after.contacts[1].position, goal.translation, atol=1e-4)
    np.testing.assert_allclose(after.contacts[1].rotation, goal.rotation, atol=1e-4)
    np.testing.assert_allclose(after.contacts[0].position, left.position, atol=1e-4)
    np.testing.assert_allclose(after.contacts[0].rotation, left.rotation, atol=1e-4)
    # The drag became an explicit base pose and joint values: saving keeps it.
    assert session.state.get(("base", "position")) is not None
    assert len(session.state.get(("joints",))) == len(after.robot.joint_names)
    reloaded = GuiState(session.state.raw).scenario.build_stance()
    np.testing.assert_allclose(reloaded.contacts[1].position, goal.translation, atol=1e-4)


def test_drag_the_impact_point_keeps_both_feet(session):
    before = session.analysis.stance
    target = DragTarget("impact")
    pose = handle_pose(session.state, before, target)
    np.testing.assert_allclose(pose.translation, session.analysis.impact.model.point, atol=1e-12)
    goal = pin.SE3(pose.rotation, pose.translation + np.array([-0.05, 0.08, -0.1]))
    assert session.drag(target, goal), session.message
    np.testing.assert_allclose(session.analysis.impact.model.point, goal.translation, atol=1e-4)
    for a, b in zip(session.analysis.stance.contacts, before.contacts, strict=True):
        np.testing.assert_allclose(a.position, b.position, atol=1e-4)
        np.testing.assert_allclose(a.rotation, b.rotation, atol=1e-4)
    assert session.summary.max_contact_velocity != pytest.approx(0.481, abs=1e-3)


def test_drag_out_of_reach_goes_part_way_and_keeps_the_feet(session):
    before = session.analysis.stance
    target = DragTarget("impact")
    pose = handle_pose(session.state, before, target)
    goal = pin.SE3(pose.rotation, pose.translation + np.array([2.0, 0.0, 0.0]))
    assert session.drag(target, goal)
    assert "out of reach" in session.message
    moved = session.analysis.impact.model.point - pose.translation
    assert 0.1 < moved[0] < 2.0
    for a, b in zip(session.analysis.stance.contacts, before.contacts, strict=True):
        np.testing.assert_allclose(a.position, b.position, atol=1e-3)


def test_drag_of_a_missing_target_is_refused(session):
    pose = pin.SE3.Identity()
    assert not session.drag(DragTarget("contact", 5), pose)
    assert "no such contact" in session.message
    assert session.set(("impact",), None)
    assert not session.drag(DragTarget("impact"), pose)
    assert "no impact" in session.message


# -- the server, driven without a browser --------------------------------------------------------
@pytest.fixture(scope="module")
def app(tmp_path_factory):
    from impact_balance.gui.app import GuiApp

    app = GuiApp(DEFAULT_SCENARIO, port=0, workspace=tmp_path_factory.mktemp("workspace"))
    yield app
    app.stop()


def reset(app) -> None:
    app.edit(lambda: app.session.load(DEFAULT_SCENARIO))


def test_app_serves_the_page(app):
    with urllib.request.urlopen(app.url, timeout=10) as response:
        assert response.status == 200
        assert b"<html" in response.read(2000).lower()
    assert app.url.startswith("http://127.0.0.1:")


def test_app_draws_the_scene(app):
    reset(app)
    names = set(app._scene_handles)
    for name in (
        "contacts/0/outline",
        "contacts/1/outline",
        "com/point",
        "zmp_area/fill",
        "impact/cone",
        "impact/impulses",
    ):
        assert f"/analysis/{name}" in names
    assert app._meshes is not None and len(app._meshes.handles) > 40  # Talos' visual meshes
    assert set(app._gizmos) == {"contact0", "contact1", "impact"}
    assert 'id="ib-vmax-com">0.481 m/s' in app.w_results.content
    assert "<svg" in app.w_view2d.content


def test_app_slider_updates_numbers_and_time(app):
    reset(app)
    slider = app._joint_widgets["arm_right_1_joint"]
    start = slider.value
    times = []
    for i in range(20):  # the same path as a browser's slider change, minus the network
        slider.value = start + 0.002 * (i + 1)
        times.append(app.last_update_ms)
        assert app.session.state.get(("joints", "arm_right_1_joint")) == pytest.approx(
            start + 0.002 * (i + 1)
        )
    assert app.session.message is None
    assert (
        f'id="ib-vmax-com">{app.session.summary.max_contact_velocity:.3f} m/s'
        in app.w_results.content
    )
    assert app.session.summary.max_contact_velocity != pytest.approx(0.481, abs=5e-4)
    median, p90 = statistics.median(times), statistics.quantiles(times, n=10)[-1]
    print(
        f"\nGUI update time (analysis + redraw), two-foot stance, 20 slider changes: "
        f"median {median:.1f} ms, p90 {p90:.1f} ms"
    )
    assert median < 200.0  # the target is 50 ms; this only catches a gross regression


def test_app_refused_value_reverts_the_widget(app):
    reset(app)
    app.w_impact_friction.value = -2.0
    assert app.session.refused
    assert app.w_impact_friction.value == pytest.approx(0.24)  # back to the good value
    assert 'id="ib-message"' in app.w_results.content and "impact.friction" in app.w_results.content
    app.w_impact_edges.value = 2
    assert app.session.refused and "cone_edges" in app.session.message
    assert app.w_impact_edges.value == 16


def test_app_a_refusal_clears_on_the_next_good_edit(app):
    reset(app)
    app.w_impact_friction.value = -2.0
    assert app.session.refused and 'id="ib-message"' in app.w_results.content
    app.w_gizmos.value = not app.w_gizmos.value  # a view option: not refused, so it clears
    assert not app.session.refused and 'id="ib-message"' not in app.w_results.content
    app.w_gizmos.value = not app.w_gizmos.value
    app.w_impact_edges.value = 2
    assert app.session.refused
    app.w_impact_friction.value = 0.3  # a good edit of another field
    assert not app.session.refused and app.session.message is None
    assert 'id="ib-message"' not in app.w_results.content
    reset(app)


def test_app_states_the_shared_session(app):
    from impact_balance.gui.app import SHARED_SESSION_NOTE

    assert "every browser tab" in SHARED_SESSION_NOTE
    assert app.w_shared_session.content == SHARED_SESSION_NOTE and app.w_shared_session.visible


def test_app_edits_a_contact_by_its_world_normal(app):
    """Switch the right sole to the world-normal form: the fields show its world normal (not
    "offset rpy 0 0 0"), the rpy field is disabled, and a new normal is analysed."""
    reset(app)
    app.w_contact_select.value = "1: right_sole_link"
    sole = app.session.analysis.stance.contacts[1]
    assert app.w_contact_orientation.value == RPY_MODE and not app.w_contact_rpy.disabled
    assert app.w_contact_normal.disabled and app.w_contact_angle.disabled
    assert np.allclose(app.w_contact_normal.value, sole.normal, atol=1e-6)  # shown, disabled
    before = app.session.summary.max_contact_velocity
    app.w_contact_orientation.value = WORLD_NORMAL_MODE
    raw = app.session.state.get(("contacts", 1))
    assert raw["normal"] == pytest.approx(sole.normal, abs=1e-9) and "rpy" not in raw["offset"]
    assert app.session.summary.max_contact_velocity == pytest.approx(before, rel=1e-9)
    assert app.w_contact_rpy.disabled and not app.w_contact_normal.disabled
    tilt = math.radians(10.0)
    app.w_contact_normal.value = (0.0, math.sin(tilt), math.cos(tilt))
    assert app.session.analysis.stance.contacts[1].normal == pytest.approx(
        [0.0, math.sin(tilt), math.cos(tilt)], abs=1e-12
    )
    app.w_contact_angle.value = 0.25
    assert app.session.state.get(("contacts", 1, "angle")) == 0.25
    # Another contact and back: the fields follow the selected contact.
    app.w_contact_select.value = "0: left_sole_link"
    assert app.w_contact_orientation.value == RPY_MODE
    app.w_contact_select.value = "1: right_sole_link"
    assert app.w_contact_orientation.value == WORLD_NORMAL_MODE
    assert app.w_contact_angle.value == pytest.approx(0.25)
    assert app.w_contact_normal.value == pytest.approx(
        (0.0, math.sin(tilt), math.cos(tilt)), abs=1e-6
    )  # shown to a micro-unit
    # Back to rpy: the same contact, written in its frame.
    rotation = app.session.analysis.stance.contacts[1].rotation
    app.w_contact_orientation.value = RPY_MODE
    assert app.session.state.get(("contacts", 1, "normal")) is None
    assert np.allclose(app.session.analysis.stance.contacts[1].rotation, rotation, atol=1e-9)
    reset(app)


def test_app_saved_file_is_named_after_it(app):
    reset(app)
    app.w_file.value = "my_push.yaml"
    app.w_overwrite.value = True
    app._save()
    saved = yaml.safe_load((app.workspace.root / "my_push.yaml").read_text())
    assert saved["name"] == "my_push" and app.session.state.scenario.name == "my_push"
    assert saved["description"].startswith(f"edited from {DEFAULT_SCENARIO}: ")
    assert app.session.message == "saved my_push.yaml" and app.w_file.value == "my_push.yaml"
    app._save()  # saved again under its own name: name and description kept
    again = yaml.safe_load((app.workspace.root / "my_push.yaml").read_text())
    assert again["name"] == "my_push" and again["description"] == saved["description"]
    reset(app)


@pytest.mark.slow
def test_app_contacts_impact_and_load(app, tmp_path):
    reset(app)
    app.w_new_frame.value = "gripper_left_base_link"
    app._on_add_contact(None)
    assert len(app.session.state.scenario.contacts) == 3
    assert app.w_contact_select.value == "2: gripper_left_base_link"
    assert "/analysis/contacts/2/outline" in app._scene_handles and "contact2" in app._gizmos
    app.w_contact_friction.value = 0.3
    assert app.session.state.scenario.contacts[2].friction == 0.3
    app._on_remove_contact(None)
    assert len(app.session.state.scenario.contacts) == 2
    assert (
        "/analysis/contacts/2/outline" not in app._scene_handles and "contact2" not in app._gizmos
    )
    # Impact off and on again: the same impact comes back.
    app.w_impact_on.value = False
    assert (
        app.session.state.scenario.impact is None and 'id="ib-vmax-com">-' in app.w_results.content
    )
    assert not any(n.startswith("/analysis/impact/") for n in app._scene_handles)
    app.w_impact_on.value = True
    assert app.session.summary.max_contact_velocity == pytest.approx(0.481, abs=5e-4)
    # Torque limits, CoM velocity: recomputed.
    app.w_com_velocity.value = (-0.2, 0.0)
    assert app.session.summary.max_contact_velocity < 0.3
    # Cannot balance: shown, and the GUI goes on.
    app.w_contact_select.value = "0: left_sole_link"
    app.w_contact_rpy.value = (math.pi, 0.0, 0.0)
    assert app.session.state.scenario.contacts[0].offset.rpy == (math.pi, 0.0, 0.0)
    app.w_contact_select.value = "1: right_sole_link"
    app.w_contact_rpy.value = (math.pi, 0.0, 0.0)
    assert "CANNOT BALANCE" in app.w_results.content
    # Save, load another scenario, load the file back: the same state.
    app.w_file.value = "gui_test_saved.yaml"
    saved = app.session.state
    app._save()
    target = app.workspace.root / "gui_test_saved.yaml"
    assert target.is_file() and app.session.message == "saved gui_test_saved.yaml"
    app.w_bundled.value = "g1_two_feet"
    app.edit(lambda: app.session.load(app.w_bundled.value))
    assert app.session.analysis.stance.robot.name == "g1"
    assert "left_knee_joint" in app._joint_widgets and "leg_left_4_joint" not in app._joint_widgets
    app.edit(lambda: app.session.load("gui_test_saved.yaml"))
    assert app.session.state == saved.saved_as("gui_test_saved.yaml")
    assert "CANNOT BALANCE" in app.w_results.content
    reset(app)
    assert app.session.analysis.stance.robot.name == "talos"


def test_app_gizmo_drag_moves_the_robot(app):
    import asyncio
    from types import SimpleNamespace

    reset(app)
    before = app.session.analysis.stance
    gizmo = app._gizmos["impact"]
    start = np.array(gizmo.position, dtype=float)
    callback = app._on_gizmo("impact")
    for k, phase in enumerate(("start", "update", "update", "end")):
        gizmo.position = start + np.array([0.0, 0.02, -0.03]) * k / 3  # as the browser moves it
        asyncio.run(callback(SimpleNamespace(target=gizmo, phase=phase)))
    goal = start + np.array([0.0, 0.02, -0.03])
    np.testing.assert_allclose(app.session.analysis.impact.model.point, goal, atol=1e-4)
    for a, b in zip(app.session.analysis.stance.contacts, before.contacts, strict=True):
        np.testing.assert_allclose(a.position, b.position, atol=1e-4)
    np.testing.assert_allclose(app._gizmos["impact"].position, goal, atol=1e-4)
    assert app._dragging is None and not app._drag_pending
    assert (
        f'id="ib-vmax-com">{app.session.summary.max_contact_velocity:.3f} m/s'
        in app.w_results.content
    )
    # Out of reach: the robot goes part of the way, the gizmo snaps back onto the hand.
    gizmo.position = goal + np.array([3.0, 0.0, 0.0])
    asyncio.run(callback(SimpleNamespace(target=gizmo, phase="end")))
    assert "out of reach" in app.session.message
    np.testing.assert_allclose(
        app._gizmos["impact"].position, app.session.analysis.impact.model.point, atol=1e-6
    )


# -- command line -------------------------------------------------------------------------------
def test_cli_gui_bad_scenario_exit_2(capsys):
    assert cli.main(["gui", "no_such_scenario_xyz"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown scenario" in err and "Traceback" not in err


def test_cli_gui_bad_host_exit_2(capsys):
    # 192.0.2.1 (TEST-NET-1) is no address of this machine: refused at once, nothing is sent.
    assert cli.main(["gui", "--host", "192.0.2.1", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "cannot serve on 192.0.2.1" in err
    assert cli.main(["gui", "--port", "70000"]) == 2
    assert "0..65535" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_gui_serves_and_stops_on_ctrl_c():
    proc = subprocess.Popen(
        [sys.executable, "-m", "impact_balance", "gui", "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.time() + 240
        url = None
        while time.time() < deadline and url is None:
            line = proc.stdout.readline()
            if not line:
                break
            if line.startswith("impact-balance gui:"):
                url = line.split(" at ")[1].split()[0]
        assert url is not None and url.startswith("http://127.0.0.1:"), (
            proc.stderr.read() if proc.poll() else url
        )
        assert "palm_push_two_feet" in line
        with urllib.request.urlopen(url, timeout=10) as response:
            assert response.status == 200
        proc.send_signal(signal.SIGINT)
        assert proc.wait(timeout=30) == 0
        assert "Traceback" not in proc.stderr.read()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_app_angular_momentum_field_sets_the_key_and_the_answer(app):
    reset(app)
    paper = app.session.summary.max_contact_velocity
    app.w_angular_momentum.value = 0.0
    try:
        assert app.session.state.scenario.angular_momentum_damping_time == 0.0
        extended = app.session.analysis.impact.extended
        assert app.session.summary.max_contact_velocity == extended.max_contact_velocity < paper
        assert f'id="ib-vmax-com">{extended.max_contact_velocity:.3f} m/s' in app.w_results.content
    finally:
        app.w_angular_momentum.value = -1.0
    assert app.session.state.scenario.angular_momentum_damping_time is None
    assert app.session.summary.max_contact_velocity == paper
