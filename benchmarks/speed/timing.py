"""Timing: wall-clock ``time.perf_counter`` per call in microseconds, after a warm-up, with the
garbage collector paused; the cases of one group run round-robin so that drifts of the
machine hit them alike."""

from __future__ import annotations

import dataclasses
import gc
import sys
import time
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["Case", "measure", "progress", "stats"]


def stats(samples_us: list[float]) -> dict[str, float]:
    a = np.asarray(samples_us, dtype=float)
    p10, p25, p50, p75, p90 = np.percentile(a, [10, 25, 50, 75, 90])
    return {
        "median": float(p50),
        "p10": float(p10),
        "p90": float(p90),
        "iqr": float(p75 - p25),
        "min": float(a.min()),
        "n": int(a.size),
    }


@dataclasses.dataclass
class Case:
    """A timed call: ``setup(i)`` (untimed, optional), ``fn()`` (timed), ``keep(result)`` (untimed).

    Results are dropped (released before the next timed call) unless ``keep`` maps them to
    what to store: keeping whole results alive (e.g. pinocchio Data) makes later allocations
    much slower and would bias the timings.
    """

    fn: Callable[[], Any]
    setup: Callable[[int], None] | None = None
    keep: Callable[[Any], Any] | None = None


def measure(
    cases: dict[str, Case],
    repeat: int,
    warmup: int,
    clock: Callable[[], float] = time.perf_counter,
) -> tuple[dict[str, list[float]], dict[str, list[Any]]]:
    """Round-robin timing of ``cases``; returns per case the times (us) and the results.

    ``clock``: seconds; wall time by default (``time.process_time``: the process's CPU time).
    """
    for w in range(warmup):
        for case in cases.values():
            if case.setup is not None:
                case.setup(-1 - w)
            case.fn()
    times: dict[str, list[float]] = {k: [] for k in cases}
    results: dict[str, list[Any]] = {k: [] for k in cases}
    gc.collect()
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        for i in range(repeat):
            for name, case in cases.items():
                if case.setup is not None:
                    case.setup(i)
                t0 = clock()
                r = case.fn()
                t1 = clock()
                times[name].append((t1 - t0) * 1e6)
                if case.keep is not None:
                    results[name].append(case.keep(r))
                r = None  # release now, outside the timed region
    finally:
        if was_enabled:
            gc.enable()
    return times, results


def progress(msg: str) -> None:
    """One progress line on stderr (stdout stays one JSON document under ``--json``)."""
    print(msg, file=sys.stderr, flush=True)
