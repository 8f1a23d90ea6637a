"""Projection of a polytope onto a plane by a parametric simplex walk around the polygon.

The support point of ``E P`` in direction ``u(theta) = (cos theta, sin theta)`` is the
projection of an optimal vertex of ``max u^T E x`` over ``P = {A x <= b, C x = d}``. A vertex
basis stays optimal over an arc of theta that has a closed form; at its end one simplex pivot
(or a few, at a degenerate vertex) gives the next basis. Walking theta once around the circle
visits every vertex of the projected polygon in counter-clockwise order. This is what
Bretl & Lall's algorithm computes with one LP per edge, but each step here is a pivot on a
dense n x n basis instead of a solver call, in a compiled kernel
(:mod:`impact_balance.projection.kernel`).

Before walking, the equalities are eliminated (``x = x0 + N z``), zero rows are checked and
dropped, rows are scaled to unit norm, and the clipping box ``|y_k| <= box`` is added as four
rows, so unbounded directions are clipped as in the Bretl path. The vertices are exact
support points (no stopping tolerance); duplicates and collinear ones are merged within
``merge_tol`` as in the Bretl path.
"""

from __future__ import annotations

import os

import numpy as np
import numpy.typing as npt

from impact_balance._jit import HAVE_NUMBA, cache_depends_on, njit
from impact_balance.geometry import polygon
from impact_balance.geometry.polygon import MERGE_AREA_TOLERANCE, Polygon, simplify_convex_kernel
from impact_balance.projection import kernel
from impact_balance.projection.kernel import (
    FAILED,
    INCONSISTENT,
    INFEASIBLE,
    LINE,
    OK,
    project,
    project_equalities,
)
from impact_balance.projection.result import ProjectionResult

__all__ = [
    "CHAIN_BASES",
    "CHECK_MERGE",
    "MAX_PIVOTS",
    "NO_HINT",
    "RANK_TOLERANCE",
    "SLACK_TOLERANCE",
    "certified_walk",
    "hint_size",
    "kernel_is_compiled",
    "project_walk",
    "warm_up",
]

#: Relative singular-value threshold for the rank of the lines of the polytope.
RANK_TOLERANCE = 1e-12
#: Largest constraint violation (unit rows, in units of b, relative to 1 + max |b|) a
#: vertex of a sound walk may show; beyond it the walk is rejected (badly scaled rows, e.g.
#: friction 1e9 next to 1e-9) and the caller falls back to Bretl.
SLACK_TOLERANCE = 1e-7
#: Distance (units of y) under which raw vertices are merged before the convexity check:
#: above the rounding of a vertex (1e-12 to 1e-10), below any backtrack worth catching.
CHECK_MERGE = 1e-9
#: Safety cap on the pivots of one walk.
MAX_PIVOTS = 5000
#: The kernel's warm-start hint when there is none (a one-off projection): never read or written.
NO_HINT = np.zeros(0, dtype=np.int64)
#: The longest chain of bases a :func:`hint_size` hint keeps (the walks of the bundled stances
#: keep 5 to 32: two bases per polygon vertex at most).
CHAIN_BASES = 64


def hint_size(variables: int) -> int:
    """The length of a walk hint with room for a chain of :data:`CHAIN_BASES` bases.

    ``variables``: the projected polytope's variables (e.g. 6 per contact: at least the
    walk's n, the variables left after the equalities). A caller that projects postures in a
    row keeps one ``np.full(hint_size(variables), -1, dtype=np.int64)``: the walk starts from
    its last optimal basis, and where the last walk's chain of optimal bases still certifies
    the new polygon, answers without walking, or walks on from the last of its first bases that
    do (``docs/numerics.md``). A shorter hint (at least ``2 + n``) keeps the start only.
    """
    return 3 + variables + (variables + 1) * CHAIN_BASES


def project_walk(
    A: np.ndarray,
    b: np.ndarray,
    C: np.ndarray,
    d: np.ndarray,
    E: np.ndarray,
    box: float = 1e3,
    merge_tol: float = 1e-8,
    max_pivots: int = MAX_PIVOTS,
) -> ProjectionResult | None:
    """Project ``{x : A x <= b, C x = d}`` onto ``y = E x`` (2 x n), clipped to ``|y_k| <= box``.

    Lines in the polytope (directions the constraints leave free and E ignores) are
    quotiented out. Returns None when the walk cannot answer (a pivot met a numerical dead
    end, an iteration cap, a vertex that violates a constraint, or vertices that are not a
    convex counter-clockwise polygon): the caller falls back to :func:`~.bretl.project_bretl`.
    """
    E = _array(E, 2)
    n = E.shape[1]
    A, C, b, d = _array(A, 2, n), _array(C, 2, n), _array(b, 1), _array(d, 1)
    status, vertices, bounded, pivots, x0, N = certified_walk(
        A, b, C, d, E, float(box), int(max_pivots), float(merge_tol), MERGE_AREA_TOLERANCE, NO_HINT
    )
    if status == LINE:
        # Lines of the polytope are the null space of [A N; E N] (a line along which E x
        # changed would have met the box rows); keep z in its orthogonal complement.
        _, S, Vt = np.linalg.svd(np.vstack([A @ N, E @ N]))
        r = int(np.sum(S > RANK_TOLERANCE * max(float(S[0]) if S.size else 0.0, 1.0)))
        N = np.ascontiguousarray(N @ Vt[:r].T)
        status, raw, more, worst = project(A, b, E, x0, N, float(box), int(max_pivots), NO_HINT)
        pivots += more
        status, vertices, bounded = _certify(
            status, raw, worst, b, float(merge_tol), MERGE_AREA_TOLERANCE, float(box)
        )
    if status == INCONSISTENT:
        return ProjectionResult(Polygon.empty(), "walk")
    if status == INFEASIBLE:
        return ProjectionResult(Polygon.empty(), "walk", n_lp=1, pivots=pivots)
    if status != OK:
        return None
    return ProjectionResult(Polygon(vertices, bool(bounded)), "walk", n_lp=1, pivots=pivots)


