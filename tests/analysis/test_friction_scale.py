"""``friction_scale``: the criterion at a share of every contact's friction."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import analyze
from impact_balance.analysis.analyze import contact_model_areas
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario import Scenario, load_scenario

HAND_HOLD = load_scenario("talos_three_contacts")


def _frictions_written(scenario: Scenario, scale: float) -> Scenario:
    """The same scenario with every contact's friction multiplied in the file itself."""
    raw = scenario.model_dump(exclude_unset=True)
    raw.pop("source", None)
    for contact in raw["contacts"]:
        contact["friction"] = contact.get("friction", 0.7) * scale
    return Scenario.from_mapping(raw, scenario.source)


def _inside(inner: Polygon, outer: Polygon, tol: float) -> bool:
    G, h = (np.asarray(a) for a in outer.halfplanes)
    return bool(np.all(inner.vertices @ G.T <= h + tol))


@pytest.mark.parametrize("name", ["palm_push_two_feet", "talos_three_contacts", "g1_two_feet"])
def test_scale_one_is_the_default_to_the_last_digit(name):
    scenario = load_scenario(name)
    default = analyze(scenario).to_dict()
    one = analyze(scenario.replace(friction_scale=1.0)).to_dict()
    for d in (default, one):
        d.pop("timings_ms")
    assert json.dumps(one) == json.dumps(default)
    assert "friction_scale" not in default


@pytest.mark.parametrize("scale", [0.65, 0.3])
def test_the_option_equals_frictions_written_in_the_file(scale):
    scaled = analyze(HAND_HOLD.replace(friction_scale=scale))
    written = analyze(_frictions_written(HAND_HOLD, scale))
    np.testing.assert_allclose(
        scaled.areas.zmp_area.vertices, written.areas.zmp_area.vertices, atol=1e-9
    )
    assert scaled.impact.max_contact_velocity == pytest.approx(
        written.impact.max_contact_velocity, abs=1e-9
    )
    # the analysis reports the scenario's own frictions, and the factor
    doc = scaled.to_dict()
    assert doc["friction_scale"] == scale
    assert [c["friction"] for c in doc["contacts"]] == [c.friction for c in HAND_HOLD.contacts]
    # the library's function for a controller's contact model gives the same areas
    areas = contact_model_areas(HAND_HOLD, scaled.stance, scale)
    np.testing.assert_allclose(areas.zmp_area.vertices, scaled.areas.zmp_area.vertices, atol=1e-12)


@settings(max_examples=12, deadline=None)
@given(scale=st.floats(0.05, 1.0))
def test_a_smaller_friction_gives_areas_inside_the_full_ones(scale):
    full = analyze(HAND_HOLD).areas
    scaled = analyze(HAND_HOLD.replace(friction_scale=scale)).areas
    assert _inside(scaled.zmp_area, full.zmp_area, 1e-7)
    assert _inside(scaled.com_velocity_area, full.com_velocity_area, 1e-6)
    assert scaled.zmp_area.area <= full.zmp_area.area + 1e-9


def test_on_feet_alone_the_zmp_area_barely_moves():
    scenario = load_scenario("palm_push_two_feet")
    full = analyze(scenario).areas.zmp_area.area
    scaled = analyze(scenario.replace(friction_scale=0.65)).areas.zmp_area.area
    assert scaled == pytest.approx(full, rel=1e-6)


@pytest.mark.parametrize("bad", [0.0, 1.01, float("nan"), -1.0])
def test_a_bad_scale_names_the_field_and_value(bad):
    with pytest.raises(ScenarioError) as info:
        HAND_HOLD.replace(friction_scale=bad)
    assert info.value.field == "friction_scale"
