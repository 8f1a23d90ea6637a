#!/usr/bin/env python
"""Issue 15 targets: the governor's time per control tick, beside a full ``analyze()`` per tick.

    python benchmarks/governor.py [--json] [--ticks N] [--scenarios NAME ...] [--criterion com|zmp]
    python benchmarks/governor.py --study [--out DIR] ...  # wall study: governor_study.py
    python benchmarks/governor.py --tolerance ...          # tolerance: governor_tolerance.py

For each scenario of the wall study (palm_push_two_feet, palm_push_ramp, kick_one_foot,
g1_two_feet), a 500 Hz trajectory of N ticks (default 2000, 4 s): every actuated joint follows
``q0 + 0.05 sin(2 pi 0.5 t + phase_j)`` rad (clipped to its limits) from the scenario's
posture, so that the posture changes at every tick, with the matching joint velocities and a
base that drifts forwards at up to 0.1 m/s (world velocities converted to pinocchio's base
frame). Timed per tick, round-robin in one run (the garbage collector paused):

- ``posture``: ``governor.limit(q_k, v_k)``, a new posture every tick (the full per-tick path);
- ``velocity``: ``governor.limit(q_0, v_k)``, the same posture, a new velocity (the fast path);
- ``analyze``: ``impact_balance.analyze`` of the equivalent scenario of tick k (the pipeline
  the governor replaces; scenario building excluded).

Every tick's governor answer is checked against ``analyze()`` (maximum within 1e-9 m/s). The
load average is printed beside the times: the machine is shared, absolute times move with it.

Targets (informative; issue 15): posture-changing ticks median <= 250 us and p99 <= 1 ms;
velocity-only ticks median <= 20 us. Exit status 1 if an answer disagrees, else 0.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import impact_balance as ib
from benchmarks.speed.machine import machine_info
from benchmarks.speed.timing import Case, measure, progress
from impact_balance.governor import Governor

#: The wall study's scenarios (issue 15, item 3).
SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")
RATE = 500.0  # Hz
AMPLITUDE = 0.05  # rad
FREQUENCY = 0.5  # Hz
TARGETS = {"posture_median": 250.0, "posture_p99": 1000.0, "velocity_median": 20.0}


def trajectory(governor: Governor, ticks: int) -> tuple[np.ndarray, np.ndarray]:
    """``(q (ticks, nq), v (ticks, nv))`` of the moving posture described in the docstring."""
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


def bench_scenario(name: str, ticks: int, criterion: str) -> dict[str, Any]:
    governor = Governor(name, criterion=criterion)
    qs, vs = trajectory(governor, ticks)
    # The equivalent scenarios, built before timing (analyze() is timed, not pydantic).
    answers = [governor.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    scenarios = [governor.scenario_at(q, a.com_velocity) for q, a in zip(qs, answers, strict=True)]
    k = {"i": 0}

    def at(i: int) -> None:
        k["i"] = i % ticks

    q_fixed = qs[0]
    # A second governor for the velocity-only ticks: the first one's posture changes every tick.
    steady = Governor(name, criterion=criterion)
    steady.limit(q_fixed, vs[0])
    cases = {
        "posture": Case(
            lambda: governor.limit(qs[k["i"]], vs[k["i"]]),
            setup=at,
            keep=lambda r: (r.max_contact_velocity, r.posture_reused),
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
    load_before = _loadavg()
    times, results = measure(cases, ticks, warmup=3)
    load_after = _loadavg()
    got = np.array([r[0] for r in results["posture"]])
    want = np.array(results["analyze"])
    finite = np.isfinite(want)
    worst = float(np.max(np.abs(got[finite] - want[finite]), initial=0.0))
    agree = bool(np.array_equal(np.isfinite(got), finite) and worst <= 1e-9)
    reused_posture = sum(r[1] for r in results["posture"])
    reused_velocity = sum(results["velocity"])
    out: dict[str, Any] = {
        "scenario": name,
        "criterion": criterion,
        "ticks": ticks,
        "loadavg_before": load_before,
        "loadavg_after": load_after,
        "agree": agree,
        "worst_difference": worst,
        "posture_reused": int(reused_posture),
        "velocity_reused": int(reused_velocity),
    }
    for case, samples in times.items():
        a = np.asarray(samples)
        out[case] = {
            "median": float(np.median(a)),
            "p99": float(np.percentile(a, 99)),
            "p90": float(np.percentile(a, 90)),
            "min": float(a.min()),
        }
    out["ratio_analyze_over_posture"] = out["analyze"]["median"] / out["posture"]["median"]
    return out


def _loadavg() -> str:
    try:
        with open("/proc/loadavg") as fh:
            return " ".join(fh.read().split()[:3])
    except OSError:
        return "unknown"


def text_report(result: dict[str, Any]) -> str:
    lines = [
        f"Machine: {result['machine']['cpu']}, {result['machine']['cpu_count']} CPUs; "
        f"Python {result['machine']['python']}",
        f"Ticks per scenario: {result['ticks']} at {RATE:g} Hz, criterion {result['criterion']}; "
        "times in us per tick, median / p99",
        "",
    ]
    head = (
        f"{'scenario':20s}  {'posture med':>11s}  {'p99':>7s}  {'velocity med':>12s}  {'p99':>6s}  "
        f"{'analyze med':>11s}  {'p99':>7s}  {'analyze/posture':>15s}  {'check':>5s}  load avg "
        "(before; after)"
    )
    lines += [head, "-" * len(head)]
    for r in result["scenarios"]:
        lines.append(
            f"{r['scenario']:20s}  {r['posture']['median']:11.1f}  {r['posture']['p99']:7.0f}  "
            f"{r['velocity']['median']:12.1f}  {r['velocity']['p99']:6.0f}  "
            f"{r['analyze']['median']:11.1f}  {r['analyze']['p99']:7.0f}  "
            f"{r['ratio_analyze_over_posture']:15.2f}  {'ok' if r['agree'] else 'FAIL':>5s}  "
            f"{r['loadavg_before']}; {r['loadavg_after']}"
        )
    lines.append("")
    lines.append("Targets (informative; they do not change the exit status)")
    for line in result["targets"]:
        lines.append("  " + line)
    lines.append(f"\n(wall time {result['wall_time_s']:.0f} s)")
    return "\n".join(lines)


def evaluate_targets(rows: list[dict[str, Any]]) -> list[str]:
    out = []
    for key, label, bound in (
        ("posture", "posture-changing ticks, median", TARGETS["posture_median"]),
        ("posture_p99", "posture-changing ticks, p99", TARGETS["posture_p99"]),
        ("velocity", "velocity-only ticks, median", TARGETS["velocity_median"]),
    ):
        case, stat = (key, "median") if not key.endswith("_p99") else (key[:-4], "p99")
        worst = max(rows, key=lambda r: r[case][stat])
        value = worst[case][stat]
        out.append(
            f"[{'PASS' if value <= bound else 'FAIL'}] {label} <= {bound:g} us: worst {value:.1f} "
            f"us ({worst['scenario']})"
        )
    return out


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    if argv[:1] == ["--study"]:  # the wall study (issue 15, item 3): benchmarks/governor_study.py
        from benchmarks import governor_study

        return governor_study.main(argv[1:])
    if argv[:1] == [
        "--tolerance"
    ]:  # posture_tolerance in the wall experiment: benchmarks/governor_tolerance.py
        from benchmarks import governor_tolerance

        return governor_tolerance.main(argv[1:])
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--json", action="store_true", help="print one JSON object instead of the table"
    )
    ap.add_argument(
        "--ticks", type=int, default=2000, help="ticks per scenario (default 2000: 4 s at 500 Hz)"
    )
    ap.add_argument(
        "--scenarios", nargs="*", default=list(SCENARIOS), help="bundled scenario names"
    )
    ap.add_argument(
        "--criterion", choices=("com", "zmp"), default="com", help="the governor's criterion"
    )
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    for name in args.scenarios:
        progress(f"{name}: {args.ticks} ticks")
        rows.append(bench_scenario(name, max(2, args.ticks), args.criterion))
    result = {
        "benchmark": "impact_balance benchmarks/governor.py",
        "machine": machine_info(),
        "ticks": args.ticks,
        "criterion": args.criterion,
        "rate_hz": RATE,
        "unit": "us",
        "scenarios": rows,
        "targets": evaluate_targets(rows),
        "wall_time_s": time.perf_counter() - t0,
    }
    if args.json:
        print(json.dumps(result, allow_nan=False))
    else:
        print(text_report(result))
    return 0 if all(r["agree"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
