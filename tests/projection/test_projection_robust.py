"""The walk projection under badly scaled rows: it must detect trouble and fall back to
Bretl, never return a wrong polygon, and keep its precision at
extreme frictions (docs/numerics.md, "Precision at extreme friction").

Independent references: Bretl's projection (one HiGHS LP per edge, HiGHS scales the rows
itself) and physics: more friction can only enlarge the set of feasible contact wrenches,
hence every area.

Tolerances: areas to 1e-6 relative; positions to MERGE_TOLERANCE (1e-6 m g), the
documented distance within which the merge of near-duplicate and near-collinear vertices
may move the boundary inwards, plus the walk's certified vertex precision (SLACK_TOLERANCE)
where two projections are nested.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.balance.areas import FORCE_BOX, FORCE_TOLERANCE, MERGE_TOLERANCE
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.contacts.wrench_polytope import wrench_polytope
from impact_balance.geometry.polygon import Polygon, simplify
from impact_balance.projection import project_polytope
from impact_balance.projection.walk import SLACK_TOLERANCE
from impact_balance.scenario import bundled_scenarios, load_scenario

STANCES = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "talos_three_contacts")


@functools.lru_cache(maxsize=8)
def _base(name: str):
    """(robot, q, contact specs) of a bundled stance."""
    scenario = load_scenario(name)
    stance = scenario.build_stance()
    return stance.robot, stance.q, tuple(c.spec for c in stance.contacts)


def _project(name: str, frictions, method: str = "auto"):
    robot, q, specs = _base(name)
    specs = [
        ContactSpec(s.frame, float(mu), s.size, s.offset)
        for s, mu in zip(specs, frictions, strict=True)
    ]
    polytope = wrench_polytope(Stance(robot, q, specs))
    return project_polytope(
        *polytope.projection_data(),
        tol=FORCE_TOLERANCE,
        box=FORCE_BOX,
        merge_tol=MERGE_TOLERANCE,
        method=method,
    )


def _check_polygon(polygon):
    """Convex, counter-clockwise, winding once, non-negative area, inside the clipping box."""
    v = polygon.vertices
    assert np.isfinite(v).all()
    assert polygon.area >= 0.0
    assert np.abs(v).max() <= FORCE_BOX * (1 + 1e-9)
    if len(v) >= 3:
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
        assert (
            cross
            >= -1e-9 * np.linalg.norm(e, axis=1) * np.linalg.norm(np.roll(e, -1, axis=0), axis=1)
        ).all()
        f = np.roll(e, -1, axis=0)
        turning = np.arctan2(cross, (e * f).sum(axis=1)).sum()
        assert turning == pytest.approx(2 * np.pi, abs=1e-6)  # one lap, not two


def _same_polygon(p, q, rel=1e-6):
    """Same area to ``rel`` and same support function in 64 directions, to ``rel`` of the
    size or MERGE_TOLERANCE: each polygon is within it of its unmerged vertices, and the two
    projections merge different lists (measured worst: 4e-7 m g, Talos' foot at mu 6e4)."""
    size = max(1e-12, np.abs(q.vertices).max())
    assert p.area == pytest.approx(q.area, rel=rel, abs=rel * size**2)
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    U = np.column_stack([np.cos(angles), np.sin(angles)])
    np.testing.assert_allclose(
        (p.vertices @ U.T).max(axis=0),
        (q.vertices @ U.T).max(axis=0),
        atol=max(rel * size, MERGE_TOLERANCE),
    )


@pytest.mark.parametrize(
    "frictions",
    [(0.7, 0.7, 1e8), (0.7, 0.7, 1e9), (1e-9, 1e-9, 0.7), (0.7, 1e9, 0.7), (1e-6, 0.7, 1e6)],
)
def test_extreme_friction_matches_bretl(frictions):
    """Extreme frictions where an unchecked walk gives a non-convex polygon (wall friction 1e9)
    or a negative area of vertices outside the clipping box (feet at 1e-9): the answer is
    Bretl's, or the walk's when it is verified to agree."""
    auto = _project("talos_three_contacts", frictions)
    bretl = _project("talos_three_contacts", frictions, method="bretl")
    _check_polygon(auto.polygon)
    assert auto.polygon.bounded == bretl.polygon.bounded
    _same_polygon(auto.polygon, bretl.polygon)


@pytest.mark.parametrize("frictions", [(1e-9, 1e-9, 0.7), (0.7, 0.7, 1e9)])
def test_walk_rejects_a_bad_walk(frictions):
    """method='walk' refuses (rather than answers) where the walk loses its way: on these
    badly scaled rows (the unnormalised polytope) its vertices violate constraints or it
    backtracks into a non-convex polygon, which the certificate catches. Whether the walk
    keeps its way on such rows changes with rounding and with the kernel (feet at 1e-6 beside
    a hand at 1e6 was refused until the walk made a fresh inverse wherever its carried one
    drifted; it now answers, within 2e-9 of Bretl's area); where it does, its answer agrees
    with Bretl's (test_extreme_friction_matches_bretl)."""
    from impact_balance.exceptions import SolverError

    with pytest.raises(SolverError):
        _project("talos_three_contacts", frictions, method="walk")


#: Nesting tolerance: the merge (MERGE_TOLERANCE) plus the walk's certified vertex precision.
NESTED = MERGE_TOLERANCE + SLACK_TOLERANCE


def _check_monotone(name, which, frictions_of_contact):
    """Projections at increasing frictions of contact ``which``: each a sound polygon equal
    to Bretl's, each area at least the previous one's and containing its vertices."""
    _, _, specs = _base(name)
    previous = None
    for mu in frictions_of_contact:
        frictions = [s.friction for s in specs]
        frictions[which] = mu
        auto = _project(name, frictions)
        bretl = _project(name, frictions, method="bretl")
        _check_polygon(auto.polygon)
        _check_polygon(bretl.polygon)
        _same_polygon(auto.polygon, bretl.polygon)
        if previous is not None:
            assert auto.polygon.area >= previous.area * (1 - 1e-6) - 1e-12, f"mu {mu}"
            if not previous.is_empty:  # every vertex of the smaller area lies in the larger one
                assert auto.polygon.contains(previous.vertices, tol=NESTED).all(), f"mu {mu}"
        previous = auto.polygon


@settings(max_examples=25, deadline=None)
@given(
    name=st.sampled_from(STANCES),
    which=st.integers(0, 2),
    exponents=st.lists(st.floats(-6.0, 6.0), min_size=2, max_size=2),
)
def test_area_is_monotone_in_friction(name, which, exponents):
    """More friction on any one contact never shrinks the force area (1e-6 <= mu <= 1e6),
    and the default projection agrees with Bretl's at both frictions."""
    _, _, specs = _base(name)
    _check_monotone(name, which % len(specs), sorted(10.0 ** np.asarray(exponents)))


@pytest.mark.parametrize("name", sorted(bundled_scenarios()))
def test_area_is_monotone_on_a_friction_grid(name):
    """The same on a deterministic grid, 1e-6 to 1e6 in steps of 10^0.2, every contact:
    the property does not hold by luck of the draw (feet at 10^4.625 and 10^5.5, a hand at
    1.6e-6 are on the grid)."""
    _, _, specs = _base(name)
    for which in range(len(specs)):
        _check_monotone(name, which, 10.0 ** np.linspace(-6.0, 6.0, 61))


@pytest.mark.parametrize("mu", [1.0, 10**4.625, 10**5.5, 1e6])
def test_walk_answers_and_equals_bretl_at_large_foot_friction(mu):
    """At large foot frictions the walk itself (no fallback) answers and gives Bretl's polygon
    to 1e-9 relative, the corner included."""
    walk = _project("palm_push_two_feet", [mu, 0.7], method="walk")
    bretl = _project("palm_push_two_feet", [mu, 0.7], method="bretl")
    _same_polygon(walk.polygon, bretl.polygon, rel=1e-9)
    reference = _project("palm_push_two_feet", [1.0, 0.7], method="bretl").polygon
    assert walk.polygon.area >= reference.area * (1 - 1e-9)


def test_merge_keeps_a_corner_over_its_near_duplicate():
    """The root cause of the shrinking areas: a corner with a vertex 7e-7 below it on a side.
    The merge drops the near-duplicate on the side, not the corner."""
    square = np.array([[1.0, -1.0], [1.0, 1.0 - 7e-7], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]])
    merged = simplify(square, 1e-6)
    assert Polygon(merged).area == 4.0
    np.testing.assert_array_equal(merged, square[[0, 2, 3, 4]])


