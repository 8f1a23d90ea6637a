"""Projection of a polytope onto a plane: Bretl & Lall's incremental algorithm (2008).

One HiGHS LP per support direction. The reference path (and the fallback of the walk).

Given ``P = {x : A x <= b, C x = d}`` and a 2 x n map ``E``, computes the convex polygon
``E P`` exactly (up to a documented tolerance) by solving one LP per support direction:

1. Shoot rays in three fixed directions (0, 120 and 240 degrees): the support points form
   an inner approximation (deterministic, unlike a random first angle).
2. For each edge of the inner polygon not yet confirmed, maximise along its outward normal.
   If the new support point lies more than ``tol`` beyond the edge, insert it (two new
   edges to check); otherwise the edge is an edge of the projection: confirm it.
3. Stop when every edge is confirmed. Each confirmed edge is a true edge within ``tol``, so
   for a polytope the result is the projection itself, not an approximation.

Duplicate and collinear vertices are merged. Unbounded directions are clipped by the box
``|y_k| <= box`` and the polygon is flagged ``bounded=False``. An infeasible polytope gives
the empty polygon.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from impact_balance.exceptions import SolverError
from impact_balance.geometry.polygon import Polygon, simplify
from impact_balance.projection.result import ProjectionResult
from impact_balance.solvers import HighsLP, LinearProgram

__all__ = [
    "INITIAL_ANGLES",
    "project_bretl",
    "warm_up",
]

#: First ray directions (rad).
INITIAL_ANGLES = (0.0, 2.0 * np.pi / 3.0, 4.0 * np.pi / 3.0)


def project_bretl(
    A: np.ndarray,
    b: np.ndarray,
    C: np.ndarray,
    d: np.ndarray,
    E: np.ndarray,
    tol: float = 1e-8,
    box: float = 1e3,
    max_lp: int = 2000,
    merge_tol: float | None = None,
) -> ProjectionResult:
    """Project ``{x : A x <= b, C x = d}`` onto ``y = E x``.

    Args:
        A: (m, n) inequality matrix of the polytope.
        b: (m,) its right-hand side.
        C: (p, n) equality matrix (may have zero rows).
        d: (p,) its right-hand side.
        E: 2 x n projection map.
        tol: Distance (in y units) under which a new support point is considered on the edge.
        box: Clipping box ``|y_k| <= box`` for unbounded directions.
        max_lp: Safety cap on the number of LPs.
        merge_tol: Distance under which final vertices are merged with a neighbour or with
            the line through their neighbours (default: ``tol``).
    """
    E = np.asarray(E, dtype=float)
    n = E.shape[1]
    lp = HighsLP(
        LinearProgram(
            np.asarray(A, dtype=float).reshape(-1, n),
            np.asarray(b, dtype=float),
            np.asarray(C, dtype=float).reshape(-1, n),
            np.asarray(d, dtype=float),
            R=E,
            lo=np.full(2, -box),
            hi=np.full(2, box),
        )
    )
    count = 0

    def support(u: np.ndarray) -> np.ndarray | None:
        nonlocal count
        count += 1
        if count > max_lp:
            raise SolverError(
                "projection", "max_lp", f"more than {max_lp} LPs; is the polytope degenerate?"
            )
        sol = lp.maximize(E.T @ u)
        if sol.status == "infeasible":
            return None
        if not sol.optimal:  # the box makes it bounded, so this would be a solver fault
            raise SolverError("HiGHS", sol.status, "support LP of the projection")
        out: npt.NDArray[np.float64] | None = E @ sol.x
        return out

    first = []
    for angle in INITIAL_ANGLES:
        y = support(np.array([np.cos(angle), np.sin(angle)]))
        if y is None:
            return ProjectionResult(Polygon.empty(), "bretl", n_lp=count)
        first.append(y)
    vertices = list(simplify(np.array(first), tol))
    if len(vertices) == 1:
        return ProjectionResult(Polygon(np.array(vertices)), "bretl", n_lp=count)
    confirmed = [False] * len(vertices)  # confirmed[i]: edge from vertex i to vertex i+1
    i = 0
    while not all(confirmed):
        if confirmed[i]:
            i = (i + 1) % len(vertices)
            continue
        a, bb = vertices[i], vertices[(i + 1) % len(vertices)]
        e = bb - a
        length = float(np.linalg.norm(e))
        if length <= tol:
            confirmed[i] = True
            continue
        normal = np.array([e[1], -e[0]]) / length
        y = support(normal)
        if y is None:  # numerically lost feasibility: stop with what we have
            raise SolverError(
                "HiGHS", "infeasible", "a support LP became infeasible during projection"
            )
        if normal @ (y - a) > tol:
            vertices.insert(i + 1, y)
            confirmed.insert(i + 1, False)
        else:
            confirmed[i] = True
            i = (i + 1) % len(vertices)
    # Every vertex is a support point, so their convex hull is the answer. Ordering them by
    # hull rather than by insertion matters with nearly opposite rows (a hand's friction
    # 1.6e-6): rounding then inserted a second lap, and the list wound twice (double area).
    polygon_vertices = Polygon.from_points(
        np.array(vertices), tol if merge_tol is None else merge_tol
    ).vertices
    bounded = bool(np.all(np.abs(polygon_vertices) < box * (1 - 1e-9)))
    return ProjectionResult(Polygon(polygon_vertices, bounded), "bretl", n_lp=count)


_warm = False


def warm_up() -> None:
    """One projection of a square, once per process.

    The first Bretl projection of a process loads and sets up HiGHS. A governor calls this when
    it is built, so that a tick whose walk falls back to Bretl does not pay it.
    """
    global _warm
    if _warm:
        return
    eye = np.eye(2)
    project_bretl(np.vstack([eye, -eye]), np.ones(4), np.zeros((0, 2)), np.zeros(0), eye)
    _warm = True
