"""A governor's answers for many postures in one call: :class:`BatchLimits`.

:meth:`Governor.limits <impact_balance.governor.Governor.limits>` answers N configurations
and N generalized velocities (a planner's candidate postures, a sweep's grid), as N calls of
:meth:`~impact_balance.governor.Governor.limit` would, to rounding. Per posture the Python
side runs pinocchio (:meth:`PostureEvaluator.kinematics
<impact_balance.governor.posture.PostureEvaluator.kinematics>`, the one-posture path's own
step); the areas, the impact model and the criterion of every posture then run in one compiled
call (:func:`~impact_balance.governor.posture_kernel.postures_kernel`: a tick's
:func:`~impact_balance.governor.posture_kernel.posture_kernel` per posture, the same numbers),
which releases the GIL, so ``threads`` > 1 evaluates postures side by side. The rows go in
chunks of up to :data:`CHUNK` postures of their own (:data:`CHUNKS` chunks, or fewer of at least
:data:`MIN_CHUNK`; with the rows that repeat them), handed to the threads in order as each asks
for the next. The rows of a chunk share one projection hint, as a governor's successive ticks
do: a row's walk first re-certifies the previous row's chain of
bases, so rows in path order (nearby postures one after the other) cost less than the same rows
shuffled; each chunk starts from a cold hint, whatever thread runs it and whatever ran before,
so the answers do not depend on the number of threads or on the schedule, to the last digit
(they equal the single ticks' to rounding, in any order). A batch that meets errors raises the
first chunk's, the error one thread raises. A posture the compiled call does not answer (a
projection Bretl's method answers, an area of fewer than 3 vertices, an impact model it
refuses), the "zmp" criterion, the joint-space inertia model, contact frictions above 1 and the
angular momentum option (``angular_momentum_damping_time``) take the one-posture path
(:meth:`PostureEvaluator.evaluate <impact_balance.governor.posture.PostureEvaluator.evaluate>`).
"""

from __future__ import annotations

import itertools
import math
import os
import threading
from collections.abc import Callable, Sequence
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
from numpy.typing import ArrayLike

from impact_balance.balance.lipm import lipm_omega
from impact_balance.constants import MAX_SPEED
from impact_balance.criteria.linear_exit import BOUNDARY_TOLERANCE, EXIT_STATUSES
from impact_balance.criteria.velocity_limit import LimitStatus
from impact_balance.exceptions import GovernorError, ImpactBalanceError, SolverError
from impact_balance.governor.limit import SpeedLimit
from impact_balance.governor.options import Criterion
from impact_balance.governor.posture import PostureEvaluator
from impact_balance.governor.posture_kernel import postures_kernel
from impact_balance.governor.tick import com_velocity
from impact_balance.governor.tree_kernel import KinematicTree, tree_postures
from impact_balance.projection.walk import MAX_PIVOTS
from impact_balance.robot.robot import Robot

__all__ = ["BLOCK", "CHUNK", "CHUNKS", "MIN_CHUNK", "BatchEvaluator", "BatchLimits"]

#: Postures per compiled call: the Python step of the next block runs while another thread's
#: compiled call runs.
BLOCK = 64
#: The most postures of their own per chunk (with the rows that repeat them): the unit a thread
#: takes, in blocks of :data:`BLOCK`, whose walks start from a cold projection hint (whatever
#: thread runs it and whatever ran before), so a batch's answers do not depend on its threads.
CHUNK = 64
#: The fewest postures per chunk (but the last): a chunk's cold start costs about one row.
MIN_CHUNK = 16
#: The chunks a batch of P postures is cut into, of ``ceil(P / CHUNKS)`` postures each; half
#: as many (down to one) while they would have fewer than :data:`MIN_CHUNK`, more while they
#: would have more than :data:`CHUNK`. A function of P only, not of the threads.
CHUNKS = 16
#: The statuses by the compiled exit's codes (an index of ``EXIT_STATUSES``).
_STATUSES = np.array(EXIT_STATUSES, dtype=object)
#: The most threads a batch takes.
MAX_THREADS = 64


