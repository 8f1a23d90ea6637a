"""Governor.limits: N postures in one call answer what N calls of Governor.limit answer, and
what analyze() answers; bad batches are refused naming the field."""

from __future__ import annotations

import contextlib
import itertools
import math
from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import impact_balance as ib
import impact_balance.governor.batch as batch_module
from impact_balance.exceptions import GovernorError
from impact_balance.governor import Governor

SCENARIOS = ("kick_one_foot", "palm_push_two_feet", "g1_two_feet")
_GOVERNORS: dict[tuple[str, str], Governor] = {}


def governor(name: str, criterion: str = "com") -> Governor:
    """One governor per scenario and criterion for the module (construction loads the model)."""
    key = (name, criterion)
    if key not in _GOVERNORS:
        _GOVERNORS[key] = Governor(name, criterion=criterion)
    return _GOVERNORS[key]


def batch(g: Governor, n: int, seed: int, speed: float = 0.3) -> tuple[np.ndarray, np.ndarray]:
    """``n`` states near the scenario's posture: joints moved by up to 0.05 rad, the base by a few
    cm, generalized velocities of standard deviation ``speed`` (rad/s; base 1/3 of it, m/s)."""
    rng = np.random.default_rng(seed)
    model = g.robot.model
    qs = np.tile(g.configuration, (n, 1))
    for name in g.robot.joint_names:
        slot = g.robot.joint_slot(name)
        if slot.nq == 1:
            moved = qs[:, slot.idx_q] + rng.uniform(-0.05, 0.05, n)
            qs[:, slot.idx_q] = np.clip(moved, slot.lower, slot.upper)
    qs[:, :3] += rng.uniform(-0.03, 0.03, (n, 3))
    vs = rng.normal(0.0, speed, (n, model.nv))
    vs[:, :3] = rng.normal(0.0, speed / 3.0, (n, 3))
    return qs, vs


