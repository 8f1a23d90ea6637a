"""The governor's tick in the MuJoCo approach loop (``benchmarks/approach.py``), the code one
side runs: ``impact-balance approach`` trials, each tick of the governor timed.

Works with the current tree and with older ones (``--baseline``): a trial is the command line
itself (``impact_balance.cli.main``), so both sides set up their trials as their own command
does; the governor the command builds is a subclass of the tree's own ``Governor`` whose
``limit`` is timed (``time.perf_counter`` around the call, as the command's own ``tick_us``).
After each trial its ticks are replayed on the same governor back to back (``replayed``): the
same postures with warm caches, the loop's own cost apart.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from typing import Any

__all__ = ["ApproachJob", "approach_job"]


class _Record:
    """What the timed governors saw: each tick's time (us) and arguments, the last governor."""

    def __init__(self) -> None:
        self.ticks: list[float] = []
        self.calls: list[tuple[Any, ...]] = []
        self.governor: Any = None

    def clear(self) -> None:
        self.ticks.clear()
        self.calls.clear()


def _timed_governor_class(record: _Record) -> type:
    """The tree's ``Governor``, each ``limit`` call timed and its arguments kept in ``record``."""
    import numpy as np

    from impact_balance import governor as package

    base = package.Governor

    class TimedGovernor(base):  # type: ignore[misc, valid-type]
        def __init__(self, *args: Any, **kwargs: Any) -> None:
            super().__init__(*args, **kwargs)
            record.governor = self

        def limit(self, *args: Any, **kwargs: Any) -> Any:
            t0 = time.perf_counter()
            answer = super().limit(*args, **kwargs)
            record.ticks.append((time.perf_counter() - t0) * 1e6)
            record.calls.append(tuple(np.array(a, copy=True) for a in args))
            return answer

    return TimedGovernor


def _replay(record: _Record) -> list[float]:
    """The trial's ticks again on its governor, back to back (warm caches), timed (us)."""
    governor, calls = record.governor, list(record.calls)
    if governor is None or len(calls) < 2:
        return []
    times = []
    governor.limit(*calls[-1])  # another posture than the first call's
    for args in calls:
        t0 = time.perf_counter()
        governor.limit(*args)
        times.append((time.perf_counter() - t0) * 1e6)
    return times


class ApproachJob:
    """One side's trials: block k runs one approach (its wall distance cycling through
    ``params["wall_distances"]``) after one untimed warm-up trial; samples are keyed
    ``"scenario/tick"``."""

    def __init__(self, params: dict[str, Any]) -> None:
        from impact_balance import governor as package

        self.params = params
        self.record = _Record()
        package.Governor = _timed_governor_class(self.record)  # what the command builds
        warm = self._trial(float(params["wall_distances"][0]))  # loads, compiles, warms MuJoCo
        self.info = {
            "scenario": params["scenario"],
            "warm_up": {"ticks": len(self.record.ticks), "outcome": warm.get("outcome")},
        }

    def _trial(self, distance: float) -> dict[str, Any]:
        from impact_balance.cli import main

        p = self.params
        argv = ["approach", p["scenario"], "--reference", str(p["reference"])]
        argv += ["--governor", p["governor"], "--wall-distance", str(distance), "--json"]
        self.record.clear()
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            status = main(argv)
        if status != 0:
            raise RuntimeError(f"approach {' '.join(argv[1:])} exited with status {status}")
        doc: dict[str, Any] = json.loads(out.getvalue())
        return doc

    def block(self, k: int, blocks: int) -> dict[str, Any]:
        distances = self.params["wall_distances"]
        distance = float(distances[k % len(distances)])
        doc = self._trial(distance)
        own = doc.get("tick_us", {})
        ticks = list(self.record.ticks)
        name = self.params["scenario"]
        return {
            "samples": {f"{name}/tick": ticks, f"{name}/replayed": _replay(self.record)},
            "checks": {
                "wall_distance": distance,
                "outcome": doc.get("outcome"),
                "speed_at_contact": doc.get("speed_at_contact"),
                "ticks": len(ticks),
                "command_ticks": own.get("count"),  # the command's own count: the same ticks
            },
        }


def approach_job(params: dict[str, Any]) -> ApproachJob:
    """``params``: ``scenario``, ``reference`` (m/s), ``governor`` (com or zmp),
    ``wall_distances`` (m, cycled over the blocks)."""
    return ApproachJob(params)
