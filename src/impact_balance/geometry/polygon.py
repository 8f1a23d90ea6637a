"""Convex polygons in the plane, as counter-clockwise vertices and as half-planes."""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance._jit import njit

__all__ = [
    "MERGE_AREA_TOLERANCE",
    "Polygon",
    "edge_halfplanes",
    "inset_polygon",
    "simplify",
    "simplify_convex",
    "simplify_convex_kernel",
]

#: Largest fraction of a polygon's area that merging its near-duplicate and near-collinear
#: vertices may remove. Bounded so that a larger set never gets a smaller merged area by
#: more than this (the distance bound alone allowed tol x perimeter: 2.9e-6 of the force
#: area of g1_two_feet with a foot friction of 6e4).
MERGE_AREA_TOLERANCE = 1e-6


@njit(cache=True)
def _chord_distance(v, p, c, n):
    """Distance from vertex c to the segment from p to n (the chord that replaces it).

    The line distance, or the distance to the nearer end when c projects outside the segment
    (of three collinear points, only the middle one is on its chord).
    """
    ex, ey = v[n, 0] - v[p, 0], v[n, 1] - v[p, 1]
    cx, cy = v[c, 0] - v[p, 0], v[c, 1] - v[p, 1]
    length2 = ex * ex + ey * ey
    t = 0.0 if length2 == 0.0 else min(1.0, max(0.0, (cx * ex + cy * ey) / length2))
    return math.hypot(cx - t * ex, cy - t * ey)


@njit(cache=True)
def _merge_cost(v, idx, k, i, total):
    """(distance, area) of dropping the vertex in position i of ``idx[:k]``.

    The largest distance from the chord between its neighbours of the original vertices it
    replaces (dropped ones included, so that drops cannot drift), and the area of the triangle
    lost.
    """
    p, c, n = idx[(i - 1) % k], idx[i], idx[(i + 1) % k]  # idx[k:] is stale
    dist = 0.0
    j = (p + 1) % total
    while j != n:
        dist = max(dist, _chord_distance(v, p, j, n))
        j = (j + 1) % total
    lost = 0.5 * abs(
        (v[c, 0] - v[p, 0]) * (v[n, 1] - v[p, 1]) - (v[c, 1] - v[p, 1]) * (v[n, 0] - v[p, 0])
    )
    return dist, lost


@njit(cache=True)
def _simplify(v: np.ndarray, tol: float, area_tol: float) -> np.ndarray:
    """Compiled loop of :func:`simplify` on a (k, 2) C-contiguous array."""
    total = len(v)
    idx = np.arange(total)
    k = total
    if total < 3:
        if total == 2 and math.hypot(v[0, 0] - v[1, 0], v[0, 1] - v[1, 1]) <= tol:
            k = 1
        return v[idx[:k]].copy()
    area = 0.0  # shoelace area of the input: the budget of area the merge may remove
    for i in range(total):
        j = (i + 1) % total
        area += 0.5 * (v[i, 0] * v[j, 1] - v[j, 0] * v[i, 1])
    lo0, hi0, lo1, hi1 = v[:, 0].min(), v[:, 0].max(), v[:, 1].min(), v[:, 1].max()
    size = math.hypot(hi0 - lo0, hi1 - lo1)
    # A polygon thinner than tol is a segment within tol: its area bounds nothing. Rounding
    # (1e-14 size^2) is free, so that collinear vertices of a segment still go.
    budget = area_tol * abs(area) if abs(area) > tol * size else math.inf
    free = 1e-14 * size * size
    # Rounding-level duplicates (within 1e-12 size; a walk records a vertex once per
    # pivot) go first in one pass: which of them stays cannot matter.
    k = 1
    for i in range(1, total):
        if math.hypot(v[i, 0] - v[idx[k - 1], 0], v[i, 1] - v[idx[k - 1], 1]) > 1e-12 * size:
            idx[k] = i
            k += 1
    while (
        k > 1
        and math.hypot(v[idx[k - 1], 0] - v[idx[0], 0], v[idx[k - 1], 1] - v[idx[0], 1])
        <= 1e-12 * size
    ):
        k -= 1
    dist = np.empty(total)
    lost = np.empty(total)
    for i in range(k):
        dist[i], lost[i] = _merge_cost(v, idx, k, i, total)
    while k > 2:
        # Of the vertices whose removal keeps every vertex removed so far within tol of the
        # new chord and fits in the area budget, the closest to its chord goes first.
        # Dropping the first vertex found within tol made the answer depend on the order: a
        # true corner next to a vertex 7e-7 below it on a side was dropped (area -1e-6).
        best, drop = math.inf, -1
        for i in range(k):
            if dist[i] < best and dist[i] <= tol and (lost[i] <= budget or lost[i] <= free):
                best, drop = dist[i], i
        if drop < 0:
            break
        budget -= max(lost[drop] - free, 0.0)
        for j in range(drop, k - 1):  # in place: a slice copy per drop cost microseconds
            idx[j], dist[j], lost[j] = idx[j + 1], dist[j + 1], lost[j + 1]
        k -= 1
        for i in ((drop - 1) % k, drop % k):  # only the two new neighbours' costs change
            dist[i], lost[i] = _merge_cost(v, idx, k, i, total)
    if k == 2 and math.hypot(v[idx[0], 0] - v[idx[1], 0], v[idx[0], 1] - v[idx[1], 1]) <= tol:
        k = 1
    return v[idx[:k]].copy()


