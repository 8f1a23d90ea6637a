"""Push predictions with the angular momentum the push leaves (``predict_push``)."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco")  # the push predictions live beside the simulation (the sim extra)

from impact_balance import analyze
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.push import PushOutcome, boundary_impulse, predict_push
from impact_balance.sim.trials.setup import Push


@pytest.fixture(scope="module")
def setups():
    scenario = load_scenario("palm_push_two_feet")
    return {
        tau: SimpleNamespace(analysis=analyze(scenario.replace(angular_momentum_damping_time=tau)))
        for tau in (None, 0.0, 0.1)
    }


@settings(max_examples=30, deadline=None)
@given(
    J=st.floats(1.0, 60.0),
    angle=st.floats(0.0, 2 * math.pi),
    d=st.floats(-0.6, 0.6),
    tau=st.sampled_from([0.0, 0.1]),
)
def test_a_push_at_height_d_counts_for_one_plus_d_over_h(setups, J, angle, d, tau):
    a = setups[tau].analysis
    com, m, omega = a.stance.com, a.stance.mass, a.areas.omega
    h = a.areas.gravity / omega**2
    u = np.array([math.cos(angle), math.sin(angle)])
    body = com + np.array([0.05, -0.02, d])
    p = predict_push(setups[tau], Push(angle, J), float(body[2]), body)
    np.testing.assert_allclose(
        p.effective_com_velocity, (J / m) * u * (1 + d / (h * (1 + omega * tau))), atol=1e-9
    )
    np.testing.assert_allclose(
        p.angular_momentum, np.cross(body - com, [*(J * u), 0.0]), atol=1e-12
    )
    assert p.effective_com_velocity_margin == pytest.approx(
        a.areas.com_velocity_area.margins(p.effective_com_velocity)[0], abs=1e-12
    )


def test_default_prediction_uses_it_and_the_paper_keeps_its_own(setups):
    a = setups[0.1].analysis
    body = a.stance.com + np.array([0.0, 0.0, 0.3])  # a torso push
    paper = setups[None].analysis
    # an impulse the paper calls safe and the extended criterion not: 97 % of the paper's boundary
    J = 0.97 * boundary_impulse(paper.areas.com_velocity_area, paper.stance.mass, 0.0)
    summary = {"outcome": "balanced", "com_velocity_margin_at_end": 0.0}
    for tau, expected in ((None, True), (0.1, False)):
        p = predict_push(setups[tau], Push(0.0, J), float(body[2]), body)
        o = PushOutcome(push=Push(0.0, J), relative=None, summary=summary, prediction=p)
        assert o.safe("paper_com", 0.0, 3.3) is True
        assert o.safe("com", 0.0, 3.3) is expected
    off_prediction = predict_push(setups[None], Push(0.0, J), float(body[2]), body)
    assert off_prediction.effective_com_velocity is None
    assert off_prediction.angular_momentum[1] == pytest.approx(0.3 * J)
