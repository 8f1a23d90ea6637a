"""analyze() runs the compiled posture (criteria.posture_kernel) where it answers: its analysis is
the steps' one (areas, impact model, criterion, every answer and the JSON document) to the last
digit, at random postures and options; where it does not answer, the steps do (and raise as they
did)."""

from __future__ import annotations

import json
import time
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.analysis import analyze as pipeline
from impact_balance.balance.areas import areas_from_polytope
from impact_balance.contacts.wrench_polytope import wrench_polytope
from impact_balance.criteria.com import ComCriterion
from impact_balance.exceptions import ScenarioError
from impact_balance.governor import Governor
from impact_balance.impact.model import impact_model
from impact_balance.scenario import load_scenario
from tests.helpers.postures import postures

SCENARIOS = (
    "palm_push_two_feet",
    "palm_push_ramp",
    "kick_one_foot",
    "g1_two_feet",
    "talos_three_contacts",
    "anymal_c_kick_three_feet",
)
_GOVERNORS: dict[str, Governor] = {}


def _governor(name: str) -> Governor:
    if name not in _GOVERNORS:
        _GOVERNORS[name] = Governor(name)
    return _GOVERNORS[name]


def _by_steps(scenario, solve_qp=None):
    """analyze() with the compiled posture turned off: the steps one by one."""
    with mock.patch.object(pipeline, "_compiled_posture", return_value=None):
        return ib.analyze(scenario, solve_qp=solve_qp)


def _document(analysis) -> str:
    out = analysis.to_dict()
    out.pop("timings_ms")
    return json.dumps(out, sort_keys=True)


def _assert_same(a, b) -> None:
    """Two analyses, array for array and number for number."""
    for field in ("force_area", "zmp_area", "com_velocity_area"):
        pa, pb = getattr(a.areas, field), getattr(b.areas, field)
        np.testing.assert_array_equal(pa.vertices, pb.vertices)
        assert pa.bounded == pb.bounded
    for field in ("omega", "plane_height", "mass", "gravity", "n_lp", "zmp_margin", "reason"):
        assert getattr(a.areas, field) == getattr(b.areas, field), field
    np.testing.assert_array_equal(a.areas.com, b.areas.com)
    ia, ib_ = a.impact, b.impact
    assert (ia is None) == (ib_ is None)
    if ia is None:
        return
    for field in ("point", "normal", "cone", "W", "jacobian", "impulse_rates"):
        np.testing.assert_array_equal(getattr(ia.model, field), getattr(ib_.model, field))
    assert ia.model.mass == ib_.model.mass and ia.model.spec == ib_.model.spec
    for field in ("com", "zmp", "extended", "safe_interval"):
        assert getattr(ia, field) == getattr(ib_, field), field
    if ia.contact_velocity is None:
        assert ib_.contact_velocity is None
    else:
        np.testing.assert_array_equal(ia.contact_velocity, ib_.contact_velocity)
    assert _document(a) == _document(b)


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    seed=st.integers(0, 2**32 - 1),
    spread=st.sampled_from([0.002, 0.02]),
    zmp_margin=st.sampled_from([0.0, 0.01]),
    velocity_margin=st.sampled_from([0.0, 0.02]),
    damping=st.sampled_from([None, 0.1]),
    speed=st.floats(0.0, 0.3),
)
def test_analyze_is_the_steps_to_the_last_digit(
    name, seed, spread, zmp_margin, velocity_margin, damping, speed
):
    g = _governor(name)
    rng = np.random.default_rng(seed)
    for q in postures(g, 3, seed, spread):
        com_velocity = rng.normal(0.0, speed, 2)
        scenario = g.scenario_at(q, np.append(com_velocity, 0.0)).replace(
            zmp_margin=zmp_margin,
            velocity_margin=velocity_margin,
            angular_momentum_damping_time=damping,
        )
        stance = scenario.build_stance()
        compiled = pipeline._compiled_posture(scenario, stance, time.perf_counter, True)
        assert compiled is not None  # the kernel answered these postures
        polytope, areas, model, criterion, _ = compiled
        # The parts against the steps computed independently of analyze():
        want_polytope = wrench_polytope(stance, scenario.torque_limits, scenario.gravity)
        for field in ("A", "b", "C", "d", "F", "grasp", "com"):
            np.testing.assert_array_equal(getattr(polytope, field), getattr(want_polytope, field))
        want = areas_from_polytope(want_polytope, scenario.plane_height, scenario.zmp_margin)
        np.testing.assert_array_equal(
            areas.com_velocity_area.vertices, want.com_velocity_area.vertices
        )
        np.testing.assert_array_equal(areas.zmp_area.vertices, want.zmp_area.vertices)
        assert areas.omega == want.omega
        assert scenario.impact is not None
        want_model = impact_model(stance, scenario.impact.spec())
        for field in ("point", "W", "jacobian", "impulse_rates"):
            np.testing.assert_array_equal(getattr(model, field), getattr(want_model, field))
        built = ComCriterion(want.com_velocity_area, want_model, scenario.velocity_margin)
        for field in ("G", "h", "rates"):
            np.testing.assert_array_equal(getattr(criterion, field), getattr(built, field))
        # and the whole analysis against analyze()'s steps
        _assert_same(ib.analyze(scenario), _by_steps(scenario))


@pytest.mark.parametrize("name", ["palm_push_two_feet", "talos_three_contacts"])
def test_the_qp_reads_the_same_polytope(name):
    scenario = load_scenario(name)
    a, b = ib.analyze(scenario, solve_qp=True), _by_steps(scenario, solve_qp=True)
    assert a.impact is not None and a.impact.qp is not None
    _assert_same(a, b)


def _frictions(scenario, scale):
    contacts = [dict(c.model_dump(exclude_unset=True)) for c in scenario.contacts]
    for c in contacts:
        c["friction"] = float(c["friction"]) * scale
    return scenario.replace(contacts=contacts)


@pytest.mark.parametrize(
    "change",
    [
        pytest.param(
            lambda s: s.replace(zmp_margin=0.3), id="no area left (the kernel's fallback)"
        ),
        pytest.param(lambda s: _frictions(s, 3.0), id="frictions above 1"),
        pytest.param(
            lambda s: s.replace(
                impact={**s.impact.model_dump(exclude_unset=True), "inertia": "joint_space"}
            ),
            id="joint-space inertia",
        ),
        pytest.param(lambda s: s.replace(impact=None), id="no impact"),
    ],
)
def test_what_the_kernel_leaves_is_answered_by_the_steps(change):
    scenario = change(load_scenario("palm_push_two_feet"))
    stance = scenario.build_stance()
    assert pipeline._compiled_posture(scenario, stance, time.perf_counter, False) is None
    _assert_same(ib.analyze(scenario), _by_steps(scenario))


def test_no_area_left_is_diagnosed():
    analysis = ib.analyze(load_scenario("palm_push_two_feet").replace(zmp_margin=0.3))
    assert not analysis.areas.can_balance
    assert analysis.areas.reason is not None and analysis.areas.reason.kind == "zmp_margin"
    assert analysis.impact is not None and analysis.impact.com.status == "cannot_balance"


def test_a_plane_above_the_com_is_refused_as_before():
    scenario = load_scenario("kick_one_foot").replace(plane_height=5.0)
    with pytest.raises(ScenarioError) as compiled:
        ib.analyze(scenario)
    with pytest.raises(ScenarioError) as steps:
        _by_steps(scenario)
    assert compiled.value.field == steps.value.field == "plane_height"
    assert str(compiled.value) == str(steps.value)
