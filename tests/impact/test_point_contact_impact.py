"""The contact-aware impact model on point feet: the limit of ever smaller soles."""

from __future__ import annotations

import numpy as np
import yaml

from impact_balance.impact.contact_aware import contact_impact
from impact_balance.scenario.bundled import scenario_path
from impact_balance.scenario.validate import scenario_from_dict


def test_point_feet_are_the_limit_of_tiny_soles():
    raw = yaml.safe_load(scenario_path("go2_kick_three_feet").read_text())
    answers = []
    for size in ([0, 0], [1e-6, 1e-6]):
        for c in raw["contacts"]:
            c["size"] = size
        scenario = scenario_from_dict(raw)
        answers.append(contact_impact(scenario.build_stance(), scenario.impact.spec(), 1.0))
    point, sole = answers
    assert point.converged and sole.converged
    assert np.allclose(point.com_velocity_jump_3d, sole.com_velocity_jump_3d, atol=1e-5)
    assert np.allclose(point.contact_impulses, sole.contact_impulses, atol=1e-4)
    assert np.linalg.norm(point.com_velocity_jump) > 0.1  # a real impact, not zero
