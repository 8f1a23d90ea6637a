"""The worker job of ``run.py --baseline``: one side's projection, pipeline stages and
``analyze()`` per bundled stance (the cases of :mod:`.pipeline` and :mod:`.projection`, which
adapt to older trees through :mod:`.compat`), timed block by block."""

from __future__ import annotations

import math
from typing import Any

import impact_balance as ib
from benchmarks.speed.compat import wrench_polytope
from benchmarks.speed.pipeline import pipeline_cases
from benchmarks.speed.projection import projection_cases
from benchmarks.speed.timing import Case, measure

__all__ = ["stage_job"]


class _StageJob:
    """Samples keyed ``"stance/case"``; ``info["answers"]``: each stance's ``analyze()``
    maximum contact velocity (None without an impact or when unbounded)."""

    def __init__(self, params: dict[str, Any]) -> None:
        self.repeat = max(1, int(params["repeat"]))
        warmup = int(params.get("warmup", 3))
        self.cases: dict[str, dict[str, Case]] = {}
        answers: dict[str, float | None] = {}
        for name in params["scenarios"]:
            sc = ib.load_scenario(name)
            cases, stance, _areas, _model = pipeline_cases(sc)
            poly = wrench_polytope(stance, sc.torque_limits, sc.gravity)
            ours = projection_cases(poly, 1e3, 0)["ours"]
            self.cases[name] = {"projection": Case(ours.fn), **cases}
            measure(self.cases[name], 0, warmup)
            answer = ib.analyze(sc).impact
            value = None if answer is None else answer.max_contact_velocity
            answers[name] = None if value is None or math.isinf(value) else float(value)
        self.info = {"answers": answers, "repeat": self.repeat}

    def block(self, k: int, blocks: int) -> dict[str, Any]:
        count = max(1, (k + 1) * self.repeat // blocks - k * self.repeat // blocks)
        samples: dict[str, list[float]] = {}
        for name, cases in self.cases.items():
            times, _ = measure(cases, count, 0)
            samples.update({f"{name}/{case}": t for case, t in times.items()})
        return {"samples": samples}


def stage_job(params: dict[str, Any]) -> _StageJob:
    """``params``: ``scenarios`` (bundled names), ``repeat`` (calls per case over all blocks),
    ``warmup`` (untimed calls per case at set-up)."""
    return _StageJob(params)
