"""The ``id`` controller clamps its desired ZMP into the area of the cones its QP enforces."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")

from impact_balance import analyze
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController


def _written(scenario: Scenario, scale: float, margin: float) -> Scenario:
    """The scenario with every contact's friction and size as the QP has them, in the file."""
    raw = scenario.model_dump(exclude_unset=True)
    raw.pop("source", None)
    for contact in raw["contacts"]:
        contact["friction"] = contact.get("friction", 0.7) * scale
        contact["size"] = [max(s - 2 * margin, 0.5 * s) for s in contact["size"]]
    return Scenario.from_mapping(raw, scenario.source)


@pytest.mark.parametrize(
    ("name", "scale", "margin"),
    [("talos_three_contacts", 0.65, 0.0), ("talos_three_contacts", 0.5, 0.01)],
)
def test_the_clamp_area_is_the_librarys_at_the_qps_contacts(name, scale, margin):
    scenario = load_scenario(name)
    gains = dataclasses.replace(InverseDynamicsGains(), friction_scale=scale, cop_margin=margin)
    controller = InverseDynamicsController(analyze(scenario), gains=gains)
    expected = analyze(_written(scenario, scale, margin)).areas.zmp_area
    np.testing.assert_allclose(controller.feedback.zmp_area.vertices, expected.vertices, atol=1e-9)
    # narrower than the scenario's own area, which the controller used to clamp into
    assert controller.feedback.zmp_area.area < analyze(scenario).areas.zmp_area.area


def test_at_full_friction_without_margin_the_clamp_is_the_analysis_area():
    analysis = analyze(load_scenario("talos_three_contacts"))
    gains = dataclasses.replace(InverseDynamicsGains(), friction_scale=1.0, cop_margin=0.0)
    controller = InverseDynamicsController(analysis, gains=gains)
    assert controller.feedback.zmp_area is analysis.areas.zmp_area


def test_the_criterions_friction_scale_does_not_move_the_controller():
    scenario = load_scenario("talos_three_contacts")
    own = InverseDynamicsController(analyze(scenario)).feedback.zmp_area
    judged = InverseDynamicsController(analyze(scenario.replace(friction_scale=0.3)))
    np.testing.assert_allclose(judged.feedback.zmp_area.vertices, own.vertices, atol=1e-12)
