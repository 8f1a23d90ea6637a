"""Re-certifying the last walk's chain of bases: the walk's polygon, without walking.

A caller that projects postures in a row keeps a hint of :func:`hint_size`; the walk writes
its chain of optimal bases there, and the next call answers from that chain when it still
certifies the new polygon (0 pivots), else walks. Either way the polygon must be the one a
walk without a hint finds (to 1e-9, issue 28's bound; the tests see 1e-13), and a chain
that no longer fits (a polygon that changed, garbage) must fall back to the walk.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from impact_balance.balance.areas import FORCE_BOX, FORCE_TOLERANCE, MERGE_TOLERANCE
from impact_balance.contacts.wrench_polytope import assemble_arrays, face_blocks
from impact_balance.geometry.polygon import MERGE_AREA_TOLERANCE
from impact_balance.governor import Governor
from impact_balance.projection import kernel as K
from impact_balance.projection import project_polytope
from impact_balance.projection.walk import (
    CHAIN_BASES,
    MAX_PIVOTS,
    NO_HINT,
    certified_walk,
    hint_size,
)

#: The benchmark's stances (``benchmarks/governor.py``): Talos on two feet, on a ramp, on one
#: foot, and G1 on two feet.
STANCES = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")


@pytest.fixture(scope="module")
def governors():
    return {name: Governor(name) for name in STANCES}


def _polytope(governor: Governor, q: np.ndarray):
    """The governor's projection data ``(A, b, C, d, E)`` at ``q`` (units of m g)."""
    ev = governor._evaluator
    k = ev.kinematics(np.ascontiguousarray(q))
    weight = k.mass * ev.settings.gravity
    blocks = face_blocks(ev._faces, k.rotations)
    A, b, C, G = assemble_arrays(
        blocks, k.local + k.origin, k.local - k.com_local, k.jacobians, ev._idx, ev._limit,
        k.gravity_torques,
    )  # fmt: skip
    return A, b / weight, C, np.array([1.0, 0.0, 0.0, 0.0]), np.ascontiguousarray(G[:2])


def _walk(data, hint):
    """``(status, vertices, pivots)`` of the certified walk of ``data`` with ``hint``."""
    status, vertices, _, pivots, _, _ = certified_walk(
        *data, FORCE_BOX, MAX_PIVOTS, MERGE_TOLERANCE, MERGE_AREA_TOLERANCE, hint
    )
    return status, vertices, pivots


def _path(governor: Governor, count: int, step: float, seed: int):
    """``count`` postures from the stance's, each joint moving by up to ``step`` rad a posture."""
    q = governor.configuration.copy()
    rng = np.random.default_rng(seed)
    direction = rng.uniform(-1.0, 1.0, size=q.size - 7)
    out = []
    for _ in range(count):
        out.append(q.copy())
        q[7:] += step * direction
    return out


def _same_polygon(walked, cold):
    """The same vertices in the same counter-clockwise order, to 1e-9, from the same first
    vertex or another: a walk from a hint may start its list at a neighbour of the first
    vertex of a walk without one (the warm start did before the chains: on two feet, three
    vertices of the soles' right edge within 5e-5 in x, the start angle between them)."""
    assert walked[0] == cold[0] == K.OK
    assert walked[1].shape == cold[1].shape
    shift = int(np.argmin(np.abs(cold[1] - walked[1][0]).sum(axis=1)))
    np.testing.assert_allclose(walked[1], np.roll(cold[1], -shift, axis=0), rtol=0, atol=1e-9)


def _answer(data):
    """What the areas answer for ``data`` without a hint: the walk's polygon, or Bretl's
    projection where the walk cannot answer (``balance.areas``' fallback), as ``(OK, vertices)``."""
    cold = _walk(data, NO_HINT)
    if cold[0] == K.OK:
        return cold
    result = project_polytope(
        *data, tol=FORCE_TOLERANCE, box=FORCE_BOX, merge_tol=MERGE_TOLERANCE, method="bretl"
    )
    return K.OK, result.polygon.vertices, None


