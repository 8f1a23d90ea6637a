"""The governor's time per tick (``benchmarks/governor.py``), the code one side runs: a moving
posture, the governor's two paths and ``analyze()`` of the same state, round-robin.

Works with the current tree and with older ones (``--baseline``): the version differences go
through :mod:`benchmarks.speed.compat`.
"""

from __future__ import annotations

from typing import Any, Literal

import numpy as np
import pinocchio as pin

import impact_balance as ib
from benchmarks.speed.compat import governed_maximum
from benchmarks.speed.timing import Case, measure
from impact_balance.governor import Governor

__all__ = ["AMPLITUDE", "FREQUENCY", "RATE", "TickBench", "governor_job", "trajectory"]

Criterion = Literal["com", "zmp"]
RATE = 500.0  # Hz
AMPLITUDE = 0.05  # rad
FREQUENCY = 0.5  # Hz


def trajectory(governor: Governor, ticks: int) -> tuple[np.ndarray, np.ndarray]:
    """``(q (ticks, nq), v (ticks, nv))`` of the moving posture of ``benchmarks/governor.py``."""
    robot, q0 = governor.robot, governor.configuration
    model = robot.model
    t = np.arange(ticks) / RATE
    qs = np.tile(q0, (ticks, 1))
    vs = np.zeros((ticks, model.nv))
    rng = np.random.default_rng(0)
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        if slot.nq != 1:
            continue
        phase = rng.uniform(0.0, 2.0 * np.pi)
        w = 2.0 * np.pi * FREQUENCY
        raw = q0[slot.idx_q] + AMPLITUDE * (np.sin(w * t + phase) - np.sin(phase))
        lo, hi = slot.lower, slot.upper
        qs[:, slot.idx_q] = np.clip(raw, lo + 1e-6, hi - 1e-6) if lo < hi else raw
        dq = AMPLITUDE * w * np.cos(w * t + phase)
        vs[:, model.joints[slot.id].idx_v] = np.where(qs[:, slot.idx_q] == raw, dq, 0.0)
    forward = 0.1 * np.sin(np.pi * t / t[-1] if ticks > 1 else t)  # m/s, world x
    qs[:, 0] += np.concatenate([[0.0], np.cumsum(forward[:-1]) / RATE])
    rotation = pin.Quaternion(q0[3:7]).normalized().matrix()
    vs[:, :3] = (rotation.T @ np.vstack([forward, np.zeros((2, ticks))])).T  # base frame
    return qs, vs


class TickBench:
    """One scenario's ticks: ``posture`` (a new posture every tick), ``velocity`` (the same
    posture, a new velocity) and ``analyze`` (the equivalent scenario), warmed up once."""

    def __init__(self, name: str, ticks: int, criterion: Criterion, warmup: int = 3) -> None:
        self.name, self.ticks, self.criterion = name, ticks, criterion
        governor = Governor(name, criterion=criterion)
        qs, vs = trajectory(governor, ticks)
        # The equivalent scenarios, built before timing (analyze() is timed, not pydantic).
        answers = [governor.limit(q, v) for q, v in zip(qs, vs, strict=True)]
        scenarios = [
            governor.scenario_at(q, a.com_velocity) for q, a in zip(qs, answers, strict=True)
        ]
        self.offset, k = 0, {"i": 0}

        def at(i: int) -> None:
            k["i"] = (self.offset + i) % ticks

        q_fixed = qs[0]
        # A second governor for the velocity-only ticks: the first one's posture changes.
        steady = Governor(name, criterion=criterion)
        steady.limit(q_fixed, vs[0])
        self.cases = {
            "posture": Case(
                lambda: governor.limit(qs[k["i"]], vs[k["i"]]),
                setup=at,
                keep=lambda r: (governed_maximum(r), r.posture_reused),
            ),
            "velocity": Case(
                lambda: steady.limit(q_fixed, vs[k["i"]]), setup=at, keep=lambda r: r.posture_reused
            ),
            "analyze": Case(
                lambda: ib.analyze(scenarios[k["i"]]),
                setup=at,
                keep=lambda a: (
                    a.impact.max_contact_velocity
                    if criterion == "com"
                    else a.impact.zmp_max_contact_velocity
                ),
            ),
        }
        measure(self.cases, 0, warmup)  # ticks ticks-1, ticks-2, ... (as one whole run)

    def run(self, start: int, count: int) -> dict[str, Any]:
        """Time ticks ``start .. start + count - 1``: per case the times (us) and the checks."""
        self.offset = start
        times, results = measure(self.cases, count, 0)
        got = np.array([r[0] for r in results["posture"]])
        want = np.array(results["analyze"], dtype=float)
        finite = np.isfinite(want)
        worst = float(np.max(np.abs(got[finite] - want[finite]), initial=0.0))
        return {
            "times": times,
            "agree": bool(np.array_equal(np.isfinite(got), finite) and worst <= 1e-9),
            "worst_difference": worst,
            "posture_reused": int(sum(r[1] for r in results["posture"])),
            "velocity_reused": int(sum(results["velocity"])),
        }


class _GovernorJob:
    """The worker job of ``governor.py --baseline``: block k times the k-th slice of the ticks
    of every scenario; samples are keyed ``"scenario/case"``."""

    def __init__(self, params: dict[str, Any]) -> None:
        self.ticks = int(params["ticks"])
        self.benches = [
            TickBench(name, self.ticks, params["criterion"]) for name in params["scenarios"]
        ]
        self.info = {"scenarios": [b.name for b in self.benches], "ticks": self.ticks}

    def block(self, k: int, blocks: int) -> dict[str, Any]:
        start, stop = k * self.ticks // blocks, (k + 1) * self.ticks // blocks
        samples: dict[str, list[float]] = {}
        checks = {}
        for bench in self.benches:
            out = bench.run(start, stop - start)
            for case, times in out.pop("times").items():
                samples[f"{bench.name}/{case}"] = times
            checks[bench.name] = out
        return {"samples": samples, "checks": checks}


def governor_job(params: dict[str, Any]) -> _GovernorJob:
    """``params``: ``scenarios`` (names), ``ticks`` (per scenario), ``criterion``."""
    return _GovernorJob(params)
