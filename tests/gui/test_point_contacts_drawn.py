"""The GUI draws a point contact as a dot, not a sole outline."""

from __future__ import annotations

from impact_balance.analysis.analyze import analyze
from impact_balance.gui.scene import Points, Segments, scene_objects
from impact_balance.scenario.validate import scenario_from_dict
from tests.helpers.quadrupeds import four_point_feet


def test_point_feet_are_dots():
    analysis = analyze(scenario_from_dict(four_point_feet("go2")))
    objects = scene_objects(analysis)
    contacts = [o for o in objects if o.name.startswith("contacts/")]
    dots = [o for o in contacts if isinstance(o, Points)]
    assert len(dots) == 4
    assert not [o for o in contacts if isinstance(o, Segments) and o.name.endswith("/outline")]


def test_the_2d_view_draws_point_feet_as_dots():
    from impact_balance.gui.view2d import PANEL_COLORS, svg_view

    svg = svg_view(analyze(scenario_from_dict(four_point_feet("go2"))))
    color = PANEL_COLORS["contact"]
    assert svg.count(f'r="3.0" fill="{color}" stroke="{color}"') == 4  # four dots
    assert svg.count('stroke-dasharray="4 2"') <= 1  # the legend's sample only: no sole outline
