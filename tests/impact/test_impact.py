"""Impact model, maximum contact velocity (CoM and ZMP criteria) and the paper's QP."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import impact_balance as ib
from impact_balance.criteria.cap import capped_velocity
from impact_balance.criteria.com import max_contact_velocity
from impact_balance.criteria.qp import QPOptions, solve_contact_velocity_qp
from impact_balance.impact.model import cone_tangents, friction_cone, impact_model

BUNDLED_IMPACTS = [
    "palm_push_two_feet",
    "palm_push_ramp",
    "kick_one_foot",
    "talos_three_contacts",
    "g1_two_feet",
]


@pytest.fixture(scope="module")
def analyses():
    return {name: ib.analyze(name) for name in BUNDLED_IMPACTS}


unit_vectors = st.tuples(*[st.floats(-1, 1)] * 3).filter(lambda v: np.linalg.norm(v) > 0.1)


@settings(max_examples=40, deadline=None)
@given(normal=unit_vectors, mu=st.floats(0.0, 1.5), edges=st.integers(3, 64))
def test_friction_cone_generators(normal, mu, edges):
    n = np.asarray(normal) / np.linalg.norm(normal)
    K = friction_cone(normal, mu, edges)
    assert K.shape == (3, edges)
    np.testing.assert_allclose(n @ K, 1.0, atol=1e-12)  # unit normal component
    tangential = K - np.outer(n, n @ K)
    np.testing.assert_allclose(np.linalg.norm(tangential, axis=0), mu, atol=1e-12)
    t1, t2 = cone_tangents(n)
    assert abs(t1 @ n) < 1e-12 and abs(t2 @ n) < 1e-12 and abs(t1 @ t2) < 1e-12
    np.testing.assert_allclose(K[:, 0], n + mu * t1, atol=1e-12)  # a_0 = 0 along t1
    if abs(n[2]) < 0.999:  # t1 is world z made orthogonal to n
        z = np.array([0, 0, 1.0]) - n[2] * n
        np.testing.assert_allclose(t1, z / np.linalg.norm(z), atol=1e-12)


def test_vertical_normal_uses_world_x():
    t1, t2 = cone_tangents(np.array([0, 0, 1.0]))
    np.testing.assert_allclose(t1, [1, 0, 0], atol=1e-12)
    np.testing.assert_allclose(t2, [0, 1, 0], atol=1e-12)


def test_composite_W_is_the_rigid_body_response(analyses):
    a = analyses["palm_push_two_feet"]
    model, stance = a.impact.model, a.stance
    W = model.W
    np.testing.assert_allclose(W, W.T, atol=1e-12)
    assert np.all(np.linalg.eigvalsh(W) > 0)
    # Independent: a rigid body of mass m and inertia Ic hit at p by iota.
    rng = np.random.default_rng(0)
    r = model.point - stance.com
    for _ in range(5):
        iota = rng.normal(size=3)
        dv_com = iota / stance.mass
        domega = np.linalg.solve(stance.com_inertia, np.cross(r, iota))
        np.testing.assert_allclose(W @ iota, dv_com + np.cross(domega, r), rtol=1e-10, atol=1e-12)


def test_composite_W_matches_lapack():
    """W's compiled 3 x 3 Cholesky solve agrees with LAPACK's; an inertia that is not positive
    definite goes to LAPACK (which refuses a singular one)."""
    from impact_balance.geometry.spatial import skew
    from impact_balance.impact.model import composite_inertia_map

    rng = np.random.default_rng(3)
    for _ in range(200):
        M = rng.normal(size=(3, 3))
        A, r, m = M @ M.T + 1e-3 * np.eye(3), rng.normal(size=3), rng.uniform(1.0, 100.0)
        expected = np.eye(3) / m - skew(r) @ np.linalg.solve(A, skew(r))
        bound = 1e-14 * np.linalg.cond(A) * np.abs(expected).max()
        np.testing.assert_allclose(composite_inertia_map(r, m, A), expected, rtol=0, atol=bound)
    indefinite = np.diag([1.0, -2.0, 4.0])
    r = np.array([0.3, -0.2, 0.5])
    np.testing.assert_allclose(
        composite_inertia_map(r, 2.0, indefinite),
        np.eye(3) / 2.0 - skew(r) @ np.diag([1.0, -0.5, 0.25]) @ skew(r),
    )
    with pytest.raises(np.linalg.LinAlgError):
        composite_inertia_map(r, 2.0, np.zeros((3, 3)))


def test_joint_space_W_option(analyses):
    a = analyses["palm_push_two_feet"]
    spec = dataclasses.replace(a.impact.model.spec, inertia="joint_space")
    model = impact_model(a.stance, spec)
    W = model.W
    np.testing.assert_allclose(W, W.T, atol=1e-9)
    # All joints free: the hand alone is much lighter than the whole rigid robot.
    n = model.normal
    assert n @ W @ n > n @ a.impact.model.W @ n


def test_impulse_vertices_lie_on_the_planes_of_restitution(analyses):
    for a in analyses.values():
        m = a.impact.model
        lo, hi = m.spec.restitution
        v_n = 0.37
        iota = m.impulse_vertices(v_n)
        response = iota @ m.W.T @ m.normal
        np.testing.assert_allclose(response[0::2], (1 + hi) * v_n, rtol=1e-10)
        np.testing.assert_allclose(response[1::2], (1 + lo) * v_n, rtol=1e-10)
        # each vertex is on a friction-cone edge, pushing the robot away from the surface
        K = m.cone
        for j, vec in enumerate(iota):
            edge = K[:, j // 2]
            np.testing.assert_allclose(np.cross(vec, edge), 0, atol=1e-10)
            assert vec @ edge > 0
        np.testing.assert_allclose(m.com_velocity_jumps(v_n), iota / m.mass)


def _check_overlap(area, model, c0, v_max):
    """One post-impact vertex on the boundary at v_max, all inside just below, one outside above."""
    at = area.margins(model.post_impact_com_velocities(c0, v_max))
    assert at.min() == pytest.approx(0.0, abs=1e-9)
    assert np.all(area.margins(model.post_impact_com_velocities(c0, v_max * (1 - 1e-6))) > 0)
    assert np.any(area.margins(model.post_impact_com_velocities(c0, v_max * (1 + 1e-6))) < 0)


@pytest.mark.parametrize("name", BUNDLED_IMPACTS)
def test_overlap_condition_at_the_maximum(analyses, name):
    a = analyses[name]
    im = a.impact
    assert im.com.status == "ok"
    _check_overlap(a.areas.com_velocity_area, im.model, a.com_velocity, im.max_contact_velocity)


@settings(max_examples=30, deadline=None)
@given(
    frac=st.tuples(st.floats(-0.8, 0.8), st.floats(-0.8, 0.8)),
    theta=st.floats(-1.2, 1.2),
    mu=st.floats(0.0, 0.6),
)
def test_overlap_condition_random_impacts(analyses, frac, theta, mu):
    """Random pre-impact CoM velocities inside the area and random impact directions."""
    a = analyses["palm_push_ramp"]
    area = a.areas.com_velocity_area
    lo, hi = area.vertices.min(0), area.vertices.max(0)
    c0 = 0.5 * (lo + hi) + 0.5 * np.asarray(frac) * (hi - lo)
    if area.margins(c0)[0] <= 1e-6:
        return
    normal = (-np.cos(theta), -np.sin(theta), 0.3 * np.sin(2 * theta))
    spec = dataclasses.replace(a.impact.model.spec, normal=normal, friction=mu)
    try:
        model = impact_model(a.stance, spec)
    except ib.ImpactModelError:
        return
    limit = max_contact_velocity(area, model, c0)
    if limit.status == "unbounded":
        assert np.all(model.com_jump_rates @ area.halfplanes[0].T <= 1e-9)
        return
    assert limit.status == "ok" and limit.max_contact_velocity > 0
    _check_overlap(area, model, c0, limit.max_contact_velocity)
    # independent bisection with Polygon.contains
    lo_s, hi_s = 0.0, 10 * limit.max_contact_velocity
    for _ in range(60):
        mid = 0.5 * (lo_s + hi_s)
        inside = np.all(area.contains(model.post_impact_com_velocities(c0, mid), tol=0.0))
        lo_s, hi_s = (mid, hi_s) if inside else (lo_s, mid)
    assert lo_s == pytest.approx(limit.max_contact_velocity, rel=1e-7)


def test_already_falling_and_cannot_balance(analyses):
    a = analyses["palm_push_two_feet"]
    model, area = a.impact.model, a.areas.com_velocity_area
    outside = area.vertices.max(0) + 0.1
    assert max_contact_velocity(area, model, outside).status == "already_falling"
    assert max_contact_velocity(area, model, outside).max_contact_velocity == 0.0
    empty = ib.Polygon.empty()
    limit = max_contact_velocity(empty, model, (0, 0))
    assert limit.status == "cannot_balance" and limit.max_contact_velocity == 0.0


def test_frictionless_vertical_impact_is_unbounded(analyses):
    a = analyses["palm_push_two_feet"]
    spec = dataclasses.replace(a.impact.model.spec, normal=(0, 0, 1), friction=0.0)
    model = impact_model(a.stance, spec)
    np.testing.assert_allclose(model.com_jump_rates, 0, atol=1e-12)
    limit = max_contact_velocity(a.areas.com_velocity_area, model, (0, 0))
    assert limit.status == "unbounded" and np.isinf(limit.max_contact_velocity)


def test_inconsistent_impact_is_a_clear_error(analyses):
    a = analyses["palm_push_two_feet"]
    spec = dataclasses.replace(a.impact.model.spec, friction=50.0)
    with pytest.raises(ib.ImpactModelError) as info:
        impact_model(a.stance, spec)
    assert info.value.field == "impact.friction"


def _zmp(force, point, com, weight, h):
    """ZMP on plane z = h of gravity compensation + force at point (paper eq. def_zmp)."""
    f = np.array([0, 0, weight]) + force
    tau = np.cross(com, [0, 0, weight]) + np.cross(point, force)
    nz = np.array([0, 0, 1.0])
    z = (np.cross(nz, tau) + h * f) / f[2]
    return z[:2]


@pytest.mark.parametrize("name", BUNDLED_IMPACTS)
def test_zmp_criterion_against_direct_zmp(analyses, name):
    a = analyses[name]
    im, m = a.impact, a.impact.model
    s = im.zmp_max_contact_velocity
    assert 0 < s < im.max_contact_velocity  # the ZMP criterion is the conservative one
    dt = m.spec.duration
    weight = a.stance.mass * a.areas.gravity

    def zmps(speed):
        return np.array(
            [
                _zmp(f, m.point, a.stance.com, weight, a.areas.plane_height)
                for f in m.impulse_vertices(speed) / dt
            ]
        )

    area = a.areas.zmp_area
    assert np.all(area.margins(zmps(s * (1 - 1e-6))) > -1e-12)
    assert np.any(area.margins(zmps(s * (1 + 1e-6))) < 0)


@pytest.mark.parametrize(
    "reference",
    [(2.5, 0.0, 0.0), (2.0, 0.4, -0.3), (0.2, 0.1, 0.0)],
    ids=["above", "oblique", "below"],
)
def test_qp_matches_the_exact_answer(analyses, reference):
    a = analyses["palm_push_two_feet"]
    model, area = a.impact.model, a.areas.com_velocity_area
    exact = max_contact_velocity(area, model, a.com_velocity).max_contact_velocity
    expected = capped_velocity(reference, model.normal, exact)
    result = solve_contact_velocity_qp(model, area, a.com_velocity, reference)
    assert result.status == "optimal"
    np.testing.assert_allclose(result.contact_velocity, expected, atol=2e-5)
    if model.approach_speed(reference) > exact:
        assert result.approach_speed == pytest.approx(exact, rel=1e-6)
    # the QP's impulses are the impulse-set vertices at its approach speed
    np.testing.assert_allclose(
        result.lambdas[:, None] * np.repeat(model.cone.T, 2, axis=0),
        model.impulse_vertices(result.approach_speed),
        atol=1e-5,
    )


def test_qp_extra_bounds_only_lower_the_answer(analyses):
    a = analyses["palm_push_two_feet"]
    model, area = a.impact.model, a.areas.com_velocity_area
    free = solve_contact_velocity_qp(model, area, a.com_velocity, (2.5, 0, 0))
    for opts in (QPOptions(joint_velocity_limits=True), QPOptions(impulsive_torque_limits=True)):
        bounded = solve_contact_velocity_qp(
            model, area, a.com_velocity, (2.5, 0, 0), a.stance.robot, None, opts
        )
        assert bounded.status == "optimal"
        assert bounded.approach_speed <= free.approach_speed + 1e-7


def test_friction_sweep_shape():
    """Paper Fig. miu-compare: the maximum falls as the impact friction grows (on these stances)."""
    speeds = [
        ib.analyze(f"palm_push_mu0{k}").impact.max_contact_velocity for k in ("10", "24", "40")
    ]
    assert speeds[0] > speeds[1] > speeds[2] > 0
