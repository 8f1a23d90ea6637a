"""``pose`` on a robot by name (Go2 on three point feet): feet laid flat, and the verdict."""

from __future__ import annotations

import json

import numpy as np
import pytest
import yaml

from impact_balance.analysis.analyze import analyze
from impact_balance.scenario import load_scenario
from tests.helpers.cli import run_cli as run

FEET = ("FR_foot", "RL_foot", "RR_foot")
DRAFT = {
    "robot": "go2",
    "configuration": "standing",
    "contacts": [{"frame": f, "friction": 0.7, "size": [0.02, 0.02]} for f in FEET],
    "impact": {
        "frame": "FL_foot",
        "normal": [-1.0, 0.0, 0.0],
        "reference_velocity": [1.0, 0.0, 0.0],
    },
}


@pytest.fixture
def draft(tmp_path):
    path = tmp_path / "go2_draft.yaml"
    path.write_text(yaml.safe_dump(DRAFT))
    return path


def _pose(capsys, draft, out, *extra):
    return run(capsys, "pose", str(draft), "--place", "FL_foot", *extra, "--out", str(out))


def test_go2_by_name_posed_feet_flat_and_analyzed(capsys, draft, tmp_path):
    out = tmp_path / "go2_kick.yaml"
    rc, text, err = _pose(capsys, draft, out, "0.25", "0.15", "0.08")
    assert rc == 0 and err == "", err
    written = yaml.safe_load(out.read_text())
    assert written["robot"] == "go2"
    assert [c.get("normal") for c in written["contacts"]] == [[0.0, 0.0, 1.0]] * 3
    assert "laid flat (normal: [0, 0, 1]): FR_foot, RL_foot, RR_foot" in text
    scenario = load_scenario(str(out))
    stance = scenario.build_stance()
    for contact in stance.contacts:
        assert np.allclose(contact.normal, [0.0, 0.0, 1.0], atol=1e-9)
    analysis = analyze(scenario)
    assert analysis.verdict == "balanced" and analysis.impact is not None
    last = text.strip().splitlines()[-1]
    assert last.startswith("verdict: can balance (balanced at rest)")
    assert f"{analysis.impact.max_contact_velocity:.3f} m/s" in last


def test_no_flat_keeps_the_frames_orientation(capsys, draft, tmp_path):
    out = tmp_path / "go2_tilted.yaml"
    rc, text, _ = _pose(capsys, draft, out, "0.25", "0.15", "0.08", "--no-flat")
    assert rc == 0
    written = yaml.safe_load(out.read_text())
    assert all("normal" not in c for c in written["contacts"])
    tilts = [
        np.degrees(np.arccos(c.normal[2])) for c in load_scenario(str(out)).build_stance().contacts
    ]
    assert max(tilts) > 20.0  # a point foot's frame follows its calf
    assert "laid flat" not in text


def test_a_stance_that_cannot_balance_is_said_so_with_why(capsys, draft, tmp_path):
    out = tmp_path / "go2_far.yaml"
    rc, text, _ = _pose(capsys, draft, out, "0.55", "0.15", "0.08", "--json")
    assert rc == 0
    doc = json.loads(text)
    assert doc["can_balance"] is False and doc["max_contact_velocity"] is None
    assert doc["verdict"] == analyze(load_scenario(str(out))).verdict
    assert doc["summary"].startswith("CANNOT BALANCE")
    assert "outside the ZMP support area (move it with --com)" in doc["summary"]
    assert doc["flat"] == list(FEET)


def test_the_suggested_com_move_makes_it_balance(capsys, draft, tmp_path):
    out = tmp_path / "go2_moved.yaml"
    rc, text, _ = _pose(capsys, draft, out, "0.45", "0.15", "0.08", "--com", "-0.06", "-0.06")
    assert rc == 0
    assert text.strip().splitlines()[-1].startswith("verdict: can balance")


def test_normal_on_a_point_foot_is_its_surface_normal(capsys, draft, tmp_path):
    out = tmp_path / "go2_ramp.yaml"
    rc, _, err = run(
        capsys,
        "pose", str(draft),
        "--place", "FR_foot", "0.19", "-0.17", "0.02", "--normal", "0", "-0.5", "0.866",
        "--out", str(out),
    )  # fmt: skip
    assert rc == 0, err
    written = yaml.safe_load(out.read_text())
    normals = {c["frame"]: c.get("normal") for c in written["contacts"]}
    ramp = np.array([0.0, -0.5, 0.866]) / np.linalg.norm([0.0, -0.5, 0.866])
    assert normals["FR_foot"] == pytest.approx(ramp, abs=1e-6)
    assert normals["RL_foot"] == normals["RR_foot"] == [0.0, 0.0, 1.0]
    stance = load_scenario(str(out)).build_stance()
    fr = stance.contacts[0]
    assert np.allclose(fr.normal, ramp, atol=1e-6)
    assert np.allclose(fr.position, [0.19, -0.17, 0.02], atol=1e-5)


def test_normal_on_a_point_frame_without_a_contact_is_refused(capsys, draft, tmp_path):
    rc, _, err = run(
        capsys,
        "pose", str(draft),
        "--place", "FL_foot", "0.25", "0.15", "0.08", "--normal", "1", "0", "0",
        "--out", str(tmp_path / "x.yaml"),
    )  # fmt: skip
    assert rc == 2
    assert "FL_foot is on a chain of 3 joints" in err and "--normal" in err
