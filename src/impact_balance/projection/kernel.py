"""Compiled kernel of the parametric walk (see :mod:`impact_balance.projection.walk`).

An active-set primal simplex on ``max c(theta)^T z  s.t.  H z <= h`` with
``c(theta) = G^T (cos theta, sin theta)``, dense, for the small LPs of contact stances
(n up to a few tens of variables, m up to a few hundred rows). A basis is a set of n
linearly independent active rows B; its vertex solves ``H_B z = h_B`` and it is optimal for
theta while the multipliers ``lambda(theta) = H_B^-T c(theta)`` are non-negative. Each
multiplier is ``rho cos(theta - alpha)``, so the end of a basis' optimal arc has a closed
form, and the walk hops from basis to basis in increasing theta: the support points it
records are the vertices of the projection ``G {z : H z <= h}``, counter-clockwise, exactly
(there is no stopping tolerance).

Optimality "at theta+" (just after a breakpoint) is lexicographic in (lambda, dlambda/dtheta),
i.e. for the objective ``c(theta) + eps c'(theta)``. The leaving row is chosen by steepest
edge; after 2n zero steps in a row, by Bland's rule (smallest row index leaves, smallest row
index enters among ties), so degenerate vertices cannot cycle. A
multiplier counts as zero within a tolerance scaled by its column of ``H_B^-1`` (its rounding
error grows with it), which keeps Bland's rule from chasing rounding noise.

The basis inverse is kept explicitly, updated by the rank-one formula at each pivot and
recomputed every ``_REFACTOR`` pivots, and in the walk around the polygon whenever it no
longer solves its system to near rounding or has carried ``_CARRY`` pivots. Without numba
the same code runs as plain Python. The small helpers the walk calls per basis or per vertex
(the rank-one update, the vertex, the accuracy and optimality checks, the breakpoint, the
recorded vertex's scan) are inlined into their callers by numba (``inline="always"``: the same
operations in the same order, hence the same numbers, without a call and its array arguments
each time); the larger ones are not, which keeps the kernel's compile time.

A caller that projects postures in a row keeps a hint: the walk starts from its last optimal
basis, and first checks whether the last walk's chain of bases (the first and last of each
polygon vertex) still certifies the new polygon, which then needs no walk, or goes on from the
last of the chain's bases that certify (:func:`walk`).
"""

from __future__ import annotations

import math

import numpy as np

from impact_balance._jit import njit

__all__ = [
    "FAILED",
    "INCONSISTENT",
    "INFEASIBLE",
    "LINE",
    "OK",
    "equality_basis",
    "project",
    "project_equalities",
    "walk",
]

#: Kernel statuses. LINE: the polytope contains a line (no vertex); the caller can quotient
#: it out and call again. INCONSISTENT: the equalities have no solution.
OK, INFEASIBLE, FAILED, LINE, INCONSISTENT = 0, 1, 2, 3, 4

#: Relative multiplier tolerance (times |column of H_B^-1| |c|).
_EPS_DUAL = 1e-11
#: Smallest |H_j p| (rows and p unit vectors) that blocks a step; smaller: parallel rows.
_EPS_PIVOT = 1e-9
#: Relative tie in the ratio test.
_EPS_TIE = 1e-12
#: Largest phase-1 infeasibility (units of h) of a feasible polytope.
_EPS_FEASIBLE = 1e-9
#: Relative norm under which a singular value or a row counts as zero.
_RANK = 1e-12
#: Pivots between two recomputations of the basis inverse.
_REFACTOR = 16
#: In the walk around the polygon: pivots after which a breakpoint recomputes the inverse
#: whatever its residuals, and the relative residual above which it does (see _accurate).
_CARRY = 8
_EPS_CARRY = 1e-14
#: Degenerate vertices (more than n rows at zero slack: a contact's 16 faces at its zero
#: wrench) cost several zero steps each, and each one scanned every row. The rows with a slack
#: up to _D_SLACK at a recorded vertex are listed; while z stays within _D_MOVE of it, every
#: other (unit) row keeps a slack above _D_SLACK - _D_MOVE > _D_STEP, so a ratio-test step up
#: to _D_STEP (with its ties) and a negative slack can only come from a listed row: scanning
#: the list gives the same numbers (9 % less time on G1's walks).
_D_SLACK = 1e-8
_D_MOVE = 1e-10
_D_STEP = 1e-9
#: Re-certifying the last walk's chain of bases (:func:`_recertify`): the most a row may be
#: violated at a vertex of the chain (relative to max(1, |h_j|); rounding at a degenerate vertex
#: shows 1e-16 to 3e-14), and the largest distance (units of the projection) between the points
#: of two bases of one polygon vertex.
_EPS_RECERT = 1e-12
_Y_SAME = 1e-10
#: A re-certification scans every row at a vertex (the reference) and, at the next ones within
#: _REF_MOVE of it, only the rows whose slack there is at most the distance moved plus
#: _REF_MARGIN: a unit row's slack moves by at most the distance, so the others stay positive
#: (the margin covers the slacks' rounding) and cannot lower the worst slack or fail the test.
_REF_MOVE = 0.2
_REF_MARGIN = 1e-8


@njit(cache=True, inline="always")
def _column_norm(M, i):
    """Euclidean norm of column i (a strided slice: a loop avoids a copy)."""
    acc = 0.0
    for k in range(M.shape[0]):
        acc += M[k, i] * M[k, i]
    return math.sqrt(acc)


@njit(cache=True, inline="always")
def _norm(v):
    """Euclidean norm (a loop: numba's linalg would add seconds of compile time)."""
    acc = 0.0
    for x in v:
        acc += x * x
    return math.sqrt(acc)


@njit(cache=True)
def _times(M, v):
    """M v for a 2-D M (a loop, for compile time and no BLAS call on tiny sizes)."""
    out = np.empty(M.shape[0])
    _times_into(M, v, out)
    return out


@njit(cache=True, inline="always")
def _times_into(M, v, out):
    """Out = M v (out preallocated)."""
    for i in range(M.shape[0]):
        acc = 0.0
        for j in range(M.shape[1]):
            acc += M[i, j] * v[j]
        out[i] = acc


@njit(cache=True, inline="always")
def _point(g0, GT, z, out, i):
    """``out[i]`` = the projected point g0 + G z (written in place: no allocation per vertex)."""
    y0, y1 = g0[0], g0[1]
    for r in range(GT.shape[0]):
        y0 += GT[r, 0] * z[r]
        y1 += GT[r, 1] * z[r]
    out[i, 0], out[i, 1] = y0, y1


@njit(cache=True, inline="always")
def _step(H, h, z, p, j, hp, slack):
    """Row j's step along ``p`` in the ratio test (inf if it does not block).

    Its ``H_j p`` and slack go to ``hp[j]`` and ``slack[j]``. Inlined by numba (called per
    row).
    """
    a = 0.0
    b = h[j]
    for k in range(H.shape[1]):
        a += H[j, k] * p[k]
        b -= H[j, k] * z[k]
    hp[j] = a
    slack[j] = b
    return max(b, 0.0) / a if a > _EPS_PIVOT else math.inf


@njit(cache=True, inline="always")
def _ties(j, active, hp, slack, bound):
    """Whether row j (its :func:`_step` made) blocks within ``bound``."""
    return not active[j] and hp[j] > _EPS_PIVOT and max(slack[j], 0.0) / hp[j] <= bound