def test_merge_is_within_its_tolerance_of_every_input_vertex():
    """Many near-collinear vertices (a side bulging by 4e-7 every 0.01): dropping them one by
    one against their current neighbours used to drift; every input vertex stays within
    the tolerance of the merged polygon (Hausdorff distance), and exact duplicates at both
    ends of the list (a walk's first and last vertex) do not cost the corner."""
    t = np.linspace(-1.0, 1.0, 201)
    bulge = 4e-7 * (1.0 - t**2)  # a side bulging by up to 4e-7, concave down: still convex
    side = np.column_stack([np.ones_like(t), t]) + np.column_stack([bulge, np.zeros_like(t)])
    ring = np.vstack(
        [[[1.0, -1.0]] * 3, side[1:-1], [[1.0, 1.0]], [[-1.0, 1.0]], [[-1.0, -1.0]], [[1.0, -1.0]]]
    )
    merged = Polygon(simplify(ring, 1e-7))
    assert merged.contains(ring, tol=1e-7 * (1 + 1e-9)).all()
    assert merged.contains(
        np.array([[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]]), tol=0.0
    ).all()


def test_certificate_refuses_a_spike_along_an_edge():
    """A walk that backtracks along an edge (out and back: two half-turns whose cross
    products are rounding of either sign) is refused, not certified convex: its half-planes
    would carry a reversed edge normal (drawn by a variant of the walk, since dropped, on
    talos_three_contacts with a hand at mu 1e6)."""
    from impact_balance.geometry.polygon import simplify_convex

    square = np.array([[1.0, -1.0], [1.0, 1.0], [-1.0, 1.0], [-1.0, -1.0]])
    assert simplify_convex(square, 1e-9, 1e-8, 1e3) is not None
    for eps in (0.0, 1e-17, -1e-17):  # the tip's cross product: zero or rounding either way
        spiked = np.array(
            [[1.0, -1.0], [1.0, 1.0], [0.0, 1.0], [0.5, 1.0 + eps], [-1.0, 1.0], [-1.0, -1.0]]
        )
        assert simplify_convex(spiked, 1e-9, 1e-8, 1e3) is None


