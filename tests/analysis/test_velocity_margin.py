"""``analyze()`` honours the scenario's ``velocity_margin`` (m/s), as a governor does."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from impact_balance import analyze, cli
from impact_balance.scenario import load_scenario


def inside_distance(vertices: np.ndarray, x: np.ndarray) -> float:
    """Signed distance (positive inside) from ``x`` to the edges' lines of the convex CCW
    polygon ``vertices``, from the vertices alone."""
    best = math.inf
    for a, b in zip(vertices, np.roll(vertices, -1, axis=0), strict=True):
        edge = b - a
        cross = float(edge[0] * (x[1] - a[1]) - edge[1] * (x[0] - a[0]))
        best = min(best, cross / float(np.hypot(*edge)))
    return best


@pytest.mark.parametrize("name", ["palm_push_two_feet", "palm_push_ramp"])
@pytest.mark.parametrize("margin", [0.01, 0.03])
def test_the_worst_post_impact_velocity_lies_the_margin_inside(name, margin):
    plain = analyze(load_scenario(name))
    a = analyze(load_scenario(name).replace(velocity_margin=margin))
    area, model = a.areas.com_velocity_area, a.impact.model
    c0 = np.asarray(a.scenario.com_velocity, dtype=float)
    s = a.impact.max_contact_velocity
    assert a.impact.com.status == "ok"
    assert 0.0 < s < plain.impact.max_contact_velocity
    worst = min(inside_distance(area.vertices, p) for p in model.post_impact_com_velocities(c0, s))
    assert worst == pytest.approx(margin, abs=1e-9)
    assert a.impact.safe_interval == pytest.approx((0.0, s), abs=1e-12)
    # The areas and the ZMP criterion do not depend on it.
    assert np.array_equal(area.vertices, plain.areas.com_velocity_area.vertices)
    assert a.impact.zmp_max_contact_velocity == plain.impact.zmp_max_contact_velocity


def test_zero_is_the_papers_criterion():
    scenario = load_scenario("palm_push_two_feet")
    a, b = analyze(scenario), analyze(scenario.replace(velocity_margin=0.0))
    assert a.impact.max_contact_velocity == b.impact.max_contact_velocity
    assert a.impact.safe_interval == b.impact.safe_interval


def test_the_option_and_the_key_agree(capsys, tmp_path):
    path = tmp_path / "margin.yaml"
    path.write_text("extends: palm_push_two_feet\nvelocity_margin: 0.02\n")
    assert cli.main(["analyze", str(path), "--json"]) == 0
    from_file = json.loads(capsys.readouterr().out)
    assert cli.main(["analyze", "palm_push_two_feet", "--velocity-margin", "0.02", "--json"]) == 0
    from_option = json.loads(capsys.readouterr().out)
    assert from_file["velocity_margin"] == from_option["velocity_margin"] == 0.02
    assert from_file["impact"] == from_option["impact"]
    expected = analyze(load_scenario("palm_push_two_feet").replace(velocity_margin=0.02))
    assert from_option["impact"]["max_contact_velocity"] == expected.impact.max_contact_velocity


@pytest.mark.parametrize(
    ("option", "value", "shown"),
    [
        ("--velocity-margin", "10.5", "--velocity-margin = 10.5: must be in [0, 10] m/s"),
        ("--velocity-margin", "-1", "--velocity-margin = -1.0: must be in [0, 10] m/s"),
        ("--zmp-margin", "11", "--zmp-margin = 11.0: must be in [0, 10] m"),
        ("--zmp-margin", "fast", "--zmp-margin = 'fast': not a number"),
    ],
)
def test_a_refused_margin_is_one_line_and_status_2(capsys, option, value, shown):
    assert cli.main(["analyze", "palm_push_two_feet", option, value]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and shown in err
