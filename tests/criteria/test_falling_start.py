"""A falling start says one consistent thing: the contact velocity follows the safe interval."""

from __future__ import annotations

import json

import numpy as np
import pytest

import impact_balance as ib
from impact_balance.cli import main
from impact_balance.criteria.cap import safe_contact_velocity


@pytest.fixture
def falling(tmp_path):
    path = tmp_path / "falling.yaml"
    path.write_text("extends: palm_push_two_feet\ncom_velocity: [0.5, 0.0]\n")
    return path


def test_reference_inside_the_interval_is_kept(falling, capsys):
    analysis = ib.analyze(str(falling))
    im = analysis.impact
    assert not analysis.com_velocity_inside and im.com.status == "already_falling"
    lo, hi = im.safe_interval
    assert 0 < lo < 0.8 < hi  # the 0.8 m/s reference would catch the fall
    np.testing.assert_allclose(im.contact_velocity, im.model.spec.reference_velocity)
    # Independent check: at the contact velocity's approach speed every post-impact vertex is
    # inside.
    speed = im.model.approach_speed(im.contact_velocity)
    post = im.model.post_impact_com_velocities(analysis.com_velocity, speed)
    G, h = analysis.areas.com_velocity_area.halfplanes
    assert np.all(post @ G.T <= h + 1e-9)
    assert main(["analyze", str(falling), "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)["impact"]
    assert doc["contact_velocity"] == pytest.approx([0.8, 0.0, 0.0])
    assert (
        doc["safe_interval"][0]
        <= -np.dot(doc["normal"], doc["contact_velocity"])
        <= doc["safe_interval"][1]
    )
    assert main(["analyze", str(falling)]) == 0
    text = capsys.readouterr().out
    assert "already falling" in text and "(x0.0)" not in text and "contact velocity (0.800" in text


@pytest.mark.parametrize("reference, expected", [(0.2, "lo"), (0.8, 0.8), (2.0, "hi")])
def test_the_approach_speed_moves_to_the_nearest_safe_speed(reference, expected):
    n = np.array([-1.0, 0.0, 0.0])
    lo, hi = 0.5, 1.21
    v = safe_contact_velocity([reference, 0.3, 0.0], n, (lo, hi))
    want = {"lo": lo, "hi": hi}.get(expected, expected)
    assert -n @ v == pytest.approx(want)
    assert v[1:] == pytest.approx([0.3, 0.0])  # only the approach component changes
    assert safe_contact_velocity([reference, 0, 0], n, None) is None


def test_no_safe_speed_means_no_contact_velocity(tmp_path):
    path = tmp_path / "gone.yaml"
    path.write_text("extends: palm_push_two_feet\ncom_velocity: [3.0, 3.0]\n")
    analysis = ib.analyze(str(path))
    assert analysis.impact.safe_interval is None and analysis.impact.contact_velocity is None
    assert analysis.to_dict()["impact"]["contact_velocity"] is None
