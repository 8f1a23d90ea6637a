"""Two installations of the project timed in one run, interleaved: the current code against a
baseline tree (``--baseline DIR``), each side in its own worker process.

Two versions of one package cannot be imported in one interpreter, so each side runs in a
fresh interpreter (``python -m benchmarks.speed.worker``) with its tree first on
``PYTHONPATH``, driven over a pipe: the parent sends "set up the job", then "run block k" to
one side and then to the other, alternating which side goes first (A B, B A, A B, ...), so that
the machine's noise hits both alike. Both workers stay alive (and warm: compiled kernels
loaded once); only one of them runs at a time. A job is ``"module:function"``:
``function(params)`` returns an object with a dict ``info`` and a method
``block(k, blocks) -> {"samples": {key: [us, ...]}, ...}``.

Each measured quantity (a key's median or p99 within a block) is reported as the ratio
current / baseline: the median of the per-block ratios with a distribution-free interval for
that median (order statistics of the blocks; its coverage is given), beside the absolute times
of both sides over all blocks.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import json
import math
import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from benchmarks.speed.machine import load_average

__all__ = [
    "BENCH_ROOT",
    "BaselineError",
    "InterleavedRun",
    "WorkerError",
    "compare",
    "current_tree",
    "exit_status",
    "median_interval",
    "resolve_tree",
    "run_interleaved",
]

T = TypeVar("T")

#: The folder holding the ``benchmarks`` package (the repository root): on every worker's path.
BENCH_ROOT = Path(__file__).resolve().parents[2]
#: The sides, in the order of a ratio: current / baseline.
SIDES = ("current", "baseline")
STATS = ("median", "p99")


class BaselineError(ValueError):
    """A ``--baseline`` (or ``--blocks``) value that cannot be used: bad input."""

    def __init__(self, field: str, value: object, reason: str) -> None:
        super().__init__(f"{field} {value!s}: {reason}")
        self.field, self.value, self.reason = field, value, reason


def exit_status(call: Callable[[], T]) -> tuple[int, T | None]:
    """Run a benchmark's measurement with the command line's error rule.

    Returns ``(0, its result)``, or, with one ``error:`` line on stderr, ``(2, None)`` for a
    :class:`BaselineError` (bad input), ``(1, None)`` for a :class:`WorkerError` (the
    environment) and ``(130, None)`` for an interrupt.
    """
    try:
        return 0, call()
    except BaselineError as exc:
        status, message = 2, str(exc)
    except WorkerError as exc:
        status, message = 1, str(exc)
    except KeyboardInterrupt:
        status, message = 130, "interrupted"
    print(f"error: {message}", file=sys.stderr)
    return status, None


class WorkerError(RuntimeError):
    """A worker process that failed (its import, its job or the pipe): the environment."""


def resolve_tree(directory: str | os.PathLike[str], field: str = "--baseline") -> Path:
    """The folder to put on ``PYTHONPATH`` for the project tree ``directory``.

    ``directory`` is a checkout (``DIR/src/impact_balance``) or an installed tree
    (``DIR/impact_balance``, e.g. a ``site-packages``).

    Raises:
        BaselineError: no such folder, or no ``impact_balance`` package in it.
    """
    root = Path(directory).expanduser()
    if not root.is_dir():
        raise BaselineError(field, directory, "is not a folder")
    for candidate in (root / "src", root):
        if (candidate / "impact_balance" / "__init__.py").is_file():
            return candidate.resolve()
    raise BaselineError(
        field, directory, "holds neither src/impact_balance/ (a checkout) nor impact_balance/"
    )


def current_tree() -> Path:
    """The folder this interpreter imports ``impact_balance`` from (without importing it)."""
    spec = importlib.util.find_spec("impact_balance")
    if spec is None or not spec.submodule_search_locations:
        raise WorkerError("impact_balance is not importable here")
    return Path(next(iter(spec.submodule_search_locations))).resolve().parent


class _Worker:
    """One side: a fresh interpreter with ``tree`` first on its path, JSON lines over a pipe."""

    def __init__(self, label: str, tree: Path) -> None:
        self.label, self.tree = label, tree
        env = dict(os.environ)
        env["PYTHONPATH"] = os.pathsep.join([str(tree), str(BENCH_ROOT)])
        env["PYTHONUNBUFFERED"] = "1"
        self.process = subprocess.Popen(
            [sys.executable, "-m", "benchmarks.speed.worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            env=env,
            cwd=str(BENCH_ROOT),
            text=True,
        )

    def request(self, message: dict[str, Any]) -> dict[str, Any]:
        assert self.process.stdin is not None and self.process.stdout is not None
        try:
            self.process.stdin.write(json.dumps(message) + "\n")
            self.process.stdin.flush()
            line = self.process.stdout.readline()
        except (BrokenPipeError, OSError) as exc:
            raise WorkerError(f"{self.label} worker ({self.tree}): pipe closed: {exc}") from exc
        if not line:
            code = self.process.wait()
            raise WorkerError(f"{self.label} worker ({self.tree}) exited with status {code}")
        reply: dict[str, Any] = json.loads(line)
        if "error" in reply:
            raise WorkerError(f"{self.label} worker ({self.tree}): {reply['error']}")
        return reply

    def close(self) -> None:
        if self.process.poll() is None:
            try:
                assert self.process.stdin is not None
                self.process.stdin.close()  # end of input: the worker returns
                self.process.wait(timeout=10)
            except (OSError, subprocess.TimeoutExpired):
                self.process.kill()
                self.process.wait()


@dataclasses.dataclass
class InterleavedRun:
    """What :func:`run_interleaved` measured: per side its tree, setup info and block replies."""

    trees: dict[str, str]
    info: dict[str, dict[str, Any]]
    blocks: dict[str, list[dict[str, Any]]]
    order: list[list[str]]
    load_average: list[list[float]]
    wall_time_s: float


def run_interleaved(
    job: str,
    params: dict[str, Any],
    trees: dict[str, Path],
    blocks: int,
    log: Callable[[str], None] | None = None,
) -> InterleavedRun:
    """Set ``job`` up on every side of ``trees``, then run ``blocks`` blocks alternating sides.

    Block k runs the sides in the order of ``trees`` when k is even, reversed when k is odd.

    Raises:
        BaselineError: ``blocks`` < 1.
        WorkerError: a worker failed (it is reported with its side and tree).
    """
    if blocks < 1:
        raise BaselineError("--blocks", blocks, "must be an integer >= 1")
    t0 = time.perf_counter()
    workers: dict[str, _Worker] = {}
    try:
        info: dict[str, dict[str, Any]] = {}
        for label, tree in trees.items():  # one after the other: set-ups compile and load
            if log:
                log(f"{label} ({tree}): setting up {job} ...")
            workers[label] = _Worker(label, tree)
            info[label] = workers[label].request({"cmd": "setup", "job": job, "params": params})
        replies: dict[str, list[dict[str, Any]]] = {label: [] for label in trees}
        order, loads = [], []
        labels = list(trees)
        for k in range(blocks):
            sequence = labels if k % 2 == 0 else labels[::-1]
            loads.append(load_average())
            for label in sequence:
                replies[label].append(workers[label].request({"cmd": "block", "k": k, "n": blocks}))
            order.append(sequence)
            if log:
                log(f"block {k + 1}/{blocks} ({' then '.join(sequence)}), load {loads[-1][0]}")
    finally:
        for worker in workers.values():
            worker.close()
    return InterleavedRun(
        trees={label: str(tree) for label, tree in trees.items()},
        info=info,
        blocks=replies,
        order=order,
        load_average=loads,
        wall_time_s=time.perf_counter() - t0,
    )


def median_interval(values: list[float], level: float = 0.95) -> tuple[float, float, float]:
    """A distribution-free interval for the median of ``values``: ``(low, high, coverage)``.

    The order statistics ``x_(k) <= median <= x_(n+1-k)`` with the largest k whose coverage
    ``1 - 2 P(Binomial(n, 1/2) < k)`` is at least ``level``; with too few values for that
    (n < 6 at 0.95), the minimum and maximum with their own coverage ``1 - 2^(1-n)``.
    """
    x = sorted(values)
    n = len(x)
    if n == 0:
        return math.nan, math.nan, 0.0
    tail, k = 0.0, 0
    for j in range(n):
        tail += math.comb(n, j) / 2.0**n
        if tail > (1.0 - level) / 2.0:
            break
        k = j + 1
    k = max(k, 1)
    below = sum(math.comb(n, j) for j in range(k)) / 2.0**n
    return x[k - 1], x[n - k], max(0.0, 1.0 - 2.0 * below)


def _stat(samples: list[float], stat: str) -> float:
    a = np.asarray(samples, dtype=float)
    if a.size == 0:
        return math.nan
    return float(np.median(a) if stat == "median" else np.percentile(a, 99))


def compare(
    run: InterleavedRun, subject: str = "current", reference: str = "baseline"
) -> dict[str, Any]:
    """Per sample key: both sides' absolute times over all blocks and the per-block ratios.

    Returns ``{key: {"current": {"median", "p99", "n"}, "baseline": {...}, "ratio": {stat:
    {"median", "low", "high", "coverage", "blocks"}}}}`` for the keys both sides measured.
    """
    out: dict[str, Any] = {}
    keys = [key for key in run.blocks[subject][0]["samples"] if _everywhere(run, key)]
    for key in keys:
        entry: dict[str, Any] = {}
        for side in (subject, reference):
            pooled = [t for block in run.blocks[side] for t in block["samples"][key]]
            entry[side] = {stat: _stat(pooled, stat) for stat in STATS} | {"n": len(pooled)}
        entry["ratio"] = {}
        for stat in STATS:
            ratios = [
                _stat(a["samples"][key], stat) / _stat(b["samples"][key], stat)
                for a, b in zip(run.blocks[subject], run.blocks[reference], strict=True)
            ]
            ratios = [r for r in ratios if math.isfinite(r)]
            low, high, coverage = median_interval(ratios)
            entry["ratio"][stat] = {  # None, not NaN, without a finite ratio (strict JSON)
                "median": float(np.median(ratios)) if ratios else None,
                "low": low if ratios else None,
                "high": high if ratios else None,
                "coverage": coverage,
                "blocks": len(ratios),
            }
        out[key] = entry
    return out


def _everywhere(run: InterleavedRun, key: str) -> bool:
    return all(key in block["samples"] for blocks in run.blocks.values() for block in blocks)
