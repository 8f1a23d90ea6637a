"""criteria.posture_answer: the compiled call's arrays become the objects the steps make (the
areas, the impact model, the CoM criterion with its margin), or None where the steps must answer."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.balance.lipm import lipm_omega
from impact_balance.criteria.com import ComCriterion, jump_rates_kernel
from impact_balance.criteria.posture_answer import posture_answer
from impact_balance.criteria.posture_kernel import FALLBACK
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import composite_inertia_map, impact_cone, model_from_inertia_map
from impact_balance.scenario import load_scenario

SPEC = load_scenario("palm_push_two_feet").impact.spec()  # type: ignore[union-attr]
PLANE, GRAVITY = 0.0, 9.81


def _polygon(radius: float, turn: float, k: int) -> Polygon:
    """A convex k-gon about the origin (m/s), turned by ``turn`` rad."""
    a = turn + 2 * np.pi * np.arange(k) / k
    return Polygon(radius * np.column_stack([np.cos(a), np.sin(a)]), True)


def _answer_of(area: Polygon, zmp: Polygon, margin: float, zmp_margin: float, mass: float):
    """posture_answer of arrays made by the steps' own functions, and those steps' model."""
    normal, cone = impact_cone(SPEC)
    arm = np.array([0.3, -0.2, 0.25])
    inertia = np.diag([8.0, 7.0, 2.0]) * mass / 60.0
    W = composite_inertia_map(arm, mass, inertia)
    com = np.array([0.01, -0.02, 0.9])
    point = com + arm
    jacobian = np.ones((3, 7))
    model = model_from_inertia_map(SPEC, point, arm, normal, cone, W, mass, jacobian)
    G, h = area.halfplanes
    rates = jump_rates_kernel(model.impulse_rates, mass, G)
    omega = lipm_omega(float(com[2]), PLANE, GRAVITY, field="plane_height")
    force = zmp.vertices / 2.0
    out = (0, force, True, zmp.vertices, True, area.vertices, True, G, h, W, model.impulse_rates)
    answer = posture_answer(
        (*out, rates), SPEC, point, normal, cone, jacobian, mass=mass, omega=omega, com=com,
        plane_height=PLANE, gravity=GRAVITY, zmp_margin=zmp_margin, velocity_margin=margin,
    )  # fmt: skip
    return answer, model, omega, com


@settings(max_examples=40, deadline=None)
@given(
    radius=st.floats(0.05, 2.0),
    turn=st.floats(0.0, 6.3),
    k=st.integers(3, 12),
    margin=st.sampled_from([0.0, 0.01, 0.2]) | st.floats(0.0, 0.3),
    mass=st.floats(5.0, 120.0),
    c0=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
)
def test_the_objects_are_the_steps_objects(radius, turn, k, margin, mass, c0):
    area = _polygon(radius, turn, k)
    zmp = _polygon(0.1, 0.3, 5)
    answer, model, omega, com = _answer_of(area, zmp, margin, 0.01, mass)
    assert answer is not None
    # The impact model: the steps' own, field for field.
    for name in ("point", "normal", "cone", "W", "jacobian", "impulse_rates"):
        np.testing.assert_array_equal(getattr(answer.impact, name), getattr(model, name))
    assert answer.impact.mass == model.mass and answer.impact.spec == model.spec
    # The criterion: ComCriterion's own half-planes (less the margin) and rates, and its answers.
    reference = ComCriterion(area, model, margin)
    np.testing.assert_array_equal(answer.criterion.G, reference.G)
    np.testing.assert_array_equal(answer.criterion.h, reference.h)
    np.testing.assert_array_equal(answer.criterion.rates, reference.rates)
    assert answer.criterion.velocity_margin == reference.velocity_margin == margin
    assert answer.criterion.limit(c0) == reference.limit(c0)
    # The areas: the arrays given, with the LIPM's numbers.
    areas = answer.projected.areas()
    assert areas.com_velocity_area is answer.criterion.area
    np.testing.assert_array_equal(areas.zmp_area.vertices, zmp.vertices)
    np.testing.assert_array_equal(areas.com, com)
    assert (areas.omega, areas.mass, areas.zmp_margin) == (omega, mass, 0.01)


@given(code=st.just(FALLBACK) | st.integers(1, 2**31 - 1))
def test_a_fallback_is_left_to_the_steps(code):
    out = (code, *([None] * 11))  # nothing after the code is read
    answer = posture_answer(
        out, SPEC, np.zeros(3), np.zeros(3), np.zeros((3, 4)), np.zeros((3, 7)), mass=1.0,
        omega=3.0, com=np.zeros(3), plane_height=0.0, gravity=GRAVITY, zmp_margin=0.0,
        velocity_margin=0.0,
    )  # fmt: skip
    assert answer is None
