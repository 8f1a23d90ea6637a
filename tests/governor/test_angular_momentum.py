"""With ``angular_momentum_damping_time`` set, the governor answers what ``analyze()`` answers."""

from __future__ import annotations

import pytest

from impact_balance import analyze
from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario


@pytest.mark.parametrize("name", ["palm_push_two_feet", "kick_one_foot", "g1_two_feet"])
@pytest.mark.parametrize("tau", [0.0, 0.1])
def test_the_governor_answers_analyze_default_with_the_angular_momentum(name, tau):
    scenario = load_scenario(name).replace(angular_momentum_damping_time=tau, velocity_margin=0.01)
    governor = Governor(scenario)
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    expected = analyze(scenario).impact
    assert expected.extended is not None
    assert limit.status == expected.extended.status
    assert limit.max_contact_velocity == pytest.approx(
        expected.extended.max_contact_velocity, abs=1e-9
    )
    assert limit.safe_interval == pytest.approx(expected.safe_interval, abs=1e-9)
    # the scenario of a tick keeps the option
    replay = governor.scenario_at(governor.configuration, scenario.com_velocity)
    assert replay.angular_momentum_damping_time == tau


@pytest.mark.parametrize("name", ["talos_three_contacts", "palm_push_two_feet"])
def test_the_governor_answers_analyze_with_the_friction_scale(name):
    scenario = load_scenario(name).replace(friction_scale=0.65)
    governor = Governor(scenario)
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    expected = analyze(scenario).impact
    assert limit.max_contact_velocity == pytest.approx(
        expected.default.max_contact_velocity, abs=1e-9
    )
    assert (
        governor.scenario_at(governor.configuration, scenario.com_velocity).friction_scale == 0.65
    )
