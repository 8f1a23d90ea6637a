"""The pink limit: its row is -n^T J dq <= ceiling dt at the configuration it is given, with the
governor's answer for that state, J checked against the point's motion; bad inputs are named."""

from __future__ import annotations

import numpy as np
import pink
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor
from impact_balance.governor.pink_limit import PinkApproachLimit

GOVERNOR = Governor("palm_push_two_feet")
MODEL = GOVERNOR.robot.model


def moved(seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A posture near the scenario's (joints moved by up to 0.05 rad) and a velocity."""
    rng = np.random.default_rng(seed)
    q = GOVERNOR.configuration.copy()
    q[7:] = np.clip(
        q[7:] + rng.uniform(-0.05, 0.05, MODEL.nq - 7),
        MODEL.lowerPositionLimit[7:],
        MODEL.upperPositionLimit[7:],
    )
    return q, rng.normal(0.0, 0.2, MODEL.nv)


def point(q: np.ndarray) -> np.ndarray:
    """The impact point by pinocchio's forward kinematics (independent of the limit)."""
    data = MODEL.createData()
    pin.framesForwardKinematics(MODEL, data, q)
    impact = GOVERNOR.scenario.impact.spec()
    return (data.oMf[MODEL.getFrameId(impact.frame)] * impact.offset).translation


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 10_000), dt=st.floats(1e-4, 0.05))
def test_the_row_is_the_governors_cap_through_the_points_jacobian(seed, dt):
    q, v = moved(seed)
    limit = PinkApproachLimit(GOVERNOR, MODEL)
    limit.velocity = v
    configuration = pink.Configuration(MODEL, MODEL.createData(), q)
    G, h = limit.compute_qp_inequalities(configuration, dt)
    expected = GOVERNOR.limit(q, v)
    assert G.shape == (1, MODEL.nv) and h.shape == (1,)
    assert h[0] == pytest.approx(expected.ceiling * dt, rel=1e-15)
    assert limit.last.limit.max_contact_velocity == expected.max_contact_velocity
    # G dq is -n . (the point's displacement) to first order, for any small dq.
    dq = np.random.default_rng(seed).normal(0.0, 1.0, MODEL.nv) * 1e-6
    displacement = point(pin.integrate(MODEL, q, dq)) - point(q)
    assert G[0] @ dq == pytest.approx(-expected.normal @ displacement, abs=1e-10)


def test_the_velocity_and_the_com_velocity_are_the_governors_inputs():
    q, v = moved(1)
    configuration = pink.Configuration(MODEL, MODEL.createData(), q)
    limit = PinkApproachLimit(GOVERNOR, MODEL)
    _, h0 = limit.compute_qp_inequalities(configuration, 0.01)  # no velocity: zero
    assert h0[0] == pytest.approx(GOVERNOR.limit(q, np.zeros(MODEL.nv)).ceiling * 0.01)
    limit.velocity = v
    _, h1 = limit.compute_qp_inequalities(configuration, 0.01)
    assert h1[0] == pytest.approx(GOVERNOR.limit(q, v).ceiling * 0.01)
    assert h1[0] != pytest.approx(h0[0])  # the velocity matters
    limit.com_velocity = [0.1, 0.0]
    _, h2 = limit.compute_qp_inequalities(configuration, 0.01)
    assert h2[0] == pytest.approx(GOVERNOR.limit_com(q, [0.1, 0.0]).ceiling * 0.01)


def test_no_safe_speed_gives_a_zero_row_and_an_unbounded_one_no_row():
    q = GOVERNOR.configuration
    configuration = pink.Configuration(MODEL, MODEL.createData(), q)
    limit = PinkApproachLimit(GOVERNOR, MODEL)
    limit.com_velocity = [2.0, 0.0]  # far outside the CoM velocity area: no safe approach
    _, h = limit.compute_qp_inequalities(configuration, 0.01)
    assert limit.last.limit.ceiling == 0.0 and h[0] == 0.0
    # A frictionless push straight down: no horizontal CoM velocity change, no bound.
    scenario = GOVERNOR.scenario
    down = scenario.replace(
        impact={**scenario.impact.model_dump(exclude_none=True), "normal": [0, 0, 1], "friction": 0}
    )
    unbounded = Governor(down)
    assert unbounded.limit(q, np.zeros(MODEL.nv)).status == "unbounded"
    assert PinkApproachLimit(unbounded, MODEL).compute_qp_inequalities(configuration, 0.01) is None


def test_bad_inputs_are_named():
    small = pin.Model()  # not the governor's robot
    with pytest.raises(GovernorError) as e:
        PinkApproachLimit(GOVERNOR, small)
    assert e.value.field == "model"
    limit = PinkApproachLimit(GOVERNOR, MODEL)
    configuration = pink.Configuration(MODEL, MODEL.createData(), GOVERNOR.configuration)
    for dt in (0.0, -0.01, float("nan")):
        with pytest.raises(GovernorError) as e:
            limit.compute_qp_inequalities(configuration, dt)
        assert e.value.field == "dt"
    limit.velocity = np.full(MODEL.nv, np.nan)
    with pytest.raises(GovernorError) as e:
        limit.compute_qp_inequalities(configuration, 0.01)
    assert e.value.field == "v"
