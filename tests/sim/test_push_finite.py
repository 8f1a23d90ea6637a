"""Push predictions with the push's duration (``predict_push(..., finite_push=True)``)."""

from __future__ import annotations

import json
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco")  # the push predictions live beside the simulation (the sim extra)

from impact_balance import analyze
from impact_balance.balance.lipm import finite_push_factor
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.push import (
    PushOutcome,
    PushTestResult,
    boundary_impulse,
    predict_push,
)
from impact_balance.sim.trials.setup import Push
from tests.helpers.cli import assert_one_line_error, run_cli
from tests.helpers.lipm import captured_after_push
from tests.helpers.reach import evenly_spaced_reach, extent_by_bisection

SUMMARY = {
    "outcome": "balanced",
    "com_velocity_margin_at_end": 0.0,
    "reason": None,
    "strict_reason": None,
    "detail": None,
    "events": [],
    "outcome_time": None,
}


@pytest.fixture(scope="module")
def setup():
    return SimpleNamespace(analysis=analyze(load_scenario("palm_push_two_feet")))


@pytest.fixture(scope="module")
def setup_tau():
    scenario = load_scenario("palm_push_two_feet").replace(angular_momentum_damping_time=0.1)
    return SimpleNamespace(analysis=analyze(scenario))


def _outcome(push, prediction) -> PushOutcome:
    return PushOutcome(push=push, relative=None, summary=SUMMARY, prediction=prediction)


@settings(max_examples=25, deadline=None)
@given(
    level=st.floats(0.6, 1.1),
    k=st.integers(0, 7),
    duration=st.floats(0.01, 0.2),
    margin=st.sampled_from([0.0, 0.01]),
)
def test_the_finite_push_call_is_the_lipm_capture_after_the_push(setup, level, k, duration, margin):
    # Independent of the module: the LIPM pushed by J / T for T with the ZMP under the CoM,
    # then braked with the ZMP at the extent of the ZMP area inset by the margin.
    a = setup.analysis
    angle = k * math.pi / 4
    u = np.array([math.cos(angle), math.sin(angle)])
    mass, omega = a.stance.mass, float(a.areas.omega)
    J = level * boundary_impulse(a.areas.com_velocity_area, mass, angle)
    push = Push(angle, J, duration)
    height = float(a.stance.com[2])
    p = predict_push(setup, push, height, a.stance.com, finite_push=True)
    extent = extent_by_bisection(a.areas.zmp_area.inset(margin).affine(1.0, -a.stance.com[:2]), u)
    kappa = finite_push_factor(omega, duration)
    assume(abs(kappa * J / mass - omega * extent) > 1e-4)  # not on the boundary itself
    captured = captured_after_push(J / mass / duration, duration, extent, omega)
    assert _outcome(push, p).safe("com", margin, omega) == captured
    # The paper's criterion stays impulsive.
    impulsive = predict_push(setup, push, height, a.stance.com)
    assert _outcome(push, p).safe("paper_com", margin, omega) == _outcome(push, impulsive).safe(
        "paper_com", margin, omega
    )
    np.testing.assert_allclose(p.com_velocity, impulsive.com_velocity)
    np.testing.assert_allclose(p.finite_push_com_velocity, kappa * J * u / mass)


def test_with_the_angular_momentum_and_the_reach_the_scaled_velocities_are_tested(setup_tau):
    a = setup_tau.analysis
    omega, mass = float(a.areas.omega), a.stance.mass
    reach = evenly_spaced_reach(np.full(8, 0.06))
    area = a.areas.com_velocity_area
    for k in range(8):
        angle = k * math.pi / 4
        push = Push(angle, 0.6 * boundary_impulse(area, mass, angle), 0.05)
        p = predict_push(setup_tau, push, 1.2, a.stance.com, reach, finite_push=True)
        q = predict_push(setup_tau, push, 1.2, a.stance.com, reach)
        kappa = finite_push_factor(omega, 0.05)
        assert p.finite_push_factor == kappa
        held = q.effective_com_velocity - q.com_velocity
        np.testing.assert_allclose(
            p.finite_push_effective_com_velocity, kappa * q.com_velocity + held, atol=1e-12
        )
        expected = min(
            float(area.margins(kappa * q.com_velocity)[0]),
            float(area.margins(kappa * q.com_velocity + held)[0]),
        )
        assert p.default_com_velocity_margin == pytest.approx(expected, abs=1e-12)
        assert p.default_com_velocity_margin < q.default_com_velocity_margin
        # The reach check with the scaled speeds: never more room than the impulsive one.
        assert p.reach_margin(0.01, omega) <= q.reach_margin(0.01, omega) + 1e-12


