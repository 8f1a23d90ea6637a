#!/usr/bin/env python
"""Issue 15 targets: the governor's time per control tick, beside a full ``analyze()`` per tick.

    python benchmarks/governor.py [--json] [--ticks N] [--scenarios NAME ...] [--criterion com|zmp]
    python benchmarks/governor.py --baseline DIR [--blocks B] ...  # ratios to another tree
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

With ``--baseline DIR`` (another checkout or installed tree of the project), the current code
and DIR's are timed in the same run, each in its own worker process, in B alternating blocks of
N/B ticks per scenario (``benchmarks/speed/interleave.py``), and every quantity is reported as
the ratio current / baseline (median of the per-block ratios, with an interval over blocks)
beside both sides' absolute times and the load average.

Targets (informative; issue 15): posture-changing ticks median <= 250 us and p99 <= 1 ms;
velocity-only ticks median <= 20 us. Exit status 1 if an answer disagrees, 2 for a bad
``--baseline`` or ``--blocks``, 1 if a worker fails, else 0.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.speed.interleave import (
    BaselineError,
    compare,
    current_tree,
    exit_status,
    resolve_tree,
    run_interleaved,
)
from benchmarks.speed.machine import machine_info
from benchmarks.speed.ticks import RATE, TickBench, trajectory
from benchmarks.speed.timing import progress

#: The wall study's scenarios (issue 15, item 3).
SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")
TARGETS = {"posture_median": 250.0, "posture_p99": 1000.0, "velocity_median": 20.0}
CASES = ("posture", "velocity", "analyze")

__all__ = ["SCENARIOS", "bench_baseline", "bench_scenario", "main", "trajectory"]


def bench_scenario(name: str, ticks: int, criterion: str) -> dict[str, Any]:
    bench = TickBench(name, ticks, criterion)
    load_before = _loadavg()
    out = bench.run(0, ticks)
    load_after = _loadavg()
    times = out.pop("times")
    result: dict[str, Any] = {
        "scenario": name,
        "criterion": criterion,
        "ticks": ticks,
        "loadavg_before": load_before,
        "loadavg_after": load_after,
        **out,
    }
    for case, samples in times.items():
        a = np.asarray(samples)
        result[case] = {
            "median": float(np.median(a)),
            "p99": float(np.percentile(a, 99)),
            "p90": float(np.percentile(a, 90)),
            "min": float(a.min()),
        }
    result["ratio_analyze_over_posture"] = result["analyze"]["median"] / result["posture"]["median"]
    return result


def bench_baseline(
    baseline: str, names: list[str], ticks: int, criterion: str, blocks: int
) -> dict[str, Any]:
    """The current code and the ``baseline`` tree, interleaved in ``blocks`` blocks of ticks."""
    trees = {"current": current_tree(), "baseline": resolve_tree(baseline)}
    if not 1 <= blocks <= ticks:
        raise BaselineError("--blocks", blocks, f"must be an integer in [1, --ticks = {ticks}]")
    params = {"scenarios": names, "ticks": ticks, "criterion": criterion}
    run = run_interleaved("benchmarks.speed.ticks:governor_job", params, trees, blocks, progress)
    ratios = compare(run)
    rows = []
    for name in names:
        checks = {side: [b["checks"][name] for b in run.blocks[side]] for side in trees}
        rows.append(
            {
                "scenario": name,
                "agree": {side: all(c["agree"] for c in checks[side]) for side in trees},
                "worst_difference": {
                    side: max(c["worst_difference"] for c in checks[side]) for side in trees
                },
                **{case: ratios[f"{name}/{case}"] for case in CASES},
            }
        )
    loads = [row[0] for row in run.load_average]
    return {
        "trees": run.trees,
        "blocks": blocks,
        "ticks_per_block": ticks // blocks,
        "order": run.order,
        "load_average_per_block": run.load_average,
        "load_average_1min_range": [min(loads), max(loads)],
        "scenarios": rows,
        "interleaved_wall_time_s": run.wall_time_s,
    }


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


def _ratio(r: dict[str, Any]) -> str:
    if r["median"] is None:
        return "-"
    return f"{r['median']:.2f} [{r['low']:.2f}-{r['high']:.2f}]"


def baseline_report(result: dict[str, Any]) -> str:
    """The side-by-side table of ``--baseline``."""
    b = result["baseline"]
    coverage = min(
        row[case]["ratio"]["median"]["coverage"] for row in b["scenarios"] for case in CASES
    )
    lines = [
        f"Side by side, interleaved: current {b['trees']['current']} / baseline "
        f"{b['trees']['baseline']}",
        f"{b['blocks']} blocks of {b['ticks_per_block']} ticks per scenario and side, "
        f"alternating; load average (1 min) {b['load_average_1min_range'][0]:.2f} to "
        f"{b['load_average_1min_range'][1]:.2f} over the blocks",
        "times in us per tick over all blocks (median / p99); ratio = current / baseline, "
        f"median of the per-block ratios [interval over blocks, coverage >= {coverage:.0%}]",
        "",
    ]
    head = (
        f"{'scenario':20s}  {'case':8s}  {'current':>7s}  {'p99':>6s}  {'baseline':>8s}  "
        f"{'p99':>6s}  {'ratio median':>18s}  {'ratio p99':>18s}  {'check':>5s}"
    )
    lines += [head, "-" * len(head)]
    for row in b["scenarios"]:
        ok = "ok" if all(row["agree"].values()) else "FAIL"
        for case in CASES:
            q = row[case]
            lines.append(
                f"{row['scenario'] if case == CASES[0] else '':20s}  {case:8s}  "
                f"{q['current']['median']:7.1f}  {q['current']['p99']:6.0f}  "
                f"{q['baseline']['median']:8.1f}  {q['baseline']['p99']:6.0f}  "
                f"{_ratio(q['ratio']['median']):>18s}  {_ratio(q['ratio']['p99']):>18s}  "
                f"{ok if case == CASES[0] else '':>5s}"
            )
    lines.append(f"\n(interleaved wall time {b['interleaved_wall_time_s']:.0f} s)")
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
    ap.add_argument(
        "--baseline",
        metavar="DIR",
        help="also time DIR (a checkout or installed tree of the project) interleaved with the "
        "current code, and report ratios current / baseline",
    )
    ap.add_argument(
        "--blocks",
        type=int,
        default=10,
        help="with --baseline: alternating blocks per side (default 10; --ticks split among them)",
    )
    args = ap.parse_args(argv)
    if args.baseline is not None:
        return _main_baseline(args)
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


def _main_baseline(args: argparse.Namespace) -> int:
    """``--baseline``: the interleaved run only (both sides in worker processes)."""
    t0 = time.perf_counter()
    ticks = max(2, args.ticks)
    status, side_by_side = exit_status(
        lambda: bench_baseline(
            args.baseline, list(args.scenarios), ticks, args.criterion, args.blocks
        )
    )
    if status:
        return status
    result = {
        "benchmark": "impact_balance benchmarks/governor.py --baseline",
        "machine": machine_info(),
        "ticks": ticks,
        "criterion": args.criterion,
        "rate_hz": RATE,
        "unit": "us",
        "baseline": side_by_side,
        "wall_time_s": time.perf_counter() - t0,
    }
    if args.json:
        print(json.dumps(result, allow_nan=False))
    else:
        print(baseline_report(result))
    agree = all(all(r["agree"].values()) for r in side_by_side["scenarios"])
    return 0 if agree else 1


if __name__ == "__main__":
    sys.exit(main())