@dataclass(frozen=True)
class BatchLimits:
    """The governor's answers for N postures, row i for ``(q_batch[i], v_batch[i])``.

    Frames and units as :class:`~impact_balance.governor.limit.SpeedLimit`'s (world axes, m/s).

    Attributes:
        criterion: "com" or "zmp".
        max_contact_velocity: (N,) m/s (inf: no approach speed is unsafe).
        status: N statuses ("ok", "unbounded", "already_falling", "cannot_balance").
        limiting_vertex: (N,) int, -1 where :class:`SpeedLimit`'s is None.
        limiting_edge: (N,) int, -1 where :class:`SpeedLimit`'s is None.
        safe_interval: (N, 2) the safe approach speeds ``(lo, hi)``, m/s; NaN rows where there
            are none.
        com_velocity: (N, 3) the CoM velocities, world, m/s.
        normal: (N, 3) the impact surface's unit normal, world.
        point: (N, 3) the impact point, world, m.
    """

    criterion: Criterion
    max_contact_velocity: npt.NDArray[np.float64]
    status: tuple[LimitStatus, ...]
    limiting_vertex: npt.NDArray[np.int64]
    limiting_edge: npt.NDArray[np.int64]
    safe_interval: npt.NDArray[np.float64]
    com_velocity: npt.NDArray[np.float64]
    normal: npt.NDArray[np.float64]
    point: npt.NDArray[np.float64]

    def __len__(self) -> int:
        """N."""
        return len(self.status)

    def __getitem__(self, i: int) -> SpeedLimit:
        """Row ``i`` as the :class:`SpeedLimit` :meth:`Governor.limit` answers for it."""
        lo, hi = (float(x) for x in self.safe_interval[i])
        vertex, edge = int(self.limiting_vertex[i]), int(self.limiting_edge[i])
        return SpeedLimit(
            self.criterion,
            float(self.max_contact_velocity[i]),
            self.status[i],
            None if vertex < 0 else vertex,
            None if edge < 0 else edge,
            None if math.isnan(lo) else (lo, hi),
            self.com_velocity[i].copy(),
            self.normal[i].copy(),
            self.point[i].copy(),
            False,
        )


class _Rows:
    """The batch's output arrays, filled row by row (each thread writes its own rows)."""

    def __init__(self, n: int) -> None:
        self.speed = np.zeros(n)
        self.status: list[LimitStatus] = ["ok"] * n
        self.vertex = np.full(n, -1, dtype=np.int64)
        self.edge = np.full(n, -1, dtype=np.int64)
        self.interval = np.full((n, 2), np.nan)
        self.com_velocity = np.zeros((n, 3))
        self.normal = np.zeros((n, 3))
        self.point = np.zeros((n, 3))

    def answer(self, criterion: Criterion) -> BatchLimits:
        return BatchLimits(
            criterion,
            self.speed,
            tuple(self.status),
            self.vertex,
            self.edge,
            self.interval,
            self.com_velocity,
            self.normal,
            self.point,
        )


class _Buffers:
    """One thread's per-posture arrays of a block (:data:`BLOCK` postures), reused block by block.

    The compiled call's per-posture arguments (see
    :func:`~impact_balance.governor.posture_kernel.postures_kernel`): row p is the block's p-th
    posture of its own; rows past the block's postures are not read.
    """

    def __init__(self, e: PostureEvaluator) -> None:
        m, nv, s = len(e._frames), e.model.nv, e.settings
        self.rotations, self.local = np.zeros((BLOCK, m, 3, 3)), np.zeros((BLOCK, m, 3))
        self.jacobians = np.zeros((BLOCK, 6 * m, nv)) if e._torques else np.zeros((BLOCK, 0, 0))
        self.origins, self.com_locals = np.zeros((BLOCK, 3)), np.zeros((BLOCK, 3))
        self.point_locals, self.inertias = np.zeros((BLOCK, 3)), np.zeros((BLOCK, 3, 3))
        self.centroidal = np.zeros((BLOCK, 6, nv))
        # mass, then (row 0) g, h, omega, velocity margin, boundary tolerance
        self.scalars = np.zeros((BLOCK, 6))
        self.scalars[0, 1:3] = s.gravity, s.plane_height
        self.scalars[0, 4:6] = s.velocity_margin, BOUNDARY_TOLERANCE
        # The tree's kinematics of a block (tree_postures), when the model's joints allow it.
        tree = KinematicTree.of(e.model, [*e._frames, e._impact_frame])
        self.tree = tree if tree.supported else None
        self.no_jacobians = np.zeros((0, 3, nv))  # the impact point's: not read by the batch