def test_json_keys_only_with_the_option(setup):
    a = setup.analysis
    omega = float(a.areas.omega)
    push = Push(0.0, 10.0, 0.05)
    on = _outcome(push, predict_push(setup, push, 1.2, a.stance.com, finite_push=True))
    off = _outcome(push, predict_push(setup, push, 1.2, a.stance.com))
    d_on, d_off = on.to_dict(0.01, omega), off.to_dict(0.01, omega)
    assert "finite_push_margin" not in d_off
    assert "predicted_finite_push_com_velocity" not in d_off
    assert "finite_push_factor" not in d_off
    kappa = finite_push_factor(omega, 0.05)
    v = np.array(d_on["predicted_com_velocity"])
    assert d_on["predicted_finite_push_com_velocity"] == pytest.approx((kappa * v).tolist())
    margin = float(a.areas.com_velocity_area.margins(kappa * v)[0]) - omega * 0.01
    assert d_on["finite_push_margin"] == pytest.approx(margin, abs=1e-12)
    assert d_on["predicted_com_velocity_margin"] == pytest.approx(margin + omega * 0.01)
    assert d_on["com_criterion_safe"] == (d_on["finite_push_margin"] >= 0.0)
    changed = {"predicted_com_velocity_margin", "com_criterion_safe"}
    same_on = {k: x for k, x in d_on.items() if "finite_push" not in k and k not in changed}
    assert same_on == {k: x for k, x in d_off.items() if k not in changed}


def test_push_test_refuses_a_bad_duration_by_name(capsys):
    rc, _, err = run_cli(
        capsys, "push-test", "palm_push_two_feet", "--finite-push", "--duration", "0", "--json"
    )
    assert_one_line_error(rc, err, "--duration")


def test_push_test_finite_push_records_the_factor_and_each_pushs_margin(capsys, tmp_path):
    journal = str(tmp_path / "j.jsonl")
    args = ("push-test", "palm_push_two_feet", "--controller", "id", "--directions", "2")
    args += ("--relative", "0.95", "--duration", "0.08", "--json", "--journal", journal)
    rc, out, _ = run_cli(capsys, *args)  # the push's duration is counted by default
    assert rc == 0
    doc = json.loads(out)
    rc, out, _ = run_cli(capsys, *args, "--finite-push")  # the same trials, reused
    assert rc == 0
    again = json.loads(out)
    assert {**again, "wall_time": 0, "reused_trials": 0} == {**doc, "wall_time": 0}
    rc, out, _ = run_cli(capsys, *args, "--no-finite-push")  # the paper's impulse
    assert rc == 0
    plain = json.loads(out)
    assert "finite_push" not in plain
    assert all("finite_push_margin" not in p for p in plain["pushes"])
    omega = doc["omega"]
    kappa = finite_push_factor(omega, 0.08)
    assert doc["finite_push"] is True
    assert all(p["finite_push_factor"] == pytest.approx(kappa) for p in doc["pushes"])
    a = analyze(load_scenario("palm_push_two_feet").replace(zmp_margin=0.0))
    for push in doc["pushes"]:
        v = kappa * np.array(push["predicted_com_velocity"])
        margin = float(a.areas.com_velocity_area.margins(v)[0]) - omega * doc["zmp_margin"]
        assert push["finite_push_margin"] == pytest.approx(margin, abs=1e-9)
        assert push["com_criterion_safe"] == (margin >= 0.0)
    # 0.95 of the boundary: the impulsive default calls it safe at no margin, kappa 1.14 not.
    assert kappa * 0.95 > 1.0
    assert not any(p["com_criterion_safe"] for p in doc["pushes"])
    assert isinstance(PushTestResult, type)


def test_calibrate_pools_finite_push_documents_of_stances_with_different_omegas():
    # The top-level setting is the same on every stance (kappa, which depends on omega, is per
    # push): calibrate pools two stances of one robot scored with the option, and refuses to
    # pool one with the option and one without.
    from impact_balance.exceptions import ScenarioError
    from impact_balance.sim.studies.calibrate import calibrate, training_set

    docs = {}
    for name in ("palm_push_two_feet", "kick_one_foot"):
        for finite in (True, False):
            a = analyze(load_scenario(name))
            setup = SimpleNamespace(analysis=a)
            omega = float(a.areas.omega)
            outcomes = []
            for k in range(4):
                angle = k * math.pi / 2
                J = 0.9 * boundary_impulse(a.areas.com_velocity_area, a.stance.mass, angle)
                push = Push(angle, J, 0.05)
                p = predict_push(setup, push, 1.2, a.stance.com, finite_push=finite)
                outcomes.append(_outcome(push, p))
            result = PushTestResult(
                name, outcomes, {"name": "id"}, {}, setup, 0.01, 0.01, omega, 0.0,
                robot="talos",
                finite_push=(0.05, finite_push_factor(omega, 0.05)) if finite else None,
            )  # fmt: skip
            docs[name, finite] = json.loads(json.dumps(result.to_dict()))
    assert docs["palm_push_two_feet", True]["omega"] != docs["kick_one_foot", True]["omega"]
    sets = [
        training_set(docs[name, True], name) for name in ("palm_push_two_feet", "kick_one_foot")
    ]
    assert all(s.criterion["finite_push"] is True for s in sets)
    calibrate(sets)  # no refusal: one criterion setting
    with pytest.raises(ScenarioError, match="criterion"):
        calibrate([sets[0], training_set(docs["kick_one_foot", False], "plain")])
