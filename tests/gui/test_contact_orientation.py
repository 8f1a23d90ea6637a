"""A contact's orientation in the GUI: offset rpy in its frame, or world normal and angle.

Switching between the two forms keeps the contact where it is (checked against the scenario
reader's own :func:`surface_rotation`), and the session analyses the edited form like a file.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from impact_balance.analysis.analyze import analyze
from impact_balance.geometry.spatial import surface_rotation
from impact_balance.gui import Session
from impact_balance.gui.contact_orientation import (
    RPY_MODE,
    WORLD_NORMAL_MODE,
    mode_of,
    normal_angle,
    switch_changes,
)

angles = st.floats(min_value=-math.pi, max_value=math.pi, allow_nan=False)


def rotation(r: float, p: float, y: float) -> np.ndarray:
    return pin.rpy.rpyToMatrix(r, p, y)


@settings(max_examples=60, deadline=None)
@given(angles, angles, angles, angles, angles, angles)
def test_normal_and_angle_rebuild_the_rotation(fr, fp, fy, cr, cp, cy):
    frame, contact = rotation(fr, fp, fy), rotation(cr, cp, cy)
    normal, angle = normal_angle(frame, contact)
    assert -math.pi <= angle <= math.pi
    assert np.linalg.norm(normal) == pytest.approx(1.0)
    # The scenario reader's construction gives the same contact back.
    assert np.allclose(surface_rotation(frame, normal, angle), contact, atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(angles, angles, angles, angles, angles, angles)
def test_switching_forms_keeps_the_world_rotation(fr, fp, fy, cr, cp, cy):
    frame, contact = rotation(fr, fp, fy), rotation(cr, cp, cy)
    to_normal = switch_changes(2, WORLD_NORMAL_MODE, frame, contact, [0.01, 0.0, -0.02])
    normal = to_normal[("contacts", 2, "normal")]
    angle = to_normal[("contacts", 2, "angle")]
    assert to_normal[("contacts", 2, "offset")] == {"position": [0.01, 0.0, -0.02]}
    assert np.allclose(surface_rotation(frame, normal, angle), contact, atol=1e-9)
    to_rpy = switch_changes(2, RPY_MODE, frame, contact, [0.01, 0.0, -0.02])
    assert to_rpy[("contacts", 2, "normal")] is None and to_rpy[("contacts", 2, "angle")] is None
    rpy = to_rpy[("contacts", 2, "offset")]["rpy"]
    assert np.allclose(frame @ pin.rpy.rpyToMatrix(*rpy), contact, atol=1e-9)


def test_an_unknown_form_is_refused_by_name():
    with pytest.raises(ValueError, match="'sideways'"):
        switch_changes(0, "sideways", np.eye(3), np.eye(3), [0.0, 0.0, 0.0])


def test_mode_of_a_contact_mapping():
    assert mode_of({"frame": "f", "normal": [0, 0, 1]}) == WORLD_NORMAL_MODE
    assert mode_of({"frame": "f", "offset": {"rpy": [0.1, 0, 0]}}) == RPY_MODE
    assert mode_of({"frame": "f"}) == RPY_MODE


def test_session_edits_a_world_normal_contact_like_a_file(tmp_path):
    """The ramp's sole, switched to its world normal: the same answer; a steeper normal typed
    in the session is analysed as the same file read by ``analyze``."""
    session = Session("palm_push_ramp", workspace=tmp_path)
    before = session.summary.max_contact_velocity
    stance = session.analysis.stance
    sole = stance.contacts[1]
    frame = stance.frame_pose(sole.spec.frame).rotation
    assert session.apply(switch_changes(1, WORLD_NORMAL_MODE, frame, sole.rotation, [0, 0, 0]))
    assert session.state.get(("contacts", 1, "normal")) == pytest.approx(sole.normal, abs=1e-12)
    assert session.summary.max_contact_velocity == pytest.approx(before, rel=1e-9)
    # A 20-degree ramp instead of 30 (normal tilted backwards, about world y).
    tilt = math.radians(20.0)
    assert session.set(("contacts", 1, "normal"), [-math.sin(tilt), 0.0, math.cos(tilt)])
    assert session.analysis.stance.contacts[1].normal == pytest.approx(
        [-math.sin(tilt), 0.0, math.cos(tilt)], abs=1e-12
    )
    assert session.set(("contacts", 1, "angle"), 0.3)
    path = session.save("ramp20.yaml")
    assert path is not None, session.message
    again = analyze(str(path))
    assert again.impact.max_contact_velocity == pytest.approx(
        session.summary.max_contact_velocity, rel=1e-12
    )
    assert again.stance.contacts[1].rotation == pytest.approx(
        session.analysis.stance.contacts[1].rotation, abs=1e-12
    )
    # Both forms at once are refused with the schema's message; the state is kept.
    assert not session.set(("contacts", 1, "offset", "rpy"), [0.1, 0.0, 0.0])
    assert session.refused and "not both" in session.message
    assert session.state.get(("contacts", 1, "angle")) == 0.3
