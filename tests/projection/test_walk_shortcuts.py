"""The walk's two shortcuts for a governor's postures, each checked against the long way.

1. At a degenerate vertex (a contact's 16 faces at its zero wrench), the ratio test and the
   vertex's slack check scan only the rows listed near the vertex (``_ratio_test_near``,
   ``_min_slack_near``): they must give the full scan's numbers, not close ones.
2. A caller that projects postures in a row passes a ``hint`` (the last walk's optimal basis)
   instead of the crash start: the polygon must be the same, and a hint that does not fit
   (another size, a singular or infeasible basis, garbage) must be ignored.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.balance.areas import projected_from_arrays
from impact_balance.governor import Governor
from impact_balance.governor.posture import PostureEvaluator
from impact_balance.projection import kernel as K
from impact_balance.projection.walk import NO_HINT


def _degenerate(rng, n: int, extra: int, far: int):
    """Unit rows H, h with ``n + extra`` rows through the vertex z (slack 0, or 1e-13 off) and
    ``far`` rows with slacks from 1e-9 to 1."""
    z = rng.normal(size=n)
    near = rng.normal(size=(n + extra, n))
    other = rng.normal(size=(far, n))
    H = np.vstack([near, other])
    H /= np.linalg.norm(H, axis=1)[:, None]
    slack = np.concatenate(
        [rng.choice([0.0, 1e-13, -1e-13], size=n + extra), 10.0 ** rng.uniform(-9, 0, size=far)]
    )
    order = rng.permutation(len(H))
    H, slack = H[order], slack[order]
    return np.ascontiguousarray(H), H @ z + slack, z


def _full_scan(H, h, z, worst):
    """``_min_slack_near`` with nothing listed yet: the scan over every row."""
    dset = np.empty(len(H) + 1, dtype=np.int64)
    dset[0] = -1
    K._min_slack_near(H, h, z, worst, np.empty(H.shape[1]), dset)


@settings(max_examples=200, deadline=None)
@given(
    st.integers(min_value=2, max_value=9),
    st.integers(min_value=0, max_value=12),
    st.integers(min_value=1, max_value=60),
    st.integers(min_value=0, max_value=2**32 - 1),
)
def test_near_scans_give_the_full_scans_numbers(n, extra, far, seed):
    rng = np.random.default_rng(seed)
    H, h, z = _degenerate(rng, n, extra, far)
    m = len(H)
    zd = np.empty(n)
    dset = np.empty(m + 1, dtype=np.int64)
    dset[0] = -1
    listed, full = np.zeros(1), np.zeros(1)
    K._min_slack_near(H, h, z, listed, zd, dset)  # lists the rows near z
    _full_scan(H, h, z, full)
    assert listed[0] == full[0]
    assert n + extra <= dset[0] <= m  # the rows through z, and far ones within _D_SLACK
    # Within _D_MOVE of where the rows were listed (a zero step's rounding): the same numbers.
    moved = z + rng.normal(size=n) * (0.5 * K._D_MOVE / np.sqrt(n))
    listed[0] = full[0] = 0.0
    K._min_slack_near(H, h, moved, listed, zd, dset)
    _full_scan(H, h, moved, full)
    assert listed[0] == full[0]
    active = np.zeros(m, dtype=np.bool_)
    active[rng.permutation(m)[: rng.integers(0, n)]] = True
    for _ in range(5):
        p = rng.normal(size=n)
        p /= np.linalg.norm(p)
        near = K._ratio_test_near(H, h, moved, p, active, np.empty(m), np.empty(m), zd, dset)
        assert near == K._ratio_test(H, h, moved, p, active, np.empty(m), np.empty(m))


def test_a_vertex_that_moved_is_scanned_in_full():
    rng = np.random.default_rng(3)
    H, h, z = _degenerate(rng, 4, 3, 20)
    m = len(H)
    zd, dset = np.empty(4), np.empty(m + 1, dtype=np.int64)
    dset[0] = -1
    K._min_slack_near(H, h, z, np.zeros(1), zd, dset)
    listed = dset[0]
    moved = z + 1e-3  # past _D_MOVE: listed again, at the new point
    K._min_slack_near(H, h, moved, np.zeros(1), zd, dset)
    np.testing.assert_array_equal(zd, moved)
    assert dset[0] != listed or not np.array_equal(zd, z)


@pytest.fixture(scope="module")
def g1_path():
    """Postures of G1 along a small joint motion, and an evaluator's arrays at each."""
    governor = Governor("g1_two_feet")
    q0 = governor.configuration.copy()
    rng = np.random.default_rng(0)
    postures = []
    for k in range(12):
        q = q0.copy()
        q[7:] += 0.004 * k * rng.uniform(-1, 1, size=q0.size - 7)
        postures.append(q)
    return governor, postures