@njit(cache=True)
def _ratio_test(H, h, z, p, active, hp, slack):
    """Largest step along unit ``p`` that keeps ``H z <= h``: (row, step), row -1 if none.

    Ties (within a relative 1e-12) go to the smallest row index (Bland). ``hp`` and ``slack``
    (m) are work buffers.
    """
    m = H.shape[0]
    best = math.inf
    for j in range(m):
        if not active[j]:
            t = _step(H, h, z, p, j, hp, slack)
            if t < best:
                best = t
    if best == math.inf:
        return -1, 0.0
    bound = best + _EPS_TIE * (1.0 + best)
    for j in range(m):
        if _ties(j, active, hp, slack, bound):
            return j, best
    return -1, 0.0  # unreachable


@njit(cache=True, inline="always")
def _near(z, zd):
    """Whether |z - zd| <= _D_MOVE (Euclidean)."""
    acc = 0.0
    for k in range(z.shape[0]):
        d = z[k] - zd[k]
        acc += d * d
    return acc <= _D_MOVE * _D_MOVE


@njit(cache=True)
def _ratio_test_near(H, h, z, p, active, hp, slack, zd, dset):
    """:func:`_ratio_test` over the rows listed near z (``dset``, at ``zd``).

    Used when that gives its answer exactly: z still within _D_MOVE of ``zd`` and a step up to
    _D_STEP.
    """
    count = dset[0]
    if count >= 0 and _near(z, zd):
        best = math.inf
        for i in range(count):
            j = dset[1 + i]
            if not active[j]:
                t = _step(H, h, z, p, j, hp, slack)
                if t < best:
                    best = t
        if best <= _D_STEP:
            bound = best + _EPS_TIE * (1.0 + best)
            for i in range(count):  # ascending rows: the first tie is the full scan's
                if _ties(dset[1 + i], active, hp, slack, bound):
                    return dset[1 + i], best
    return _ratio_test(H, h, z, p, active, hp, slack)


@njit(cache=True)
def _min_slack_near(H, h, z, worst, zd, dset):
    """A vertex's feasibility check: ``worst[0]`` = min(worst[0], min_j h_j - H_j z).

    ``worst[0]`` <= 0. Over the rows listed near z (``dset``) when z is within _D_MOVE of where
    they were listed (``zd``: the others' slacks are positive there); else over every row,
    listing them again at z.
    """
    m, n = H.shape
    count = dset[0]
    if count >= 0 and _near(z, zd):
        for i in range(count):
            j = dset[1 + i]
            b = h[j]
            for k in range(n):
                b -= H[j, k] * z[k]
            if b < worst[0]:
                worst[0] = b
        return
    count = 0
    for j in range(m):
        b = h[j]
        for k in range(n):
            b -= H[j, k] * z[k]
        if b < worst[0]:
            worst[0] = b
        if b <= _D_SLACK:
            dset[1 + count] = j
            count += 1
    dset[0] = count
    zd[:] = z


@njit(cache=True)
def _project_out(Q, k, v, out):
    """``out`` = v minus its components along the k orthonormal rows of Q; returns |out|."""
    n = Q.shape[1]
    for j in range(n):  # element by element: out may be v (a slice copy would allocate)
        out[j] = v[j]
    for _ in range(2):  # twice is enough (Kahan): keeps out orthogonal to working precision
        for i in range(k):
            d = 0.0
            for j in range(n):
                d += Q[i, j] * out[j]
            for j in range(n):
                out[j] -= d * Q[i, j]
    acc = 0.0
    for j in range(n):
        acc += out[j] * out[j]
    return math.sqrt(acc)


@njit(cache=True)
def _longest_axis(Q, k, out):
    """``out`` = the coordinate axis that keeps most of its length, projected; returns |out|.

    The axis keeps most of its length once the k orthonormal rows of Q are projected out
    (pivoted, hence well conditioned).
    """
    n = Q.shape[1]
    best, axis = -1.0, 0
    for i in range(n):
        left = 1.0  # |P e_i|^2 = 1 - sum_r Q[r, i]^2
        for r in range(k):
            left -= Q[r, i] * Q[r, i]
        if left > best:
            best, axis = left, i
    out[:] = 0.0
    out[axis] = 1.0
    return _project_out(Q, k, out, out)


@njit(cache=True)
def _null_direction(Q, k, c, dc, p):
    """Unit direction ``p`` orthogonal to the k working rows (orthonormal basis ``Q[:k]``).

    Lexicographically ascending for (c, dc): the projection of c, else of dc, else of the
    coordinate axis that keeps most of its length.

    Returns kind: 0 = ascending for c, 1 = ascending for dc only, 2 = neutral.
    """
    kind = 0
    norm = _project_out(Q, k, c, p)
    if norm <= 1e-9:
        kind = 1
        norm = _project_out(Q, k, dc, p)
    if norm <= 1e-9:
        kind = 2
        norm = _longest_axis(Q, k, p)
    p /= norm
    return kind


@njit(cache=True)
def _crash(H, h, z, W, k, active, c, dc):
    """Grow the working set to n rows by steps orthogonal to it (z feasible, moved in place).

    Returns (status, k).
    """
    n = H.shape[1]
    Q = np.zeros((n, n))  # orthonormal basis of the working rows, by Gram-Schmidt
    p = np.empty(n)
    hp = np.empty(H.shape[0])
    slack = np.empty(H.shape[0])
    for i in range(k):
        norm = _project_out(Q, i, H[W[i]], Q[i])
        Q[i] /= norm
    while k < n:
        kind = _null_direction(Q, k, c, dc, p)
        j, t = _ratio_test(H, h, z, p, active, hp, slack)
        if j < 0:
            if kind != 2:
                return FAILED, k  # ascending without bound
            p *= -1.0
            j, t = _ratio_test(H, h, z, p, active, hp, slack)
            if j < 0:
                return LINE, k  # a line in the polytope: no vertex
        for i in range(n):
            z[i] += t * p[i]
        W[k] = j
        active[j] = True
        norm = _project_out(Q, k, H[j], Q[k])
        Q[k] /= norm
        k += 1
    return OK, k


@njit(cache=True)
def _invert(B, out):
    """Gauss-Jordan inverse with partial pivoting into ``out`` (B is overwritten).

    For the small bases here this beats a LAPACK call through numba by its fixed cost.
    Returns False when B is singular to working precision. Only B's columns after the pivot's
    are updated: the others are never read again (the pivots, their rows' factors and ``out``
    are the full elimination's numbers).
    """
    n = B.shape[0]
    out[:, :] = 0.0
    for i in range(n):
        out[i, i] = 1.0
    norm = 0.0
    for i in range(n):
        for j in range(n):
            norm = max(norm, abs(B[i, j]))
    for col in range(n):
        piv = col
        for r in range(col + 1, n):
            if abs(B[r, col]) > abs(B[piv, col]):
                piv = r
        if abs(B[piv, col]) <= 1e-14 * norm:
            return False
        if piv != col:
            for j in range(col, n):
                B[col, j], B[piv, j] = B[piv, j], B[col, j]
            for j in range(n):
                out[col, j], out[piv, j] = out[piv, j], out[col, j]
        inv = 1.0 / B[col, col]
        for j in range(col + 1, n):
            B[col, j] *= inv
        for j in range(n):
            out[col, j] *= inv
        for r in range(n):
            if r != col:
                f = B[r, col]
                if f != 0.0:
                    for j in range(col + 1, n):
                        B[r, j] -= f * B[col, j]
                    for j in range(n):
                        out[r, j] -= f * out[col, j]
    return True


