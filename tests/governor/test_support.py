"""The governor's contact-aware option (governor/support.py): the smaller of the two models'
maximum speeds, the rates' reuse between recomputations, warm starts, bad arguments."""

from __future__ import annotations

import numpy as np
import pytest

import impact_balance as ib
from impact_balance.exceptions import GovernorError
from impact_balance.governor import ContactAwareOptions, Governor
from impact_balance.governor.support import combine
from impact_balance.impact.contact_aware import contact_impact
from impact_balance.scenario import load_scenario


def contact_aware_maximum(name: str, margin: float) -> float:
    """The contact-aware criterion computed independently: analyze(), contact_impact at 1 m/s at
    both restitution bounds, the first exit of the scenario's CoM velocity from the inset area."""
    a = ib.analyze(name)
    spec = a.scenario.impact.spec()
    area = a.areas.com_velocity_area_inset(margin) if margin > 0 else a.areas.com_velocity_area
    G, h = area.halfplanes
    c0 = np.asarray(a.com_velocity, dtype=float)
    best = np.inf
    for c_r in spec.restitution:
        rate = G @ contact_impact(a.stance, spec, 1.0, restitution=c_r).com_velocity_jump
        slack = h - G @ c0
        best = min(best, float(np.min(slack[rate > 1e-12] / rate[rate > 1e-12])))
    return best


def governors(name: str, margin: float, every: int = 5):
    scenario = load_scenario(name).model_copy(update={"zmp_margin": margin})
    return Governor(scenario), Governor(scenario, contact_aware=ContactAwareOptions(every=every))


def test_g1_is_bounded_by_its_feet():
    """G1: the contact-aware jump is larger than the floating set's, so it binds (0.40 m/s against
    0.64 with the 10 mm margin), and the answer is the independent computation's."""
    plain, aware = governors("g1_two_feet", 0.01)
    q, v = aware.configuration, np.zeros(aware.nv)
    floating, limit = plain.limit(q, v), aware.limit(q, v)
    assert limit.binding == "contact_aware"
    assert limit.max_contact_velocity == pytest.approx(
        contact_aware_maximum("g1_two_feet", 0.01), abs=1e-6
    )
    assert 0.38 < limit.max_contact_velocity < 0.43 < 0.6 < floating.max_contact_velocity
    assert limit.safe_interval == pytest.approx((0.0, limit.max_contact_velocity))
    assert limit.ceiling == pytest.approx(limit.max_contact_velocity)


def test_two_flat_feet_keep_the_floating_answer():
    """Talos on two flat feet: the floating set binds (0.481 against 0.527 without margin): the
    option changes nothing."""
    plain, aware = governors("palm_push_two_feet", 0.0)
    q, v = aware.configuration, np.zeros(aware.nv)
    a, b = plain.limit(q, v), aware.limit(q, v)
    assert b.binding == "floating"
    assert b.max_contact_velocity == a.max_contact_velocity
    assert b.safe_interval == a.safe_interval
    assert contact_aware_maximum("palm_push_two_feet", 0.0) > a.max_contact_velocity


def test_rates_are_reused_between_recomputations():
    """With every=3 the rates are recomputed at postures 1, 4, 7...; velocity-only ticks do not
    count; the answer between recomputations uses the last rates with the current area."""
    _, aware = governors("g1_two_feet", 0.01, every=3)
    q0 = aware.configuration.copy()
    v = np.zeros(aware.nv)
    ages = []
    for k in range(5):
        q = q0.copy()
        q[7:] += 0.001 * k
        aware.limit(q, v)
        aware.limit(q, v)  # velocity-only: same posture
        ages.append(aware._support.answer(aware.posture.com_criterion, np.zeros(3)).age)
    assert ages == [0, 1, 2, 0, 1]


def test_warm_start_reaches_the_same_fixed_point():
    a = ib.analyze("palm_push_ramp")
    spec = a.scenario.impact.spec()
    cold = contact_impact(a.stance, spec, 1.0)
    warm = contact_impact(
        a.stance,
        spec,
        1.0,
        initial_dxi=np.concatenate([cold.com_velocity_jump_3d, cold.angular_velocity_jump]),
    )
    assert cold.converged and warm.converged
    assert warm.iterations < cold.iterations
    assert np.allclose(warm.com_velocity_jump, cold.com_velocity_jump, atol=1e-8)


def test_combine_intersects_the_safe_intervals():
    assert combine((0.0, 0.5), (0.0, 0.4)) == (0.0, 0.4)
    assert combine((0.1, 0.5), (0.0, 0.4)) == (0.1, 0.4)
    assert combine((0.45, 0.5), (0.0, 0.4)) is None
    assert combine(None, (0.0, 0.4)) is None


@pytest.mark.parametrize(
    "kwargs, field",
    [
        ({"criterion": "zmp", "contact_aware": True}, "contact_aware"),
        ({"contact_aware": {"every": 0}}, "contact_aware.every"),
    ],
)
def test_bad_options_are_governor_errors(kwargs, field):
    with pytest.raises(GovernorError) as info:
        if isinstance(kwargs.get("contact_aware"), dict):  # the options refuse it when made
            kwargs = {**kwargs, "contact_aware": ContactAwareOptions(**kwargs["contact_aware"])}
        Governor("palm_push_two_feet", **kwargs)
    assert info.value.field == field