def _capture(governor: Governor, postures):
    """The arguments the evaluator hands projected_from_arrays at each posture."""
    import impact_balance.balance.areas as P  # the evaluator's posture_areas calls it

    captured = []
    original = P.projected_from_arrays

    def spy(*args):
        captured.append(args[:-1])  # without the hint
        return original(*args)

    P.projected_from_arrays = spy
    try:
        evaluator = PostureEvaluator(governor.robot, governor._evaluator.settings)
        for q in postures:
            evaluator.evaluate(q, steps=True)  # the steps call projected_from_arrays
    finally:
        P.projected_from_arrays = original
    return captured


def test_a_warm_started_walk_gives_the_cold_walks_polygon(g1_path):
    governor, postures = g1_path
    hint = np.full(2 + 12, -1, dtype=np.int64)
    warm_pivots = cold_pivots = 0
    for args in _capture(governor, postures):
        cold = projected_from_arrays(*args)
        warm = projected_from_arrays(*args, hint)
        assert (
            hint[0] > 0 and hint[1] == 8
        )  # written: G1's 60 rows, 12 wrench variables less 4 equalities
        a, b = cold.com_velocity_area, warm.com_velocity_area
        assert a.vertices.shape == b.vertices.shape
        np.testing.assert_allclose(b.vertices, a.vertices, rtol=0, atol=1e-12)
        assert b.area == pytest.approx(a.area, rel=1e-12)
        cold_pivots += cold.n_lp
        warm_pivots += warm.n_lp
    assert warm_pivots == cold_pivots  # one walk each: no fallback to Bretl


@pytest.mark.parametrize("bad", ["size", "rows", "singular", "infeasible", "range"])
def test_a_hint_that_does_not_fit_changes_nothing(g1_path, bad):
    governor, postures = g1_path
    args = _capture(governor, postures[:1])[0]
    cold = projected_from_arrays(*args)
    hint = np.full(2 + 12, -1, dtype=np.int64)
    projected_from_arrays(*args, hint)
    m, n = int(hint[0]), int(hint[1])
    if bad == "size":
        hint = hint[: n + 1].copy()  # too short: neither read nor written
    elif bad == "rows":
        hint[0] = m + 1
    elif bad == "singular":
        hint[3] = hint[2]  # the same row twice
    elif bad == "infeasible":
        hint[2 : n + 2] = np.arange(
            m - n, m
        )  # the last rows: the box's, not a vertex of this polytope
    else:
        hint[2] = m + 5
    before = hint.copy()
    warm = projected_from_arrays(*args, hint)
    np.testing.assert_allclose(
        warm.com_velocity_area.vertices, cold.com_velocity_area.vertices, rtol=0, atol=1e-12
    )
    if bad == "size":
        np.testing.assert_array_equal(hint, before)
    else:
        assert hint[0] == m and hint[1] == n and len(set(hint[2 : n + 2].tolist())) == n


def test_warm_start_takes_a_feasible_vertex_basis_only():
    """The unit square |z_i| <= 1 cut by z_0 + z_1 <= 1.5: the corner (1, 1) is a vertex of
    the arrangement but outside; (1, 0.5) is a vertex of the polytope."""
    H = np.array([[1.0, 0], [0, 1], [-1, 0], [0, -1], [1, 1]])
    H /= np.linalg.norm(H, axis=1)[:, None]
    h = np.array([1.0, 1, 1, 1, 1.5]) / np.array([1, 1, 1, 1, np.sqrt(2)])
    m, n = H.shape
    for rows, feasible, vertex in (
        ([0, 1], False, None),
        ([0, 4], True, (1.0, 0.5)),
        ([0, 0], False, None),
        ([0, 2], False, None),
    ):
        W, Binv, z = np.zeros(n, dtype=np.int64), np.empty((n, n)), np.zeros(n)
        active = np.zeros(m, dtype=np.bool_)
        hint = np.array([m, n, *rows], dtype=np.int64)
        assert K._warm_start(H, h, W, Binv, z, active, K._workspace(m, n), hint) == feasible
        if feasible:
            np.testing.assert_allclose(z, vertex, atol=1e-15)
            assert sorted(np.flatnonzero(active)) == sorted(rows)
        else:
            assert not active.any() and not z.any()  # the crash starts from 0 as before