@njit(cache=True)
def _certify(status, vertices, worst, b, merge_tol, area_tol, box):
    """A walk's raw vertices certified and merged: ``(status, vertices, bounded)``.

    The status is FAILED when the walk cannot answer (see :func:`project_walk`).
    """
    none = np.empty((0, 2))
    if status == FAILED or status == LINE:
        return FAILED, none, True
    # Certificate: every vertex was feasible (the kernel checked each against every row, and
    # each is optimal for its arc by the multipliers' signs) and the polygon is convex,
    # counter-clockwise and winds once (checked with the merge, below). Anything else is a
    # numerical failure of the walk, never an answer.
    # (max |b| only when the slack is below the smallest threshold it can give: rarely.)
    if status == OK and worst < -SLACK_TOLERANCE:
        big = 0.0
        for i in range(b.size):
            big = max(big, abs(b[i]))
        if worst < -SLACK_TOLERANCE * (1.0 + big):
            return FAILED, none, True
    if status != OK:
        return status, none, True
    # Check convexity before the merge: merging first could hide a backtrack (a walk that
    # went 1e-6 back inside and returned, whose detour then replaced the true corner). The
    # first pass only drops rounding-level duplicates, which would fail the strict check:
    # within 1e-9, or 10 times the worst slack (a vertex's rounding shows in its slacks; 1e-8
    # with a friction of 2.5e4 on Talos's foot).
    ok, merged, bounded = simplify_convex_kernel(
        vertices, min(merge_tol, max(CHECK_MERGE, -10.0 * worst)), merge_tol, area_tol, box
    )
    if not ok:
        return FAILED, none, True
    return OK, merged, bounded


@njit(cache=True)
def certified_walk(A, b, C, d, E, box, max_pivots, merge_tol, area_tol, hint):
    """The walk of :func:`project_walk` in one compiled call, certificate and merge included.

    A governor pays each call's dispatch every tick.

    Returns ``(status, vertices, bounded, pivots, x0, N)`` with a kernel status: OK (the
    certified polygon), INFEASIBLE or INCONSISTENT (empty), FAILED (the walk cannot answer),
    LINE (the polytope holds a line: :func:`project_walk` quotients it out; ``x0 + N z``
    spans the equalities). ``hint``: the kernel's warm start, kept by a caller that projects
    postures in a row (:func:`~impact_balance.projection.kernel.walk`); :data:`NO_HINT` for none.
    """
    status, raw, pivots, worst, x0, N = project_equalities(A, b, C, d, E, box, max_pivots, hint)
    if status == LINE or status == INCONSISTENT:
        return status, np.empty((0, 2)), True, pivots, x0, N
    status, vertices, bounded = _certify(status, raw, worst, b, merge_tol, area_tol, box)
    return status, vertices, bounded, pivots, x0, N


# The compiled functions above embed the kernel's and the polygon module's.
cache_depends_on(_certify, polygon)
cache_depends_on(certified_walk, polygon, kernel)


def _array(x: npt.ArrayLike, ndim: int, columns: int | None = None) -> np.ndarray:
    """``x`` as a C-contiguous float64 array of ``ndim`` dimensions (``columns`` columns).

    Itself when it already is one (a polytope's own arrays, every governor tick).
    """
    if (
        type(x) is np.ndarray
        and x.dtype == np.float64
        and x.ndim == ndim
        and x.flags.c_contiguous
        and (columns is None or x.shape[1] == columns)
    ):
        return x
    a = np.asarray(x, dtype=float)
    shape = (-1,) if ndim == 1 else (-1, a.shape[-1] if columns is None else columns)
    return np.ascontiguousarray(np.reshape(a, shape))


def kernel_is_compiled() -> bool:
    """Whether numba's on-disk cache holds the kernel.

    If not, the first projection compiles it (once per installation). True without numba
    (nothing to compile).
    """
    if not HAVE_NUMBA:
        return True
    try:  # numba's cache index of the entry point; private API, hence the guard
        return os.path.exists(project._cache._cache_file._index_path)  # type: ignore[attr-defined]
    except AttributeError:
        return True


_warm = False


def warm_up() -> float:
    """Load (or compile) the kernel now, by projecting a square; returns the seconds spent.

    0.0 once done. numba loads a cached kernel on its first call (and compiles it after an
    installation): callers that time a projection call this first, so that the load is not
    mistaken for the projection.
    """
    global _warm
    if _warm:
        return 0.0
    import time

    t = time.perf_counter()
    eye = np.eye(2)
    project_walk(np.vstack([eye, -eye]), np.ones(4), np.zeros((0, 2)), np.zeros(0), eye)
    _warm = True
    return time.perf_counter() - t
