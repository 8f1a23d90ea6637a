"""Polygon.inset (the ZMP margin): the erosion of a convex polygon by a disc.

Checked against analytic cases and, on random polygons, against the definition itself: a
point is in the inset polygon exactly when its margin in the original is at least the distance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull, HalfspaceIntersection

from impact_balance.geometry.polygon import Polygon


def rectangle(a: float, b: float, centre=(0.0, 0.0)) -> Polygon:
    cx, cy = centre
    return Polygon(
        np.array(
            [
                [cx - a / 2, cy - b / 2],
                [cx + a / 2, cy - b / 2],
                [cx + a / 2, cy + b / 2],
                [cx - a / 2, cy + b / 2],
            ]
        )
    )


def regular(k: int, inradius: float) -> Polygon:
    angles = 2 * np.pi * (np.arange(k) + 0.5) / k
    R = inradius / math.cos(math.pi / k)
    return Polygon(R * np.column_stack([np.cos(angles), np.sin(angles)]))


@pytest.mark.parametrize("a, b, d", [(2.0, 1.0, 0.1), (0.2, 0.1, 0.03), (1e-3, 3e-3, 4e-4)])
def test_rectangle_shrinks_by_twice_the_distance(a, b, d):
    inset = rectangle(a, b, centre=(5.0, -3.0)).inset(d)
    assert len(inset.vertices) == 4
    assert inset.area == pytest.approx((a - 2 * d) * (b - 2 * d), rel=1e-12)
    assert inset.vertices.min(axis=0) == pytest.approx(
        [5.0 - a / 2 + d, -3.0 - b / 2 + d], abs=1e-12
    )


@pytest.mark.parametrize("k", [3, 5, 8, 17])
def test_regular_polygon_scales_about_its_centre(k):
    p = regular(k, 1.0)
    inset = p.inset(0.25)
    assert inset.area == pytest.approx(0.75**2 * p.area, rel=1e-12)
    assert (
        regular(k, 1.0).inset(1.0).is_empty
    )  # at the inradius only the centre is left: no interior


def test_short_edges_leave_first():
    # A thin pentagon: its short top edge collapses long before the polygon does.
    p = Polygon(
        np.array([[0.0, 0.0], [4.0, 0.0], [4.0, 1.0], [2.05, 1.5], [1.95, 1.5], [0.0, 1.0]])
    )
    # Its edge shrinks at 2 tan(7 deg) per unit inset (turning angle 14 deg): gone at d = 0.40.
    for d, corners in ((0.3, 6), (0.5, 5), (0.6, 3)):
        inset = p.inset(d)
        assert len(inset.vertices) == corners
        assert np.all(p.margins(inset.vertices) >= d - 1e-12)
        assert np.min(p.margins(inset.vertices)) == pytest.approx(d, abs=1e-12)


def test_zero_distance_and_degenerate_polygons():
    r = rectangle(1.0, 1.0)
    assert r.inset(0.0) is r
    assert Polygon(np.array([[0.0, 0.0], [1.0, 0.0]])).inset(1e-9).is_empty
    assert Polygon(np.array([[0.0, 0.0]])).inset(1e-9).is_empty
    assert Polygon.empty().inset(0.1).is_empty
    with pytest.raises(ValueError):
        r.inset(-0.1)
    with pytest.raises(ValueError):
        r.inset(math.nan)


def _halfspace_reference(p: Polygon, d: float) -> float:
    """Area of the inset polygon by qhull's half-space intersection (an independent computation)."""
    G, h = p.halfplanes
    hs = np.column_stack([G, -(h - d)])  # A x + b <= 0
    # A strictly interior point of the eroded set: sample the original's deepest point roughly.
    xs = p.vertices.mean(axis=0)
    if np.min(h - d - G @ xs) <= 1e-9:
        return 0.0
    pts = HalfspaceIntersection(hs, xs).intersections
    # qhull's hull, not Polygon.from_points: the latter merges nearly collinear vertices (a
    # sliver of area below its merge tolerance), which the polygon under test may keep.
    return float(ConvexHull(pts).volume)


@settings(max_examples=200, deadline=None)
@example(  # a vertex 1e-9 off an edge: a sliver the reference must not merge away
    points=[(0.0, 0.0), (0.0, 0.25), (0.6101949144738379, 0.0), (0.375, -1e-09)],
    fraction=0.0,
    scale=1.0,
)
@given(
    points=st.lists(st.tuples(st.floats(-1, 1), st.floats(-1, 1)), min_size=3, max_size=30),
    fraction=st.floats(0.0, 1.2),
    scale=st.sampled_from([1e-3, 1.0, 1e3]),
)
def test_inset_is_the_erosion(points, fraction, scale):
    p = Polygon.from_points(scale * np.array(points))
    if len(p.vertices) < 3 or p.area < 1e-6 * scale**2:
        return
    # The inradius is at most the largest margin of any vertex mean; use the polygon size for d.
    size = float(np.ptp(p.vertices, axis=0).min())
    d = fraction * size / 2
    inset = p.inset(d)
    rng = np.random.default_rng(0)
    lo, hi = p.vertices.min(axis=0), p.vertices.max(axis=0)
    samples = rng.uniform(lo, hi, size=(2000, 2))
    deep = p.margins(samples)
    tol = 1e-9 * scale
    if inset.is_empty:
        assert np.all(deep <= d + tol)
        return
    assert np.all(p.margins(inset.vertices) >= d - tol)  # every corner is at least d inside
    inside = inset.margins(samples)
    clear = np.abs(deep - d) > tol  # away from the boundary, the two tests agree
    assert np.array_equal((inside >= 0)[clear], (deep >= d)[clear])
    reference = _halfspace_reference(p, d)
    if reference > 0:
        assert inset.area == pytest.approx(reference, rel=1e-9, abs=1e-12 * scale**2)