@settings(max_examples=24, deadline=None)
@given(
    st.sampled_from(STANCES),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=1e-5, max_value=3e-3),
)
# A posture where the walk without a hint fails (122 pivots) and the areas fall back to Bretl's
# projection: the re-certified chain gives Bretl's polygon (to 3e-13).
@example("palm_push_two_feet", 1552546378, 0.0003891760975884306)
# A G1 path whose fifth posture's chain certifies its first two bases; the walk that goes on from
# the second cycles at a degenerate vertex (1e-16 from the walk's own numbers there) and fails,
# and the walk from the warm start answers.
@example("g1_two_feet", 13723, 1e-05)
def test_a_recertified_polygon_is_the_walked_one(governors, name, seed, step):
    governor = governors[name]
    hint = np.full(hint_size(12), -1, dtype=np.int64)
    for q in _path(governor, 6, step, seed):
        data = _polytope(governor, q)
        _same_polygon(_walk(data, hint), _answer(data))


@pytest.mark.parametrize("name", STANCES)
def test_postures_in_a_row_are_mostly_recertified(governors, name):
    """A governor's postures (1 mrad a tick): most keep their polygon's chain of bases. On one
    foot (2 variables, a walk of 4 pivots for a chain of 5 bases) the chain is not kept: the
    walk costs what re-certifying would."""
    governor = governors[name]
    hint = np.full(hint_size(12), -1, dtype=np.int64)
    recertified = kept = 0
    for q in _path(governor, 20, 1e-3, 7):
        data = _polytope(governor, q)
        walked = _walk(data, hint)
        _same_polygon(walked, _walk(data, NO_HINT))
        recertified += walked[2] == 0
        n = data[0].shape[1] - 4
        assert 0 <= hint[n + 2] <= CHAIN_BASES
        kept += hint[n + 2] > 0
    if name == "kick_one_foot":
        assert kept == recertified == 0
    else:
        assert recertified >= 10 and kept == 20


def test_a_posture_far_away_is_walked(governors):
    """The chain of the stance's posture does not certify a posture 0.1 rad away."""
    governor = governors["palm_push_two_feet"]
    hint = np.full(hint_size(12), -1, dtype=np.int64)
    near, far = _path(governor, 2, 0.1, 3)
    _walk(_polytope(governor, near), hint)
    data = _polytope(governor, far)
    walked = _walk(data, hint)
    assert walked[2] > 0
    _same_polygon(walked, _walk(data, NO_HINT))


def _square(cut: float):
    """The square |z_i| <= 1 and the row z_0 + z_1 <= cut (unit rows), projected by G = I."""
    H = np.array([[1.0, 0.0], [0.0, 1.0], [-1.0, 0.0], [0.0, -1.0], [1.0, 1.0]])
    h = np.array([1.0, 1.0, 1.0, 1.0, cut])
    norms = np.linalg.norm(H, axis=1)
    return np.ascontiguousarray(H / norms[:, None]), h / norms


def _kernel_walk(H, h, hint):
    worst = np.zeros(1)
    status, vertices, count, pivots = K.walk(H, h, np.eye(2), np.zeros(2), 0.0, 100, worst, hint)
    return status, vertices[:count], pivots


@pytest.mark.parametrize(
    ("cut", "recertified", "corners"),
    [
        (2.5, True, [(1, 1), (-1, 1), (-1, -1), (1, -1)]),  # the cut stays away: the square
        (1.5, False, [(1, 0.5), (0.5, 1), (-1, 1), (-1, -1), (1, -1)]),  # a new edge
        (2.0, False, [(1, 1), (-1, 1), (-1, -1), (1, -1)]),  # the cut through the corner
    ],
)
def test_a_polygon_that_changes_combinatorially_is_walked(cut, recertified, corners):
    """The square's chain of bases against a cut that leaves it, cuts a corner off (a new
    vertex: walked) or passes through one (a degenerate corner).

    The chain as a walk keeps it (a walk this short does not: re-certifying its 4 bases costs
    what its 4 pivots do): ``(m, n)``, the start, the length, then ``[kind, rows]`` per basis
    in the walk's row positions: the corners (1, 1), (-1, 1), (-1, -1), (1, -1).
    """
    chain = [[0, 0, 1], [0, 2, 1], [0, 2, 3], [0, 0, 3]]
    hint = np.array([5, 2, 0, 1, 4, *np.ravel(chain)], dtype=np.int64)
    H, h = _square(3.0)
    status, _, pivots = _kernel_walk(H, h, hint.copy())
    assert status == K.OK and pivots == 0  # the chain certifies the square
    H, h = _square(cut)
    status, vertices, pivots = _kernel_walk(H, h, hint)
    cold = _kernel_walk(H, h, NO_HINT)
    assert status == cold[0] == K.OK
    assert (pivots == 0) == recertified or cut == 2.0
    # The polygon's corners, each recorded (consecutive duplicates removed), in either case.
    kept = {tuple(np.round(v, 12)) for v in vertices}
    assert (
        kept == {tuple(map(float, c)) for c in corners} == {tuple(np.round(v, 12)) for v in cold[1]}
    )