@pytest.mark.parametrize("hint", [[-1] * 14, np.zeros(14), np.zeros((2, 7), dtype=np.int64)])
def test_a_hint_of_the_wrong_kind_is_a_clear_error(g1_path, hint):
    governor, postures = g1_path
    args = _capture(governor, postures[:1])[0]
    with pytest.raises(ValueError, match="hint must be a writable 1-D int64 numpy array"):
        projected_from_arrays(*args, hint)


def test_one_off_projections_take_no_hint():
    assert NO_HINT.size == 0


def test_the_governor_loads_its_criterion_code_before_the_first_tick():
    """numba loads a cached function on its first call (1-3 ms): the governor's constructor
    makes that call, so the first tick is not the one that pays it."""
    from impact_balance.criteria import com as criteria

    Governor("palm_push_two_feet")
    assert criteria._com_exit.signatures and criteria._com_exits.signatures


# A G1 posture of the wall study (reference 0.8 m/s, wall 17 cm, 1.9 s in) where the walk's
# simplex cycles through 4 vertices with real steps (0.1 to 0.25) whose multipliers are within
# the tolerance of zero: Bland's rule does not break it either, and the caller falls back to
# Bretl. The walk used to run to its 5000-pivot cap first (3.3 ms of a 6 ms tick, 20 ms with
# the first load of the fallback's compiled map).
G1_CYCLE = [
    -0.03219221031075935,
    -0.004988224506426797,
    0.7698711775785513,
    0.0013834443295910157,
    0.01027549787989299,
    0.012435679150228888,
    0.9998689184634059,
    -0.2694202835015543,
    -0.006333308441799225,
    -0.024354110123499396,
    0.52116030619674,
    -0.272377902516348,
    -0.007266514362196788,
    -0.2641335708155025,
    -0.007784604361771792,
    -0.02374101418517601,
    0.5300341586963578,
    -0.28650134785021475,
    -0.005560567783511484,
    -0.2635033715723783,
    -0.08635030486376054,
    -0.09659816984866619,
    0.12161047449464814,
    -0.02941163338840707,
    -0.013962263719116203,
    0.029412333747104773,
    1.1121955155513435e-06,
    0.005638440126555487,
    -0.0011339678455517892,
    -0.2509309006211736,
    -0.2224619002108893,
    0.483773200814152,
    0.09100599239609793,
    -1.155579025762308,
    0.28504224799064953,
    -1.5247268177348186,
]


def test_a_cycling_walk_gives_up_early_and_the_answer_is_bretls():
    import impact_balance.balance.areas as areas
    from impact_balance import analyze
    from impact_balance.balance.areas import FORCE_BOX, MERGE_TOLERANCE
    from impact_balance.projection.walk import MAX_PIVOTS, MERGE_AREA_TOLERANCE, certified_walk

    governor = Governor("g1_two_feet")
    q = np.array(G1_CYCLE)
    refused = []
    original = areas._projected

    def spy(walked, data, *rest):
        if walked[0] != K.OK:
            refused.append(data)
        return original(walked, data, *rest)

    areas._projected = spy
    try:
        answer = governor.limit(q, np.zeros(governor.nv))
    finally:
        areas._projected = original
    assert len(refused) == 1  # this posture's walk is refused (and no other projection's)
    A, b, C, d, E = refused[0]
    status, _, _, pivots, _, N = certified_walk(
        A, b, C, d, E, FORCE_BOX, MAX_PIVOTS, MERGE_TOLERANCE, MERGE_AREA_TOLERANCE, NO_HINT
    )
    assert status == K.FAILED
    n, m = N.shape[1], A.shape[0] + 4  # the rows of A (some dropped as zero) and the box's 4
    assert pivots <= 5 * (n + m) < MAX_PIVOTS
    # The fallback's answer is analyze()'s for the same state (which falls back the same way).
    reference = analyze(governor.scenario_at(q, answer.com_velocity))
    assert answer.max_contact_velocity == pytest.approx(
        reference.impact.max_contact_velocity, abs=1e-9
    )
