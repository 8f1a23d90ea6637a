"""analyze()'s areas step is the governor's (posture_areas, from the stance's arrays): the same
polytope as wrench_polytope and the same numbers as projecting it, for every bundled stance and for
frictions either side of 1 (the compiled path and the friction-normalised one)."""

from __future__ import annotations

import numpy as np
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.analysis.analyze import stance_areas
from impact_balance.balance.areas import areas_from_polytope
from impact_balance.contacts.wrench_polytope import wrench_polytope
from impact_balance.scenario import bundled_scenarios

NAMES = sorted(bundled_scenarios())


def _with_friction(name: str, scale: float):
    scenario = ib.load_scenario(name)
    contacts = [
        c.model_copy(update={"friction": float(c.friction) * scale}) for c in scenario.contacts
    ]
    return scenario.model_copy(update={"contacts": contacts})


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(NAMES), scale=st.sampled_from([1.0, 0.3, 2.5, 40.0]))
def test_analyze_areas_equal_the_polytope_projection(name, scale):
    scenario = _with_friction(name, scale)
    stance = scenario.build_stance()
    polytope, areas = stance_areas(scenario, stance)
    want_polytope = wrench_polytope(stance, scenario.torque_limits, scenario.gravity)
    want = areas_from_polytope(want_polytope, scenario.plane_height, scenario.zmp_margin)
    for field in ("A", "b", "C", "d", "F", "grasp", "com"):
        np.testing.assert_array_equal(getattr(polytope, field), getattr(want_polytope, field))
    if want_polytope.scaling is None:
        assert polytope.scaling is None
    else:
        np.testing.assert_array_equal(polytope.scaling, want_polytope.scaling)
    assert (polytope.n_cwc_rows, polytope.mass, polytope.gravity) == (
        want_polytope.n_cwc_rows,
        want_polytope.mass,
        want_polytope.gravity,
    )
    for got, expected in (
        (areas.force_area, want.force_area),
        (areas.zmp_area, want.zmp_area),
        (areas.com_velocity_area, want.com_velocity_area),
    ):
        np.testing.assert_array_equal(got.vertices, expected.vertices)
        assert got.bounded == expected.bounded
    assert areas.omega == want.omega and areas.n_lp == want.n_lp