def _square_cuts(cuts):
    """The square |z_i| <= 1 and the rows ``row . z <= cut`` (unit rows), projected by G = I."""
    H = np.vstack([np.eye(2), -np.eye(2), [row for row, _ in cuts]])
    h = np.concatenate([np.ones(4), [cut for _, cut in cuts]])
    norms = np.linalg.norm(H, axis=1)
    return np.ascontiguousarray(H / norms[:, None]), h / norms


#: The square's chain as a walk from theta = 0 keeps it: the corners (1, 1), (-1, 1), (-1, -1),
#: (1, -1), ``[kind, rows]`` each.
SQUARE_CHAIN = [[0, 0, 1], [0, 2, 1], [0, 2, 3], [0, 0, 3]]


def _square_hint(chain, m=5):
    """A hint of the square's walk: ``(m, n)``, the start, the chain's length and the chain."""
    return np.array([m, 2, *chain[0][1:], len(chain), *np.ravel(chain), *[-1] * 30], dtype=np.int64)


def test_a_chain_that_fails_midway_goes_on_from_its_last_certified_basis():
    """A cut through the third corner: the chain's first two bases still certify, the walk goes
    on from the second (fewer pivots than a walk from the start) and writes a chain that begins
    with them; the polygon is the walk's without a hint."""
    H, h = _square_cuts([([-1.0, -1.0], 1.5)])
    hint = _square_hint(SQUARE_CHAIN)
    status, vertices, pivots = _kernel_walk(H, h, hint)
    cold = _kernel_walk(H, h, NO_HINT)
    assert status == cold[0] == K.OK
    assert 0 < pivots < cold[2]
    np.testing.assert_allclose(vertices, cold[1], rtol=0, atol=1e-12)
    corners = {tuple(np.round(v, 12)) for v in vertices}
    assert corners == {(1, 1), (-1, 1), (-1, -0.5), (-0.5, -1), (1, -1)}
    assert hint[4] == 5 and hint[5:11].tolist() == np.ravel(SQUARE_CHAIN[:2]).tolist()
    # The new chain certifies the cut square: the next call does not walk.
    assert _kernel_walk(H, h, hint)[2] == 0


def test_a_chain_that_closes_early_is_shortened():
    """A chain with a basis more than its polygon needs: the arcs of the first four reach the
    start angle plus 2 pi, which certifies the square; the chain keeps those four."""
    H, h = _square_cuts([([-1.0, -1.0], 3.0)])
    hint = _square_hint([*SQUARE_CHAIN, [0, 0, 1]])
    status, vertices, pivots = _kernel_walk(H, h, hint)
    assert status == K.OK and pivots == 0 and hint[4] == 4
    np.testing.assert_allclose(vertices, _kernel_walk(H, h, NO_HINT)[1], rtol=0, atol=1e-12)


@pytest.mark.parametrize("name", ["palm_push_two_feet", "palm_push_ramp", "g1_two_feet"])
def test_a_chain_whose_last_basis_fails_costs_less_than_a_walk(governors, name):
    """The last basis of a stance's chain made singular (its first row twice), at a posture
    the chain certifies: the walk goes on from the basis before it, with fewer pivots than a
    walk from the warm start alone, and finds the polygon of a walk without a hint."""
    governor = governors[name]
    hint = np.full(hint_size(12), -1, dtype=np.int64)
    for q in _path(governor, 3, 1e-3, 5):  # a governor's first ticks
        data = _polytope(governor, q)
        _walk(data, hint)
    assert _walk(data, hint.copy())[2] == 0  # the chain certifies the last posture's polygon
    n = 8  # 12 wrench variables less the 4 equalities
    length = int(hint[n + 2])
    assert length > 2
    start_only = hint.copy()
    start_only[n + 2] = 0  # the warm start, no chain
    last = n + 3 + (length - 1) * (n + 1)
    hint[last + 2 : last + 1 + n] = hint[last + 1]
    resumed, warm = _walk(data, hint), _walk(data, start_only)
    _same_polygon(resumed, _answer(data))
    _same_polygon(warm, _answer(data))
    assert 0 < resumed[2] < warm[2]