class BatchEvaluator:
    """Evaluates postures in batches, with one :class:`PostureEvaluator` per thread.

    Args:
        robot: The governor's robot. evaluator: Its posture evaluator (its settings are used;
            it is not called).
        check: The governor's per-configuration check: ``check(q, field)`` returns the
            configuration as a contiguous float vector or raises
            :class:`~impact_balance.exceptions.GovernorError`.
        first_fault: The same check over rows: ``first_fault(qs)`` ((N, nq) C-contiguous
            floats) is the first row ``check`` refuses, -1 if none (``check`` then names it).
    """

    def __init__(
        self,
        robot: Robot,
        evaluator: PostureEvaluator,
        check: Callable[[npt.NDArray[np.float64], str], npt.NDArray[np.float64]],
        first_fault: Callable[[npt.NDArray[np.float64]], int],
    ) -> None:
        self.robot, self.settings, self.check = robot, evaluator.settings, check
        self.first_fault = first_fault
        # Each evaluator with its block buffers (None where the compiled call does not answer),
        # made on first use and kept for the next batches.
        self._evaluators: list[tuple[PostureEvaluator, _Buffers | None]] = []
        self._lock = threading.Lock()
        # The threads of threads > 1, kept for the next batches (starting threads costs about as
        # much as 10 to 50 rows): the pool, its size and the process that made it.
        self._pool: tuple[ThreadPoolExecutor, int, int] | None = None

    def limits(self, q_batch: ArrayLike, v_batch: ArrayLike, threads: int = 1) -> BatchLimits:
        """See :meth:`impact_balance.governor.Governor.limits`."""
        model = self.robot.model
        qs = _matrix(q_batch, model.nq, "q_batch")
        vs = _matrix(v_batch, model.nv, "v_batch")
        if len(vs) != len(qs):
            raise GovernorError(
                "v_batch", f"{len(vs)} rows", f"must have as many rows as q_batch ({len(qs)})"
            )
        if isinstance(threads, bool) or not isinstance(threads, int | np.integer):
            raise GovernorError("threads", threads, "must be an integer")
        if not 1 <= threads <= MAX_THREADS:
            raise GovernorError("threads", threads, f"must be in [1, {MAX_THREADS}]")
        repeated = np.zeros(len(qs), dtype=np.bool_)  # row i's q is row i - 1's
        repeated[1:] = (qs[1:] == qs[:-1]).all(axis=1)
        start = 0  # every row in one compiled pass; a row at fault is named by the check
        while (k := self.first_fault(qs[start:])) >= 0:
            i = start + k
            qs[i] = self.check(qs[i], f"q_batch[{i}]")
            start = i + 1
        rows = _Rows(len(qs))
        chunks = _Chunks(_chunk_bounds(repeated))
        workers = min(threads, chunks.count)
        evaluators = self._take(workers)
        try:
            if workers == 1:
                _Worker(*evaluators[0], qs, vs, rows).run(chunks, repeated)
            elif workers > 1:
                pool = self._executor(workers - 1)
                futures = [
                    pool.submit(_Worker(*e, qs, vs, rows).run, chunks, repeated)
                    for e in evaluators[1:]
                ]
                try:  # the calling thread takes chunks too
                    _Worker(*evaluators[0], qs, vs, rows).run(chunks, repeated)
                except BaseException:  # e.g. KeyboardInterrupt: the workers take no more chunks
                    chunks.stop()
                    raise
                finally:  # every chunk done before the evaluators go back or an error is raised
                    wait(futures)
                for future in futures:
                    future.result()  # a worker's own fault (its chunks' errors are in chunks)
            chunks.raise_first()
        finally:
            with self._lock:
                self._evaluators.extend(evaluators)
        return rows.answer(self.settings.criterion)

    def _executor(self, n: int) -> ThreadPoolExecutor:
        """A pool of at least ``n`` threads, kept for the next batches.

        Made again for more threads than it has (the previous pool is dropped, not shut down:
        a batch running on it finishes there, and its threads end with it), and in a process
        forked after it was made (whose copy has no threads).
        """
        with self._lock:
            pid = os.getpid()
            if self._pool is not None and self._pool[1] >= n and self._pool[2] == pid:
                return self._pool[0]
            pool = ThreadPoolExecutor(n, thread_name_prefix="impact-balance-batch")
            self._pool = (pool, n, pid)
            return pool

    def _take(self, n: int) -> list[tuple[PostureEvaluator, _Buffers | None]]:
        """``n`` evaluators of this batch's own, with their buffers (made on first use).

        Not shared while taken.
        """
        with self._lock:
            taken, self._evaluators = self._evaluators[:n], self._evaluators[n:]
        for _ in range(n - len(taken)):
            e = PostureEvaluator(self.robot, self.settings)
            taken.append((e, _Buffers(e) if e._compiled else None))
        return taken


