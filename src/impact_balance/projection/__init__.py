"""Projection of a polytope ``{x : A x <= b, C x = d}`` onto a plane ``y = E x``.

Two exact methods, same answer (the tests and ``benchmarks/run.py`` check it against each
other and against pypoman):

- ``walk`` (default): a parametric simplex walk around the polygon in a compiled kernel,
  one pivot per vertex (:mod:`.walk`);
- ``bretl``: Bretl & Lall's incremental projection, one HiGHS LP per edge (:mod:`.bretl`),
  used as the fallback when the walk cannot answer: a polytope containing a line, or a walk
  that fails its own certificate (a vertex violating a constraint by more than 1e-7, or
  vertices that are not a convex counter-clockwise polygon winding once), which happens with
  badly scaled rows such as friction 1e9 beside 0.7.
"""

from __future__ import annotations

import numpy as np

from impact_balance.exceptions import SolverError
from impact_balance.projection.bretl import project_bretl
from impact_balance.projection.result import ProjectionResult
from impact_balance.projection.walk import project_walk

__all__ = ["METHODS", "ProjectionResult", "project_bretl", "project_polytope", "project_walk"]

#: Accepted values of ``method``.
METHODS = ("auto", "walk", "bretl")


def project_polytope(
    A: np.ndarray,
    b: np.ndarray,
    C: np.ndarray,
    d: np.ndarray,
    E: np.ndarray,
    tol: float = 1e-8,
    box: float = 1e3,
    max_lp: int = 2000,
    merge_tol: float | None = None,
    method: str = "auto",
) -> ProjectionResult:
    """Project ``{x : A x <= b, C x = d}`` onto ``y = E x``.

    Args:
        A: (m, n) inequality matrix of the polytope.
        b: (m,) its right-hand side.
        C: (p, n) equality matrix (may have zero rows).
        d: (p,) its right-hand side.
        E: 2 x n projection map.
        tol: Bretl: distance (in y units) under which a new support point is on the edge.
        box: Clipping box ``|y_k| <= box`` for unbounded directions; the polygon is then
            flagged ``bounded=False``.
        max_lp: Bretl: safety cap on the number of LPs.
        merge_tol: Distance under which final vertices are merged with a neighbour or with
            the line through their neighbours (default: ``tol``).
        method: "auto" (the walk, Bretl if the walk cannot answer), "walk" or "bretl".

    Raises:
        SolverError: unknown method, or "walk" asked and the walk cannot answer.
    """
    merge = tol if merge_tol is None else merge_tol
    if method not in METHODS:
        raise SolverError("projection", method, f"unknown method; valid: {', '.join(METHODS)}")
    if method != "bretl":
        result = project_walk(A, b, C, d, E, box=box, merge_tol=merge)
        # An empty walk is confirmed by Bretl's first LP under "auto": its phase 1 certifies
        # nothing on badly scaled rows (a wall hand at friction 1e12 gave an empty area where
        # the area is 0.195 (m g)^2). It costs that LP only on stances that cannot balance.
        if result is not None and (method == "walk" or not result.polygon.is_empty):
            return result
        if method == "walk":
            raise SolverError(
                "projection walk",
                "failed",
                "the polytope contains a line or a pivot was singular; use method='bretl'",
            )
    result = project_bretl(A, b, C, d, E, tol=tol, box=box, max_lp=max_lp, merge_tol=merge)
    polygon = result.polygon
    if not (np.isfinite(polygon.vertices).all() and polygon.area >= 0.0):  # never a wrong answer
        raise SolverError(
            "projection", "bretl", "the projected polygon is not finite and counter-clockwise"
        )
    return result