@settings(max_examples=20, deadline=None)
@given(
    st.sampled_from(("palm_push_two_feet", "palm_push_ramp", "g1_two_feet")),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=1e-5, max_value=3e-3),
)
def test_a_chain_whose_tail_is_garbage_gives_the_walked_polygon(governors, name, seed, step):
    """A stance's chain with its bases from a random one on replaced by random rows and kinds:
    whatever certifies, the walk goes on from there and finds the polygon of a walk without a
    hint (or Bretl's, where that walk cannot answer)."""
    governor = governors[name]
    first, second = _path(governor, 2, step, seed)
    hint = np.full(hint_size(12), -1, dtype=np.int64)
    _walk(_polytope(governor, first), hint)
    data = _polytope(governor, second)
    n, m = 8, data[0].shape[0] + 4  # the walk's variables and rows (the box's four with them)
    length = int(hint[n + 2])
    rng = np.random.default_rng(seed)
    if length > 1:
        cut = int(rng.integers(1, length))
        at = n + 3 + cut * (n + 1)
        hint[at : n + 3 + length * (n + 1)] = rng.integers(0, m, size=(length - cut) * (n + 1))
        hint[at : n + 3 + length * (n + 1) : n + 1] = rng.integers(0, 2, size=length - cut)
    _same_polygon(_walk(data, hint), _answer(data))


@settings(max_examples=200, deadline=None)
@given(
    st.integers(min_value=1, max_value=9),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=0.0, max_value=2.0 * math.pi),
)
def test_the_optimality_test_from_the_rates_is_the_pricings(n, seed, theta):
    """:func:`_optimal_at` (the re-certification's test, from the multipliers' coefficients)
    answers as the walk's pricing (:func:`_priced` of every column, from ``c``, ``dc``: where
    :func:`_optimize` stops) wherever no multiplier is within rounding of the tolerance: random
    bases, multipliers at zero and at the tolerance."""
    rng = np.random.default_rng(seed)
    Binv, GT = rng.normal(size=(n, n)), rng.normal(size=(n, 2))
    if rng.random() < 0.5:  # a multiplier at zero at theta (a breakpoint), or at its tolerance
        i = int(rng.integers(n))
        u = np.array([math.cos(theta), math.sin(theta)])
        target = rng.choice([0.0, 1e-11, -1e-11]) * np.linalg.norm(Binv[:, i])
        Binv[:, i] += (target - (GT @ u) @ Binv[:, i]) * (GT @ u) / float((GT @ u) @ (GT @ u))
    c = GT @ np.array([math.cos(theta), math.sin(theta)])
    dc = GT @ np.array([-math.sin(theta), math.cos(theta)])
    scale = float(np.linalg.norm(GT))
    ab = np.empty((4, n))
    K._rates(Binv, GT, scale, ab)
    norms = np.linalg.norm(Binv, axis=0)
    eps = K._EPS_DUAL * scale * np.maximum(1.0, norms)
    lam, dlam = Binv.T @ c, Binv.T @ dc
    rounding = 1e-13 * (1.0 + np.abs(Binv).sum(axis=0) * np.abs(GT).sum())
    clear = np.all(np.abs(np.abs(lam) - eps) > rounding) and np.all(
        np.abs(np.abs(dlam) - eps) > rounding
    )
    if clear:
        priced = all(K._priced(Binv, i, c, dc, scale)[0] == 2 for i in range(n))
        assert K._optimal_at(ab, math.cos(theta), math.sin(theta)) == priced


