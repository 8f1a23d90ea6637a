"""A governor and ``analyze()`` read the scenario's margins the same way, so they agree."""

from __future__ import annotations

import numpy as np
import pytest

from impact_balance import analyze
from impact_balance.exceptions import GovernorError
from impact_balance.governor import CRITERIA, STARTS, ContactAwareOptions, Governor
from impact_balance.scenario import load_scenario


@pytest.mark.parametrize("name", ["palm_push_two_feet", "palm_push_ramp", "kick_one_foot"])
@pytest.mark.parametrize("velocity_margin", [0.0, 0.015])
@pytest.mark.parametrize("zmp_margin", [0.0, 0.01])
def test_the_governor_answers_what_analyze_answers(name, velocity_margin, zmp_margin):
    scenario = load_scenario(name).replace(velocity_margin=velocity_margin, zmp_margin=zmp_margin)
    governor = Governor(scenario)
    assert governor.velocity_margin == velocity_margin
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    expected = analyze(scenario).impact
    assert limit.status == expected.com.status
    assert limit.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-9)
    assert limit.safe_interval == pytest.approx(expected.safe_interval, abs=1e-9)
    # And the scenario of a tick, analysed, is the same answer (margins included).
    replay = governor.scenario_at(governor.configuration, scenario.com_velocity)
    assert (replay.velocity_margin, replay.zmp_margin) == (velocity_margin, zmp_margin)
    again = analyze(replay).impact
    assert again.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-9)


def test_a_margin_lowers_the_answer_and_an_argument_overrides_the_scenario():
    scenario = load_scenario("palm_push_two_feet")
    plain = Governor(scenario)
    from_scenario = Governor(scenario.replace(velocity_margin=0.02))
    from_argument = Governor(scenario, velocity_margin=0.02)
    zeroed = Governor(scenario.replace(velocity_margin=0.02), velocity_margin=0.0)
    q, c = plain.configuration, np.zeros(3)
    a, b, d, z = (
        g.limit_com(q, c).max_contact_velocity
        for g in (plain, from_scenario, from_argument, zeroed)
    )
    assert b < a and b == d and z == a
    assert from_argument.scenario.velocity_margin == 0.02


@pytest.mark.parametrize("margin", [-0.01, 10.5, float("nan"), "fast"])
def test_a_refused_margin_names_the_argument(margin):
    with pytest.raises(GovernorError) as info:
        Governor("palm_push_two_feet", velocity_margin=margin)  # type: ignore[arg-type]
    assert info.value.field == "velocity_margin"


def test_the_zmp_criterion_has_no_velocity_margin():
    with pytest.raises(GovernorError, match="com criterion only"):
        Governor("palm_push_two_feet", "zmp", velocity_margin=0.02)
    # A scenario's own margin is the CoM criterion's: the ZMP governor answers analyze's ZMP one.
    scenario = load_scenario("palm_push_two_feet").replace(velocity_margin=0.02)
    governor = Governor(scenario, "zmp")
    assert governor.velocity_margin == 0.0
    limit = governor.limit_com(governor.configuration, scenario.com_velocity)
    expected = analyze(scenario).impact.zmp_max_contact_velocity
    assert limit.max_contact_velocity == pytest.approx(expected, abs=1e-9)


def test_the_families_are_closed():
    assert CRITERIA == ("com", "zmp") and STARTS == ("union", "warm", "cold")
    with pytest.raises(GovernorError) as info:
        ContactAwareOptions(every=0)
    assert info.value.field == "contact_aware.every"
    with pytest.raises(GovernorError) as info:
        ContactAwareOptions(every=True)  # a bool is not a count
    assert info.value.field == "contact_aware.every"
    assert ContactAwareOptions(every=np.int64(3)).every == 3
    with pytest.raises(GovernorError, match="CoM criterion only"):
        Governor("palm_push_two_feet", "zmp", contact_aware=True)
