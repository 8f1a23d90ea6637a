"""Convex polygons in the plane, as counter-clockwise vertices and as half-planes."""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from scipy.spatial import ConvexHull, QhullError

__all__ = ["Polygon"]


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def simplify(vertices: np.ndarray, tol: float = 1e-9) -> np.ndarray:
    """Merge duplicate and collinear consecutive vertices of a CCW convex polygon.

    ``tol`` is a distance: a vertex closer than ``tol`` to its neighbour, or to the line
    through its two neighbours, is dropped.
    """
    v = [np.asarray(p, dtype=float) for p in vertices]
    changed = True
    while changed and len(v) > 1:
        changed = False
        # duplicates
        k = 0
        while k < len(v) and len(v) > 1:
            if np.linalg.norm(v[k] - v[(k + 1) % len(v)]) <= tol:
                del v[(k + 1) % len(v)]
                changed = True
            else:
                k += 1
        if len(v) < 3:
            break
        for k in range(len(v)):
            prev, cur, nxt = v[k - 1], v[k], v[(k + 1) % len(v)]
            base = np.linalg.norm(nxt - prev)
            if base > 0 and abs(_cross(prev, cur, nxt)) / base <= tol:
                del v[k]
                changed = True
                break
    return np.array(v).reshape(-1, 2)


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
        return cls(np.zeros((0, 2)))

    @classmethod
    def from_points(cls, points: np.ndarray, tol: float = 1e-9) -> Polygon:
        """Convex hull of a point cloud (degenerate clouds give a point or a segment)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        if len(points) == 0:
            return cls.empty()
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
        if len(self.vertices) < 3:
            return self.vertices.mean(axis=0) if len(self.vertices) else np.full(2, np.nan)
        x, y = self.vertices.T
        xs, ys = np.roll(x, -1), np.roll(y, -1)
        cross = x * ys - xs * y
        a = cross.sum() / 2
        return np.array([((x + xs) * cross).sum(), ((y + ys) * cross).sum()]) / (6 * a)

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
        edges = np.roll(v, -1, axis=0) - v
        normals = np.column_stack([edges[:, 1], -edges[:, 0]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        return _frozen(normals, np.einsum("ij,ij->i", normals, v))

    def margins(self, points: np.ndarray) -> np.ndarray:
        """Signed distance-like margin of each point: ``min_k (h_k - G_k p)`` (>= 0 inside)."""
        G, h = self.halfplanes
        points = np.atleast_2d(points)
        return np.min(h[None, :] - points @ G.T, axis=1)

    def contains(self, points: np.ndarray, tol: float = 1e-9) -> np.ndarray | bool:
        """Whether each point lies in the polygon (within ``tol``)."""
        inside = self.margins(points) >= -tol
        return bool(inside[0]) if np.ndim(points) == 1 else inside

    def affine(self, scale: float, offset: np.ndarray) -> Polygon:
        """The image ``{scale * x + offset}`` (a negative scale is a half-turn: still CCW)."""
        if scale == 0.0:
            raise ValueError("scale must be non-zero")
        return Polygon(self.vertices * scale + np.asarray(offset, dtype=float), self.bounded)

    def to_dict(self) -> dict:
        G, h = self.halfplanes
        return {
            "vertices": self.vertices.tolist(),
            "halfplanes": {"G": G.tolist(), "h": h.tolist()},
            "area": self.area,
            "bounded": self.bounded,
        }
