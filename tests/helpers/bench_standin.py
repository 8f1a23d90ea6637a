"""A stand-in job for the interleaved benchmark driver (``benchmarks.speed.interleave``).

Each side's ``impact_balance`` is a fake package whose ``DELAY`` (s) says how long one call
spins, in CPU time of its thread (``time.sleep`` and the wall clock move by whole time slices
on a loaded machine: the stand-in tests the driver, not the machine), and whose ``FAIL`` makes
the job's setup raise."""

from __future__ import annotations

import time
from typing import Any

import impact_balance

__all__ = ["SleepJob", "sleep_job"]


class SleepJob:
    """``samples["sleep"]``: ``params["calls"]`` waits of ``impact_balance.DELAY`` per block."""

    def __init__(self, params: dict[str, Any]) -> None:
        if getattr(impact_balance, "FAIL", False):
            raise RuntimeError("this side was told to fail")
        self.delay = float(impact_balance.DELAY)
        self.calls = int(params["calls"])
        self.info = {"delay": self.delay}

    def block(self, k: int, blocks: int) -> dict[str, Any]:
        times = []
        for _ in range(self.calls):
            t0 = time.thread_time()
            while time.thread_time() - t0 < self.delay:
                pass
            times.append((time.thread_time() - t0) * 1e6)
        return {"samples": {"sleep": times}, "k": k}


def sleep_job(params: dict[str, Any]) -> SleepJob:
    return SleepJob(params)
