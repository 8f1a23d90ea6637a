"""Polygon comparison for the answer checks, independent of ``impact_balance.geometry.polygon``:
hull (monotone chain), area (shoelace), intersection (Sutherland-Hodgman) and the relative
area of the symmetric difference."""

from __future__ import annotations

import numpy as np

__all__ = ["area", "compare", "hull", "intersection"]


def hull(points: np.ndarray) -> np.ndarray:
    """Convex hull, counter-clockwise, collinear points dropped (Andrew's monotone chain)."""
    pts = sorted({(float(x), float(y)) for x, y in np.asarray(points, dtype=float).reshape(-1, 2)})
    if len(pts) <= 2:
        return np.array(pts).reshape(-1, 2)

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    upper: list = []
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return np.array(lower[:-1] + upper[:-1])


def area(v: np.ndarray) -> float:
    if len(v) < 3:
        return 0.0
    x, y = v[:, 0], v[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _side(a, b, v) -> float:
    """Twice the signed area of the triangle (a, b, v): > 0 when v is left of the line a -> b."""
    return (b[0] - a[0]) * (v[1] - a[1]) - (b[1] - a[1]) * (v[0] - a[0])


def intersection(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Intersection of two CCW convex polygons (Sutherland-Hodgman)."""
    out = [tuple(v) for v in p]
    for k in range(len(q)):
        a, b = q[k], q[(k + 1) % len(q)]
        if not out:
            break
        inp, out = out, []
        for j in range(len(inp)):
            cur, prev = inp[j], inp[j - 1]
            sc, sp = _side(a, b, cur), _side(a, b, prev)
            if sc >= 0:
                if sp < 0:
                    t = sp / (sp - sc)
                    out.append((prev[0] + t * (cur[0] - prev[0]), prev[1] + t * (cur[1] - prev[1])))
                out.append(cur)
            elif sp >= 0:
                t = sp / (sp - sc)
                out.append((prev[0] + t * (cur[0] - prev[0]), prev[1] + t * (cur[1] - prev[1])))
    return np.array(out).reshape(-1, 2)


def compare(reference: np.ndarray, other: np.ndarray) -> dict[str, float]:
    """Relative area difference and relative symmetric-difference area of two point sets' hulls."""
    P, Q = hull(reference), hull(other)
    a_p, a_q = area(P), area(Q)
    if a_p <= 0.0:  # degenerate reference: absolute figures
        return {"area_rel_diff": abs(a_q - a_p), "symdiff_rel": abs(a_q - a_p), "degenerate": True}
    a_i = area(intersection(P, Q)) if len(Q) >= 3 else 0.0
    return {
        "area_rel_diff": (a_q - a_p) / a_p,
        "symdiff_rel": (a_p + a_q - 2.0 * a_i) / a_p,
        "degenerate": False,
    }