@njit(cache=True)
def _convex_ccw(v):
    """Whether the (k, 2) vertices form a convex counter-clockwise polygon that winds once.

    Every turn must be a left turn (cross product >= -1e-9 of the edge lengths' product,
    i.e. a clockwise kink under a nano-radian) and the turning angles must add up to 2 pi:
    a walk that lost its way backtracks (a half-turn) or winds twice. A turn counts in
    [0, pi] (a tolerated clockwise kink as 0): a spike out and back along an edge is two
    half-turns whose signs are rounding (cross ~ 0), which would cancel as +pi and -pi, and
    instead add 2 pi too many. Fewer than 3 vertices (a point or a segment) pass; non-finite
    coordinates fail.
    """
    k = v.shape[0]
    for i in range(k):
        if not (math.isfinite(v[i, 0]) and math.isfinite(v[i, 1])):
            return False
    if k < 3:
        return True
    total = 0.0
    for i in range(k):
        a = v[i - 1]
        b = v[i]
        c = v[(i + 1) % k]
        e0x, e0y = b[0] - a[0], b[1] - a[1]
        e1x, e1y = c[0] - b[0], c[1] - b[1]
        cross = e0x * e1y - e0y * e1x
        dot = e0x * e1x + e0y * e1y
        if cross < -1e-9 * math.hypot(e0x, e0y) * math.hypot(e1x, e1y):
            return False
        total += math.atan2(cross if cross > 0.0 else 0.0, dot)  # +0.0: max(-0.0, 0.0) is -0.0
    return abs(total - 2.0 * math.pi) < 1e-6


@njit(cache=True)
def simplify_convex_kernel(v, check_tol, tol, area_tol, box):
    """:func:`simplify_convex` compiled, on a contiguous (k, 2) float array.

    Returns ``(ok, vertices, bounded)``: ``ok`` False when the check fails. A compiled
    caller (the projection walk) calls it directly.
    """
    first = _simplify(v, check_tol, area_tol)
    if not _convex_ccw(first):
        return False, first, False
    out = _simplify(first, tol, area_tol)
    bounded = True
    limit = box * (1.0 - 1e-9)
    for i in range(out.shape[0]):
        for j in range(2):
            if not abs(out[i, j]) < limit:  # also False for a NaN
                bounded = False
    return True, out, bounded


def simplify_convex(
    vertices: np.ndarray,
    check_tol: float,
    tol: float,
    box: float,
    area_tol: float = MERGE_AREA_TOLERANCE,
) -> tuple[np.ndarray, bool] | None:
    """A projection's raw vertices (k >= 1, counter-clockwise), certified and merged.

    In one compiled call: merged within ``check_tol`` (rounding-level duplicates), checked
    convex, counter-clockwise and winding once (see :func:`_convex_ccw`), then merged within
    ``tol`` (see :func:`simplify`). Returns ``(vertices, bounded)``, bounded when every
    coordinate is under ``box`` (the clipping box), or None when the check fails.
    """
    v = np.ascontiguousarray(np.asarray(vertices, dtype=float).reshape(-1, 2))
    ok, out, bounded = simplify_convex_kernel(
        v, float(check_tol), float(tol), float(area_tol), float(box)
    )
    return (out, bool(bounded)) if ok else None