def _chunk_bounds(repeated: npt.NDArray[np.bool_]) -> list[int]:
    """The rows' chunks, as bounds: chunk c is rows ``bounds[c]`` to ``bounds[c + 1]``.

    Of P postures of their own (``repeated[i]``: row i's q is row i - 1's; ``repeated[0]`` is
    false), each chunk has ``ceil(P / c)`` (the last one fewer, at most :data:`CHUNK`), with the
    rows that repeat them: c is :data:`CHUNKS`, halved while ``P < c * MIN_CHUNK`` and c > 1
    (an even count of equal chunks shares out evenly).
    """
    starts = np.flatnonzero(~repeated)
    count = CHUNKS
    while count > 1 and len(starts) < count * MIN_CHUNK:
        count //= 2
    size = max(1, min(CHUNK, -(-len(starts) // count)))
    return [*starts[::size].tolist(), len(repeated)]


class _Chunks:
    """A batch's chunks, handed to its threads in order as they ask (thread-safe).

    A thread that meets an error in a chunk records it (:meth:`fail`) and takes no more; the
    other threads finish the chunks they hold and take no more. :meth:`raise_first` then raises
    the error of the first chunk that had one: the error a one-thread batch raises.
    """

    def __init__(self, bounds: list[int]) -> None:
        self.bounds, self.count = bounds, len(bounds) - 1
        self._next, self._stopped = 0, False
        self._errors: dict[int, BaseException] = {}
        self._lock = threading.Lock()

    def take(self) -> int | None:
        """The next chunk's index, None when none is left (or the batch stopped)."""
        with self._lock:
            if self._stopped or self._next >= self.count:
                return None
            self._next += 1
            return self._next - 1

    def fail(self, chunk: int, error: BaseException) -> None:
        """Record chunk ``chunk``'s error; no chunk is handed out after it."""
        with self._lock:
            self._errors[chunk] = error
            self._stopped = True

    def stop(self) -> None:
        """Hand out no more chunks."""
        with self._lock:
            self._stopped = True

    def raise_first(self) -> None:
        """Raise the error of the first chunk that had one (none: return)."""
        if self._errors:
            raise self._errors[min(self._errors)]


class _Worker:
    """One thread of a batch: the chunks it takes, their Python step and compiled calls."""

    def __init__(
        self,
        evaluator: PostureEvaluator,
        buffers: _Buffers | None,
        qs: npt.NDArray[np.float64],
        vs: npt.NDArray[np.float64],
        rows: _Rows,
    ) -> None:
        self.e, self.qs, self.vs, self.rows = evaluator, qs, vs, rows
        # The compiled call answers the posture kernel's case (the paper's "com" criterion, the
        # composite inertia, unscaled contacts); every other row takes limit()'s path.
        self.compiled = evaluator._compiled
        if self.compiled:
            assert buffers is not None  # made with the evaluator (BatchEvaluator._take)
            self.buffers = buffers

    def run(self, chunks: _Chunks, repeated: npt.NDArray[np.bool_]) -> None:
        """Answer the chunks this thread takes, until none is left.

        ``repeated``: as :func:`_chunk_bounds`'s. Each chunk's walks start from a cold projection
        hint, then carry it from row to row. An error is recorded with its chunk
        (:meth:`_Chunks.fail`), not raised.
        """
        hint = self.e._hint
        while (c := chunks.take()) is not None:
            a, b = chunks.bounds[c], chunks.bounds[c + 1]
            hint.fill(-1)
            try:
                if not self.compiled:
                    for i in range(a, b):
                        self.single(i)
                    continue
                # Blocks of BLOCK postures of their own, each with the rows that repeat them.
                starts = (a + np.flatnonzero(~repeated[a:b])).tolist()
                for lo, hi in itertools.pairwise([*starts[::BLOCK], b]):
                    self.block(lo, hi, repeated[lo:hi])
            except Exception as exc:  # raised by the batch once every thread is done
                chunks.fail(c, exc)
                return

    def block(self, start: int, stop: int, same: npt.NDArray[np.bool_]) -> None:
        """The kinematics of rows ``start`` to ``stop``, then their compiled call and answers.

        ``same[r]``: row ``start + r`` repeats the posture of the row before it (only its
        velocity is new); ``same[0]`` is false. At most :data:`BLOCK` rows have a posture of
        their own.
        """
        e, n, rows, b = self.e, stop - start, self.rows, self.buffers  # the kernel writes rows
        rotations, local, jacobians, scalars = b.rotations, b.local, b.jacobians, b.scalars
        own = start + np.flatnonzero(~same)  # the rows of a posture of their own
        if b.tree is not None:
            self.tree_kinematics(own)
        else:
            for p, i in enumerate(own.tolist()):
                origin, com_local, mass, inertia, Ag = e._placements(
                    self.qs[i], rotations[p], local[p], jacobians[p]
                )
                b.origins[p], b.com_locals[p], b.centroidal[p], b.inertias[p] = (
                    origin,
                    com_local,
                    Ag,
                    inertia,
                )
                b.point_locals[p] = e.impact_point()
                scalars[p, 0] = mass
                scalars[p, 3] = self.omega(float(com_local[2]) + float(origin[2]), i)
        codes, velocities = np.empty(n, dtype=np.int64), rows.com_velocity[start:stop]
        too_fast = postures_kernel(
            e._faces, rotations, local, b.origins, b.com_locals, b.centroidal, e._gravity,
            e._torques, jacobians, e._idx, e._limit, scalars, e._hint, MAX_PIVOTS, e._constants,
            b.point_locals, b.inertias, e._normal, e._cone, self.vs[start:stop], same, codes,
            rows.speed[start:stop], rows.vertex[start:stop], rows.edge[start:stop],
            rows.interval[start:stop], velocities, rows.point[start:stop], MAX_SPEED * MAX_SPEED,
        )  # fmt: skip
        if too_fast >= 0:
            _too_fast(velocities[too_fast], start + too_fast)
        rows.normal[start:stop] = e._normal
        rows.status[start:stop] = _STATUSES[codes].tolist()  # code -1: overwritten below
        for r in np.flatnonzero(codes < 0).tolist():
            # Bretl's projection, a small area, a refused impact model
            self.single(start + r)

    def tree_kinematics(self, rows: npt.NDArray[np.int64]) -> None:
        """The kinematics of batch rows ``rows`` into the block's buffers, in one compiled call.

        :func:`~impact_balance.governor.tree_kernel.tree_postures` (the GIL released), for the
        block's postures of their own, in order.
        """
        e, b, s = self.e, self.buffers, self.e.settings
        t = b.tree
        assert t is not None
        low = tree_postures(
            t.parents, t.kinds, t.idx_q, t.idx_v, t.placements, t.masses, t.levers, t.inertias,
            t.frame_joints, t.frame_placements, self.qs[rows], e._free_flyer, e._torques,
            float(s.plane_height), float(s.gravity), b.rotations, b.local, b.jacobians,
            b.origins, b.com_locals, b.centroidal, b.point_locals, b.no_jacobians, b.inertias,
            b.scalars,
        )  # fmt: skip
        if low >= 0:  # the CoM not above the plane: the check names the row
            self.omega(float(b.com_locals[low, 2]) + float(b.origins[low, 2]), int(rows[low]))

    def omega(self, com_height: float, i: int) -> float:
        """The LIPM's omega (1/s) of row ``i`` at its CoM height (m).

        Raises:
            ScenarioError: The plane is not below the CoM (naming the row, as ``limit``).
        """
        s = self.e.settings
        try:
            return lipm_omega(com_height, s.plane_height, s.gravity, field="plane_height")
        except ImpactBalanceError as exc:
            raise _in_row(exc, i) from None

    def single(self, i: int) -> None:
        """Row ``i`` by the one-posture path (what :meth:`Governor.limit` does)."""
        rows = self.rows
        try:
            posture = self.e.evaluate(self.qs[i])
        except SolverError as exc:
            raise exc.within(f"q_batch[{i}]") from None
        except ImpactBalanceError as exc:  # as limit() raises it, naming the row
            raise _in_row(exc, i) from None
        com_velocity = _com_velocity(posture.com_jacobian, self.vs[i], i)
        criterion = posture.com_criterion
        interval: tuple[float, float] | None
        if criterion is not None:
            limit = criterion.limit(com_velocity)
            interval = criterion.interval(com_velocity, limit)
        else:
            assert posture.zmp_limit is not None  # the "zmp" criterion's posture has it
            limit = posture.zmp_limit
            interval = (0.0, limit.max_contact_velocity) if limit.from_inside else None
        rows.speed[i], rows.status[i] = limit.max_contact_velocity, limit.status
        rows.vertex[i] = -1 if limit.limiting_vertex is None else limit.limiting_vertex
        rows.edge[i] = -1 if limit.limiting_edge is None else limit.limiting_edge
        rows.interval[i] = (math.nan, math.nan) if interval is None else interval
        rows.com_velocity[i] = com_velocity
        rows.normal[i], rows.point[i] = posture.impact.normal, posture.impact.point


def _com_velocity(
    com_jacobian: npt.NDArray[np.float64], v: npt.NDArray[np.float64], i: int
) -> npt.NDArray[np.float64]:
    """``com_jacobian @ v`` (row ``i``), checked as :meth:`Governor.limit` checks it (m/s).

    The single tick's product (:func:`~impact_balance.governor.tick.com_velocity`).
    """
    out = np.empty(3)
    com_velocity(com_jacobian, v, out)
    cx, cy, cz = (float(x) for x in out)
    if not cx * cx + cy * cy + cz * cz <= MAX_SPEED * MAX_SPEED:
        _too_fast(out, i)
    return out


def _too_fast(com_velocity: npt.NDArray[np.float64], i: int) -> None:
    """:class:`GovernorError` naming row ``i``, whose CoM velocity (m/s) is above the bound."""
    raise GovernorError(
        f"v_batch[{i}]",
        f"CoM velocity {math.hypot(*com_velocity):.3g} m/s",
        f"gives a CoM speed above {MAX_SPEED:g} m/s (the scenario's bound)",
    )


def _in_row(exc: ImpactBalanceError, i: int) -> ImpactBalanceError:
    """``exc`` with its message prefixed by the row it is about (``q_batch[i]: ...``)."""
    if exc.args and isinstance(exc.args[0], str):
        exc.args = (f"q_batch[{i}]: {exc.args[0]}", *exc.args[1:])
    return exc


def _matrix(x: ArrayLike, size: int, field: str) -> npt.NDArray[np.float64]:
    """``x`` as a (N, size) C-contiguous float array of finite real numbers (a copy)."""
    try:
        raw = np.asarray(x)
        if raw.dtype.kind not in "iuf":
            raise TypeError(raw.dtype)
        a = np.array(raw, dtype=float, order="C")
    except (TypeError, ValueError):
        raise GovernorError(field, _shown(x), f"must be rows of {size} real numbers") from None
    if a.ndim != 2 or a.shape[1] != size:
        raise GovernorError(field, f"shape {a.shape}", f"must be (N, {size})")
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        i, j = (int(x) for x in bad[0])
        raise GovernorError(f"{field}[{i}][{j}]", float(a[i, j]), "must be finite")
    return a


def _shown(x: object) -> object:
    """``x`` for an error message (a sequence is shown by its type and length)."""
    return f"{type(x).__name__} of {len(x)}" if isinstance(x, Sequence) else x
