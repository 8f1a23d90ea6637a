"""Projection of polytopes onto the plane (both methods: the parametric walk and Bretl's LP-per-edge
algorithm), and the Polygon it returns.

Every projection test runs for both methods (the ``method`` fixture). Expected polygons come from
geometry (boxes, simplices, zonotopes as hulls of projected vertices) or from independent LPs
(scipy.optimize.linprog): support values in many directions, the distance of each returned vertex to
the true projection, and membership.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import linprog

from impact_balance.exceptions import SolverError
from impact_balance.geometry.polygon import Polygon
from impact_balance.projection import project_bretl, project_polytope, project_walk


@pytest.fixture(scope="module", params=["walk", "bretl"])
def method(request):
    return request.param


def project(A, b, E, C=None, d=None, **kw):
    n = np.asarray(E).shape[1]
    C = np.zeros((0, n)) if C is None else C
    d = np.zeros(0) if d is None else d
    return project_polytope(
        np.asarray(A, float),
        np.asarray(b, float),
        np.asarray(C, float),
        np.asarray(d, float),
        np.asarray(E, float),
        **kw,
    )


def box_rows(lo, hi):
    n = len(lo)
    return np.vstack([np.eye(n), -np.eye(n)]), np.concatenate([hi, -np.asarray(lo)])


def assert_ccw_convex(v):
    k = len(v)
    if k < 3:
        return
    e = np.roll(v, -1, axis=0) - v
    cross = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
    assert np.all(cross > 0), "vertices must be strictly convex and counter-clockwise"


def lp_support(A, b, C, d, E, u):
    """max u . E x over the polytope (scipy HiGHS); None if infeasible."""
    r = linprog(
        -(E.T @ u),
        A_ub=A,
        b_ub=b,
        A_eq=C if len(C) else None,
        b_eq=d if len(C) else None,
        bounds=(None, None),
        method="highs",
    )
    assert r.status in (0, 2), r.message
    return None if r.status == 2 else float(u @ E @ r.x)


def lp_distance(A, b, C, d, E, y):
    """min ||E x - y||_inf over the polytope: 0 iff y is in the projection."""
    n = E.shape[1]
    # variables (x, t): minimise t s.t. E x - y <= t, y - E x <= t
    c = np.zeros(n + 1)
    c[-1] = 1
    A_ub = np.block([[A, np.zeros((len(A), 1))], [E, -np.ones((2, 1))], [-E, -np.ones((2, 1))]])
    b_ub = np.concatenate([b, y, -y])
    A_eq = np.hstack([C, np.zeros((len(C), 1))]) if len(C) else None
    r = linprog(
        c,
        A_ub=A_ub,
        b_ub=b_ub,
        A_eq=A_eq,
        b_eq=d if len(C) else None,
        bounds=(None, None),
        method="highs",
    )
    assert r.status == 0, r.message
    return float(r.fun)


def own_halfplanes(v):
    """Outward unit normals and offsets of a CCW polygon / segment / point (independent code)."""
    if len(v) >= 3:
        e = np.roll(v, -1, axis=0) - v
        n = np.column_stack([e[:, 1], -e[:, 0]])
        n /= np.linalg.norm(n, axis=1, keepdims=True)
        return n, np.einsum("ij,ij->i", n, v)
    if len(v) == 2:
        t = (v[1] - v[0]) / np.linalg.norm(v[1] - v[0])
        n = np.array([t[1], -t[0]])
        G = np.array([n, -n, t, -t])
        return G, np.array([n @ v[0], -n @ v[0], t @ v[1], -t @ v[0]])
    G = np.array([[1.0, 0], [-1, 0], [0, 1], [0, -1]])
    return G, G @ v[0]


def assert_is_projection(A, b, C, d, E, poly, tol=1e-7, n_dirs=64):
    """poly == E {A x <= b, C x = d} within tol, using LPs only."""
    v = poly.vertices
    assert len(v) >= 1
    # poly within the projection: every vertex is (within tol) a projected feasible point
    for y in v:
        assert lp_distance(A, b, C, d, E, y) <= tol
    # projection within poly: no feasible point beyond any of poly's own edges
    G, h = own_halfplanes(v)
    for g, hk in zip(G, h, strict=True):
        assert lp_support(A, b, C, d, E, g) <= hk + tol
    # and the brief's support-function comparison in evenly spread directions
    for a in np.linspace(0, 2 * np.pi, n_dirs, endpoint=False):
        u = np.array([np.cos(a), np.sin(a)])
        assert abs(lp_support(A, b, C, d, E, u) - np.max(v @ u)) <= tol


# Analytic polytopes --------------------------------------------------------------------
def test_box_projects_to_its_rectangle(geo, method):
    lo, hi = np.array([-1.0, 0.5, -3, -2]), np.array([2.0, 1.5, 3, 2])
    A, b = box_rows(lo, hi)
    E = np.eye(4)[:2]
    res = project(A, b, E, method=method)
    poly = res.polygon
    assert poly.bounded and len(poly.vertices) == 4
    assert_ccw_convex(poly.vertices)
    rect = np.array([[-1, 0.5], [2, 0.5], [2, 1.5], [-1, 1.5]])
    assert geo.hausdorff(poly.vertices, rect) <= 1e-9
    assert poly.area == pytest.approx(3.0, rel=1e-12)
    assert res.method == method
    if method == "bretl":
        assert res.n_lp >= 4  # at least one LP per edge to confirm it
    else:
        assert res.pivots >= 3  # at least one pivot per vertex after the first


@settings(max_examples=30, deadline=None)
@given(n=st.integers(2, 5), seed=st.integers(0, 2**32 - 1))
def test_box_under_random_map_is_the_zonotope_hull(geo, n, seed, method):
    rng = np.random.default_rng(seed)
    lo = rng.uniform(-2, 0, n)
    hi = lo + rng.uniform(0.05, 2, n)
    E = rng.normal(size=(2, n))
    A, b = box_rows(lo, hi)
    poly = project(A, b, E, method=method).polygon
    corners = np.array(list(itertools.product(*zip(lo, hi, strict=True))))
    expected = geo.hull(corners @ E.T)
    assert_ccw_convex(poly.vertices)
    assert geo.hausdorff(poly.vertices, expected) <= 1e-7
    assert poly.area == pytest.approx(geo.area(expected), rel=1e-7, abs=1e-12)
    assert len(poly.vertices) == len(expected)


def test_simplex_with_inequalities_and_with_an_equality(geo, method):
    tri = np.array([[0, 0], [1, 0], [0, 1.0]])
    # {x >= 0, sum x <= 1} in R^3
    A = np.vstack([-np.eye(3), np.ones((1, 3))])
    b = np.array([0, 0, 0, 1.0])
    poly = project(A, b, np.eye(3)[:2], method=method).polygon
    assert len(poly.vertices) == 3 and geo.hausdorff(poly.vertices, tri) <= 1e-9
    assert poly.area == pytest.approx(0.5, rel=1e-12)
    # {x >= 0, sum x = 1} in R^3: same triangle, and the map E sends vertex e_i to E[:, i]
    E = np.array([[2.0, -1.0, 0.5], [0.0, 1.0, 3.0]])
    poly = project(
        -np.eye(3), np.zeros(3), E, C=np.ones((1, 3)), d=np.array([1.0]), method=method
    ).polygon
    assert len(poly.vertices) == 3 and geo.hausdorff(poly.vertices, E.T) <= 1e-9


def test_unbounded_polyhedron_is_flagged_and_clipped(method):
    # quadrant {x >= 0}: the clipped projection is [0, box]^2
    res = project(-np.eye(2), np.zeros(2), np.eye(2), box=50.0, method=method)
    poly = res.polygon
    assert not poly.bounded
    assert np.all(np.abs(poly.vertices) <= 50.0 + 1e-9)
    assert any(np.allclose(v, [0, 0], atol=1e-9) for v in poly.vertices)
    assert poly.area == pytest.approx(2500.0, rel=1e-9)
    # half-strip {0 <= x1 <= 1, x2 >= 0}, also in a higher dimension with a free coordinate
    A = np.array([[1.0, 0, 0], [-1, 0, 0], [0, -1, 0]])
    poly = project(A, np.array([1.0, 0, 0]), np.eye(3)[:2], method=method).polygon
    assert not poly.bounded
    # a bounded polytope well inside the box stays bounded
    A, b = box_rows(-np.full(2, 500.0), np.full(2, 500.0))
    assert project(A, b, np.eye(2), method=method).polygon.bounded


def test_infeasible_polytope_gives_the_empty_polygon(method):
    A = np.array([[1.0, 0], [-1.0, 0]])
    b = np.array([-1.0, -1.0])  # x1 <= -1 and x1 >= 1
    poly = project(A, b, np.eye(2), method=method).polygon
    assert poly.is_empty and len(poly.vertices) == 0 and poly.area == 0.0
    # feasible inequalities, inconsistent equality
    A, b = box_rows(np.zeros(3), np.ones(3))
    poly = project(
        A, b, np.eye(3)[:2], C=np.array([[1.0, 1, 1]]), d=np.array([4.0]), method=method
    ).polygon
    assert poly.is_empty
    G, h = poly.halfplanes
    assert not np.any(G @ np.zeros(2) <= h)  # the empty set's half-planes exclude everything
    assert not poly.contains(np.zeros(2))


def test_degenerate_projections_segment_and_point(geo, method):
    A, b = box_rows(np.zeros(3), np.ones(3))
    # rank-1 map: the segment from (0, 0) to (2, 4)
    E = np.array([[1.0, 1, 0], [2, 2, 0]])
    poly = project(A, b, E, method=method).polygon
    assert len(poly.vertices) == 2 and poly.area == 0.0
    assert geo.hausdorff(poly.vertices, [[0, 0], [2, 4]]) <= 1e-9
    # segment by an equality: x1 = x2 within the unit box, projected on (x1, x2)
    poly = project(
        A, b, np.eye(3)[:2], C=np.array([[1.0, -1, 0]]), d=np.zeros(1), method=method
    ).polygon
    assert len(poly.vertices) == 2 and geo.hausdorff(poly.vertices, [[0, 0], [1, 1]]) <= 1e-9
    # point: zero map, and a fully pinned polytope
    poly = project(A, b, np.zeros((2, 3)), method=method).polygon
    assert len(poly.vertices) == 1 and np.allclose(poly.vertices[0], 0, atol=1e-12)
    E = np.array([[1.0, 2, 3], [-1, 0, 1]])
    c = np.array([0.2, 0.3, 0.4])
    poly = project(A, b, E, C=np.eye(3), d=c, method=method).polygon
    assert len(poly.vertices) == 1 and np.allclose(poly.vertices[0], E @ c, atol=1e-9)


def _random_polytope(rng, n, m, with_eq):
    A = rng.normal(size=(m, n))
    A /= np.linalg.norm(A, axis=1, keepdims=True)
    b = rng.uniform(0.1, 1.0, m)  # the origin is feasible
    Ab, bb = box_rows(-np.full(n, 2.0), np.full(n, 2.0))  # bounded
    A, b = np.vstack([A, Ab]), np.concatenate([b, bb])
    if with_eq:
        C = rng.normal(size=(1, n))
        d = np.zeros(1)
    else:
        C, d = np.zeros((0, n)), np.zeros(0)
    E = rng.normal(size=(2, n))
    return A, b, C, d, E


def test_determinism(method):
    A, b, C, d, E = _random_polytope(np.random.default_rng(7), 5, 12, True)
    r1, r2 = (
        project_polytope(A, b, C, d, E, method=method),
        project_polytope(A, b, C, d, E, method=method),
    )
    assert len(r1.polygon.vertices) >= 3
    assert np.array_equal(r1.polygon.vertices, r2.polygon.vertices)
    assert r1.method == r2.method == method
    assert (r1.n_lp, r1.pivots) == (r2.n_lp, r2.pivots) and r1.polygon.bounded == r2.polygon.bounded


@pytest.mark.slow
@settings(max_examples=30, deadline=None)
@given(
    n=st.integers(2, 5), m=st.integers(3, 12), with_eq=st.booleans(), seed=st.integers(0, 2**32 - 1)
)
def test_random_polytopes_against_linprog(n, m, with_eq, seed, method):
    A, b, C, d, E = _random_polytope(np.random.default_rng(seed), n, m, with_eq)
    poly = project_polytope(A, b, C, d, E, method=method).polygon
    assert poly.bounded
    assert_ccw_convex(poly.vertices)
    assert_is_projection(A, b, C, d, E, poly)


# The walk against Bretl ------------------------------------------------------------------
def _cone_polytope(rng, n_contacts, faces):
    """Stacked pyramids {F_i x_i <= 0} sharing a load sum(x_i[-1]) = 1: degenerate at every apex
    (a contact carrying nothing), like the contact wrench cones of a stance."""
    k = 3
    blocks = []
    for _ in range(n_contacts):
        mu = rng.uniform(0.2, 1.0)
        angles = np.linspace(0, 2 * np.pi, faces, endpoint=False) + rng.uniform(0, 1)
        blocks.append(np.column_stack([np.cos(angles), np.sin(angles), -mu * np.ones(faces)]))
    n = k * n_contacts
    A = np.zeros((faces * n_contacts, n))
    for i, F in enumerate(blocks):
        A[i * faces : (i + 1) * faces, i * k : (i + 1) * k] = F
    b = np.zeros(len(A))
    C = np.zeros((1, n))
    C[0, k - 1 :: k] = 1.0
    d = np.ones(1)
    E = np.zeros((2, n))
    for i in range(n_contacts):  # resultant horizontal force, plus a random twist
        E[:, i * k : i * k + 2] = np.eye(2) + 0.3 * rng.normal(size=(2, 2))
    return A, b, C, d, E


@settings(max_examples=40, deadline=None)
@given(n_contacts=st.integers(1, 4), faces=st.integers(3, 8), seed=st.integers(0, 2**32 - 1))
def test_walk_equals_bretl_on_degenerate_cone_stacks(geo, n_contacts, faces, seed):
    A, b, C, d, E = _cone_polytope(np.random.default_rng(seed), n_contacts, faces)
    walk = project_walk(A, b, C, d, E)
    assert walk is not None and walk.method == "walk"
    bretl = project_bretl(A, b, C, d, E)
    assert_ccw_convex(walk.polygon.vertices)
    assert len(walk.polygon.vertices) == len(bretl.polygon.vertices)
    assert geo.hausdorff(walk.polygon.vertices, bretl.polygon.vertices) <= 1e-7
    assert_is_projection(A, b, C, d, E, walk.polygon)


def test_lines_in_the_polytope_are_quotiented_out(geo, method):
    # the strip |x1| <= 1 (x2 free) under a map that ignores x2: the walk has no vertex to
    # start from until the line is projected out
    A = np.array([[1.0, 0], [-1.0, 0]])
    E = np.array([[1.0, 0], [0.5, 0]])
    res = project(A, np.ones(2), E, method=method)
    assert res.method == method
    assert geo.hausdorff(res.polygon.vertices, [[-1, -0.5], [1, 0.5]]) <= 1e-9
    # a slab in R^3 with a free coordinate, projected onto a plane with the free one
    A = np.array([[1.0, 1, 0], [-1.0, -1, 0], [0, 1, 0], [0, -1, 0]])
    res = project(A, np.ones(4), np.array([[1.0, 0, 0], [0, 1, 0]]), method=method)
    assert geo.hausdorff(res.polygon.vertices, [[-2, 1], [0, -1], [2, -1], [0, 1]]) <= 1e-9


def test_unknown_method_is_refused():
    with pytest.raises(SolverError, match="unknown method"):
        project(np.eye(2), np.ones(2), np.eye(2), method="simplex")


# Polygon.halfplanes and contains ---------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(n=st.integers(2, 5), m=st.integers(3, 12), seed=st.integers(0, 2**32 - 1))
def test_halfplanes_round_trip_and_membership(n, m, seed, method):
    rng = np.random.default_rng(seed)
    A, b, C, d, E = _random_polytope(rng, n, m, False)
    poly = project_polytope(A, b, C, d, E, method=method).polygon
    v = poly.vertices
    G, h = poly.halfplanes
    assert len(v) >= 3 and len(G) == len(v)
    np.testing.assert_allclose(np.linalg.norm(G, axis=1), 1.0, atol=1e-12)
    slack = h[None, :] - v @ G.T  # (vertex, row)
    assert np.all(slack >= -1e-9)
    assert np.all(np.sum(np.abs(slack) <= 1e-9, axis=1) == 2)  # each vertex on exactly two edges
    # each pair of consecutive rows meets at a vertex
    for k in range(len(G)):
        P = np.linalg.solve(G[[k - 1, k]], h[[k - 1, k]])
        assert np.min(np.linalg.norm(v - P, axis=1)) <= 1e-8
    # contains() agrees with LP membership for points not too close to the boundary
    lo, hi = v.min(axis=0) - 0.3, v.max(axis=0) + 0.3
    for y in rng.uniform(lo, hi, size=(40, 2)):
        dist = lp_distance(A, b, C, d, E, y)
        margin = float(np.min(h - G @ y))
        if abs(margin) < 1e-6:
            continue
        assert poly.contains(y) == (dist <= 1e-9)


def test_halfplanes_of_segment_point_and_rectangle():
    seg = Polygon(np.array([[0.0, 0.0], [2.0, 4.0]]))
    G, h = seg.halfplanes
    for p in seg.vertices:
        assert np.all(G @ p <= h + 1e-12)
        assert np.sum(np.abs(G @ p - h) <= 1e-12) == 3  # both sides and its end cap
    assert seg.contains(np.array([1.0, 2.0]))
    assert not seg.contains(np.array([1.0, 2.1]))
    assert not seg.contains(np.array([3.0, 6.0]))
    assert not seg.contains(np.array([-1.0, -2.0]))
    pt = Polygon(np.array([[0.3, -0.2]]))
    G, h = pt.halfplanes
    np.testing.assert_allclose(G @ pt.vertices[0], h, atol=1e-15)
    assert pt.contains(np.array([0.3, -0.2])) and not pt.contains(np.array([0.3, -0.19]))
    rect = Polygon(np.array([[-1.0, -0.5], [1.0, -0.5], [1.0, 0.5], [-1.0, 0.5]]))
    rng = np.random.default_rng(3)
    pts = rng.uniform(-1.5, 1.5, size=(200, 2))
    expected = (np.abs(pts[:, 0]) <= 1.0) & (np.abs(pts[:, 1]) <= 0.5)
    assert np.array_equal(rect.contains(pts), expected)