def simplify(
    vertices: np.ndarray, tol: float = 1e-9, area_tol: float = MERGE_AREA_TOLERANCE
) -> np.ndarray:
    """Merge duplicate and collinear consecutive vertices of a CCW convex polygon.

    ``tol`` is a distance: while some vertex can be dropped with every vertex dropped so far
    between its neighbours within ``tol`` of the chord that replaces them (a vertex within
    ``tol`` of a neighbour can), and with the area removed so far at most ``area_tol`` times
    the input's area, the one with the smallest such distance is dropped. So every input
    vertex lies within ``tol`` of the result (Hausdorff distance <= tol: the merge cannot
    drift), the result keeps all but ``area_tol`` of the area (exact duplicates cost
    nothing), and closest first keeps the extreme vertices: of a corner and a near-duplicate
    of it on a side, the near-duplicate goes.
    """
    v = np.ascontiguousarray(np.asarray(vertices, dtype=float).reshape(-1, 2))
    if len(v) == 0:
        out: npt.NDArray[np.float64] = v.copy()
        return out
    return _simplify(v, float(tol), float(area_tol))


@njit(cache=True)
def _corner(n: np.ndarray, h: np.ndarray, a: int, b: int) -> tuple[float, float, float, float]:
    """Corner of lines ``a`` and ``b`` (``n_k . x = h_k - t``) as ``x0 + t x1``: (x0, y0, x1, y1).

    Undefined (NaN) when the lines are parallel.
    """
    det = n[a, 0] * n[b, 1] - n[a, 1] * n[b, 0]
    if det <= 1e-15:
        return math.nan, math.nan, math.nan, math.nan
    # Inverse of [[n_a], [n_b]] applied to (h_a, h_b) and to (-1, -1).
    x0 = (n[b, 1] * h[a] - n[a, 1] * h[b]) / det
    y0 = (-n[b, 0] * h[a] + n[a, 0] * h[b]) / det
    x1 = (-n[b, 1] + n[a, 1]) / det
    y1 = (n[b, 0] - n[a, 0]) / det
    return x0, y0, x1, y1


@njit(cache=True)
def _collapse_time(n: np.ndarray, h: np.ndarray, a: int, i: int, b: int) -> float:
    """When edge ``i`` (between lines ``a`` and ``b``) shrinks to nothing.

    Every line moves inwards at unit speed; inf if it never does, -inf if its neighbours are
    parallel.
    """
    p = _corner(n, h, a, i)
    q = _corner(n, h, i, b)
    if math.isnan(p[0]) or math.isnan(q[0]):
        return -math.inf
    ex, ey = -n[i, 1], n[i, 0]  # the edge's direction (CCW)
    length0 = (q[0] - p[0]) * ex + (q[1] - p[1]) * ey
    rate = (q[2] - p[2]) * ex + (q[3] - p[3]) * ey
    if rate >= 0.0:
        return math.inf
    return -length0 / rate


@njit(cache=True)
def _inset(n: np.ndarray, h: np.ndarray, d: float) -> np.ndarray:
    """Vertices of ``{x : n_k . x <= h_k - d}``, (0, 2) when empty.

    For the edges (unit outward normals ``n``, CCW) of a convex polygon.

    The lines move inwards together; an edge whose length reaches zero before ``d`` leaves
    (earliest first, as in the straight skeleton of a convex polygon) and its neighbours meet.
    """
    k = len(h)
    nxt = np.empty(k, dtype=np.int64)
    prv = np.empty(k, dtype=np.int64)
    for i in range(k):
        nxt[i] = (i + 1) % k
        prv[i] = (i - 1) % k
    times = np.empty(k)
    for i in range(k):
        times[i] = _collapse_time(n, h, prv[i], i, nxt[i])
    alive = np.ones(k, dtype=np.bool_)
    count = k
    while count >= 3:
        i = -1
        earliest = math.inf
        for j in range(k):
            if alive[j] and times[j] < earliest:
                earliest, i = times[j], j
        if i < 0 or earliest > d:
            break
        alive[i] = False
        count -= 1
        a, b = prv[i], nxt[i]
        nxt[a], prv[b] = b, a
        if count >= 3:
            times[a] = _collapse_time(n, h, prv[a], a, b)
            times[b] = _collapse_time(n, h, a, b, nxt[b])
    if count < 3:
        return np.zeros((0, 2))
    out = np.empty((count, 2))
    first = 0
    while not alive[first]:
        first += 1
    i, m = first, 0
    while True:
        c = _corner(n, h, i, nxt[i])
        if math.isnan(c[0]):
            return np.zeros((0, 2))
        out[m, 0] = c[0] + d * c[2]
        out[m, 1] = c[1] + d * c[3]
        m += 1
        i = nxt[i]
        if i == first:
            break
    return out