@njit(cache=True)
def _workspace(m, n):
    """The walk's work buffers, made once per walk.

    (p, col, alpha) of n, (hp, slack) of m, an n x n basis copy, a 4 x n buffer for the
    breakpoints, z's copy near a vertex and its list of rows.
    """
    dset = np.empty(m + 1, dtype=np.int64)  # [0]: count (-1: none yet), then the rows
    dset[0] = -1
    return (
        np.empty(n),
        np.empty(n),
        np.empty(n),
        np.empty(m),
        np.empty(m),
        np.empty((n, n)),
        np.empty((4, n)),
        np.empty(n),
        dset,
    )


@njit(cache=True)
def _refactor(H, h, W, Binv, z, B):
    """Recompute the basis inverse and the vertex from scratch; False if singular.

    ``B`` (n x n): a work buffer (the walk's ``work[5]``).
    """
    n = H.shape[1]
    for i in range(n):
        for j in range(n):
            B[i, j] = H[W[i], j]
    if not _invert(B, Binv):
        return False
    _vertex(h, W, Binv, z)
    return True


@njit(cache=True, inline="always")
def _pivot(H, h, W, Binv, z, leave, j, since, work):
    """Row ``j`` replaces the basis row in position ``leave``; updates Binv and z in place.

    Returns the pivots since the last refactorisation.
    """
    W[leave] = j
    if since + 1 >= _REFACTOR and _refactor(H, h, W, Binv, z, work[5]):
        return 0
    _update(H, Binv, leave, j, work)
    _vertex(h, W, Binv, z)
    return since + 1


@njit(cache=True, inline="always")
def _update(H, Binv, leave, j, work):
    """The rank-one update of Binv for row ``j`` entering in position ``leave`` (z untouched)."""
    n = H.shape[1]
    # Rank-one update: column i of the new inverse is Binv[:, i] - col (a . Binv[:, i]) / piv
    # for i != leave, and col / piv for i == leave, with col = Binv[:, leave], a = H[j].
    col, alpha = work[1], work[2]
    alpha[:] = 0.0
    for r in range(n):
        col[r] = Binv[r, leave]
        for i in range(n):
            alpha[i] += H[j, r] * Binv[r, i]
    piv = alpha[leave]
    for i in range(n):
        alpha[i] = alpha[i] / piv  # each quotient once: the same numbers as per element
    for r in range(n):
        for i in range(n):
            Binv[r, i] -= col[r] * alpha[i]
        Binv[r, leave] = col[r] / piv


@njit(cache=True, inline="always")
def _accurate(H, h, W, Binv, z, ones):
    """Whether a carried basis inverse still solves its system to near rounding.

    The vertex ``H_W z = h_W`` within 1e-14 of max(1, |h_W|), and ``H_W (Binv 1) = 1`` within
    1e-14 n (3 n^2 products, where a fresh inverse costs 2 n^3). ``ones`` (n): a work buffer.
    """
    n = Binv.shape[0]
    size = 1.0
    for i in range(n):
        size = max(size, abs(h[W[i]]))
    for k in range(n):
        acc = 0.0
        for col in range(n):
            acc += Binv[k, col]
        ones[k] = acc  # Binv 1
    for i in range(n):
        r1 = -h[W[i]]
        r2 = -1.0
        for k in range(n):
            r1 += H[W[i], k] * z[k]
            r2 += H[W[i], k] * ones[k]
        if abs(r1) > _EPS_CARRY * size or abs(r2) > _EPS_CARRY * n:
            return False
    return True


@njit(cache=True, inline="always")
def _vertex(h, W, Binv, z):
    """Z = Binv h_W."""
    n = Binv.shape[0]
    for r in range(n):
        acc = 0.0
        for i in range(n):
            acc += Binv[r, i] * h[W[i]]
        z[r] = acc


@njit(cache=True, inline="always")
def _priced(Binv, i, c, dc, scale):
    """Basis column i at theta+: ``(tier, rate)``, tier 2 when it is no entering candidate.

    Tier 0: its multiplier ``lambda_i = Binv[:, i] . c`` is negative (rate ``lambda_i`` over
    the column's norm); tier 1: within the tolerance of zero and decreasing (rate its
    theta-derivative ``Binv[:, i] . dc`` over the norm). Inlined by numba (called per column).
    """
    n = Binv.shape[0]
    lam, dlam, norm = 0.0, 0.0, 0.0
    for r in range(n):
        lam += Binv[r, i] * c[r]
        dlam += Binv[r, i] * dc[r]
        norm += Binv[r, i] * Binv[r, i]
    norm = math.sqrt(norm)
    eps = _EPS_DUAL * scale * max(1.0, norm)
    if lam < -eps:
        return 0, lam / norm
    if lam <= eps and dlam < -eps:
        return 1, dlam / norm
    return 2, 0.0


@njit(cache=True)
def _optimize(H, h, z, W, Binv, active, c, dc, scale, max_pivots, work):
    """Simplex pivots from the vertex basis (W, Binv, z) until it is lexicographically optimal.

    The objective is (c, dc); ``scale`` scales the multiplier tolerance.

    Returns (status, pivots).
    """
    n = H.shape[1]
    pivots = 0
    since = 0
    p = work[0]
    stalled = 0  # consecutive zero steps
    while True:
        # Entering candidates: multipliers negative at theta+. Steepest edge (most negative
        # lambda_i / |Binv[:, i]|, the objective's rate along the unit edge direction), with
        # the theta-derivative as a tie-break tier; Bland's rule once zero steps pile up, or
        # pivots (a cycle of real steps through multipliers within the tolerance of zero: 4
        # vertices in turn, steps of 0.1 to 0.25, on a G1 posture of the wall study).
        bland = stalled > 2 * n or pivots > 2 * (n + H.shape[0])
        leave = -1
        tier = 2
        best = 0.0
        for i in range(n):
            this_tier, rate = _priced(Binv, i, c, dc, scale)
            if this_tier == 2:
                continue
            if bland:
                if leave < 0 or W[i] < W[leave]:
                    leave = i
            elif this_tier < tier or (this_tier == tier and rate < best):
                leave, tier, best = i, this_tier, rate
        if leave < 0:
            return OK, pivots
        pivots += 1
        # A breakpoint takes a pivot or two; 4 (n + m) is a cycle that Bland's rule did not
        # break either (that G1 posture: the walk ran to the 5000-pivot cap, 3.3 ms, before
        # the caller fell back to Bretl; now 292 pivots).
        if pivots > max_pivots or pivots > 4 * (n + H.shape[0]):
            return FAILED, pivots
        norm = _column_norm(Binv, leave)
        for r in range(n):
            p[r] = -Binv[r, leave] / norm
        active[W[leave]] = False
        j, t = _ratio_test_near(H, h, z, p, active, work[3], work[4], work[7], work[8])
        if j < 0:
            return FAILED, pivots  # unbounded edge: the box is missing
        stalled = stalled + 1 if t == 0.0 else 0
        if stalled > 3 * n + H.shape[0]:
            # Bland's rule has had m + n zero steps and not left the vertex: its multipliers'
            # tolerance let it cycle (rows 1, 2 and 8 in turn on a G1 posture, until the
            # 5000-pivot cap: 75 ms). The caller falls back to Bretl.
            return FAILED, pivots
        active[j] = True
        since = _pivot(H, h, W, Binv, z, leave, j, since, work)


@njit(cache=True, inline="always")
def _rho(a, b, eps):
    """``(zero, rho)``: whether ``hypot(a, b) <= eps``, and |(a, b)| to within an ulp.

    ``hypot`` (about 13 ns) only where ``max(|a|, |b|) <= eps`` (above it, hypot, which is at
    least that max, exceeds eps: the same test) or where the squares could overflow or
    underflow; else ``sqrt(a^2 + b^2)`` (2 ns), which callers use only in lower bounds that
    carry a margin far above its rounding.
    """
    big = max(abs(a), abs(b))
    if big <= eps or not (1e-100 < big < 1e100):
        rho = math.hypot(a, b)
        return rho <= eps, rho
    return False, math.sqrt(a * a + b * b)


