#!/usr/bin/env python
"""Issue 28: the governor's tick in the MuJoCo approach loop, pooled over trials.

    python benchmarks/approach.py [--scenario NAME] [--trials N] [--json]
    python benchmarks/approach.py --baseline DIR [--trials N] ...  # ratios to another tree

Each trial is ``impact-balance approach NAME --reference V --governor com --wall-distance D``
(the command itself, in a worker process: ``benchmarks/speed/approach.py``), with every call of
the governor's ``limit`` timed: the posture-changing ticks of a governed approach in the MuJoCo
loop, between the simulation's steps (their caches cold, unlike ``benchmarks/governor.py``'s
replayed ticks). One untimed warm-up trial per side first. The ticks of all trials are pooled:
median and p99 (us), with the load average beside.

With ``--baseline DIR`` (another checkout or installed tree of the project), the current code
and DIR's run in two worker processes, one trial each in turn (A B, B A, ...:
``benchmarks/speed/interleave.py``), and the pooled median and p99 are reported as the ratio
current / pooled baseline, beside the median of the per-trial ratios with its interval.

Exit status 2 for a bad ``--baseline`` or option, 1 if a worker or a trial fails, 130 when
interrupted, else 0.
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
from benchmarks.speed.timing import progress

__all__ = ["main", "pooled"]

JOB = "benchmarks.speed.approach:approach_job"


def pooled(samples: list[list[float]]) -> dict[str, Any]:
    """Median and p99 (us) of the ticks of every trial together, and their count."""
    ticks = np.concatenate([np.asarray(s, dtype=float) for s in samples]) if samples else []
    if len(ticks) == 0:
        return {"median": None, "p99": None, "count": 0}
    return {
        "median": float(np.median(ticks)),
        "p99": float(np.percentile(ticks, 99)),
        "count": len(ticks),
    }


def measure(args: argparse.Namespace) -> dict[str, Any]:
    """The interleaved run: per side the pooled ticks and the trials; ratios with a baseline."""
    trees = {"current": current_tree()}
    if args.baseline is not None:
        trees["baseline"] = resolve_tree(args.baseline)
    if args.trials < 1:
        raise BaselineError("--trials", args.trials, "must be an integer >= 1")
    params = {
        "scenario": args.scenario,
        "reference": args.reference,
        "governor": args.governor,
        "wall_distances": args.wall_distances,
    }
    run = run_interleaved(JOB, params, trees, args.trials, progress)
    key, replayed = f"{args.scenario}/tick", f"{args.scenario}/replayed"
    sides = {}
    for side in trees:
        blocks = run.blocks[side]
        sides[side] = {
            "tree": run.trees[side],
            "warm_up": run.info[side]["info"]["warm_up"],
            "tick_us": pooled([b["samples"][key] for b in blocks]),
            "replayed_tick_us": pooled([b["samples"][replayed] for b in blocks]),
            "trials": [b["checks"] for b in blocks],
        }
    loads = [row[0] for row in run.load_average]
    out: dict[str, Any] = {
        "scenario": args.scenario,
        "reference": args.reference,
        "governor": args.governor,
        "trials_per_side": args.trials,
        "order": run.order,
        "load_average_per_trial": run.load_average,
        "load_average_1min_range": [min(loads), max(loads)],
        "sides": sides,
        "interleaved_wall_time_s": run.wall_time_s,
    }
    if "baseline" in trees:
        ratios = compare(run)
        for name, k in (("", key), ("replayed_", replayed)):
            now, then = sides["current"][f"{name}tick_us"], sides["baseline"][f"{name}tick_us"]
            out[f"{name}pooled_ratio"] = {
                stat: (now[stat] / then[stat] if now[stat] and then[stat] else None)
                for stat in ("median", "p99")
            }
            out[f"{name}per_trial_ratio"] = ratios[k]["ratio"] if k in ratios else None
    return out


def report(result: dict[str, Any]) -> str:
    r = result["approach"]
    lines = [
        f"{r['scenario']}: governed approach ({r['governor']} governor, reference "
        f"{r['reference']:g} m/s), {r['trials_per_side']} timed trials per side after one warm-up; "
        f"load average (1 min) {r['load_average_1min_range'][0]:.2f} to "
        f"{r['load_average_1min_range'][1]:.2f}",
        f"{'side':9s}  {'ticks':>5s}  {'median us':>9s}  {'p99 us':>7s}  "
        f"{'replayed median':>15s}  {'p99':>5s}  outcomes  tree",
    ]
    for side, s in r["sides"].items():
        t, w = s["tick_us"], s["replayed_tick_us"]
        outcomes = ",".join(sorted({str(trial["outcome"]) for trial in s["trials"]}))
        lines.append(
            f"{side:9s}  {t['count']:5d}  {_us(t['median'], 1):>9s}  {_us(t['p99'], 0):>7s}  "
            f"{_us(w['median'], 1):>15s}  {_us(w['p99'], 0):>5s}  {outcomes:8s}  {s['tree']}"
        )
    for name, label in (("", "loop ticks"), ("replayed_", "replayed ticks")):
        if f"{name}pooled_ratio" not in r:
            continue
        pr, per = r[f"{name}pooled_ratio"], r[f"{name}per_trial_ratio"]
        line = (
            f"{label}, ratio current / baseline, pooled: median {_us(pr['median'], 2)}, "
            f"p99 {_us(pr['p99'], 2)}"
        )
        if per is not None:
            line += (
                f"; per trial: median {_us(per['median']['median'], 2)} "
                f"[{_us(per['median']['low'], 2)}-{_us(per['median']['high'], 2)}], p99 "
                f"{_us(per['p99']['median'], 2)} "
                f"[{_us(per['p99']['low'], 2)}-{_us(per['p99']['high'], 2)}]"
            )
        lines.append(line)
    lines.append(f"(interleaved wall time {r['interleaved_wall_time_s']:.0f} s)")
    return "\n".join(lines)


def _us(x: float | None, digits: int) -> str:
    return "-" if x is None else f"{x:.{digits}f}"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scenario", default="g1_two_feet", help="bundled scenario with an impact")
    ap.add_argument("--trials", type=int, default=6, help="timed trials per side (default 6)")
    ap.add_argument("--reference", type=float, default=0.8, help="reference speed, m/s")
    ap.add_argument("--governor", choices=("com", "zmp"), default="com")
    ap.add_argument(
        "--wall-distances",
        type=float,
        nargs="+",
        default=[0.15],
        metavar="D",
        help="wall distances (m), cycled over the trials (default 0.15)",
    )
    ap.add_argument("--baseline", metavar="DIR", help="also run DIR's tree, interleaved")
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    status, approach = exit_status(lambda: measure(args))
    if status:
        return status
    result = {
        "benchmark": "impact_balance benchmarks/approach.py",
        "machine": machine_info(),
        "unit": "us",
        "approach": approach,
        "wall_time_s": time.perf_counter() - t0,
    }
    if args.json:
        print(json.dumps(result, allow_nan=False))
    else:
        print(report(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
