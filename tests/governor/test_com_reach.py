"""The governor capped within the CoM's reach (``Governor(com_reach=...)``)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance import analyze, load_scenario
from impact_balance.analysis.reach import reach_answer
from impact_balance.balance.reach import ReachOptions, com_reach
from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor

#: A wide Talos stance hit sideways, whose reach binds (the third held-out set's).
WIDE = Path(__file__).parents[2] / "studies" / "held_out_3" / "talos_wide_right_palm_side.yaml"
#: A cheap search (the same code as the default's; the reach is used as given).
CHEAP = ReachOptions(directions=8, bisections=4, iterations=200)


@pytest.fixture(scope="module")
def wide():
    scenario = load_scenario(str(WIDE)).replace(zmp_margin=0.01)
    reach = com_reach(scenario.build_stance(scenario.load_robot()), CHEAP)
    governor = Governor(scenario, com_reach=reach)
    q = governor.configuration.copy()
    # a neighbouring posture: a tick there makes the next tick at q a new posture
    other = q.copy()
    other[-1] += 1e-4
    return scenario, reach, governor, q, other


def _velocity(governor: Governor, q: np.ndarray, com_velocity) -> np.ndarray:
    """A generalized velocity whose CoM velocity is ``com_velocity`` (world xy, m/s) at ``q``."""
    assert governor.posture.key == q.tobytes()
    J = governor.posture.com_jacobian
    return np.linalg.lstsq(J[:2], np.asarray(com_velocity, dtype=float), rcond=None)[0]


@settings(max_examples=6, deadline=None)
@given(st.floats(-0.08, 0.08), st.floats(-0.08, 0.08))
def test_the_cap_is_reach_answer_of_the_same_posture(wide, vx, vy):
    scenario, reach, governor, q, other = wide
    governor.limit(q, np.zeros(governor.nv))
    v = _velocity(governor, q, (vx, vy))
    governor.limit(other, np.zeros(governor.nv))  # the next tick at q evaluates it anew
    limit = governor.limit(q, v)
    assert not limit.posture_reused
    expected = reach_answer(analyze(governor.scenario_at(q, limit.com_velocity)), reach=reach)
    assert limit.max_contact_velocity == pytest.approx(expected.max_contact_velocity, abs=1e-9)
    plain = Governor(scenario).limit(q, v)
    assert limit.max_contact_velocity <= plain.max_contact_velocity
    assert limit.ceiling == pytest.approx(limit.max_contact_velocity, abs=1e-12)
    if limit.max_contact_velocity < plain.max_contact_velocity:
        assert limit.binding == "com_reach"
        assert limit.safe_interval[0] == plain.safe_interval[0]
    else:
        assert limit.binding == plain.binding and limit.safe_interval == plain.safe_interval


def test_the_reach_binds_on_the_wide_stance_from_rest(wide):
    scenario, _, governor, q, other = wide
    governor.limit(other, np.zeros(governor.nv))
    limit = governor.limit(q, np.zeros(governor.nv))
    plain = Governor(scenario).limit(q, np.zeros(governor.nv))
    assert limit.binding == "com_reach"
    assert 0.0 < limit.max_contact_velocity < 0.95 * plain.max_contact_velocity
    # the cap lets through the bound within reach, not the criterion's own maximum
    normal = limit.normal
    capped = governor.cap(-plain.max_contact_velocity * normal, limit)
    assert float(-normal @ capped) == pytest.approx(limit.max_contact_velocity, abs=1e-12)


def test_a_velocity_only_tick_reuses_the_postures_bound(wide):
    scenario, _, governor, q, other = wide
    governor.limit(other, np.zeros(governor.nv))
    first = governor.limit(q, np.zeros(governor.nv))
    v = _velocity(governor, q, (0.03, 0.02))
    again = governor.limit(q, v)
    plain = Governor(scenario).limit(q, v)
    assert again.posture_reused
    assert again.max_contact_velocity == min(first.max_contact_velocity, plain.max_contact_velocity)


def test_a_governor_without_the_reach_has_none():
    governor = Governor("palm_push_two_feet")
    assert governor.com_reach is None
    limit = governor.limit(governor.configuration, np.zeros(governor.nv))
    assert limit.binding == "floating"


@pytest.mark.parametrize(
    "value, criterion, needle",
    [("yes", "com", "must be True"), (True, "zmp", '"com" criterion'), (3, "com", "must be")],
)
def test_bad_reach_options_name_the_field(value, criterion, needle):
    with pytest.raises(GovernorError) as caught:
        Governor("palm_push_two_feet", criterion, com_reach=value)
    assert caught.value.field == "com_reach" and needle in str(caught.value)


def test_the_batch_refuses_a_reach(wide):
    _, _, governor, q, _ = wide
    with pytest.raises(GovernorError) as caught:
        governor.limits(q[None, :], np.zeros((1, governor.nv)))
    assert caught.value.field == "com_reach"
