"""Push predictions that keep the capture within the CoM's reach (``predict_push`` with a reach)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco")  # the push predictions live beside the simulation (the sim extra)

from impact_balance import analyze
from impact_balance.balance.reach import ComReach
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.push import PushOutcome, boundary_impulse, predict_push
from impact_balance.sim.trials.setup import Push
from tests.helpers.lipm import stop_distance
from tests.helpers.reach import evenly_spaced_reach, extent_by_bisection

SUMMARY = {"outcome": "balanced", "com_velocity_margin_at_end": 0.0}


@pytest.fixture(scope="module")
def setup():
    scenario = load_scenario("palm_push_two_feet").replace(angular_momentum_damping_time=0.1)
    return SimpleNamespace(analysis=analyze(scenario))


@settings(max_examples=30, deadline=None)
@given(
    level=st.floats(0.2, 1.1),
    k=st.integers(0, 7),
    radii=st.lists(st.floats(0.0, 0.2), min_size=8, max_size=8),
    margin=st.sampled_from([0.0, 0.01]),
)
def test_called_safe_with_a_reach_means_the_lipm_stops_within_it(setup, level, k, radii, margin):
    # Independent of the formula: a pelvis push (no angular momentum) along a sampled
    # direction, the LIPM integrated with the ZMP at the inset area's extent.
    assume(abs(level - 1.0) > 1e-3)  # on the boundary itself the LIPM stops only at infinity
    a = setup.analysis
    angle = k * math.pi / 4
    u = np.array([math.cos(angle), math.sin(angle)])
    J = level * boundary_impulse(a.areas.com_velocity_area, a.stance.mass, angle)
    reach = evenly_spaced_reach(radii)
    p = predict_push(setup, Push(angle, J), float(a.stance.com[2]), a.stance.com, reach)
    free = predict_push(setup, Push(angle, J), float(a.stance.com[2]), a.stance.com)
    outcome = PushOutcome(push=Push(angle, J), relative=None, summary=SUMMARY, prediction=p)
    without = PushOutcome(push=Push(angle, J), relative=None, summary=SUMMARY, prediction=free)
    omega = float(a.areas.omega)
    if outcome.safe("com", margin, omega):
        assert without.safe("com", margin, omega)
        area = a.areas.com_velocity_area.inset(omega * margin)
        speed = float(np.linalg.norm(p.com_velocity))
        stop = stop_distance(speed, extent_by_bisection(area, u) / omega, omega)
        assert stop <= reach.along(u) + 1e-9


def test_a_reach_beyond_the_area_changes_nothing_and_none_calls_nothing_safe(setup):
    a = setup.analysis
    omega = float(a.areas.omega)
    for k in range(8):
        angle = k * math.pi / 4
        J = 0.6 * boundary_impulse(a.areas.com_velocity_area, a.stance.mass, angle)
        push = Push(angle, J)
        calls = []
        for reach in (None, evenly_spaced_reach([10.0] * 8), evenly_spaced_reach([0.0] * 8)):
            p = predict_push(setup, push, float(a.stance.com[2]), a.stance.com, reach)
            o = PushOutcome(push=push, relative=None, summary=SUMMARY, prediction=p)
            calls.append(o.safe("com", 0.01, omega))
            margin = p.reach_margin(0.01, omega)
            assert (margin is None) == (reach is None)
        assert calls[0] is True
        assert calls[1] is True
        assert calls[2] is False


@pytest.mark.slow
def test_push_test_com_reach_reports_the_reach_and_each_pushs_margin(capsys, tmp_path):
    import json

    from impact_balance.balance.reach import reach_speed_limit
    from tests.helpers.cli import run_cli

    rc, out, _ = run_cli(
        capsys,
        "push-test",
        "palm_push_two_feet",
        "--controller",
        "id",
        "--directions",
        "2",
        "--relative",
        "0.5",
        "--com-reach",
        "--no-finite-push",  # the impulse's velocity against the reach (kappa: test_push_finite)
        "--json",
        "--journal",
        str(tmp_path / "j.jsonl"),
    )
    assert rc == 0
    doc = json.loads(out)
    reach = doc["com_reach"]
    assert len(reach["radii"]) == 16 and min(reach["radii"]) > 0.0
    a = analyze(load_scenario("palm_push_two_feet").replace(zmp_margin=0.0))
    omega, margin = doc["omega"], doc["zmp_margin"]
    limit = ComReach(
        np.deg2rad(reach["azimuths_deg"]), np.array(reach["radii"]), reach["height"], np.zeros(1)
    )
    area = a.areas.com_velocity_area.inset(omega * margin)
    for push in doc["pushes"]:
        v = np.array(push["predicted_com_velocity"])
        expected = reach_speed_limit(area, omega, limit, v) - float(np.linalg.norm(v))
        assert push["com_reach_margin"] == pytest.approx(expected, abs=1e-9)
        assert push["com_criterion_safe"] == (push["com_reach_margin"] >= 0.0)
