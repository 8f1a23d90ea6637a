"""Contact wrench cone: the face matrix and the span describe the same (physical) cone.

Reference facts used here, derived independently of the implementation:
- a unit-normal force along a friction-pyramid edge e = (+-mu, +-mu, 1) applied at a
  rectangle corner p = (+-X, +-Y, 0) has the wrench [e; p x e] at the contact centre, and the
  CWC is the cone spanned by these 16 wrenches (Caron et al. 2015);
- a pure force f at a point (x, y, 0) has the wrench [f; (x, y, 0) x f];
- distance from w to a cone K satisfies dist(w, K) >= max_k (C_k w) / ||C_k|| whenever
  C_k k <= 0 for all k in K (so a point violating a face cannot be a non-negative combination).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog, nnls
from scipy.spatial.transform import Rotation

from impact_balance.contacts.cwc import cwc_faces, cwc_faces_world, cwc_span, rotate_wrench_matrix

MU = st.floats(0.1, 1.5)
HALF = st.floats(0.01, 0.3)
SEED = st.integers(0, 2**32 - 1)
FAST = settings(max_examples=40, deadline=None)


def corner_generators(mu: float, X: float, Y: float) -> np.ndarray:
    """The 16 generators built from the physics (6 x 16), independently of cwc_span."""
    cols = []
    for sx in (1, -1):
        for sy in (1, -1):
            p = np.array([sx * X, sy * Y, 0.0])
            for ex in (1, -1):
                for ey in (1, -1):
                    e = np.array([ex * mu, ey * mu, 1.0])
                    cols.append(np.concatenate([e, np.cross(p, e)]))
    return np.array(cols).T


def point_force(f, x: float, y: float) -> np.ndarray:
    """Wrench [f; tau] at the contact centre of a pure force f applied at (x, y, 0)."""
    f = np.asarray(f, dtype=float)
    return np.concatenate([f, np.cross([x, y, 0.0], f)])


def column_set_equal(A: np.ndarray, B: np.ndarray, tol: float = 1e-12) -> bool:
    """Same set of columns (any order)."""
    if A.shape != B.shape:
        return False
    used = set()
    for a in A.T:
        match = [
            j for j, b in enumerate(B.T) if j not in used and np.allclose(a, b, atol=tol, rtol=0)
        ]
        if not match:
            return False
        used.add(match[0])
    return True


def test_shapes_and_span_is_physical_corner_forces():
    C, S = cwc_faces(0.7, 0.1, 0.05), cwc_span(0.7, 0.1, 0.05)
    assert C.shape == (16, 6)
    assert S.shape == (6, 16)
    assert column_set_equal(S, corner_generators(0.7, 0.1, 0.05))


# (a) -------------------------------------------------------------------------------------
@FAST
@given(mu=MU, X=HALF, Y=HALF)
def test_span_generators_satisfy_faces(mu, X, Y):
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    assert column_set_equal(S, corner_generators(mu, X, Y), tol=1e-12)
    assert np.max(C @ S) <= 1e-9


# (b) -------------------------------------------------------------------------------------
def _nnls_residual(S: np.ndarray, w: np.ndarray) -> float:
    return float(nnls(S, w)[1])


@FAST
@given(mu=MU, X=HALF, Y=HALF, seed=SEED)
def test_nonnegative_combinations_are_in_the_faces_and_the_span(mu, X, Y, seed):
    rng = np.random.default_rng(seed)
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    lam = rng.exponential(size=(16, 20)) * (rng.random((16, 20)) < 0.5)  # sparse too: faces
    W = S @ lam
    scale = np.linalg.norm(W, axis=0) + 1e-300
    assert np.all((C @ W) / scale <= 1e-9)
    for w in W.T:
        assert _nnls_residual(S, w) <= 1e-9 * (1 + np.linalg.norm(w))


@FAST
@given(mu=MU, X=HALF, Y=HALF, seed=SEED)
def test_random_wrenches_in_faces_iff_in_span(mu, X, Y, seed):
    """Rejection sampling: w with C w <= 0 is a non-negative combination; w with a violated
    face is at least max_k C_k w / ||C_k|| away from the span."""
    rng = np.random.default_rng(seed)
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    norms = np.linalg.norm(C, axis=1)
    # Sample around the cone: fz = 1, the rest spread a bit beyond the cone's extent.
    n = 400
    W = np.empty((6, n))
    W[2] = 1.0
    W[0] = rng.uniform(-1.3 * mu, 1.3 * mu, n)
    W[1] = rng.uniform(-1.3 * mu, 1.3 * mu, n)
    W[3] = rng.uniform(-1.3 * Y, 1.3 * Y, n)  # tau_x = y fz
    W[4] = rng.uniform(-1.3 * X, 1.3 * X, n)  # tau_y = -x fz
    W[5] = rng.uniform(-1.3 * mu * (X + Y), 1.3 * mu * (X + Y), n)
    W *= rng.uniform(0.1, 10.0, n)  # any positive scale (cone)
    viol = np.max((C @ W) / norms[:, None], axis=0)
    inside, outside = viol <= 0.0, viol > 0.0
    assert inside.sum() >= 5 and outside.sum() >= 5  # the sampler hits both sides
    for w in W[:, inside].T:
        assert _nnls_residual(S, w) <= 1e-8 * np.linalg.norm(w)
    for w, v in zip(W[:, outside].T, viol[outside], strict=True):
        assert _nnls_residual(S, w) >= v * (1 - 1e-6) - 1e-12


def test_points_clearly_outside_are_not_in_span_linprog():
    """Same claim with an LP (exact feasibility): a violated face means no lambda >= 0."""
    mu, X, Y = 0.6, 0.11, 0.07
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    rng = np.random.default_rng(1)
    checked = 0
    while checked < 30:
        w = rng.normal(size=6)
        feasible = (
            linprog(np.zeros(16), A_eq=S, b_eq=w, bounds=(0, None), method="highs").status == 0
        )
        if np.max(C @ w) > 1e-6:
            assert not feasible
            checked += 1
        elif np.max(C @ w) <= 0:
            assert feasible


# (c) -------------------------------------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(mu=MU, X=HALF, Y=HALF)
def test_faces_are_a_minimal_description(mu, X, Y):
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    assert np.linalg.matrix_rank(S) == 6  # full-dimensional cone
    Cn = C / np.linalg.norm(C, axis=1, keepdims=True)
    Sn = S / np.linalg.norm(S, axis=0, keepdims=True)
    for k in range(16):
        tight = np.abs(Cn[k] @ Sn) <= 1e-9
        assert np.linalg.matrix_rank(Sn[:, tight], tol=1e-7) == 5, f"face {k} is not a facet"
    # 16 distinct facets: no two rows are the same after normalisation
    gaps = np.linalg.norm(Cn[:, None, :] - Cn[None, :, :], axis=2) + 10 * np.eye(16)
    assert gaps.min() > 1e-6


# Physical meaning of the rows (X and Y are HALF sizes, wrench order [f; tau]) ------------
@pytest.mark.parametrize("mu, X, Y", [(0.7, 0.1, 0.05), (0.3, 0.05, 0.12)])
def test_centre_of_pressure_rows_use_half_sizes(mu, X, Y):
    C = cwc_faces(mu, X, Y)
    fz = np.array([0.0, 0.0, 2.0])
    assert np.all(C @ point_force(fz, 0.0, 0.0) < 0)
    for x, y in [(X, Y), (-X, Y), (X, -Y), (-X, -Y), (0.99 * X, 0.0), (0.0, -0.99 * Y)]:
        assert np.max(C @ point_force(fz, x, y)) <= 1e-12
    for x, y in [(1.01 * X, 0.0), (-1.01 * X, 0.0), (0.0, 1.01 * Y), (0.0, -1.01 * Y)]:
        assert np.max(C @ point_force(fz, x, y)) > 0
    # friction pyramid: |fx|, |fy| <= mu fz, at the centre
    assert np.max(C @ point_force([0.99 * mu, -0.99 * mu, 1.0], 0, 0)) <= 0
    assert np.max(C @ point_force([1.01 * mu, 0.0, 1.0], 0, 0)) > 0
    assert np.max(C @ point_force([0.0, -1.01 * mu, 1.0], 0, 0)) > 0
    # a pure torque or a pulling force is never admissible
    for w in np.eye(6)[[3, 4, 5]]:
        assert np.max(C @ w) > 0 and np.max(C @ -w) > 0
    assert np.max(C @ point_force([0, 0, -1.0], 0, 0)) > 0


@pytest.mark.parametrize("mu, X, Y", [(0.7, 0.1, 0.05), (1.2, 0.02, 0.2)])
def test_yaw_torque_bound_is_mu_times_half_perimeter(mu, X, Y):
    """With fz = 1 and no other force/torque, |tau_z| <= mu (X + Y) (four corner forces
    tangent to the rectangle's circumference), from the faces and from the span."""
    C, S = cwc_faces(mu, X, Y), cwc_span(mu, X, Y)
    fixed = np.eye(6)[:5]
    target = np.array([0, 0, 1.0, 0, 0])
    for sign in (1, -1):
        r = linprog(
            -sign * np.eye(6)[5],
            A_ub=C,
            b_ub=np.zeros(16),
            A_eq=fixed,
            b_eq=target,
            bounds=(None, None),
        )
        assert r.status == 0 and sign * r.x[5] == pytest.approx(mu * (X + Y), rel=1e-9)
        r = linprog(-sign * S[5], A_eq=S[:5], b_eq=target, bounds=(0, None))
        assert r.status == 0 and sign * (S[5] @ r.x) == pytest.approx(mu * (X + Y), rel=1e-9)


# (d) -------------------------------------------------------------------------------------
@FAST
@given(mu=MU, X=HALF, Y=HALF, seed=SEED)
def test_world_faces_check_the_rotated_back_wrench(mu, X, Y, seed):
    rng = np.random.default_rng(seed)
    R = Rotation.random(random_state=rng).as_matrix()
    Cw, C = cwc_faces_world(mu, X, Y, R), cwc_faces(mu, X, Y)
    assert Cw.shape == (16, 6)
    W = rng.normal(size=(6, 50))
    local = np.vstack([R.T @ W[:3], R.T @ W[3:]])
    np.testing.assert_allclose(Cw @ W, C @ local, atol=1e-12)
    # a local generator mapped to world is inside the world cone; the world normal force
    # (R e_z) is strictly inside, its opposite outside
    S = cwc_span(mu, X, Y)
    Sw = np.vstack([R @ S[:3], R @ S[3:]])
    assert np.max(Cw @ Sw) <= 1e-9
    normal = np.concatenate([R[:, 2], np.zeros(3)])
    assert np.all(Cw @ normal < 0) and np.max(Cw @ -normal) > 0


def test_world_faces_for_a_wall_contact():
    """Contact normal along world -x (a wall in front): a push along -x at the centre is
    admissible, vertical friction up to mu times the push, and the centre of pressure is
    bounded by X along the contact's local x axis, which is world up here."""
    mu, X, Y = 0.5, 0.1, 0.05
    R = Rotation.from_euler("y", -90, degrees=True).as_matrix()
    np.testing.assert_allclose(R[:, 2], [-1, 0, 0], atol=1e-15)
    Cw = cwc_faces_world(mu, X, Y, R)
    push = np.array([-1.0, 0, 0, 0, 0, 0])
    assert np.all(Cw @ push < 0)
    assert np.max(Cw @ (push + np.array([0, 0, 0.49, 0, 0, 0]))) <= 0
    assert np.max(Cw @ (push + np.array([0, 0, 0.51, 0, 0, 0]))) > 0
    # force at local point (x, 0, 0): local x axis is world R[:,0] = (0, 0, 1) (up)
    for x, ok in [(0.099, True), (0.101, False)]:
        p = R @ np.array([x, 0.0, 0.0])
        w = np.concatenate([push[:3], np.cross(p, push[:3])])
        assert (np.max(Cw @ w) <= 0) == ok


def test_cached_faces_are_handed_out_as_copies():
    """The local face matrix is cached per (mu, X, Y): mutating a returned one changes nothing."""
    mu, X, Y = 0.7, 0.1, 0.05
    R = Rotation.from_euler("xyz", [0.3, -0.2, 1.0]).as_matrix()
    C, Cw = cwc_faces(mu, X, Y), cwc_faces_world(mu, X, Y, R)
    expected_C, expected_Cw = C.copy(), Cw.copy()
    C[:] = 0.0
    Cw[:] = 0.0
    np.testing.assert_array_equal(cwc_faces(mu, X, Y), expected_C)
    np.testing.assert_array_equal(cwc_faces_world(mu, X, Y, R), expected_Cw)
    np.testing.assert_allclose(
        expected_Cw, expected_C @ rotate_wrench_matrix(R).T, rtol=0, atol=1e-15
    )