@njit(cache=True, inline="always")
def _arc_end(a, b, theta):
    """Step after theta at which ``a cos + b sin`` turns negative, in (0, 2 pi]."""
    # lambda = rho cos(theta - alpha) turns negative when theta - alpha passes pi/2
    d = (math.atan2(b, a) + 0.5 * math.pi - theta) % (2.0 * math.pi)
    return 2.0 * math.pi if d < 1e-13 else d


@njit(cache=True, inline="always")
def _breakpoint(Binv, GT, theta, cos_t, sin_t, scale, ab):
    """Smallest angle > theta at which a multiplier of the basis turns negative (inf if none).

    ``cos_t, sin_t``: cos and sin of theta; ``ab`` (4, n): work buffer. :func:`_rates`, then
    :func:`_breakpoint_at`.
    """
    _rates(Binv, GT, scale, ab)
    return _breakpoint_at(ab, theta, cos_t, sin_t)


@njit(cache=True, inline="always")
def _rates(Binv, GT, scale, ab):
    """The multipliers' coefficients of the basis and their tolerances: ``ab[0], ab[1], ab[3]``.

    ``lambda_i(theta) = a_i cos(theta) + b_i sin(theta)`` with ``(a_i, b_i) = GT^T Binv[:, i]``
    (the columns' sums row by row of Binv, each in its column loop's order), and the tolerance
    within which lambda_i counts as zero, ``_EPS_DUAL scale max(1, |Binv[:, i]|)`` (as
    :func:`_priced`'s). ``ab[2]`` is left for :func:`_breakpoint_at`.
    """
    n = Binv.shape[0]
    ab[0], ab[1], ab[3] = 0.0, 0.0, 0.0
    for k in range(n):
        g0, g1 = GT[k, 0], GT[k, 1]
        for i in range(n):
            x = Binv[k, i]
            ab[0, i] += g0 * x
            ab[1, i] += g1 * x
            ab[3, i] += x * x
    for i in range(n):
        ab[3, i] = _EPS_DUAL * scale * max(1.0, math.sqrt(ab[3, i]))


@njit(cache=True, inline="always")
def _breakpoint_at(ab, theta, cos_t, sin_t):
    """:func:`_breakpoint` from the basis's :func:`_rates` (``ab[2]``: work).

    Each multiplier's step is ``_arc_end``'s (an atan2 and a modulo); a cheap lower bound skips
    those that cannot be the smallest by more than 1e-9 rad, so the answer is the same number.
    """
    n = ab.shape[1]
    first = -1
    # lambda_i(theta) = a cos(theta) + b sin(theta) = rho cos(phi), phi = theta - alpha_i
    for i in range(n):
        a, b = ab[0, i], ab[1, i]
        zero, rho = _rho(a, b, ab[3, i])
        if zero:
            ab[2, i] = math.inf  # identically zero multiplier
            continue
        lam = a * cos_t + b * sin_t  # rho cos(phi)
        if a * sin_t - b * cos_t <= 0.0:  # rho sin(phi): phi in [-pi, 0], step in [pi/2, 3 pi/2]
            ab[2, i] = 0.5 * math.pi
        elif lam > 0.0:  # phi in (0, pi/2): step = asin(lam / rho) >= lam / rho
            ab[2, i] = lam / rho
        else:  # at or past its zero: no bound
            ab[2, i] = 0.0
        if first < 0 or ab[2, i] < ab[2, first]:
            first = i
    if first < 0:
        return math.inf
    step = _arc_end(ab[0, first], ab[1, first], theta)
    for i in range(n):
        if i != first and ab[2, i] <= step + 1e-9:
            step = min(step, _arc_end(ab[0, i], ab[1, i], theta))
    return theta + step


@njit(cache=True, inline="always")
def _optimal_at(ab, cos_t, sin_t):
    """Whether the basis is lexicographically optimal at theta+, from its :func:`_rates`.

    Where :func:`_optimize` stops: no column is an entering candidate by :func:`_priced`'s test,
    with the multipliers ``lambda_i = a_i cos + b_i sin`` and their theta-derivatives
    ``-a_i sin + b_i cos`` (``Binv[:, i] . c`` and ``. dc`` to rounding).
    """
    for i in range(ab.shape[1]):
        a, b = ab[0, i], ab[1, i]
        lam = a * cos_t + b * sin_t
        dlam = b * cos_t - a * sin_t
        eps = ab[3, i]
        if lam < -eps or (lam <= eps and dlam < -eps):
            return False
    return True


@njit(cache=True)
def _warm_start(H, h, W, Binv, z, active, work, hint):
    """Start from the basis in ``hint`` when it is a feasible vertex basis here.

    ``hint`` = (m, n, the n rows), written by the previous walk of the same caller (a governor's
    last posture, whose optimal basis at theta0 is one or two pivots from this one's). Replaces
    the crash, which costs n ratio tests over every row. Any feasible vertex basis is a valid
    simplex start, so the walk's answer is the same polygon (its vertices to rounding). Returns
    False otherwise, z back at 0 (the crash's start: the caller tries only where 0 is
    feasible).
    """
    m, n = H.shape
    if hint.shape[0] < n + 2 or hint[0] != m or hint[1] != n:
        return False
    for i in range(n):
        W[i] = hint[2 + i]
        if W[i] < 0 or W[i] >= m:
            return False
    # A singular basis (a row twice, say) can pass _invert's pivot test at condition 1e16:
    # _accurate refuses its inverse, whose vertex is not the basis's.
    if not (_refactor(H, h, W, Binv, z, work[5]) and _accurate(H, h, W, Binv, z, work[2])):
        z[:] = 0.0
        return False
    for j in range(m):  # feasible to the rounding of a fresh vertex, as the crash's are
        b = h[j]
        for k in range(n):
            b -= H[j, k] * z[k]
        if b < -_EPS_CARRY * max(1.0, abs(h[j])):
            z[:] = 0.0
            return False
    for i in range(n):
        active[W[i]] = True
    return True


@njit(cache=True)
def _phase_one(H, h, z, W, active, max_pivots):
    """A feasible point of ``{H z <= h}`` into ``z``; returns (status, pivots, k).

    When the phase-1 optimum is a vertex basis of it, its rows go into ``W[:k]``, flagged in
    ``active``.

    Phase 1: max -s over {H z - s <= h, s >= 0} from (0, s0), s0 feasible.
    """
    m, n = H.shape
    Ha = np.zeros((m + 1, n + 1))
    Ha[:m, :n] = H
    Ha[:m, n] = -1.0
    Ha[m, n] = -1.0
    ha = np.zeros(m + 1)
    ha[:m] = h
    za = np.zeros(n + 1)
    za[n] = max(0.0, -h.min()) + 1.0
    Wa = np.zeros(n + 1, dtype=np.int64)
    active_a = np.zeros(m + 1, dtype=np.bool_)
    c1 = np.zeros(n + 1)
    c1[n] = -1.0
    status, _ = _crash(Ha, ha, za, Wa, 0, active_a, c1, np.zeros(n + 1))
    if status != OK:
        return status, 0, 0
    Binv_a = np.empty((n + 1, n + 1))
    work = _workspace(m + 1, n + 1)
    if not _refactor(Ha, ha, Wa, Binv_a, za, work[5]):
        return FAILED, 0, 0
    status, pivots = _optimize(
        Ha, ha, za, Wa, Binv_a, active_a, c1, np.zeros(n + 1), 1.0, max_pivots, work
    )
    if status != OK:
        return status, pivots, 0
    if za[n] > _EPS_FEASIBLE:
        return INFEASIBLE, pivots, 0
    # When s >= 0 is in the phase-1 basis, the other n rows are a vertex basis of {H z <= h}.
    z[:] = za[:n]
    k = 0
    if active_a[m]:
        for i in range(n + 1):
            if Wa[i] != m:
                W[k] = Wa[i]
                active[Wa[i]] = True
                k += 1
    return OK, pivots, k