@njit(cache=True)
def edge_halfplanes(v):
    """Unit outward normals ``G`` (k, 2) and offsets ``h`` (k,) of a CCW polygon's edges.

    The polygon ``v`` has k >= 3 vertices: edge i goes from vertex i to i+1, its normal is the
    edge turned clockwise. Compiled.
    """
    k = v.shape[0]
    G = np.empty((k, 2))
    h = np.empty(k)
    for i in range(k):
        j = (i + 1) % k
        nx, ny = v[j, 1] - v[i, 1], -(v[j, 0] - v[i, 0])
        norm = math.sqrt(nx * nx + ny * ny)
        nx, ny = nx / norm, ny / norm
        G[i, 0], G[i, 1] = nx, ny
        h[i] = nx * v[i, 0] + ny * v[i, 1]
    return G, h


@njit(cache=True)
def inset_polygon(v, distance):
    """Vertices of the CCW polygon ``v`` (k >= 3) shrunk by ``distance`` > 0; (0, 2) when empty.

    One compiled call: a governor shrinks an area every tick.
    """
    G, h = edge_halfplanes(v)
    # Relative to a point inside (the vertices' mean): corners stay well conditioned far
    # from the origin.
    k = v.shape[0]
    cx, cy = 0.0, 0.0
    for i in range(k):
        cx += v[i, 0]
        cy += v[i, 1]
    cx, cy = cx / k, cy / k
    for i in range(k):
        h[i] -= G[i, 0] * cx + G[i, 1] * cy
    out = _inset(G, h, distance)
    if out.shape[0] == 0:
        return out
    # Edges that left at about ``distance`` leave (near-)duplicate corners: merge them.
    scale = 0.0
    for i in range(out.shape[0]):
        scale = max(scale, abs(out[i, 0]), abs(out[i, 1]))
    out = _simplify(out, 1e-12 * max(1.0, scale), MERGE_AREA_TOLERANCE)
    for i in range(out.shape[0]):
        out[i, 0] += cx
        out[i, 1] += cy
    return out


