"""``pose`` with point contacts on a humanoid: placed by position, laid flat, normals written."""

from __future__ import annotations

import numpy as np
import yaml

from impact_balance.scenario import load_scenario
from impact_balance.scenario.bundled import scenario_path
from tests.helpers.cli import run_cli


def _draft(tmp_path, normal=None):
    raw = yaml.safe_load(scenario_path("palm_push_two_feet").read_text())
    for c in raw["contacts"]:
        c["size"] = [0, 0]
        c.pop("offset", None)
        if normal is not None:
            c["normal"] = normal
    path = tmp_path / "talos_points.yaml"
    path.write_text(yaml.safe_dump(raw))
    return path


def test_point_soles_on_the_ground_are_written_flat(capsys, tmp_path):
    draft, out = _draft(tmp_path), tmp_path / "posed.yaml"
    before = load_scenario(str(draft)).build_stance().contacts[1].position
    target = before + np.array([0.02, 0.0, 0.0])
    rc, text, err = run_cli(
        capsys,
        "pose",
        str(draft),
        "--place",
        "right_sole_link",
        *map(str, target),
        "--out",
        str(out),
    )
    assert rc == 0, err
    written = yaml.safe_load(out.read_text())
    assert [c.get("normal") for c in written["contacts"]] == [[0.0, 0.0, 1.0]] * 2
    assert "laid flat" in text
    stance = load_scenario(str(out)).build_stance()
    assert np.allclose(stance.contacts[1].position, target, atol=1e-4)
    assert all(c.is_point for c in stance.contacts)


def test_normal_on_a_point_contact_is_its_surface_normal(capsys, tmp_path):
    draft, out = _draft(tmp_path, normal=[0, 0, 1]), tmp_path / "posed.yaml"
    stance = load_scenario(str(draft)).build_stance()
    before = stance.contacts[1].position
    frame_before = stance.frame_pose("right_sole_link").rotation
    n = [0.0, -0.5, 0.866]
    rc, _, err = run_cli(
        capsys,
        "pose",
        str(draft),
        "--place",
        "right_sole_link",
        *map(str, before),
        "--normal",
        *map(str, n),
        "--out",
        str(out),
    )
    assert rc == 0, err
    written = yaml.safe_load(out.read_text())
    assert np.allclose(written["contacts"][1]["normal"], np.array(n) / np.linalg.norm(n), atol=1e-5)
    posed = load_scenario(str(out)).build_stance()
    assert np.allclose(posed.contacts[1].normal, np.array(n) / np.linalg.norm(n), atol=1e-6)
    # a point is not turned: its frame keeps (nearly) its orientation
    turned = posed.frame_pose("right_sole_link").rotation @ frame_before.T
    assert np.degrees(np.arccos(np.clip((np.trace(turned) - 1) / 2, -1, 1))) < 10