@njit(cache=True, inline="always")
def _record(H, h, GT, g0, z, worst, ref, vertices, count):
    """Record a re-certified vertex z: ``(count, strict)``, the vertex count after it and its check.

    Its slacks go to ``worst`` as :func:`_min_slack_near` sets it; ``strict`` is whether each is
    at least -_EPS_RECERT max(1, |h_j|). ``ref`` (1 + m + n): a flag, every row's slack at the
    reference vertex and that vertex (see _REF_MOVE), replaced by z when z is not within
    _REF_MOVE of it. Its point is kept when it differs from the last one.
    """
    m, n = H.shape
    d = 0.0
    if ref[0] > 0.0:
        acc = 0.0
        for k in range(n):
            e = z[k] - ref[1 + m + k]
            acc += e * e
        d = math.sqrt(acc)
    full = ref[0] <= 0.0 or d > _REF_MOVE
    bound = d + _REF_MARGIN
    strict = True
    for j in range(m):
        if not full and ref[1 + j] > bound:
            continue  # positive at z
        b = h[j]
        for k in range(n):
            b -= H[j, k] * z[k]
        if full:
            ref[1 + j] = b
        if b < worst[0]:
            worst[0] = b
        if b < 0.0 and b < -_EPS_RECERT * max(1.0, abs(h[j])):
            strict = False
    if full:
        ref[0] = 1.0
        ref[1 + m : 1 + m + n] = z
    _point(g0, GT, z, vertices, count)
    if (
        count == 0
        or abs(vertices[count, 0] - vertices[count - 1, 0])
        + abs(vertices[count, 1] - vertices[count - 1, 1])
        > 0.0
    ):
        count += 1
    return count, strict


@njit(cache=True, inline="always")
def _directions(GT, theta, c, dc):
    """``c = G^T u(theta)``, ``dc = G^T u'(theta)`` in place; returns (cos theta, sin theta)."""
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    for i in range(GT.shape[0]):  # _times_into's sums, term by term
        c[i] = 0.0 + GT[i, 0] * cos_t + GT[i, 1] * sin_t
        dc[i] = 0.0 + GT[i, 0] * -sin_t + GT[i, 1] * cos_t
    return cos_t, sin_t


@njit(cache=True, inline="always")
def _keep(bases, recorded, W, y, yfirst):
    """One more basis of the walk's chain (optimal at a breakpoint, point y) into ``bases``.

    The chain keeps, of each run of bases at one polygon vertex (y within _Y_SAME of the run's
    first, ``yfirst``), the first (kind 0) and the last (kind 1): row ``[kind, W...]``.
    Returns the chain's length, which may exceed the rows of ``bases`` (then it is not kept).
    """
    same = recorded > 0 and math.hypot(y[0] - yfirst[0], y[1] - yfirst[1]) <= _Y_SAME
    slot = recorded
    if same and recorded >= 2 and recorded <= bases.shape[0] and bases[recorded - 1, 0] == 1:
        slot = recorded - 1  # the run's last so far: replaced
    if not same:
        yfirst[:] = y
    if slot < bases.shape[0]:
        bases[slot, 0] = 1 if same else 0
        bases[slot, 1:] = W
    return slot + 1


@njit(cache=True)
def _replace(H, h, W, Binv, z, target, work):
    """The basis W turned into ``target`` (n rows): the rank-one updates made, or -1.

    Position by position (:func:`_update`, the vertex once after the last), each through a
    pivot element ``H_j . Binv[:, i]`` the walk's ratio test would accept (above 1e-9
    |Binv[:, i]|); when one is not (a singular basis on the way), a fresh inverse of ``target``
    instead, checked as :func:`_warm_start` checks its own: -2. -1 when a row is out of range
    or ``target``'s inverse fails.
    """
    m, n = H.shape
    made = 0
    for i in range(n):
        j = target[i]
        if j == W[i]:
            continue
        if j < 0 or j >= m:
            return -1
        piv = 0.0
        for r in range(n):
            piv += H[j, r] * Binv[r, i]
        if abs(piv) <= _EPS_PIVOT * _column_norm(Binv, i):
            W[:] = target
            fresh = _refactor(H, h, W, Binv, z, work[5]) and _accurate(H, h, W, Binv, z, work[2])
            return -2 if fresh else -1
        W[i] = j
        _update(H, Binv, i, j, work)
        made += 1
    if made:
        _vertex(h, W, Binv, z)
    return made


@njit(cache=True)
def _arc_start(Binv, GT, theta, scale):
    """Where the basis's optimal arc starts in [theta, theta + pi): inf if it has none there.

    :func:`_arc_start_at` of the basis's :func:`_rates`.
    """
    ab = np.empty((4, Binv.shape[0]))
    _rates(Binv, GT, scale, ab)
    return _arc_start_at(ab, theta)


@njit(cache=True, inline="always")
def _arc_start_at(ab, theta):
    """:func:`_arc_start` from the basis's :func:`_rates` (``ab[2]``: work).

    Each multiplier ``lambda_i = rho_i cos(t - alpha_i)`` is non-negative on the half-circle
    that starts at ``alpha_i - pi/2``: within [theta, theta + pi], one that starts at
    ``theta + s_i`` with s_i <= pi bounds the arc from below (lo), one that starts later
    (s_i > pi) ends at ``theta + s_i - pi`` (hi). A multiplier clearly positive at theta (above
    1e-9 rho_i) is one of the latter, and its end comes no sooner than a cheap lower bound
    (:func:`_breakpoint_at`'s); its angle (an atan2 and a modulo) is computed only when that
    bound does not clear lo by 1e-9: the same answer.
    """
    cos_t, sin_t = math.cos(theta), math.sin(theta)
    lo, hi = 0.0, math.pi
    for i in range(ab.shape[1]):
        a, b = ab[0, i], ab[1, i]
        zero, rho = _rho(a, b, ab[3, i])
        ab[2, i] = -1.0  # no bound: done, or identically zero
        if zero:
            continue  # identically zero multiplier
        lam = a * cos_t + b * sin_t  # rho cos(theta - alpha_i)
        if lam > 1e-9 * rho:  # s_i in (pi, 2 pi): an end; its lower bound for later
            ab[2, i] = 0.5 * math.pi if a * sin_t - b * cos_t <= 0.0 else lam / rho
            continue
        s = (math.atan2(b, a) - 0.5 * math.pi - theta) % (2.0 * math.pi)
        if s <= math.pi:
            lo = max(lo, s)
        else:
            hi = min(hi, s - math.pi)
    for i in range(ab.shape[1]):
        if ab[2, i] >= 0.0 and ab[2, i] <= lo + 1e-9:
            s = (math.atan2(ab[1, i], ab[0, i]) - 0.5 * math.pi - theta) % (2.0 * math.pi)
            if s <= math.pi:  # not reached (s_i > pi), kept for the same answer
                lo = max(lo, s)
            else:
                hi = min(hi, s - math.pi)
    return theta + lo if lo <= hi and lo < math.pi else math.inf


