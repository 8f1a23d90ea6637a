"""The angular momentum an impulse leaves, and the effective post-impact CoM velocity."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

import impact_balance as ib
from impact_balance.exceptions import ScenarioError
from impact_balance.impact.angular_momentum import (
    AngularMomentumTerm,
    angular_momentum_gain,
    angular_momentum_jump_rates,
    centroidal_angular_momentum_jump,
    effective_impulse_rates,
)

impulses = st.tuples(*[st.floats(-50.0, 50.0)] * 3)


@pytest.fixture(scope="module")
def palm():
    return ib.analyze("palm_push_two_feet")


def _pinocchio_state(stance):
    model = stance.model
    data = model.createData()
    pin.forwardKinematics(model, data, stance.q)
    pin.updateFramePlacements(model, data)
    com = pin.centerOfMass(model, data, stance.q)
    return model, data, np.array(com)


@settings(max_examples=15, deadline=None)
@given(impulse=impulses)
def test_centroidal_map_of_the_joint_space_jump_is_the_impulse_moment(palm, impulse):
    """dL = Ag dqdot with dqdot = M^-1 J^T iota (all joints free) equals (p - c) x iota."""
    stance, impact = palm.stance, palm.impact.model
    iota = np.asarray(impulse)
    model = stance.model
    data = model.createData()
    M = pin.crba(model, data, stance.q)
    M = np.triu(M) + np.triu(M, 1).T
    dqdot = np.linalg.solve(M, impact.jacobian.T @ iota)
    dL = centroidal_angular_momentum_jump(model, stance.q, dqdot)
    expected = np.cross(impact.point - stance.com, iota)
    np.testing.assert_allclose(dL, expected, atol=1e-9 * (1 + np.linalg.norm(iota)))


@settings(max_examples=15, deadline=None)
@given(impulse=impulses)
def test_centroidal_map_of_the_composite_jump_is_the_impulse_moment(palm, impulse):
    """The paper's model: the robot as one rigid body (joints locked), dL = Ag dqdot again."""
    stance, impact = palm.stance, palm.impact.model
    iota = np.asarray(impulse)
    arm = impact.point - stance.com
    dv_c = iota / stance.mass
    dw = np.linalg.solve(stance.com_inertia, np.cross(arm, iota))
    model, data, com = _pinocchio_state(stance)
    base = data.oMi[1]
    v_base = dv_c + np.cross(dw, base.translation - com)  # rigid-body velocity at the base
    dqdot = np.zeros(model.nv)
    dqdot[:3] = base.rotation.T @ v_base
    dqdot[3:6] = base.rotation.T @ dw
    dL = centroidal_angular_momentum_jump(model, stance.q, dqdot)
    np.testing.assert_allclose(dL, np.cross(arm, iota), atol=1e-9 * (1 + np.linalg.norm(iota)))
    # and the library's rates are that moment
    np.testing.assert_allclose(angular_momentum_jump_rates(arm, iota[None, :])[0], dL, atol=1e-9)


@settings(max_examples=60, deadline=None)
@given(
    J=st.floats(0.1, 100.0),
    angle=st.floats(0.0, 2 * math.pi),
    d=st.floats(-1.0, 1.0),
    lateral=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),
    omega=st.floats(2.0, 5.0),
    tau=st.floats(0.0, 2.0),
)
def test_horizontal_push_at_height_d(J, angle, d, lateral, omega, tau):
    """A horizontal push J u at d above the CoM: v_eff = (J / m) u (1 + d / (h (1 + omega tau)))."""
    g, m = 9.81, 90.0
    h = g / omega**2
    u = np.array([math.cos(angle), math.sin(angle)])
    iota = np.array([*(J * u), 0.0])
    term = AngularMomentumTerm(np.array([*lateral, d]), angular_momentum_gain(omega, g, tau), tau)
    v_eff = effective_impulse_rates(iota[None, :], term)[0, :2] / m
    expected = (J / m) * u * (1 + d / (h * (1 + omega * tau)))
    np.testing.assert_allclose(v_eff, expected, atol=1e-9)


def test_gain_limits_and_errors():
    assert angular_momentum_gain(3.0, 9.81, None) == 0.0
    assert angular_momentum_gain(3.0, 9.81, math.inf) == 0.0
    assert angular_momentum_gain(3.0, 9.81, 0.0) == pytest.approx(9.0 / 9.81, rel=1e-15)
    with pytest.raises(ScenarioError, match="angular_momentum_damping_time"):
        angular_momentum_gain(3.0, 9.81, -0.1)


def _captured_with_zmp_at_edge(v, L0, tau, omega, g, m, edge):
    """Integrate c'' = omega^2 (c - p_cmp) with the ZMP held at the edge (1D, x, c0 = 0).

    L_y(t) = L0 exp(-t / tau) (tau = 0: removed at once, an impulse of CMP); p_cmp = edge +
    L_y' / (m g). True when the CoM turns back (the divergent component falls behind the edge:
    the best capture stops it), False when it runs away forward.
    """
    if tau == 0.0:  # L removed at once: the CMP impulse -L0 / (m g) shifts c' by omega^2 L0/(m g)
        v = v + omega**2 * L0 / (m * g)

        def cmp(t):
            return edge
    else:

        def cmp(t):
            return edge - L0 / tau * math.exp(-t / tau) / (m * g)

    def rhs(t, y):
        return [y[1], omega**2 * (y[0] - cmp(t))]

    sol = solve_ivp(rhs, (0.0, 12.0 / omega), [0.0, v], rtol=1e-11, atol=1e-13, max_step=0.01)
    return sol.y[1, -1] < 0.0


@settings(max_examples=12, deadline=None)
@given(
    L0=st.floats(-10.0, 10.0),
    tau=st.sampled_from([0.0, 0.02, 0.1, 0.5]),
    omega=st.floats(2.5, 4.5),
    edge=st.floats(0.03, 0.15),
)
def test_flywheel_lipm_capture_matches_the_effective_velocity(L0, tau, omega, edge):
    """Independent check of the formula: the CoM stops iff v_eff lies inside (omega * edge)."""
    g, m = 9.81, 90.0
    h = g / omega**2
    boundary_eff = omega * edge  # the CoM velocity area's edge along x
    # the pre-impact velocity whose v_eff is on the boundary
    v_on = boundary_eff - L0 / (m * h * (1 + omega * tau))
    for factor, inside in ((0.98, True), (1.02, False)):
        v = v_on + (factor - 1.0) * boundary_eff
        v_eff = v + L0 / (m * h * (1 + omega * tau))
        assert (v_eff <= boundary_eff) == inside
        assert _captured_with_zmp_at_edge(v, L0, tau, omega, g, m, edge) == inside


def test_no_term_is_the_paper(palm):
    rates = palm.impact.model.impulse_rates
    np.testing.assert_array_equal(effective_impulse_rates(rates, None), rates)
    term = AngularMomentumTerm(np.ones(3), 0.0, math.inf)
    np.testing.assert_array_equal(effective_impulse_rates(rates, term), rates)
