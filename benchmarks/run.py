#!/usr/bin/env python
"""Benchmark of impact_balance (issue 3, measurement part).

    python benchmarks/run.py [--json] [--repeat N] [--scenarios NAME ...] [--no-scaling]
    python benchmarks/run.py --baseline DIR [--blocks B] ...   # also: ratios to another tree

Measures, in one run and on the same polytopes:

1. the CoM-velocity-area projection (``impact_balance.projection.project_polytope``, what
   ``areas_from_polytope`` calls: the compiled parametric walk) against
   ``pypoman.project_polytope(..., method="bretl")`` and against the project's own
   LP-per-edge Bretl path (HiGHS), given the same inequality, equality and projection
   matrices, and checks at every repetition that all give the same polygon (relative area of
   the symmetric difference);
2. the whole pipeline from a configuration to the answer, stage by stage, and
   ``impact_balance.analyze`` end to end (YAML loading excluded);
3. the maximum contact velocity alone, given the area;
4. scaling with the number of contacts (Talos, 1 to 4, with and without torque limits) and
   with the number of friction-cone edges of the impact model (8 to 64);
5. with ``--baseline DIR`` (another checkout or installed tree of the project): the projection,
   the stages and ``analyze()`` of every stance, the current code and DIR's timed in the same
   run, each in its own worker process, in B alternating blocks of N/B calls per case
   (``benchmarks/speed/interleave.py``), reported as ratios current / baseline (median of the
   per-block ratios, with an interval over blocks) beside both sides' times.

Times are wall-clock ``time.perf_counter`` per call, in microseconds, after a warm-up, with
the garbage collector paused; cases of one group are run round-robin so that drifts of the
machine hit them alike. Reported: median and p10-p90 (IQR and min in the JSON).

Exit status: 0 when every pypoman/impact_balance comparison agrees within ``--tol``
(default 1e-6 relative area), 1 otherwise (or when a ``--baseline`` worker fails), 2 for a bad
``--baseline`` or ``--blocks``. Performance targets are reported PASS/FAIL but
never change the exit status.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from pathlib import Path
from typing import Any

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

import impact_balance as ib
from benchmarks.speed.checks import answer_checks
from benchmarks.speed.interleave import (
    BaselineError,
    WorkerError,
    compare,
    current_tree,
    resolve_tree,
    run_interleaved,
)
from benchmarks.speed.machine import load_average, machine_info
from benchmarks.speed.profiling import profile_report, profile_text
from benchmarks.speed.projection import pypoman
from benchmarks.speed.report import baseline_text, text_report
from benchmarks.speed.scaling import bench_cone_edges, bench_contacts
from benchmarks.speed.stances import bench_stance
from benchmarks.speed.targets import evaluate_targets
from benchmarks.speed.timing import progress


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0], formatter_class=argparse.RawDescriptionHelpFormatter
    )
    ap.add_argument(
        "--json", action="store_true", help="print one JSON object instead of the text tables"
    )
    ap.add_argument(
        "--repeat", type=int, default=50, help="timed repetitions per case (default 50)"
    )
    ap.add_argument(
        "--warmup", type=int, default=3, help="untimed warm-up calls per case (default 3)"
    )
    ap.add_argument("--scenarios", nargs="*", help="bundled scenario names (default: all)")
    ap.add_argument("--no-scaling", action="store_true", help="skip the scaling part")
    ap.add_argument(
        "--pypoman-scale",
        type=float,
        default=1e3,
        help="pypoman projects onto SCALE*F (its tolerances are absolute: 1e-4, 1e-2); default 1e3",
    )
    ap.add_argument(
        "--tol",
        type=float,
        default=1e-6,
        help="max relative area of the symmetric difference (default 1e-6)",
    )
    ap.add_argument(
        "--profile",
        action="store_true",
        help="also profile analyze() and the projection (cProfile + micro-breakdown)",
    )
    ap.add_argument(
        "--seed",
        type=int,
        default=0,
        help="seed of numpy's global RNG for pypoman (seed + repetition)",
    )
    ap.add_argument(
        "--no-sweep", action="store_true", help="skip the sweep rates (benchmarks/sweep.py --quick)"
    )
    ap.add_argument(
        "--baseline",
        metavar="DIR",
        help="also time DIR (a checkout or installed tree of the project) interleaved with the "
        "current code (part 5), and report ratios current / baseline",
    )
    ap.add_argument(
        "--blocks",
        type=int,
        default=10,
        help="with --baseline: alternating blocks per side (default 10; --repeat split among them)",
    )
    args = ap.parse_args(argv)
    args.repeat = max(1, args.repeat)
    try:
        trees = None if args.baseline is None else _trees(args)
    except BaselineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    args.repeat_cheap = 10 * args.repeat
    if pypoman is None:
        progress("warning: pypoman is not installed: no comparison")
    warnings.simplefilter("ignore")  # pypoman/cvxopt chatter must not pollute --json

    t_start = time.perf_counter()
    names = args.scenarios or list(ib.bundled_scenarios())
    stances: dict[str, Any] = {name: bench_stance(name, args) for name in names}
    result: dict[str, Any] = {
        "benchmark": "impact_balance benchmarks/run.py",
        "machine": machine_info(),
        "settings": {
            "repeat": args.repeat,
            "repeat_cheap": args.repeat_cheap,
            "warmup": args.warmup,
            "pypoman_scale": args.pypoman_scale,
            "tol": args.tol,
            "seed": args.seed,
            "unit": "us",
        },
        "stances": stances,
    }
    if not args.no_scaling:
        progress("scaling: contacts ...")
        contacts = bench_contacts(args)
        progress("scaling: cone edges ...")
        result["scaling"] = {"contacts": contacts, "cone_edges": bench_cone_edges(args)}

    if trees is not None:
        try:
            result["baseline"] = bench_baseline(trees, names, args)
        except WorkerError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        except KeyboardInterrupt:
            print("error: interrupted", file=sys.stderr)
            return 130
    result["checks"] = answer_checks(result, args.tol)
    result["targets"] = evaluate_targets(result)
    if args.profile:
        progress("profile ...")
        result["profile"] = profile_report(args)
    if not args.no_sweep:
        progress("sweep (benchmarks/sweep.py --quick) ...")
        from sweep import measure as measure_sweep  # benchmarks/sweep.py, beside this file

        result["sweep"] = measure_sweep(quick=True)
    result["wall_time_s"] = time.perf_counter() - t_start
    result["machine"]["load_average_after"] = load_average()

    if args.json:
        print(json.dumps(result, indent=1, default=float))
    else:
        print(text_report(result, args))
        if "baseline" in result:
            print("\n" + baseline_text(result["baseline"]))
        if args.profile:
            print(profile_text(result["profile"]))
        m = result["machine"]
        print(
            f"\n(wall time {result['wall_time_s']:.0f} s; load average before "
            f"{' '.join(map(str, m['load_average_before']))}, after "
            f"{' '.join(map(str, m['load_average_after']))})"
        )
    return 0 if result["checks"]["ok"] else 1


def _trees(args: argparse.Namespace) -> dict[str, Path]:
    """The two sides of ``--baseline``, checked before anything is timed."""
    if args.blocks < 1:
        raise BaselineError("--blocks", args.blocks, "must be an integer >= 1")
    return {"current": current_tree(), "baseline": resolve_tree(args.baseline)}


def bench_baseline(trees: dict[str, Path], names: list[str], args: Any) -> dict[str, Any]:
    """Part 5: the stances' projection, stages and analyze(), both trees interleaved."""
    params = {"scenarios": names, "repeat": args.repeat, "warmup": args.warmup}
    progress(f"baseline: {args.blocks} interleaved blocks ...")
    run = run_interleaved(
        "benchmarks.speed.stage_job:stage_job", params, trees, args.blocks, progress
    )
    ratios = compare(run)
    answers = {side: run.info[side]["info"]["answers"] for side in trees}
    stances = {}
    for name in names:
        cases = {key.split("/", 1)[1]: q for key, q in ratios.items() if key.startswith(name + "/")}
        same = answers["current"].get(name) == answers["baseline"].get(name)
        stances[name] = {"cases": cases, "same_answer": same}
    loads = [row[0] for row in run.load_average]
    return {
        "trees": run.trees,
        "blocks": args.blocks,
        "answers": answers,
        "load_average_per_block": run.load_average,
        "load_average_1min_range": [min(loads), max(loads)],
        "stances": stances,
        "interleaved_wall_time_s": run.wall_time_s,
    }


if __name__ == "__main__":
    sys.exit(main())