def test_an_empty_walk_is_confirmed_by_bretl():
    """A wall hand at friction 1e12 (beyond the scenarios' 1e6, through the library): the
    walk's phase 1 calls the badly scaled polytope infeasible; "auto" asks Bretl, which finds
    the same area as at 1e10."""
    auto = _project("talos_three_contacts", (0.7, 0.7, 1e12))
    reference = _project("talos_three_contacts", (0.7, 0.7, 1e10), method="bretl")
    _check_polygon(auto.polygon)
    assert auto.method == "bretl"
    _same_polygon(auto.polygon, reference.polygon)


@settings(max_examples=50, deadline=None)
@given(st.integers(min_value=2, max_value=12), st.integers(min_value=0, max_value=2**32 - 1))
def test_carried_inverse_check_accepts_a_fresh_inverse_and_refuses_a_drifted_one(n, seed):
    """The walk carries its basis inverse across breakpoints only while ``_accurate`` holds:
    a fresh inverse of a well-conditioned basis (orthonormal rows) passes it; the same inverse
    or vertex off by 1e-9 of its size (the drift of rank-one updates on an ill-conditioned
    basis) does not. (A fresh inverse of an ill-conditioned basis may fail it too: the walk
    then makes a fresh one, as it did at every breakpoint before.)"""
    from impact_balance.projection.kernel import _accurate

    rng = np.random.default_rng(seed)
    m = n + 5
    H = rng.normal(size=(m, n))
    H /= np.linalg.norm(H, axis=1)[:, None]
    W = rng.permutation(m)[:n].astype(np.int64)
    H[W] = np.linalg.qr(rng.normal(size=(n, n)))[0].T  # an orthonormal basis: condition 1
    h = rng.uniform(0.1, 2.0, size=m)
    Binv = np.linalg.inv(H[W])
    z = Binv @ h[W]
    buffer = np.empty(n)
    assert _accurate(H, h, W, Binv, z, buffer)
    drifted = Binv.copy()
    drifted[rng.integers(n), rng.integers(n)] += 1e-9 * np.abs(Binv).max()
    assert not _accurate(H, h, W, drifted, z, buffer)
    assert not _accurate(
        H,
        h,
        W,
        Binv,
        z + 1e-9 * max(1.0, np.abs(z).max()) * rng.choice([-1.0, 1.0], size=n),
        buffer,
    )


def test_bretl_answers_where_the_warm_simplex_stopped_undecided():
    """Found by test_area_is_monotone_in_friction: on the ramp with its left foot at friction
    10^4.406 (the unnormalised polytope), HiGHS's warm-started primal simplex ended one of
    Bretl's LPs with status Unknown and the projection raised. The LP is now solved again from
    scratch (HiGHS's defaults), and Bretl's polygon is the walk's."""
    _, _, specs = _base("palm_push_ramp")
    frictions = [s.friction for s in specs]
    frictions[0] = 10.0**4.405863216728498
    bretl = _project("palm_push_ramp", frictions, method="bretl")
    walk = _project("palm_push_ramp", frictions, method="walk")
    _check_polygon(bretl.polygon)
    _same_polygon(walk.polygon, bretl.polygon)
