"""The CMP feedback what-if of ``benchmarks/torso_tipping.py`` (docs/studies/torso-pushes.md §8).

The ZMP offset that removes the angular momentum at ``-K_L L`` is checked against the moment of
the contact force about the CoM (a cross product, independent of the offset's formula); the
feedback's clamp against the polygon; the id QP's CoM acceleration against the LIPM about the
clamped ZMP minus that offset (pinocchio's centroidal dynamics with the QP's accelerations).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

pytest.importorskip("mujoco", reason="needs the sim extra (MuJoCo)")
pytest.importorskip("pandas", reason="needs the logs extra (pandas)")

from benchmarks.torso_tipping import CmpFeedback
from benchmarks.torso_tipping import zmp_offset as angular_momentum_zmp_offset
from impact_balance.analysis.analyze import analyze
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario import load_scenario
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.control.zmp import DcmFeedback, clamp_to_polygon

finite = st.floats(-5.0, 5.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    L=st.tuples(finite, finite, finite),
    com=st.tuples(finite, finite, st.floats(0.3, 1.5)),
    com_dd=st.tuples(finite, finite),
    damping=st.floats(0.5, 30.0),
    mass=st.floats(5.0, 150.0),
)
def test_the_offset_makes_the_contact_force_remove_angular_momentum_at_k_l(
    L, com, com_dd, damping, mass
):
    """A force through the CMP + offset has the moment ``-K_L L`` (horizontal) about the CoM."""
    g, c, L = 9.81, np.array(com), np.array(L)
    height = c[2]  # the contact plane is z = 0
    omega2 = g / height
    cmp = c[:2] - np.array(com_dd) / omega2  # the LIPM's pivot: c_dd = omega^2 (c - cmp)
    d = angular_momentum_zmp_offset(L, damping, mass, g)
    zmp = np.array([*(cmp + d), 0.0])
    force = mass * np.array([com_dd[0], com_dd[1], g])  # f_z = m g: the LIPM's
    moment = np.cross(zmp - c, force)
    np.testing.assert_allclose(moment[:2], -damping * L[:2], atol=1e-9 * (1 + np.abs(L).max()))
    # Its size: |d| = K_L |L_xy| / (m g), perpendicular to L_xy.
    assert np.linalg.norm(d) == pytest.approx(damping * np.linalg.norm(L[:2]) / (mass * g))
    assert abs(d @ L[:2]) <= 1e-12 * (1 + np.abs(L).max()) ** 2


def test_a_forward_pitch_moves_the_zmp_forward():
    """L along +y (pitching forward, toward +x): removing it pushes the ZMP forward (+x)."""
    d = angular_momentum_zmp_offset(np.array([0.0, 2.0, 0.0]), 10.0, 40.0, 9.81)
    assert d[0] == pytest.approx(20.0 / (40.0 * 9.81))
    assert d[1] == 0.0


SQUARE = Polygon(np.array([[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1], [-0.1, 0.1]]))


def stub_controller(L):
    """What :class:`CmpFeedback` reads of the controller: L, K_L, m, g."""
    return SimpleNamespace(
        data=SimpleNamespace(hg=SimpleNamespace(angular=np.array(L))),
        gains=SimpleNamespace(angular_momentum_damping=10.0),
        mass=30.0,
        gravity=9.81,
    )


@settings(max_examples=100, deadline=None)
@given(
    com=st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3)),
    vel=st.tuples(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0)),
    L=st.tuples(st.floats(-3.0, 3.0), st.floats(-3.0, 3.0), st.floats(-3.0, 3.0)),
)
def test_the_feedback_clamps_the_cmp_plus_the_offset(com, vel, L):
    """Unclamped: the CMP is the DCM feedback's point; clamped: CMP + offset in the shrunk area."""
    plain = DcmFeedback(SQUARE, 3.0, np.zeros(2), gain=2.0, margin=0.01)
    fb = CmpFeedback(plain, stub_controller(L))
    d = np.array([10.0 * L[1], -10.0 * L[0]]) / (30.0 * 9.81)
    cmp, xi, clamped = fb.desired_zmp(np.array(com), np.array(vel))
    xi_ref = np.array(com) + np.array(vel) / 3.0
    np.testing.assert_allclose(xi, xi_ref)
    point = xi_ref + (2.0 / 3.0) * xi_ref  # p_cmp = xi + (k / omega)(xi - 0)
    zmp = cmp + d
    if clamped:
        assert np.all(np.abs(zmp) <= 0.09 + 1e-6)  # the square shrunk by the 10 mm margin
        assert np.linalg.norm(zmp - (point + d)) > 1e-9
    else:
        np.testing.assert_allclose(cmp, point, atol=1e-12)
        assert np.all(np.abs(point + d) <= 0.09 + 1e-9)


@pytest.mark.parametrize("what_if", [False, True])
def test_the_com_task_pivots_about_the_clamped_zmp_minus_the_offset(what_if):
    """The QP's CoM acceleration is the LIPM's about ``p - d``, ``p`` the clamp of CMP + d.

    Unclamped, ``p - d`` is the feedback's point, the controller's own pivot: the what-if
    changes the QP only while the clamp acts, so the states here move faster than it captures.
    """
    analysis = analyze(load_scenario("palm_push_two_feet"))
    controller = InverseDynamicsController(analysis, gains=InverseDynamicsGains())
    plain = controller.feedback
    if what_if:
        controller.feedback = CmpFeedback(plain, controller)
    model, data = analysis.stance.model, analysis.stance.model.createData()
    q = analysis.stance.q.copy()
    rng = np.random.default_rng(5)
    K_L, mass, g = controller.gains.angular_momentum_damping, controller.mass, controller.gravity
    checked = 0
    for _trial in range(6):
        v = np.zeros(model.nv)
        v[:2] = 0.5 * rng.standard_normal(2)  # a CoM velocity that the clamp cannot capture
        v[3:6] = 0.4 * rng.standard_normal(3)  # the body turning: L about the CoM
        v[6:] = 0.1 * rng.standard_normal(model.nv - 6)
        out = controller.step(0.0, q, v)
        L = np.array(pin.computeCentroidalMomentum(model, data, q, v).angular)
        d = angular_momentum_zmp_offset(L, K_L, mass, g)
        com = np.array(data.com[0])
        vcom = np.array(data.vcom[0])
        xi = com[:2] + vcom[:2] / plain.omega
        point = xi + (plain.gain / plain.omega) * (xi - plain.dcm_reference)
        p_plain = clamp_to_polygon(plain.zmp_area, point, plain.margin)
        p_offset = clamp_to_polygon(plain.zmp_area, point + d, plain.margin)
        pivot, other = (p_offset - d, p_plain) if what_if else (p_plain, p_offset - d)
        np.testing.assert_allclose(out.zmp, pivot, atol=1e-6)
        pin.computeCentroidalMomentumTimeVariation(model, data, q, v, out.a)
        com_dd = np.array(data.dhg.linear) / mass
        expected = controller.omega**2 * (com[:2] - pivot)
        gap = controller.omega**2 * np.linalg.norm(pivot - other)  # what the what-if changes
        if gap > 0.3:
            checked += 1
            assert np.linalg.norm(com_dd[:2] - expected) < 0.25 * gap  # nearer than the other
    assert checked >= 3  # the offset mattered on most states
