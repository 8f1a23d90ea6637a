"""The walk projection under badly scaled rows: it must detect trouble and fall back to
Bretl, never return a wrong polygon (issue 8, section 3).

Independent references: Bretl's projection (one HiGHS LP per edge, HiGHS scales the rows
itself) and physics: more friction can only enlarge the set of feasible contact wrenches,
hence every area.
"""

from __future__ import annotations

import functools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.areas import FORCE_BOX, FORCE_TOLERANCE, MERGE_TOLERANCE
from impact_balance.constraints import wrench_polytope
from impact_balance.projection import project_polytope
from impact_balance.scenario import load_scenario
from impact_balance.stance import ContactSpec, Stance

STANCES = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "talos_three_contacts")


@functools.lru_cache(maxsize=8)
def _base(name: str):
    """(robot, q, contact specs) of a bundled stance."""
    scenario = load_scenario(name)
    stance = scenario.build_stance()
    return stance.robot, stance.q, tuple(c.spec for c in stance.contacts)


def _project(name: str, frictions, method: str = "auto"):
    robot, q, specs = _base(name)
    specs = [ContactSpec(s.frame, float(mu), s.size, s.offset) for s, mu in zip(specs, frictions)]
    polytope = wrench_polytope(Stance(robot, q, specs))
    w = polytope.weight
    return project_polytope(
        polytope.A, polytope.b / w, polytope.C, polytope.d / w, polytope.F,
        tol=FORCE_TOLERANCE, box=FORCE_BOX, merge_tol=MERGE_TOLERANCE, method=method,
    )


def _check_polygon(polygon):
    """Convex, counter-clockwise, non-negative area, inside the clipping box."""
    v = polygon.vertices
    assert np.isfinite(v).all()
    assert polygon.area >= 0.0
    assert np.abs(v).max() <= FORCE_BOX * (1 + 1e-9)
    if len(v) >= 3:
        e = np.roll(v, -1, axis=0) - v
        cross = e[:, 0] * np.roll(e[:, 1], -1) - e[:, 1] * np.roll(e[:, 0], -1)
        assert (cross >= -1e-9 * np.linalg.norm(e, axis=1) * np.linalg.norm(np.roll(e, -1, axis=0), axis=1)).all()


def _same_polygon(p, q, rel=1e-6):
    """Same area and same support function in 64 directions, to ``rel`` of the size."""
    size = max(1e-12, np.abs(q.vertices).max())
    assert p.area == pytest.approx(q.area, rel=rel, abs=rel * size**2)
    angles = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    U = np.column_stack([np.cos(angles), np.sin(angles)])
    np.testing.assert_allclose((p.vertices @ U.T).max(axis=0), (q.vertices @ U.T).max(axis=0), atol=rel * size)


@pytest.mark.parametrize(
    "frictions",
    [(0.7, 0.7, 1e8), (0.7, 0.7, 1e9), (1e-9, 1e-9, 0.7), (0.7, 1e9, 0.7), (1e-6, 0.7, 1e6)],
)
def test_extreme_friction_matches_bretl(frictions):
    """The cases of the issue: the walk gave a non-convex polygon (wall friction 1e9) and a
    negative area of vertices outside the clipping box (feet at 1e-9). The answer is now
    Bretl's, or the walk's when it is verified to agree."""
    auto = _project("talos_three_contacts", frictions)
    bretl = _project("talos_three_contacts", frictions, method="bretl")
    _check_polygon(auto.polygon)
    assert auto.polygon.bounded == bretl.polygon.bounded
    _same_polygon(auto.polygon, bretl.polygon)


def test_walk_rejects_a_bad_walk():
    """method='walk' refuses (rather than answers) where the walk loses its way."""
    from impact_balance.exceptions import SolverError

    with pytest.raises(SolverError):
        _project("talos_three_contacts", (0.7, 0.7, 1e9), method="walk")


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
    which %= len(specs)
    lo, hi = sorted(10.0 ** np.asarray(exponents))
    polygons = []
    for mu in (lo, hi):
        frictions = [s.friction for s in specs]
        frictions[which] = mu
        auto = _project(name, frictions)
        _check_polygon(auto.polygon)
        _same_polygon(auto.polygon, _project(name, frictions, method="bretl").polygon)
        polygons.append(auto.polygon)
    small, large = polygons
    assert large.area >= small.area * (1 - 1e-6) - 1e-12
    if not small.is_empty:  # every vertex of the smaller area lies in the larger one
        assert large.contains(small.vertices, tol=1e-6).all()