@settings(max_examples=60, deadline=None)
@given(st.integers(min_value=0, max_value=2**32 - 1), st.integers(min_value=1, max_value=20))
def test_a_chain_of_garbage_changes_nothing(seed, length):
    """Any chain (rows out of range, repeated, singular, the wrong kinds) gives the walk's
    polygon: it certifies or the walk answers."""
    H, h = _square(1.5)
    rng = np.random.default_rng(seed)
    hint = np.full(3 + 3 * 32, -1, dtype=np.int64)
    hint[0], hint[1], hint[4] = 5, 2, length  # (m, n), then the chain's length after the start
    hint[2:4] = rng.integers(-1, 6, size=2)
    hint[5 : 5 + 3 * length] = rng.integers(-1, 6, size=3 * length)
    hint[5 : 5 + 3 * length : 3] = rng.integers(0, 2, size=length)  # the kinds
    status, vertices, _ = _kernel_walk(H, h, hint)
    cold = _kernel_walk(H, h, NO_HINT)
    assert status == cold[0]
    np.testing.assert_allclose(vertices, cold[1], rtol=0, atol=1e-12)


def test_the_hint_size_holds_the_chain():
    n = 12  # 6 wrench variables per contact, two contacts: at most 12 after the equalities
    assert (hint_size(n) - n - 3) // (n + 1) == CHAIN_BASES
    assert hint_size(n) - 2 - n > 0
    assert NO_HINT.size == 0


def test_an_arc_start_is_where_the_multipliers_turn_non_negative():
    """:func:`_arc_start` against a scan of the multipliers over the half circle after theta."""
    rng = np.random.default_rng(11)
    for _ in range(200):
        n = int(rng.integers(2, 6))
        Binv, GT = rng.normal(size=(n, n)), rng.normal(size=(n, 2))
        theta = rng.uniform(0.0, 2.0 * math.pi)
        start = K._arc_start(Binv, GT, theta, 1.0)
        ts = theta + np.linspace(0.0, math.pi, 20001)[:-1]
        lam = (GT.T @ Binv).T @ np.vstack([np.cos(ts), np.sin(ts)])  # (n, samples)
        optimal = np.all(lam >= -1e-12, axis=0)
        if math.isinf(start):
            assert not optimal[1:-1].any()
        else:
            first = ts[np.argmax(optimal)]
            assert optimal.any() and abs(first - start) <= math.pi / 20000 + 1e-12


def _arc_start_every_angle(Binv, GT, theta, scale):
    """The arc's start with every multiplier's angle computed (the formula, in Python)."""
    ab = np.empty((4, Binv.shape[0]))
    K._rates(Binv, GT, scale, ab)
    lo, hi = 0.0, math.pi
    for i in range(Binv.shape[0]):
        a, b = float(ab[0, i]), float(ab[1, i])
        if math.hypot(a, b) <= ab[3, i]:
            continue
        s = (math.atan2(b, a) - 0.5 * math.pi - theta) % (2.0 * math.pi)
        if s <= math.pi:
            lo = max(lo, s)
        else:
            hi = min(hi, s - math.pi)
    return theta + lo if lo <= hi and lo < math.pi else math.inf


@settings(max_examples=300, deadline=None)
@given(
    st.integers(min_value=1, max_value=12),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=0.0, max_value=2.0 * math.pi),
    st.sampled_from((0.0, 1e-12, 1e-9, 1e-3)),
)
def test_an_arc_start_skips_no_angle_that_decides_it(n, seed, theta, near):
    """:func:`_arc_start` (which computes a multiplier's angle only where its lower bound does
    not clear the others) equals the formula with every angle computed, bit for bit: random
    bases, and multipliers placed at or near zero at theta (``near`` of their norm), where a
    bound is tightest."""
    rng = np.random.default_rng(seed)
    Binv, GT = rng.normal(size=(n, n)), rng.normal(size=(n, 2))
    u = np.array([math.cos(theta), math.sin(theta)])
    for i in range(n):
        if rng.random() < 0.4:  # lambda_i(theta) moved to +-near |(a_i, b_i)|
            target = rng.choice([-1.0, 1.0]) * near * np.linalg.norm(GT.T @ Binv[:, i])
            Binv[:, i] += (target - (GT @ u) @ Binv[:, i]) * (GT @ u) / float((GT @ u) @ (GT @ u))
    for scale in (1.0, 1e9):  # 1e9: some multipliers within the tolerance of zero
        expected = _arc_start_every_angle(Binv, GT, theta, scale)
        assert K._arc_start(Binv, GT, theta, scale) == expected