@njit(cache=True)
def _next_basis(H, h, GT, W, Binv, z, theta, scale, kind, rows, since, work):
    """The chain's next basis (``rows``) and the angle it is optimal at: ``(theta, since)``.

    ``theta``: the previous basis's breakpoint. Kind 0: optimal there. Kind 1 (the same
    polygon vertex as the previous basis, checked by the caller): at the start of its own
    optimal arc, after the previous one's end and within pi of it; every direction between is
    a positive combination of the directions the vertex is optimal for at those two angles, so
    it is optimal in between too (its normal cone is convex). ``since``: pivots since the last
    fresh inverse (after _CARRY, the new basis's inverse is a fresh one; so it is when the
    updated one fails its check). The new basis's :func:`_rates` go to ``work[6]``. Returns
    theta = inf when the chain does not certify.
    """
    if since >= _CARRY:
        for i in range(W.shape[0]):
            if rows[i] < 0 or rows[i] >= H.shape[0]:
                return math.inf, since
        W[:] = rows
        fresh = _refactor(H, h, W, Binv, z, work[5]) and _accurate(H, h, W, Binv, z, work[2])
        piv = -2 if fresh else -1
    else:
        piv = _replace(H, h, W, Binv, z, rows, work)
    if piv == -1:
        return math.inf, since
    if piv == -2:  # a fresh inverse, checked
        since = 0
    elif piv > 0:
        since += piv
        if not _accurate(H, h, W, Binv, z, work[2]):
            if not _refactor(H, h, W, Binv, z, work[5]):
                return math.inf, since
            since = 0
    _rates(Binv, GT, scale, work[6])
    if kind == 1:
        theta = _arc_start_at(work[6], theta)
    return theta, since


#: :func:`_recertify`'s status when only the chain's first bases certify: the walk goes on
#: from the last of them (:func:`walk`).
_PREFIX = 5


@njit(cache=True)
def _recertify(H, h, GT, g0, theta0, scale, low, hint, W, Binv, z, work, yrun):
    """The walk's vertices from the last walk's chain of bases (``hint``), as far as they certify.

    The walk's certificate, without its ratio tests and pricing rounds: each basis of the chain
    is a vertex basis (its inverse solves its system to 1e-14, fresh at least every _CARRY
    pivots), its vertex satisfies every row to _EPS_RECERT max(1, |h_j|), it is lexicographically
    optimal at its angle (:func:`_next_basis`; the first at theta0), and the last certified
    one's arc reaches theta0 + 2 pi. Every direction then has an optimal vertex among the
    recorded ones: the polygon the walk would find.

    Returns ``(status, vertices, count, theta, good)``: OK (the polygon: ``vertices[:count]``
    of the first ``good`` bases), _PREFIX (only the first ``good`` bases certify, the last one
    optimal at ``theta``: where the walk goes on) or FAILED. ``low[0]``: the worst slack of the
    certified vertices, as the walk sets its own; ``yrun``: the point of the last certified
    basis of kind 0 (the first of its polygon vertex).
    """
    m, n = H.shape
    K = hint[n + 2]
    none = np.empty((0, 2))
    if K > _chain_capacity(hint, n):
        return FAILED, none, 0, theta0, 0
    vertices = np.empty((K, 2))
    ref = np.zeros(1 + m + n)  # the slacks at a reference vertex (see _record)
    ab = work[6]
    base = n + 3
    for i in range(n):
        W[i] = hint[base + 1 + i]
        if W[i] < 0 or W[i] >= m:
            return FAILED, none, 0, theta0, 0
    if hint[base] != 0 or not (
        _refactor(H, h, W, Binv, z, work[5]) and _accurate(H, h, W, Binv, z, work[2])
    ):
        return FAILED, none, 0, theta0, 0
    _rates(Binv, GT, scale, ab)
    end = theta0 + 2.0 * math.pi
    theta, good_theta = theta0, theta0
    u0, u1 = math.cos(theta0), math.sin(theta0)
    since = 0
    count = 0
    good = 0
    for k in range(K):
        at = base + k * (n + 1)
        if k > 0:
            step = _breakpoint_at(ab, theta, u0, u1)
            if step >= end:  # the previous basis's arc closes the polygon
                return OK, vertices, count, good_theta, good
            theta, since = _next_basis(
                H, h, GT, W, Binv, z, step, scale, hint[at], hint[at + 1 : at + 1 + n], since,
                work,
            )  # fmt: skip
            if theta >= end:
                break
            u0, u1 = math.cos(theta), math.sin(theta)
        if not _optimal_at(ab, u0, u1):
            break
        last, before = count, low[0]
        count, strict = _record(H, h, GT, g0, z, low, ref, vertices, count)
        if not strict or (k > 0 and hint[at] == 1 and _moved(vertices, last)):
            count, low[0] = last, before
            break
        good, good_theta = k + 1, theta
        if hint[at] == 0:
            yrun[0], yrun[1] = vertices[count - 1, 0], vertices[count - 1, 1]
    if good == K and _breakpoint_at(ab, theta, u0, u1) >= end:
        return OK, vertices, count, good_theta, good
    return (_PREFIX if good > 0 else FAILED), vertices, count, good_theta, good


@njit(cache=True, inline="always")
def _moved(vertices, i):
    """Whether point i (at ``vertices[i]``, kept or not) is beyond _Y_SAME of point i - 1."""
    return (
        math.hypot(vertices[i, 0] - vertices[i - 1, 0], vertices[i, 1] - vertices[i - 1, 1])
        > _Y_SAME
    )