def assert_rows_equal(answers, singles, tol: float = 1e-12) -> None:
    assert len(answers) == len(singles)
    for i, one in enumerate(singles):
        row = answers[i]
        assert row.status == one.status, i
        assert row.limiting_vertex == one.limiting_vertex, i
        assert row.limiting_edge == one.limiting_edge, i
        if math.isfinite(one.max_contact_velocity):
            assert row.max_contact_velocity == pytest.approx(one.max_contact_velocity, abs=tol)
        else:
            assert row.max_contact_velocity == one.max_contact_velocity
        if one.safe_interval is None:
            assert row.safe_interval is None, i
        else:
            assert row.safe_interval is not None, i
            np.testing.assert_allclose(row.safe_interval, one.safe_interval, rtol=0, atol=tol)
        np.testing.assert_array_equal(row.com_velocity, one.com_velocity)
        np.testing.assert_array_equal(row.point, one.point)
        np.testing.assert_array_equal(row.normal, one.normal)
        assert not row.posture_reused


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    n=st.integers(1, 40),
    seed=st.integers(0, 2**32 - 1),
    speed=st.sampled_from([0.05, 0.3, 3.0]),
)
def test_batch_equals_single_ticks(name, n, seed, speed):
    g = governor(name)
    qs, vs = batch(g, n, seed, speed)
    answers = g.limits(qs, vs)
    singles = [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    assert_rows_equal(answers, singles)


def test_batch_covers_falling_starts_and_agrees_with_analyze():
    # Slow and fast CoM velocities: "ok" rows answered by the compiled call, "already_falling"
    # rows by the one-posture path (their safe interval is computed from the margins).
    g = governor("kick_one_foot")
    qs, vs = batch(g, 24, 7, 0.3)
    vs[::2] *= 20.0
    answers = g.limits(qs, vs)
    assert {"ok", "already_falling"} <= set(answers.status)
    for i in range(0, 24, 5):  # an independent computation: the whole pipeline
        analysis = ib.analyze(g.scenario_at(qs[i], answers.com_velocity[i]))
        want = analysis.impact.max_contact_velocity
        assert answers.max_contact_velocity[i] == pytest.approx(want, abs=1e-9)
        assert answers.status[i] == analysis.impact.com.status
        got, want_interval = answers[i].safe_interval, analysis.impact.safe_interval
        assert (got is None) == (want_interval is None)
        if got is not None:
            np.testing.assert_allclose(got, want_interval, rtol=1e-9, atol=1e-9)


def test_threads_answer_the_same():
    g = governor("palm_push_two_feet")
    qs, vs = batch(g, 70, 3)
    with chunks_of(8):
        one, two = g.limits(qs, vs), g.limits(qs, vs, threads=3)
    assert_batches_identical(two, one)


def chunks_of(size: int) -> contextlib.ExitStack:
    """Within: a batch's chunks have ``size`` postures of their own each (the last one fewer)."""
    stack = contextlib.ExitStack()
    stack.enter_context(mock.patch.object(batch_module, "CHUNK", size))
    stack.enter_context(mock.patch.object(batch_module, "MIN_CHUNK", size))
    return stack


def assert_batches_identical(got, want) -> None:
    """Two batches' answers equal to the last digit, every array and status."""
    assert got.criterion == want.criterion and got.status == want.status
    for key in (
        "max_contact_velocity",
        "limiting_vertex",
        "limiting_edge",
        "safe_interval",
        "com_velocity",
        "normal",
        "point",
    ):
        np.testing.assert_array_equal(getattr(got, key), getattr(want, key), err_msg=key)


@settings(max_examples=8, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    n=st.integers(1, 60),
    seed=st.integers(0, 2**32 - 1),
    chunk=st.integers(1, 40),
    threads=st.integers(2, 4),
    repeats=st.lists(st.integers(1, 3), min_size=60, max_size=60),
)
def test_answers_do_not_depend_on_the_threads(name, n, seed, chunk, threads, repeats):
    # The rows go in chunks of CHUNK postures of their own, handed to the threads as they ask,
    # each chunk's walks starting from a cold hint: one thread and several give the same
    # numbers to the last digit, whatever ran before. Independently: each chunk's rows as a
    # batch of their own on a fresh governor give those numbers too, and the single ticks agree.
    g = governor(name)
    qs, vs = path(g, n, seed)
    qs = np.repeat(qs, repeats[:n], axis=0)  # some rows repeat the posture before them
    vs = np.repeat(vs, repeats[:n], axis=0) * np.linspace(0.5, 1.5, len(qs))[:, None]
    with chunks_of(chunk):
        one = g.limits(qs, vs)
        many = g.limits(qs, vs, threads=threads)
        again = g.limits(qs, vs)  # after a batch on other threads, with other hints left
        starts = np.flatnonzero(np.r_[True, np.diff(np.repeat(np.arange(n), repeats[:n])) != 0])
        bounds = [*starts[::chunk].tolist(), len(qs)]
        fresh = Governor(name)
        alone = [fresh.limits(qs[a:b], vs[a:b]) for a, b in itertools.pairwise(bounds)]
    assert_batches_identical(many, one)
    assert_batches_identical(again, one)
    np.testing.assert_array_equal(
        np.concatenate([x.max_contact_velocity for x in alone]), one.max_contact_velocity
    )
    assert sum((x.status for x in alone), ()) == one.status
    for i in range(0, len(qs), max(1, len(qs) // 5)):
        assert_rows_agree([one[i]], [g.limit(qs[i], vs[i])])


@given(
    postures=st.integers(1, 3000),
    repeats=st.lists(st.integers(1, 4), min_size=1, max_size=3000),
)
def test_chunks_cut_the_postures_evenly(postures, repeats):
    # Chunks start at a posture of its own (a row that repeats the one before stays with it)
    # and hold the same number of postures but the last, at most CHUNK: CHUNKS chunks, or a
    # power of two fewer of at least MIN_CHUNK postures each when there are fewer postures.
    counts = (repeats * (postures // len(repeats) + 1))[:postures]
    repeated = np.ones(sum(counts), dtype=bool)
    starts = np.cumsum([0, *counts[:-1]])
    repeated[starts] = False
    bounds = batch_module._chunk_bounds(repeated)
    assert bounds[0] == 0 and bounds[-1] == len(repeated)
    assert not repeated[bounds[:-1]].any()
    sizes = [int(np.count_nonzero(~repeated[a:b])) for a, b in itertools.pairwise(bounds)]
    assert sum(sizes) == postures and len(set(sizes[:-1])) <= 1 and 0 < sizes[-1] <= sizes[0]
    chunk, least, most = batch_module.CHUNKS, batch_module.MIN_CHUNK, batch_module.CHUNK
    assert sizes[0] <= most
    if postures > chunk * most:
        assert sizes[0] == most
    else:
        assert len(sizes) in {chunk >> k for k in range(chunk.bit_length())}
        assert len(sizes) == 1 or sizes[0] >= least  # no chunk below MIN_CHUNK but the last
        assert len(sizes) == chunk or postures < 2 * len(sizes) * least  # no more could be made


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    bad=st.lists(st.integers(0, 39), min_size=1, max_size=4, unique=True),
    chunk=st.integers(1, 12),
    threads=st.integers(1, 3),
)
def test_the_first_refused_row_is_named_whatever_the_threads(bad, chunk, threads):
    # CoM speeds above the bound on rows ``bad``: the batch names the first of them, as one
    # thread taking the rows in order would, however many threads share the chunks.
    g = governor("kick_one_foot")
    qs, vs = batch(g, 40, 17)
    vs[bad] *= 1e6
    with chunks_of(chunk), pytest.raises(GovernorError) as info:
        g.limits(qs, vs, threads=threads)
    assert info.value.field == f"v_batch[{min(bad)}]"
    with pytest.raises(GovernorError):  # the single tick refuses that row too
        g.limit(qs[min(bad)], vs[min(bad)])


def test_zmp_criterion_batch_equals_single_ticks():
    g = governor("kick_one_foot", "zmp")
    qs, vs = batch(g, 6, 11)
    assert_rows_equal(g.limits(qs, vs), [g.limit(q, v) for q, v in zip(qs, vs, strict=True)])


def test_angular_momentum_batch_equals_single_ticks_and_counts_the_term():
    from impact_balance.scenario import load_scenario

    scenario = load_scenario("palm_push_two_feet")
    paper = governor("palm_push_two_feet")
    g = Governor(scenario.replace(angular_momentum_damping_time=0.1))
    qs, vs = batch(g, 8, 5)
    answers = g.limits(qs, vs)
    assert_rows_equal(answers, [g.limit(q, v) for q, v in zip(qs, vs, strict=True)])
    # the palm is above the CoM: counting the angular momentum lowers every answer
    assert np.all(answers.max_contact_velocity < paper.limits(qs, vs).max_contact_velocity)


def test_empty_batch():
    g = governor("kick_one_foot")
    answers = g.limits(np.zeros((0, g.nq)), np.zeros((0, g.nv)))
    assert len(answers) == 0 and answers.max_contact_velocity.shape == (0,)


def test_batch_leaves_the_tick_state_alone():
    g = Governor("kick_one_foot")
    before = g.posture
    qs, vs = batch(g, 3, 5)
    g.limits(qs, vs)
    assert g.last is None and g.posture is before


@pytest.mark.parametrize(
    ("q_rows", "v_rows", "threads", "field"),
    [
        ("flat", None, 1, "q_batch"),
        (None, "short", 1, "v_batch"),
        ("nan", None, 1, "q_batch[1][4]"),
        (None, "rows", 1, "v_batch"),
        ("joint", None, 1, "q_batch[2]"),
        ("text", None, 1, "q_batch"),
        (None, None, 0, "threads"),
        (None, None, 65, "threads"),
        (None, None, 1.5, "threads"),
        (None, "fast", 1, "v_batch[0]"),
    ],
)
def test_bad_batches_are_refused_naming_the_field(q_rows, v_rows, threads, field):
    g = governor("kick_one_foot")
    qs, vs = batch(g, 3, 1)
    if q_rows == "flat":
        qs = qs[0]
    elif q_rows == "nan":
        qs[1, 4] = np.nan
    elif q_rows == "joint":
        slot = g.robot.joint_slot(g.robot.joint_names[-1])
        qs[2, slot.idx_q] = slot.upper + 1.0
    elif q_rows == "text":
        qs = [["a"] * g.nq] * 3
    if v_rows == "short":
        vs = vs[:, :-1]
    elif v_rows == "rows":
        vs = vs[:2]
    elif v_rows == "fast":
        vs[0] *= 1e6
    with pytest.raises(GovernorError) as info:
        g.limits(qs, vs, threads=threads)
    assert info.value.field.startswith(field)
    assert field in str(info.value)


def test_contact_aware_governor_refuses_a_batch():
    g = Governor("kick_one_foot", contact_aware=True)
    qs, vs = batch(g, 2, 0)
    with pytest.raises(GovernorError, match="contact_aware"):
        g.limits(qs, vs)


@pytest.mark.parametrize("name", ["kick_one_foot", "g1_two_feet"])
def test_many_velocities_at_one_posture_reuse_it(name):
    # Rows that repeat the previous row's q are velocity-only ticks: the same answers as a
    # governor whose posture is reused, and far cheaper than evaluating the posture again.
    g = governor(name)
    qs, vs = batch(g, 3, 21, 1.0)
    qs = np.repeat(qs, [1, 40, 5], axis=0)
    vs = np.random.default_rng(4).normal(0.0, 1.0, (len(qs), g.nv))
    vs[:, :3] *= 0.3
    answers = g.limits(qs, vs)
    singles = [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    assert sum(s.posture_reused for s in singles) >= 42
    assert_rows_equal(answers, singles)
    # Chunks of one posture each (with its repeated rows) over four threads: the same.
    with chunks_of(1):
        assert_rows_equal(g.limits(qs, vs, threads=4), singles)


def test_a_posture_the_pipeline_refuses_names_its_row():
    # The CoM of row 1 below the LIPM plane: the ScenarioError limit() raises, with the row.
    g = governor("kick_one_foot")
    qs, vs = batch(g, 3, 9)
    qs[1, 2] -= 5.0  # the base (and the CoM) 5 m lower
    with pytest.raises(ib.ScenarioError, match=r"q_batch\[1\]: plane_height") as info:
        g.limits(qs, vs)
    assert info.value.field == "plane_height"
    with pytest.raises(ib.ScenarioError, match="plane_height"):
        g.limit(qs[1], vs[1])


def path(g: Governor, n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """``n`` states 2 ms apart along a smooth motion: every actuated joint follows
    ``0.05 (sin(pi t + phase) - sin(phase))`` rad from the scenario's posture (clipped to its
    limits), with its joint velocity; the base drifts forwards at 0.05 m/s. Consecutive rows
    differ a little: each row's projection can re-certify the previous row's bases."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 0.002
    qs = np.tile(g.configuration, (n, 1))
    vs = np.zeros((n, g.nv))
    for name in g.robot.joint_names:
        slot = g.robot.joint_slot(name)
        if slot.nq != 1:
            continue
        phase = rng.uniform(0.0, 2.0 * np.pi)
        raw = qs[0, slot.idx_q] + 0.05 * (np.sin(np.pi * t + phase) - np.sin(phase))
        qs[:, slot.idx_q] = np.clip(raw, slot.lower + 1e-6, slot.upper - 1e-6)
        vs[:, g.robot.model.joints[slot.id].idx_v] = 0.05 * np.pi * np.cos(np.pi * t + phase)
    qs[:, 0] += 0.05 * t
    vs[:, 0] = 0.05  # the base's forward speed (base frame: the scenarios stand upright)
    return qs, vs


def assert_rows_agree(answers, singles, tol: float = 1e-9) -> None:
    """Row for row, the same answer to ``tol`` m/s; the edge index only in kind (a walk from
    another warm start may list the same polygon from a neighbouring first vertex)."""
    assert len(answers) == len(singles)
    for i, one in enumerate(singles):
        row = answers[i]
        assert row.status == one.status, i
        assert row.limiting_vertex == one.limiting_vertex, i
        assert (row.limiting_edge is None) == (one.limiting_edge is None), i
        if math.isfinite(one.max_contact_velocity):
            assert row.max_contact_velocity == pytest.approx(one.max_contact_velocity, abs=tol)
        else:
            assert row.max_contact_velocity == one.max_contact_velocity
        assert (row.safe_interval is None) == (one.safe_interval is None), i
        if one.safe_interval is not None:
            np.testing.assert_allclose(row.safe_interval, one.safe_interval, rtol=0, atol=tol)
        np.testing.assert_array_equal(row.com_velocity, one.com_velocity)
        np.testing.assert_array_equal(row.point, one.point)


@settings(max_examples=6, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    name=st.sampled_from(SCENARIOS),
    n=st.integers(2, 40),
    seed=st.integers(0, 2**32 - 1),
    order=st.randoms(use_true_random=False),
)
def test_batch_rows_in_any_order_equal_single_ticks(name, n, seed, order):
    # In path order each row's projection starts from the previous row's chain of bases (the
    # batch's hint); shuffled, the chain mostly fails its check and the row walks. Either way
    # every row is the single tick's answer, and the same rows in both orders agree.
    g = governor(name)
    qs, vs = path(g, n, seed)
    singles = [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    in_order = g.limits(qs, vs)
    assert_rows_agree(in_order, singles)
    perm = list(range(n))
    order.shuffle(perm)
    shuffled = g.limits(qs[perm], vs[perm])
    assert_rows_agree(shuffled, [singles[i] for i in perm])
    # an independent computation for one row: the whole pipeline
    i = n // 2
    analysis = ib.analyze(g.scenario_at(qs[i], in_order.com_velocity[i]))
    want = analysis.impact.max_contact_velocity
    assert in_order.max_contact_velocity[i] == pytest.approx(want, abs=1e-9)


def test_the_rows_of_a_batch_share_the_walks_hint():
    # The batch's evaluator keeps one projection hint for its rows (a governor's ticks keep
    # theirs): after rows along a path it holds the last walk's start basis and chain of bases.
    g = Governor("palm_push_two_feet")
    qs, vs = path(g, 30, 2)
    g.limits(qs, vs)
    ((evaluator, _buffers),) = g._batch._evaluators
    hint = evaluator._hint
    m, n = int(hint[0]), int(hint[1])
    assert m > 0 and 0 < n < m
    assert np.all((hint[2 : n + 2] >= 0) & (hint[2 : n + 2] < m))
    assert hint[n + 2] > 0  # a chain: the next row re-certifies it before walking
    # the batch's hint is its own: the governor's ticks keep theirs
    assert evaluator is not g._evaluator


def _spoil(g: Governor, q: np.ndarray, fault: str, rng: np.random.Generator) -> None:
    """Make configuration ``q`` one that limit() refuses (in place)."""
    if fault == "nan":
        q[int(rng.integers(0, g.nq))] = np.nan
    elif fault == "joint":
        slot = g.robot.joint_slot(
            g.robot.joint_names[int(rng.integers(0, len(g.robot.joint_names)))]
        )
        if slot.nq == 1 and slot.lower < slot.upper:
            q[slot.idx_q] = slot.upper + float(rng.uniform(0.01, 1.0))
        else:
            q[3:7] *= 1.5  # the base quaternion instead
    elif fault == "quaternion":
        q[3:7] *= float(rng.choice([0.5, 1.1]))
    else:  # a base beyond any physical position
        q[int(rng.integers(0, 3))] = float(rng.choice([-1.0, 1.0])) * 1e200


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 2**32 - 1),
    bad=st.lists(st.integers(0, 7), min_size=0, max_size=3, unique=True),
    faults=st.lists(st.sampled_from(["nan", "joint", "quaternion", "far"]), min_size=3, max_size=3),
)
def test_rows_are_checked_as_limit_checks_them(seed, bad, faults):
    # Independent of the batch's one compiled pass: limit() on each row in turn, the first row
    # it refuses is the one the batch names, with the same reason (a number not finite is
    # named first, wherever it is, by its row and column).
    g = governor("kick_one_foot")
    qs, vs = batch(g, 8, seed % 1000)
    rng = np.random.default_rng(seed)
    for row, fault in zip(bad, faults, strict=False):
        _spoil(g, qs[row], fault, rng)
    if np.isnan(qs).any():
        i, j = (int(x) for x in np.argwhere(np.isnan(qs))[0])
        with pytest.raises(GovernorError, match="must be finite") as info:
            g.limits(qs, vs)
        assert info.value.field == f"q_batch[{i}][{j}]"
        return
    want = None
    for i, (q, v) in enumerate(zip(qs, vs, strict=True)):
        try:
            g.limit(q, v)
        except GovernorError as exc:
            want = (i, exc)
            break
    if want is None:
        assert len(g.limits(qs, vs)) == 8
        return
    with pytest.raises(GovernorError) as info:
        g.limits(qs, vs, threads=int(rng.integers(1, 3)))
    i, exc = want
    assert info.value.field == f"q_batch[{i}]" + exc.field[1:]
    assert info.value.reason == exc.reason


@pytest.mark.parametrize("threads", [1, 2])
def test_a_batchs_buffers_serve_the_next_batches(threads, monkeypatch):
    # The block buffers of each thread's evaluator are kept for the next batch: a small batch
    # after a larger one (its buffers holding the larger one's last block) answers as the
    # single ticks do, rows that repeat a posture included, and the buffers are the same arrays.
    g = Governor("palm_push_two_feet")
    qs, vs = batch(g, 45, 11)
    monkeypatch.setattr(batch_module, "CHUNK", 8)  # six chunks: every thread takes some
    monkeypatch.setattr(batch_module, "MIN_CHUNK", 8)
    assert_rows_equal(
        g.limits(qs, vs, threads=threads), [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    )
    kept = {id(b) for _, b in g._batch._evaluators}
    assert len(kept) == threads and None not in {b for _, b in g._batch._evaluators}
    small_q, small_v = batch(g, 4, 12)
    small_q = np.repeat(small_q, [1, 3, 1, 2], axis=0)
    small_v = np.random.default_rng(13).normal(0.0, 0.3, (len(small_q), g.nv))
    singles = [g.limit(q, v) for q, v in zip(small_q, small_v, strict=True)]
    assert_rows_equal(g.limits(small_q, small_v, threads=threads), singles)
    assert {id(b) for _, b in g._batch._evaluators} == kept


def test_the_threads_of_a_batch_serve_the_next_batches(monkeypatch):
    # threads > 1 runs on the calling thread and a pool of threads - 1 kept by the governor:
    # the next batch of as many threads or fewer takes the same pool, a batch of more threads a
    # larger one, a process forked after the pool was made (its copy has no threads) a new one;
    # the answers are the single ticks'.
    monkeypatch.setattr(batch_module, "CHUNK", 4)
    monkeypatch.setattr(batch_module, "MIN_CHUNK", 4)
    g = Governor("kick_one_foot")
    qs, vs = batch(g, 24, 21)
    singles = [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    assert_rows_equal(g.limits(qs, vs, threads=2), singles)
    pool, size, _ = g._batch._pool
    assert size == 1
    assert_rows_equal(g.limits(qs, vs, threads=2), singles)
    assert g._batch._pool[0] is pool
    assert_rows_equal(g.limits(qs, vs, threads=3), singles)
    larger, size, _ = g._batch._pool
    assert larger is not pool and size == 2
    assert_rows_equal(g.limits(qs, vs, threads=2), singles)
    assert g._batch._pool[0] is larger
    monkeypatch.setattr(batch_module.os, "getpid", lambda: -1)  # as in a forked child
    assert_rows_equal(g.limits(qs, vs, threads=2), singles)
    assert g._batch._pool[0] is not larger and g._batch._pool[1:] == (1, -1)


def test_a_refused_row_in_a_threads_chunk_leaves_the_governor_usable(monkeypatch):
    # A chunk's error is raised once every thread is done: the evaluators go back to the pool
    # and the next batch on the same threads answers.
    monkeypatch.setattr(batch_module, "CHUNK", 4)
    monkeypatch.setattr(batch_module, "MIN_CHUNK", 4)
    g = Governor("kick_one_foot")
    qs, vs = batch(g, 12, 22)
    bad = vs.copy()
    bad[9] *= 1e6  # a CoM speed above the bound, in the third chunk
    with pytest.raises(GovernorError, match=r"v_batch\[9\]"):
        g.limits(qs, bad, threads=2)
    assert len(g._batch._evaluators) == 2
    assert_rows_equal(
        g.limits(qs, vs, threads=2), [g.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    )