@settings(max_examples=300, deadline=None)
@given(
    st.integers(min_value=1, max_value=12),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=0.0, max_value=2.0 * math.pi),
    st.sampled_from((0.0, 1e-12, 1e-9, 1e-3)),
    st.sampled_from((1.0, 1e9, 1e-120, 1e120)),
)
def test_a_breakpoint_is_the_first_arc_end_of_every_multiplier(n, seed, theta, near, size):
    """:func:`_breakpoint` (an arc end computed only where its lower bound does not clear the
    smallest) equals the smallest arc end with every one computed by ``hypot`` and ``atan2``,
    bit for bit: random bases of any size (the squares' overflow and underflow), multipliers
    at or near zero at theta."""
    rng = np.random.default_rng(seed)
    Binv, GT = rng.normal(size=(n, n)) * size, rng.normal(size=(n, 2))
    u = np.array([math.cos(theta), math.sin(theta)])
    for i in range(n):
        if rng.random() < 0.4:  # lambda_i(theta) moved to +-near |(a_i, b_i)|
            target = rng.choice([-1.0, 1.0]) * near * np.linalg.norm(GT.T @ Binv[:, i])
            Binv[:, i] += (target - (GT @ u) @ Binv[:, i]) * (GT @ u) / float((GT @ u) @ (GT @ u))
    for scale in (1.0, 1e9):
        ab = np.empty((4, n))
        K._rates(Binv, GT, scale, ab)
        expected = math.inf
        for i in range(n):
            a, b = float(ab[0, i]), float(ab[1, i])
            if math.hypot(a, b) <= ab[3, i]:
                continue
            d = (math.atan2(b, a) + 0.5 * math.pi - theta) % (2.0 * math.pi)
            expected = min(expected, 2.0 * math.pi if d < 1e-13 else d)
        got = K._breakpoint(Binv, GT, theta, math.cos(theta), math.sin(theta), scale, ab)
        assert got == theta + expected


def _slacks(H, h, z):
    """Every row's slack ``h_j - H_j z``, summed in the kernel's order (the same numbers)."""
    out = []
    for j in range(len(h)):
        b = float(h[j])
        for k in range(len(z)):
            b -= float(H[j, k]) * float(z[k])
        out.append(b)
    return np.array(out)


@settings(max_examples=100, deadline=None)
@given(
    st.integers(min_value=2, max_value=9),
    st.integers(min_value=4, max_value=80),
    st.integers(min_value=0, max_value=2**32 - 1),
    st.floats(min_value=1e-12, max_value=1.0),
)
def test_a_re_certified_vertex_is_checked_as_by_a_full_scan(n, m, seed, step):
    """``_record`` scans only the rows near its reference vertex: the worst slack and the strict
    test must be the full scan's, exactly, along a path of vertices near and far."""
    rng = np.random.default_rng(seed)
    H = rng.normal(size=(m, n))
    H = np.ascontiguousarray(H / np.linalg.norm(H, axis=1)[:, None])
    z = rng.normal(size=n)
    slack = np.where(rng.random(m) < 0.3, rng.choice([0.0, 1e-13, -1e-13, -1e-9], size=m), 0.0)
    h = H @ z + slack + np.where(slack == 0.0, 10.0 ** rng.uniform(-9, 0, size=m), 0.0)
    ref = np.zeros(1 + m + n)
    vertices = np.empty((8, 2))
    GT, g0 = rng.normal(size=(n, 2)), np.zeros(2)
    count = 0
    for k in range(8):
        point = z + step * k * rng.normal(size=n) / np.sqrt(n)
        worst, full = np.zeros(1), _slacks(H, h, point)
        count, strict = K._record(H, h, GT, g0, point, worst, ref, vertices, count)
        assert worst[0] == min(0.0, float(np.min(full)))
        assert strict == bool(np.all(full >= -K._EPS_RECERT * np.maximum(1.0, np.abs(h))))