@njit(cache=True)
def _chain_capacity(hint, n):
    """How many bases (a kind and n rows each) ``hint`` holds after its first n + 3 entries."""
    return max(0, (hint.shape[0] - n - 3) // (n + 1))


@njit(cache=True)
def _from_chain(H, h, GT, g0, theta0, scale, worst, hint, W, Binv, z, work, yrun):
    """:func:`_recertify` when ``hint`` holds a chain for this (m, n).

    Returns ``(status, vertices, count, theta, good)``: OK (the polygon, its chain shortened
    to the ``good`` bases that certify it), _PREFIX (the basis to go on from in W, Binv and z,
    a fresh inverse, checked, optimal at ``theta``; the chain's first ``good`` bases still in
    ``hint``) or FAILED (the walk's state back at its start: z = 0, nothing listed near a
    vertex, the chain dropped from ``hint``). ``worst[0]`` takes the certified vertices' worst
    slack unless FAILED.
    """
    m, n = H.shape
    work[8][0] = -1  # nothing listed near a vertex
    if hint[0] == m and hint[1] == n and hint[n + 2] > 0:
        low = np.zeros(1)  # the walk's worst slack, kept apart until the chain is certified
        status, vertices, count, theta, good = _recertify(
            H, h, GT, g0, theta0, scale, low, hint, W, Binv, z, work, yrun
        )
        if status == _PREFIX:  # the last certified basis again, a fresh inverse
            at = n + 3 + (good - 1) * (n + 1)
            W[:] = hint[at + 1 : at + 1 + n]
            if not (_refactor(H, h, W, Binv, z, work[5]) and _accurate(H, h, W, Binv, z, work[2])):
                status = FAILED
        if status != FAILED:
            if status == OK:
                hint[n + 2] = good
            worst[0] = min(worst[0], low[0])
            return status, vertices, count, theta, good
        z[:] = 0.0
    hint[n + 2] = 0
    return FAILED, np.empty((0, 2)), 0, theta0, 0


@njit(cache=True)
def _store_chain(hint, bases, recorded):
    """The walk's chain of ``recorded`` bases (:func:`_keep`) into ``hint``, when it fits."""
    capacity, size = bases.shape
    n = size - 1
    if 0 < recorded <= capacity:
        hint[n + 2] = recorded
        for k in range(recorded):
            hint[n + 3 + k * size : n + 3 + (k + 1) * size] = bases[k]


@njit(cache=True)
def _start(H, h, z, W, Binv, active, c, dc, scale, max_pivots, work, hint):
    """The walk's first basis, optimal for (c, dc) (theta0); returns (status, pivots).

    Phase 1 when z = 0 is not feasible, then the warm start (``hint``) or the crash, pivots
    to optimality, its inverse checked; its rows go to ``hint`` (the next call's start).
    """
    m, n = H.shape
    k = 0
    pivots = 0
    if h.min() < 0.0:  # z = 0 is not feasible (it is for contact stances: x0 is inside)
        status, pivots, k = _phase_one(H, h, z, W, active, max_pivots)
        if status != OK:
            return status, pivots
    if not (k == 0 and h.min() >= 0.0 and _warm_start(H, h, W, Binv, z, active, work, hint)):
        status, k = _crash(H, h, z, W, k, active, c, dc)
        if status != OK:
            return status, pivots
        if not _refactor(H, h, W, Binv, z, work[5]):
            return FAILED, pivots
    status, piv = _optimize(H, h, z, W, Binv, active, c, dc, scale, max_pivots, work)
    pivots += piv
    if status != OK:
        return status, pivots
    if piv and not _accurate(H, h, W, Binv, z, work[2]):
        if not _refactor(H, h, W, Binv, z, work[5]):
            return FAILED, pivots
    if hint.shape[0] >= n + 2:  # the optimal basis at theta0: the next call's start
        hint[0], hint[1] = m, n
        hint[2 : n + 2] = W
    return OK, pivots


@njit(cache=True)
def _resume(hint, W, active, bases, good, prefix, count, vertices):
    """The walk's state after the chain's first ``good`` certified bases (:func:`_from_chain`).

    Their points (``prefix[:count]``) into ``vertices``, their rows into ``bases`` (the chain
    the walk goes on writing) and the last one's rows (``W``) flagged in ``active``; the chain
    dropped from ``hint`` until the walk stores its own.
    """
    n = W.shape[0]
    vertices[:count] = prefix[:count]
    for k in range(good):
        at = n + 3 + k * (n + 1)
        bases[k] = hint[at : at + n + 1]
    hint[n + 2] = 0
    for i in range(n):
        active[W[i]] = True


@njit(cache=True)
def _walk(H, h, GT, g0, theta0, max_pivots, worst, hint):
    """:func:`walk`, and whether it went on from a chain's certified bases.

    Returns ``(status, vertices, count, pivots, resumed)``.
    """
    m, n = H.shape
    z = np.zeros(n)
    W = np.zeros(n, dtype=np.int64)
    Binv = np.empty((n, n))
    work = _workspace(m, n)
    scale = _norm(GT.ravel())  # sqrt(|G^T u|^2 + |G^T u'|^2), the same for every theta
    bases = np.empty((_chain_capacity(hint, n), n + 1), dtype=np.int64)
    yfirst = np.empty(2)  # the point of the chain's last run
    status, prefix, count, theta, recorded = FAILED, np.empty((0, 2)), 0, theta0, 0
    if bases.shape[0]:
        status, prefix, count, theta, recorded = _from_chain(
            H, h, GT, g0, theta0, scale, worst, hint, W, Binv, z, work, yfirst
        )
        if status == OK:
            return OK, prefix, count, 0, False
    active = np.zeros(m, dtype=np.bool_)
    u = np.array([math.cos(theta0), math.sin(theta0)])
    du = np.array([-math.sin(theta0), math.cos(theta0)])
    c, dc = _times(GT, u), _times(GT, du)
    vertices = np.empty((max_pivots + 2, 2))
    pivots = 0
    resumed = status == _PREFIX
    if resumed:  # the walk goes on from the chain's last certified basis, optimal at theta
        _resume(hint, W, active, bases, recorded, prefix, count, vertices)
        u[0], u[1] = math.cos(theta), math.sin(theta)
        since = 0
    else:
        status, pivots = _start(H, h, z, W, Binv, active, c, dc, scale, max_pivots, work, hint)
        if status != OK:
            return status, np.empty((0, 2)), 0, pivots, False
        _min_slack_near(H, h, z, worst, work[7], work[8])
        _point(g0, GT, z, vertices, 0)
        count = 1
        recorded = _keep(bases, 0, W, vertices[0], yfirst) if bases.shape[0] else 0
        theta = theta0
        since = _CARRY  # pivots since the last fresh inverse (the first breakpoint makes one)
    while True:
        theta = _breakpoint(Binv, GT, theta, u[0], u[1], scale, work[6])
        if theta >= theta0 + 2.0 * math.pi:
            break
        u[0], u[1] = math.cos(theta), math.sin(theta)
        du[0], du[1] = -math.sin(theta), math.cos(theta)
        _times_into(GT, u, c)
        _times_into(GT, du, dc)
        # The inverse is carried across breakpoints by rank-one updates only while it still
        # solves its system to 1e-14 (checked after the pivots that changed it, below) and for
        # at most _CARRY pivots; then a fresh one. The check, not the count, guards the
        # precision (docs/studies/design-history.md, "Core floors").
        if since >= _CARRY:
            if not _refactor(H, h, W, Binv, z, work[5]):
                return FAILED, vertices, count, pivots, resumed
            since = 0
        status, piv = _optimize(H, h, z, W, Binv, active, c, dc, scale, max_pivots, work)
        pivots += piv
        since += piv
        if status != OK or count > max_pivots:
            return FAILED, vertices, count, pivots, resumed
        # The vertex from a fresh inverse when the pivots' rank-one updates left the inverse
        # off: through a small pivot element (a basis at condition 4e6 on G1) the inverse was
        # 1e-5 off and its vertex violated a row by 2e-6, which made the walk refuse and fall
        # back to Bretl (5 ms) on 5 % of G1's postures; the basis's own vertex is within 1e-11.
        if piv and not _accurate(H, h, W, Binv, z, work[2]):
            if not _refactor(H, h, W, Binv, z, work[5]):
                return FAILED, vertices, count, pivots, resumed
            since = 0
        # piv == 0: the crossing multiplier was within the tolerance of zero; the next
        # breakpoint search starts past it. A vertex reached by zero steps (a new basis of it)
        # is recorded too: on an ill-conditioned stance each basis gives it to within ~1e-8,
        # not to rounding, and the merge keeps the outermost (skipping them lost 5e-7 of the
        # area at a hand friction of 1.6e-6).
        _min_slack_near(H, h, z, worst, work[7], work[8])
        _point(g0, GT, z, vertices, count)  # kept when it differs from the last one
        if (
            abs(vertices[count, 0] - vertices[count - 1, 0])
            + abs(vertices[count, 1] - vertices[count - 1, 1])
            > 0.0
        ):
            count += 1
        if bases.shape[0]:  # a chain for the next call (see _keep)
            recorded = _keep(bases, recorded, W, vertices[count - 1], yfirst)
    # A chain is kept when re-certifying it costs less than the walk did (not on one foot), or
    # when the walk went on from one.
    if recorded < pivots or resumed:
        _store_chain(hint, bases, recorded)
    return OK, vertices, count, pivots, resumed


@njit(cache=True)
def walk(H, h, GT, g0, theta0, max_pivots, worst, hint):
    """Vertices of ``g0 + G {z : H z <= h}`` (rows of H unit norm; ``GT`` = G^T, n x 2).

    Returns (status, vertices, count, pivots): ``vertices[:count]`` are the support points
    in counter-clockwise order, consecutive duplicates removed (the last may equal the first).
    ``worst[0]`` receives the smallest slack of the recorded vertices (>= -rounding for a
    sound walk; the caller rejects the walk otherwise).

    ``hint`` (int64), kept by a caller that projects postures in a row: ``(m, n)``, the optimal
    basis at theta0 (n rows; see :func:`_warm_start`), then, when it has room, the number of
    bases of the last walk's chain and the chain itself (n rows each). A chain that still
    certifies this polytope's polygon answers without walking (:func:`_from_chain`, 0
    pivots); one whose first bases certify it only in part, from the first on, has the walk
    go on from the last of those (its pivots the ones after it); else the walk starts from
    the basis, as it does when going on from a chain's bases fails (a cycle of zero steps that
    the walk from the start may not meet). Either walk writes its own chain. An empty hint is
    neither read nor written.
    """
    start = worst[0]
    status, vertices, count, pivots, resumed = _walk(H, h, GT, g0, theta0, max_pivots, worst, hint)
    if status == FAILED and resumed:  # the chain is dropped: from the warm start
        worst[0] = start
        status, vertices, count, more, _ = _walk(H, h, GT, g0, theta0, max_pivots, worst, hint)
        pivots += more
    return status, vertices, count, pivots


@njit(cache=True)
def project(A, b, E, x0, N, box, max_pivots, hint):
    """Projection of ``{x : A x <= b, x = x0 + N z}`` onto ``y = E x``, clipped to ``|y_k| <= box``.

    Drops zero rows of ``A N`` (checking them), scales the rows to unit norm, adds the box as
    four rows and walks.
    Returns (status, vertices (k, 2) counter-clockwise, unmerged, pivots, worst): ``worst``
    is the smallest slack of a visited point in the unit-row constraints (see :func:`walk`).
    """
    none = np.empty((0, 2))
    n, k = N.shape
    m0 = A.shape[0]
    H = np.zeros((m0 + 4, k))  # the rows of A N first, then scaled and compacted in place
    h = np.empty(m0 + 4)
    G = np.zeros((2, k))
    g0 = _times(E, x0)
    norms = np.empty(m0)
    biggest = 1.0
    for i in range(m0):
        acc = 0.0  # h_i = b_i - A_i x0 (_times's sum)
        for r in range(n):
            acc += A[i, r] * x0[r]
        h[i] = b[i] - acc
        for r in range(n):
            if A[i, r] != 0.0:  # A is sparse (contact blocks)
                for j in range(k):
                    H[i, j] += A[i, r] * N[r, j]
        norms[i] = _norm(H[i])
        biggest = max(biggest, norms[i])
    for i in range(2):
        for r in range(n):
            for j in range(k):
                G[i, j] += E[i, r] * N[r, j]
    if k == 0:  # a single point
        for i in range(m0):
            if h[i] < -_EPS_FEASIBLE:
                return INFEASIBLE, none, 0, 0.0
        out = np.empty((1, 2))
        out[0] = g0
        return OK, out, 0, 0.0
    # Unit rows; zero rows are checked then dropped (row m <= i: compacted in place).
    m = 0
    for i in range(m0):
        if norms[i] <= _RANK * biggest:
            if h[i] < -_EPS_FEASIBLE:
                return INFEASIBLE, none, 0, 0.0
        else:
            for j in range(k):  # element by element: no temporary array per row
                H[m, j] = H[i, j] / norms[i]
            h[m] = h[i] / norms[i]
            m += 1
    # The clipping box: +-G_k z <= box -+ g0_k.
    for i in range(2):
        gk = _norm(G[i])
        if gk > 0.0:
            for j in range(k):
                H[m, j] = G[i, j] / gk
                H[m + 1, j] = -G[i, j] / gk
            h[m] = (box - g0[i]) / gk
            h[m + 1] = (box + g0[i]) / gk
            m += 2
    worst = np.zeros(1)
    if m < H.shape[0]:  # rows dropped (or no box): the walk's arrays are the kept rows
        H, h = H[:m].copy(), h[:m].copy()
    status, vertices, count, pivots = walk(H, h, G.T.copy(), g0, 0.0, max_pivots, worst, hint)
    if status != OK:
        return status, none, pivots, worst[0]
    # The caller merges near-duplicate vertices and checks convexity (walk._certify, with the
    # polygon module's compiled merge; its cache is stamped with both files).
    return OK, vertices[:count].copy(), pivots, worst[0]


@njit(cache=True)
def equality_basis(C, d):
    """``x = x0 + N z`` spanning ``{x : C x = d}``: minimum-norm x0, orthonormal columns N.

    Modified Gram-Schmidt (twice) on the rows of C; dependent rows are checked for
    consistency. Returns (status, x0, N); status INFEASIBLE for inconsistent equalities.
    """
    m, n = C.shape
    Q = np.zeros((n, n))  # orthonormal rows: the row space of C, then its complement
    y = np.zeros(n)  # coordinates of x0 along Q's rows
    scale = 1.0
    size = 1.0
    for i in range(m):
        scale = max(scale, _norm(C[i]))
        size += abs(d[i])
    r = 0
    v = np.empty(n)
    for i in range(m):
        v[:] = C[i]
        di = d[i]
        for _ in range(2):
            for k in range(r):
                c = 0.0
                for j in range(n):
                    c += Q[k, j] * v[j]
                for j in range(n):
                    v[j] -= c * Q[k, j]
                di -= c * y[k]
        nv = _norm(v)
        if nv <= 1e-10 * scale:  # a dependent row: it must agree with the others
            if abs(di) > _EPS_FEASIBLE * size:
                return INFEASIBLE, np.zeros(n), np.zeros((n, 0))
            continue
        for j in range(n):
            Q[r, j] = v[j] / nv
        y[r] = di / nv
        r += 1
    x0 = np.zeros(n)
    for k in range(r):
        for j in range(n):
            x0[j] += y[k] * Q[k, j]
    # Complete Q with the coordinate axes that keep most of their length (_longest_axis's
    # choice, its |P e_i|^2 = 1 - sum_r Q[r, i]^2 carried from one row to the next: the same
    # subtractions in the same order).
    left = np.ones(n)
    for k in range(r):
        for i in range(n):
            left[i] -= Q[k, i] * Q[k, i]
    for count in range(r, n):
        best, axis = -1.0, 0
        for i in range(n):
            if left[i] > best:
                best, axis = left[i], i
        v[:] = 0.0
        v[axis] = 1.0
        norm = _project_out(Q, count, v, v)
        for j in range(n):
            Q[count, j] = v[j] / norm
        for i in range(n):
            left[i] -= Q[count, i] * Q[count, i]
    return OK, x0, Q[r:].T.copy()


@njit(cache=True)
def project_equalities(A, b, C, d, E, box, max_pivots, hint):
    """:func:`project` of ``{x : A x <= b, C x = d}``, the equalities eliminated.

    By :func:`equality_basis`, in the same compiled call (a governor pays each call's dispatch
    every tick). Returns (status, vertices, pivots, worst, x0, N); status INCONSISTENT for
    inconsistent equalities.
    """
    status, x0, N = equality_basis(C, d)
    if status == INFEASIBLE:
        return INCONSISTENT, np.empty((0, 2)), 0, 0.0, x0, N
    status, vertices, pivots, worst = project(A, b, E, x0, N, box, max_pivots, hint)
    return status, vertices, pivots, worst, x0, N
