"""Run a sweep: chunks on this process, on local worker processes, or on a Dask cluster.

Three backends, one loop:

- ``workers=1``: the chunks run in this process (no start-up cost).
- ``workers=N`` (default: every core this process may use): a
  :class:`concurrent.futures.ProcessPoolExecutor` with the ``forkserver`` start method (``spawn``
  where there is none; never a fork of this process, which holds threads and solver state);
  each worker builds one
  :class:`~impact_balance.sweep.evaluate.Evaluator` in its initializer, so the robot is loaded
  once per worker and the compiled projection kernel comes from numba's disk cache.
- ``scheduler=ADDRESS`` (or a :class:`distributed.Client`): Dask distributed. The plan is
  scattered to every worker once; each worker keeps one evaluator per plan.

Whatever the backend, the parent writes each finished chunk at once (see
:mod:`~impact_balance.sweep.store`), and skips the chunks already written and checked: the same
command resumes an interrupted sweep (bad parts are moved aside and computed again). The rows
of a chunk depend on the plan only, so the results are the same on any number of workers.

Nothing is created before the inputs are known good: the output folder is checked, the
workers started or the scheduler reached, and only then is the folder made.

Workers die with their sweep: Ctrl-C or SIGTERM stops the run (finished chunks are written,
running ones get :data:`STOP_GRACE_S` seconds, then the workers are killed), also while the
workers start, and each local
worker watches the command's process and exits when it ends, even by SIGKILL (Linux: a pidfd;
elsewhere it polls twice a second).

No wait is unbounded: the workers must start, and the next chunk must finish, within
``chunk_timeout`` seconds (:data:`CHUNK_TIMEOUT_S` by default; ``--chunk-timeout``). A worker
that is stopped (SIGSTOP) or stuck makes the run fail after that time with an
:class:`~impact_balance.exceptions.EnvironmentFailure` naming the chunks not finished; a local
worker killed (by the out-of-memory killer, say) fails the run at once, naming a chunk it left.
Either way the finished chunks are written, the workers are ended, and the same command
resumes.
"""

from __future__ import annotations

import contextlib
import multiprocessing
import os
import select
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor
from concurrent.futures import TimeoutError as FutureTimeout
from concurrent.futures import wait as wait_futures
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from types import FrameType
from typing import Any, Literal

import pyarrow as pa
from tqdm import tqdm

from impact_balance.balance.areas import areas_from_polytope
from impact_balance.contacts.wrench_polytope import wrench_polytope
from impact_balance.exceptions import EnvironmentFailure, OptionError
from impact_balance.scenario import scenario_from_dict
from impact_balance.sweep.evaluate import Evaluator
from impact_balance.sweep.plan import SweepPlan
from impact_balance.sweep.store import PartProblem, ResultStore

__all__ = [
    "CHUNK_TIMEOUT_S",
    "STOP_GRACE_S",
    "BackendName",
    "RunReport",
    "dask_chunk",
    "default_workers",
    "run_sweep",
]

#: Where the chunks ran: nowhere (nothing was left), this process, local worker processes, or a
#: Dask cluster.
BackendName = Literal["none", "inline", "processes", "dask"]

#: After Ctrl-C or SIGTERM, how long running chunks may finish before the workers are killed, s.
STOP_GRACE_S = 1.0
#: Default longest wait for the workers to start, and for the next chunk to finish, s.
CHUNK_TIMEOUT_S = 900.0
#: Chunks named in a message; the others are counted.
_NAMED_CHUNKS = 5


def _chunk_list(chunks: list[int]) -> str:
    shown = ", ".join(str(c) for c in chunks[:_NAMED_CHUNKS])
    more = f" and {len(chunks) - _NAMED_CHUNKS} more" if len(chunks) > _NAMED_CHUNKS else ""
    return f"chunk{'s' if len(chunks) > 1 else ''} {shown}{more}"


def _stalled(timeout: float, chunks: list[int]) -> EnvironmentFailure:
    return EnvironmentFailure(
        "--chunk-timeout",
        timeout,
        f"no chunk finished within {timeout:g} s ({_chunk_list(sorted(chunks))} not finished: a "
        "worker is stopped or stuck); the finished chunks are written: run the same command to "
        "resume, with a longer --chunk-timeout if chunks take longer",
    )


def _worker_died(chunk: int, left: int) -> EnvironmentFailure:
    return EnvironmentFailure(
        "chunk",
        chunk,
        f"a worker process died while {left} chunk(s) were unfinished (killed: out of memory?); "
        "the finished chunks are written: run the same command to resume",
    )