def _frozen(G: np.ndarray, h: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Read-only arrays: the half-planes are cached on the (immutable) polygon."""
    G.setflags(write=False)
    h.setflags(write=False)
    return G, h


@dataclass(frozen=True)
class Polygon:
    """A convex polygon (possibly degenerate) in the plane.

    Attributes:
        vertices: (k, 2) counter-clockwise vertices, no duplicates, no collinear triples.
            k = 0: empty set; k = 1: a point; k = 2: a segment.
        bounded: False when the true set is unbounded and was clipped to a finite box.
    """

    vertices: np.ndarray
    bounded: bool = True

    def __post_init__(self) -> None:
        object.__setattr__(self, "vertices", np.asarray(self.vertices, dtype=float).reshape(-1, 2))

    @classmethod
    def empty(cls) -> Polygon:
        """The empty polygon (no vertex)."""
        return cls(np.zeros((0, 2)))

    @classmethod
    def with_halfplanes(
        cls, vertices: np.ndarray, bounded: bool, G: np.ndarray, h: np.ndarray
    ) -> Polygon:
        """The polygon of ``vertices`` (k >= 3) with its :attr:`halfplanes` ``(G, h)``.

        They were computed with it (by ``edge_halfplanes``, in a compiled pipeline): not computed
        again.
        """
        polygon = cls(vertices, bounded)
        polygon.__dict__["halfplanes"] = _frozen(G, h)  # the cached_property's own slot
        return polygon

    @classmethod
    def from_points(cls, points: np.ndarray, tol: float = 1e-9) -> Polygon:
        """Convex hull of a point cloud (degenerate clouds give a point or a segment)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(points) == 0:
            return cls.empty()
        from scipy.spatial import (
            ConvexHull,
            QhullError,
        )  # here: ~0.2 s to import, not needed to analyze

        try:
            hull = ConvexHull(points)
            return cls(simplify(points[hull.vertices], tol))  # qhull returns 2D hulls CCW
        except (QhullError, ValueError):
            centre = points.mean(axis=0)
            spread = points - centre
            _, _, vt = np.linalg.svd(spread, full_matrices=False)
            t = spread @ vt[0]
            ends = points[[int(np.argmin(t)), int(np.argmax(t))]]
            return cls(simplify(ends, tol))

    @property
    def is_empty(self) -> bool:
        """Whether the polygon has no vertex."""
        return len(self.vertices) == 0

    @property
    def area(self) -> float:
        """Area (shoelace formula); 0 for degenerate polygons."""
        if len(self.vertices) < 3:
            return 0.0
        x, y = self.vertices.T
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))

    @property
    def centroid(self) -> np.ndarray:
        """The centroid (2,); the vertices' mean under 3 vertices, NaN when empty."""
        if len(self.vertices) < 3:
            return self.vertices.mean(axis=0) if len(self.vertices) else np.full(2, np.nan)
        x, y = self.vertices.T
        xs, ys = np.roll(x, -1), np.roll(y, -1)
        cross = x * ys - xs * y
        a = cross.sum() / 2
        out: npt.NDArray[np.float64] = np.array(
            [((x + xs) * cross).sum(), ((y + ys) * cross).sum()]
        ) / (6 * a)
        return out

    @cached_property
    def halfplanes(self) -> tuple[np.ndarray, np.ndarray]:
        """``(G, h)`` with unit-norm rows such that the polygon is ``{x : G x <= h}``.

        A segment gets its two sides plus two end caps, a point four axis bounds, and the
        empty set the single infeasible row ``0 x <= -1``.
        """
        v = self.vertices
        if len(v) == 0:
            return _frozen(np.zeros((1, 2)), np.array([-1.0]))
        if len(v) == 1:
            G = np.array([[1.0, 0], [-1.0, 0], [0, 1.0], [0, -1.0]])
            return _frozen(G, G @ v[0])
        if len(v) == 2:
            e = (v[1] - v[0]) / np.linalg.norm(v[1] - v[0])
            n = np.array([e[1], -e[0]])
            G = np.array([n, -n, e, -e])
            h = np.array([n @ v[0], -n @ v[0], e @ v[1], -e @ v[0]])
            return _frozen(G, h)
        return _frozen(*edge_halfplanes(np.ascontiguousarray(v)))

    def margins(self, points: np.ndarray) -> np.ndarray:
        """Signed distance-like margin of each point: ``min_k (h_k - G_k p)`` (>= 0 inside)."""
        G, h = self.halfplanes
        points = np.atleast_2d(points)
        out: npt.NDArray[np.float64] = np.min(h[None, :] - points @ G.T, axis=1)
        return out

    def contains(self, points: np.ndarray, tol: float = 1e-9) -> np.ndarray | bool:
        """Whether each point lies in the polygon (within ``tol``)."""
        inside = self.margins(points) >= -tol
        return bool(inside[0]) if np.ndim(points) == 1 else inside

    def affine(self, scale: float, offset: np.ndarray) -> Polygon:
        """The image ``{scale * x + offset}`` (a negative scale is a half-turn: still CCW)."""
        if scale == 0.0:
            raise ValueError("scale must be non-zero")
        return Polygon(self.vertices * scale + np.asarray(offset, dtype=float), self.bounded)

    def inset(self, distance: float) -> Polygon:
        """The points at least ``distance`` inside the polygon (its erosion by a disc).

        The intersection of its half-planes moved inwards by ``distance`` (same units).

        Empty from the inradius on (what is left there has no interior); a point or a segment
        has nothing left for any positive distance. ``distance`` 0 returns the polygon itself.
        """
        distance = float(distance)
        if not (math.isfinite(distance) and distance >= 0.0):
            raise ValueError(f"inset distance must be finite and >= 0, not {distance}")
        if distance == 0.0:
            return self
        if len(self.vertices) < 3:
            return Polygon.empty()
        return Polygon(inset_polygon(np.ascontiguousarray(self.vertices), distance), self.bounded)

    def to_dict(self) -> dict[str, Any]:
        """The polygon as JSON: ``vertices``, ``halfplanes`` (``G``, ``h``), ``area``, ``bounded``.

        Returns:
            A JSON-ready dict (lists of floats).
        """
        G, h = self.halfplanes
        return {
            "vertices": self.vertices.tolist(),
            "halfplanes": {"G": G.tolist(), "h": h.tolist()},
            "area": self.area,
            "bounded": self.bounded,
        }
