"""A contact's size: both lengths positive (a sole) or both zero (a point foot)."""

from __future__ import annotations

import pytest

from impact_balance.exceptions import ScenarioError
from impact_balance.scenario.validate import scenario_from_dict


def _scenario(size):
    return {
        "robot": "go2",
        "configuration": "standing",
        "contacts": [
            {"frame": f, "friction": 0.7, "size": size, "normal": [0, 0, 1]}
            for f in ("FL_foot", "FR_foot", "RL_foot", "RR_foot")
        ],
    }


def test_a_point_is_size_zero_zero_and_a_half_point_is_refused():
    scenario = scenario_from_dict(_scenario([0, 0]))
    assert all(c.is_point for c in scenario.build_stance().contacts)
    for bad in ([0, 0.1], [0.1, 0], [-0.1, -0.1]):
        with pytest.raises(ScenarioError) as err:
            scenario_from_dict(_scenario(bad))
        text = str(err.value)
        assert "contacts[0].size" in text and "[0, 0]" in text, text
        assert str(bad[0]) in text or str(bad[1]) in text, text