def default_workers() -> int:
    """The number of cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


@dataclass(frozen=True)
class RunReport:
    """What a run did.

    Attributes:
        out: The output folder.
        backend: "inline", "processes" or "dask" ("none" when nothing was left to compute).
        workers: Worker count (Dask: the cluster's threads).
        n_points, n_chunks: Size of the sweep.
        chunks_before: Chunks already done when the run started (resumed).
        chunks_computed: Chunks computed and written by this run.
        points_computed: Points of those chunks.
        interrupted: True after Ctrl-C or ``stop_after``: run the same command to finish.
        elapsed_s: Wall time of the computing loop (after the workers started), s.
        startup_s: Time to start the workers and load the robot in them, s.
        rejected: Bad parts found in the folder (moved to ``rejected/`` and computed again).
    """

    out: Path
    backend: BackendName
    workers: int
    n_points: int
    n_chunks: int
    chunks_before: int
    chunks_computed: int
    points_computed: int
    interrupted: bool
    elapsed_s: float
    startup_s: float
    rejected: tuple[PartProblem, ...] = ()

    @property
    def complete(self) -> bool:
        """Every chunk of the sweep is written."""
        return self.chunks_before + self.chunks_computed == self.n_chunks

    @property
    def rate(self) -> float:
        """Points per second of the computing loop."""
        return self.points_computed / self.elapsed_s if self.elapsed_s > 0 else float("nan")


# -- worker-side entry points (module level: picklable by reference) -----------------------
_EVALUATOR: Evaluator | None = None
_EVALUATORS: dict[str, Evaluator] = {}
_LOCK = threading.Lock()


def _watch_parent(pid: int) -> None:
    """End this worker when process ``pid`` (the sweep command) ends, however it ends.

    The worker's own parent is multiprocessing's fork server, not the command: a daemon thread
    waits on a pidfd of the command (readable when it exits), or polls it where there is none.
    """
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:  # already gone
        os._exit(1)
    except (AttributeError, OSError):  # not Linux >= 5.3
        fd = None

    def watch() -> None:
        if fd is not None:
            select.select([fd], [], [])
        else:  # pragma: no cover - not Linux
            while True:
                time.sleep(0.5)
                try:
                    os.kill(pid, 0)
                except ProcessLookupError:
                    break
                except PermissionError:
                    continue
        os._exit(1)

    threading.Thread(target=watch, name="impact-balance-sweep-watch", daemon=True).start()


def _init_process(plan: SweepPlan, parent: int | None = None) -> None:
    # The parent handles Ctrl-C and SIGTERM (it cancels the queue and keeps what is finished).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if parent is not None:
        _watch_parent(parent)
    global _EVALUATOR
    _EVALUATOR = Evaluator(plan)
    _EVALUATOR.warm_up()


def _process_chunk(chunk: int) -> pa.Table:
    assert _EVALUATOR is not None
    return _EVALUATOR.evaluate_chunk(chunk)


def _ready() -> int:
    return os.getpid()


def dask_chunk(plan: SweepPlan, chunk: int) -> pa.Table:
    """Evaluate one chunk on a Dask worker (one evaluator per plan and worker process)."""
    with _LOCK:
        evaluator = _EVALUATORS.get(plan.digest)
        if evaluator is None:
            evaluator = Evaluator(plan)
            evaluator.warm_up()
            _EVALUATORS[plan.digest] = evaluator
    return evaluator.evaluate_chunk(chunk)


def _warm_kernel(plan: SweepPlan) -> None:
    """Compile (or load from numba's cache) the projection kernel before workers start."""
    scenario = scenario_from_dict(plan.base, plan.base_source)
    stance = scenario.build_stance()
    areas_from_polytope(
        wrench_polytope(stance, scenario.torque_limits, scenario.gravity),
        scenario.plane_height,
        scenario.zmp_margin,
    )


def _context() -> multiprocessing.context.BaseContext:
    """``forkserver`` where available (Linux), ``spawn`` elsewhere.

    One server process imports the library once and forks the workers from that clean,
    single-threaded state, so N workers cost one import. Never a plain fork of this process
    (threads, open solvers).
    """
    if "forkserver" in multiprocessing.get_all_start_methods():
        context = multiprocessing.get_context("forkserver")
        context.set_forkserver_preload([__name__])
        return context
    return multiprocessing.get_context("spawn")  # pragma: no cover - not Linux


# -- backends: each yields (chunk, table) as chunks finish ---------------------------------
class _Backend:
    """A way to compute chunks; this base computes nothing (a finished folder).

    ``run`` yields ``(chunk, table)`` as chunks finish; ``stop`` cancels what is left and
    returns what finished meanwhile; ``abort`` ends the workers after an error; ``close``
    releases them after a run.
    """

    name: BackendName = "none"
    workers = 0

    def run(self, chunks: list[int]) -> Iterator[tuple[int, pa.Table]]:
        """The chunks' tables, as they finish."""
        return iter(())

    def stop(self) -> list[tuple[int, pa.Table]]:
        """Cancel what is left; the chunks that finished meanwhile."""
        return []

    def abort(self) -> None:
        """End the workers at once (after an error in the parent)."""

    def close(self) -> None:
        """Release the workers after a run."""


class _Inline(_Backend):
    """The chunks run in this process."""

    name: BackendName = "inline"

    def __init__(self, plan: SweepPlan) -> None:
        self.evaluator = Evaluator(plan)
        self.evaluator.warm_up()
        self.workers = 1

    def run(self, chunks: list[int]) -> Iterator[tuple[int, pa.Table]]:
        """Each chunk's table, computed here, in order."""
        for chunk in chunks:
            yield chunk, self.evaluator.evaluate_chunk(chunk)


class _Processes(_Backend):
    """Local worker processes (see the module docstring)."""

    name: BackendName = "processes"

    def __init__(self, plan: SweepPlan, workers: int, timeout: float) -> None:
        _warm_kernel(plan)
        context = _context()
        self.workers, self.timeout = workers, timeout
        self.pool = ProcessPoolExecutor(
            max_workers=workers,
            mp_context=context,
            initializer=_init_process,
            initargs=(plan, os.getpid()),
        )
        self.futures: dict[Future[pa.Table], int] = {}
        self.processes: list[Any] = []
        # Start every worker (and its robot) before the clock of the computing loop starts.
        try:
            for f in [self.pool.submit(_ready) for _ in range(workers)]:
                f.result(timeout=timeout)
        except FutureTimeout:
            self.kill()
            raise EnvironmentFailure(
                "--chunk-timeout",
                timeout,
                f"the workers did not start within {timeout:g} s (a worker is stopped or stuck)",
            ) from None
        except BrokenProcessPool:
            self.kill()
            raise EnvironmentFailure(
                "--workers",
                workers,
                "a worker process died while starting (killed: out of memory?)",
            ) from None
        except BaseException:
            self.kill()
            raise
        finally:
            # CPython's executor keeps its processes here; kept to end them on a stop.
            self.processes = list((getattr(self.pool, "_processes", None) or {}).values())

    def run(self, chunks: list[int]) -> Iterator[tuple[int, pa.Table]]:
        """The chunks' tables, as the workers finish them."""
        self.futures = {}
        for c in chunks:
            try:
                self.futures[self.pool.submit(_process_chunk, c)] = c
            except BrokenProcessPool:
                raise _worker_died(c, len(chunks) - len(self.futures)) from None
        pending = set(self.futures)
        while pending:
            done, pending = wait_futures(pending, timeout=self.timeout, return_when=FIRST_COMPLETED)
            if not done:
                raise _stalled(self.timeout, list(self.futures.values()))
            for f in sorted(done, key=self.futures.__getitem__):
                chunk = self.futures.pop(f)
                try:
                    table = f.result()
                except BrokenProcessPool:
                    raise _worker_died(chunk, len(self.futures) + 1) from None
                yield chunk, table

    def stop(self) -> list[tuple[int, pa.Table]]:
        """Cancel what has not started, give what runs :data:`STOP_GRACE_S` seconds.

        Then kill the workers, and return what finished meanwhile.
        """
        for f in self.futures:
            f.cancel()
        running = [f for f in self.futures if not f.done()]
        if running:
            wait_futures(running, timeout=STOP_GRACE_S)
        done = [
            (c, f.result())
            for f, c in self.futures.items()
            if f.done() and not f.cancelled() and f.exception() is None
        ]
        self.futures = {}
        self.kill()
        return done

    def kill(self) -> None:
        """End every worker now (their chunks in flight are lost; finished ones were returned)."""
        processes = self.processes or list((getattr(self.pool, "_processes", None) or {}).values())
        for process in processes:
            with contextlib.suppress(Exception):
                process.kill()
        self.pool.shutdown(wait=False, cancel_futures=True)
        for process in processes:
            with contextlib.suppress(Exception):
                process.join(STOP_GRACE_S)

    def abort(self) -> None:
        """Kill the workers."""
        self.kill()

    def close(self) -> None:
        """Shut the pool down, waiting for its workers."""
        self.pool.shutdown(wait=True, cancel_futures=True)


class _Dask(_Backend):
    """A Dask cluster, by its scheduler's address or a client."""

    name: BackendName = "dask"

    def __init__(self, plan: SweepPlan, scheduler: Any, timeout: float) -> None:
        from impact_balance.sweep.cluster import CONNECT_TIMEOUT_S, bounded, connect

        self.own = isinstance(scheduler, str)
        self.client = connect(scheduler) if self.own else scheduler
        self.timeout = timeout
        address = getattr(self.client, "scheduler", None)
        shown = scheduler if self.own else getattr(address, "address", None)
        try:
            self.workers = (
                sum(
                    bounded(
                        self.client.nthreads, CONNECT_TIMEOUT_S, "--scheduler", shown, "workers"
                    ).values()
                )
                or 1
            )
            self.plan_future = bounded(
                lambda: self.client.scatter(plan, broadcast=True),
                timeout,
                "--scheduler",
                shown,
                "sending the plan to the workers",
            )
        except BaseException:
            self.abort()
            raise
        self.plan = plan
        self.futures: dict[Any, int] = {}

    def run(self, chunks: list[int]) -> Iterator[tuple[int, pa.Table]]:
        """The chunks' tables, as the cluster finishes them."""
        from distributed import wait as dask_wait

        self.futures = {
            self.client.submit(
                dask_chunk,
                self.plan_future,
                c,
                key=f"impact-balance-sweep-{self.plan.digest}-{c}",
                pure=False,
            ): c
            for c in chunks
        }
        pending = list(self.futures)
        while pending:
            try:
                done, left = dask_wait(pending, timeout=self.timeout, return_when="FIRST_COMPLETED")  # type: ignore[no-untyped-call]
            except TimeoutError:
                raise _stalled(self.timeout, list(self.futures.values())) from None
            pending = list(left)
            for f in sorted(done, key=self.futures.__getitem__):
                chunk = self.futures.pop(f)
                try:
                    table = f.result(timeout=self.timeout)
                except TimeoutError:
                    raise _stalled(self.timeout, [chunk, *self.futures.values()]) from None
                yield chunk, table

    def stop(self) -> list[tuple[int, pa.Table]]:
        """Cancel the tasks left; the chunks that finished meanwhile."""
        done = []
        for f, c in self.futures.items():
            if f.status == "finished":
                with contextlib.suppress(Exception):  # a worker that does not answer: recomputed
                    done.append((c, f.result(timeout=STOP_GRACE_S)))
        self.client.cancel(list(self.futures))
        self.futures = {}
        return done

    def abort(self) -> None:
        """Close the client (the cluster's workers are not this run's)."""
        self.close()

    def close(self) -> None:
        """Close the client if this run opened it."""
        if self.own:
            self.client.close()


def _start_backend(
    plan: SweepPlan, todo: list[int], workers: int | None, scheduler: Any, timeout: float
) -> _Backend:
    """The backend for the chunks ``todo`` (see :func:`run_sweep`), its workers started."""
    n = workers or default_workers()
    if not todo:
        return _Backend()
    if scheduler is not None:
        return _Dask(plan, scheduler, timeout)
    if n <= 1 or len(todo) <= 1:
        return _Inline(plan)
    return _Processes(plan, min(n, len(todo)), timeout)


class _ChunkWriter:
    """Writes each finished chunk to the store, counts it and moves the progress bar."""

    def __init__(
        self,
        store: ResultStore,
        plan: SweepPlan,
        done: set[int],
        progress: bool,
        on_chunk: Callable[[int], None] | None,
    ) -> None:
        self.store = store
        self.on_chunk = on_chunk
        self.computed = self.points = 0
        done_points = sum(plan.chunk_range(c)[1] - plan.chunk_range(c)[0] for c in done)
        self.bar = tqdm(
            total=plan.n_points,
            initial=done_points,
            unit="pt",
            desc="sweep",
            file=sys.stderr,
            disable=not progress,
            dynamic_ncols=True,
            smoothing=0.05,
        )

    def keep(self, chunk: int, table: pa.Table) -> None:
        """Write chunk ``chunk``'s rows and count them."""
        self.store.write(chunk, table)
        self.computed += 1
        self.points += table.num_rows
        self.bar.update(table.num_rows)
        if self.on_chunk is not None:
            self.on_chunk(chunk)

    def close(self) -> None:
        """Close the progress bar."""
        self.bar.close()


def _compute(
    backend: _Backend, todo: list[int], writer: _ChunkWriter, stop_after: int | None
) -> tuple[bool, float]:
    """Compute the chunks ``todo`` and write them; whether interrupted, and the time it took (s).

    Ctrl-C (or SIGTERM) stops the loop and keeps what finished; the backend is stopped,
    aborted (after an error) or closed, whatever happens.
    """
    interrupted = failed = False
    t1 = time.perf_counter()
    try:
        with _sigterm_interrupts():
            try:
                for chunk, table in backend.run(todo):
                    writer.keep(chunk, table)
                    if stop_after is not None and writer.computed >= stop_after:
                        interrupted = writer.computed < len(todo)
                        break
            except KeyboardInterrupt:
                interrupted = True
                for chunk, table in backend.stop():
                    writer.keep(chunk, table)
    except BaseException:
        failed = True
        raise
    finally:
        elapsed = time.perf_counter() - t1
        if interrupted and not isinstance(backend, _Inline):
            backend.stop()
        if failed:
            backend.abort()  # an error in the parent (a full disk...): no worker outlives it
        else:
            backend.close()
        writer.close()
    return interrupted, elapsed


def run_sweep(
    plan: SweepPlan,
    out: str | Path,
    workers: int | None = None,
    scheduler: Any = None,
    progress: bool = True,
    stop_after: int | None = None,
    on_chunk: Callable[[int], None] | None = None,
    notify: Callable[[str], None] | None = None,
    chunk_timeout: float = CHUNK_TIMEOUT_S,
) -> RunReport:
    """Compute the chunks of ``plan`` not yet in ``out``, writing each one as it finishes.

    Ctrl-C (or SIGTERM, in the main thread) stops the run: chunks already written stay, chunks
    that finish within :data:`STOP_GRACE_S` are written too, the workers are ended, and the
    report says ``interrupted``.

    Args:
        plan: The sweep.
        out: Output folder (created; an existing one with the same sweep is resumed).
        workers: Local worker processes (default: every core); 1 runs in this process.
        scheduler: A Dask scheduler address (``tcp://host:8786``) or a ``distributed.Client``;
            then ``workers`` is ignored.
        progress: Show a progress bar (tqdm, on stderr) with the rate and the time left.
        stop_after: Stop after writing this many chunks (as if killed; for tests and demos).
        on_chunk: Called with each chunk index once its part file is written.
        notify: Called with one line per bad part found in ``out`` (moved to ``rejected/``,
            computed again).
        chunk_timeout: Longest wait for the workers to start and for the next chunk to finish,
            s (worker processes and Dask; see the module docstring).

    Returns:
        What the run did.

    Raises:
        OptionError: ``chunk_timeout`` is not a positive number.
        SweepError: ``out`` holds another sweep, or is not a sweep folder.
        EnvironmentFailure: the scheduler cannot be reached (nothing is created then); no chunk
            finished within ``chunk_timeout``; a worker process died.
        KeyboardInterrupt: Ctrl-C or SIGTERM while the workers start.
    """
    if isinstance(chunk_timeout, bool) or not (
        isinstance(chunk_timeout, (int, float)) and 0 < chunk_timeout < float("inf")
    ):
        raise OptionError("--chunk-timeout", chunk_timeout, "must be a positive number of seconds")
    store = ResultStore.prepare(out, plan)  # checks only: nothing is created yet
    good = set(store.check.good) if store.check is not None else set()
    todo = [c for c in range(plan.n_chunks) if c not in good]
    t0 = time.perf_counter()
    with _sigterm_interrupts():  # SIGTERM while the workers start: stop as Ctrl-C does
        backend = _start_backend(plan, todo, workers, scheduler, chunk_timeout)
        startup = time.perf_counter() - t0
        try:
            store.create(notify)  # the inputs are good and the workers are up: now the folder
        except BaseException:
            backend.abort()
            raise
        done = store.finished()
        writer = _ChunkWriter(store, plan, done, progress, on_chunk)
        interrupted, elapsed = _compute(backend, todo, writer, stop_after)
    return RunReport(
        Path(out),
        backend.name,
        backend.workers,
        plan.n_points,
        plan.n_chunks,
        len(done),
        writer.computed,
        writer.points,
        interrupted,
        elapsed,
        startup,
        tuple(store.problems),
    )


@contextlib.contextmanager
def _sigterm_interrupts() -> Iterator[None]:
    """Within the block, SIGTERM stops the run as Ctrl-C does (main thread only)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum: int, frame: FrameType | None) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGTERM, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)
