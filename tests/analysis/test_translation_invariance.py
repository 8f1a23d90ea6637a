"""Translating the whole stance changes nothing.

Physics is invariant under a translation of the robot together with its ZMP plane, so the
CoM velocity area and the maximum contact velocity must not move. World coordinates of
1e6 m keep only ~1e-10 m of resolution (0.125 m at 1e15 m), so this holds only because the
pipeline works with positions relative to the stance (see ``Stance``).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.balance.areas import balance_areas
from impact_balance.contacts.stance import Stance
from impact_balance.criteria.com import max_contact_velocity
from impact_balance.criteria.zmp import zmp_max_contact_velocity
from impact_balance.exceptions import NonFiniteResultError
from impact_balance.impact.model import impact_model
from impact_balance.scenario import load_scenario

NAMES = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "talos_three_contacts")


@functools.lru_cache(maxsize=8)
def _setup(name: str):
    scenario = load_scenario(name)
    stance = scenario.build_stance()
    return scenario, stance.robot, stance.q, [c.spec() for c in scenario.contacts]


def _answer(name: str, shift: np.ndarray):
    scenario, robot, q, specs = _setup(name)
    q = q.copy()
    q[:3] += shift
    stance = Stance(robot, q, specs)
    h = scenario.plane_height + shift[2]
    areas = balance_areas(stance, plane_height=h)
    model = impact_model(stance, scenario.impact.spec())
    com_limit = max_contact_velocity(areas.com_velocity_area, model, scenario.com_velocity)
    zmp_limit = zmp_max_contact_velocity(
        areas.zmp_area, model, stance.com, h, scenario.gravity, scenario.impact.duration
    )
    return stance, areas, model, com_limit, zmp_limit


@settings(max_examples=20, deadline=None)
@given(
    name=st.sampled_from(NAMES),
    exponent=st.floats(3.0, 6.0),
    direction=st.tuples(*[st.floats(-1.0, 1.0)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1),
)
def test_translation_invariance(name, exponent, direction):
    shift = 10.0**exponent * np.asarray(direction) / np.linalg.norm(direction)
    st0, areas0, model0, com0, zmp0 = _answer(name, np.zeros(3))
    st1, areas1, model1, com1, zmp1 = _answer(name, shift)
    np.testing.assert_allclose(st1.com - shift, st0.com, atol=1e-9 * 10.0**exponent)
    v0, v1 = areas0.com_velocity_area, areas1.com_velocity_area
    assert v1.area == pytest.approx(v0.area, rel=1e-9)
    np.testing.assert_allclose(v1.vertices, v0.vertices, rtol=0, atol=1e-9)
    np.testing.assert_allclose(model1.W, model0.W, rtol=1e-12, atol=0)
    assert com1.max_contact_velocity == pytest.approx(com0.max_contact_velocity, rel=1e-9)
    # The ZMP criterion works with world ZMPs: ~1e-16 relative rounding of the coordinates.
    assert zmp1.max_contact_velocity == pytest.approx(zmp0.max_contact_velocity, rel=1e-6)


def test_far_horizontal_translation_keeps_the_maximum():
    """1e15 m away (horizontally) the maximum contact velocity is the one at the origin."""
    _, areas0, _, com0, _ = _answer("palm_push_two_feet", np.zeros(3))
    _, areas1, _, com1, _ = _answer("palm_push_two_feet", np.array([1e15, -1e15, 0.0]))
    assert com1.max_contact_velocity == pytest.approx(com0.max_contact_velocity, rel=1e-12)
    assert areas1.com_velocity_area.area == pytest.approx(areas0.com_velocity_area.area, rel=1e-12)


def test_overflow_is_an_error_not_nan():
    """An impact point 1e160 m from the CoM overflows W: a named error, not NaN output."""
    scenario, *_ = _setup("palm_push_two_feet")
    impact = scenario.impact.model_copy(
        update={"offset": scenario.impact.offset.model_copy(update={"position": (1e160, 0.0, 0.0)})}
    )
    with pytest.raises(ib.ImpactBalanceError, match=r"impact\.offset") as info:
        ib.analyze(scenario.model_copy(update={"impact": impact}))
    assert "nan" not in str(info.value).lower()


def test_non_finite_area_names_the_field():
    """A plane 1e160 m below the CoM: the ZMP area's size overflows; the error names it."""
    scenario, *_ = _setup("palm_push_two_feet")
    with pytest.raises(NonFiniteResultError, match="zmp_area") as info:
        ib.analyze(scenario.model_copy(update={"plane_height": -1e160}))
    assert "plane_height" in str(info.value)
