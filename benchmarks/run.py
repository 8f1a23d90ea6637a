#!/usr/bin/env python
"""Benchmark of impact_balance (issue 3, measurement part).

    python benchmarks/run.py [--json] [--repeat N] [--scenarios NAME ...] [--no-scaling]

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
   with the number of friction-cone edges of the impact model (8 to 64).

Times are wall-clock ``time.perf_counter`` per call, in microseconds, after a warm-up, with
the garbage collector paused; cases of one group are run round-robin so that drifts of the
machine hit them alike. Reported: median and p10-p90 (IQR and min in the JSON).

Exit status: 0 when every pypoman/impact_balance comparison agrees within ``--tol``
(default 1e-6 relative area), 1 otherwise. Performance targets are reported PASS/FAIL but
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
from benchmarks.speed.machine import load_average, machine_info
from benchmarks.speed.profiling import profile_report, profile_text
from benchmarks.speed.projection import pypoman
from benchmarks.speed.report import text_report
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
    args = ap.parse_args(argv)
    args.repeat = max(1, args.repeat)
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
        if args.profile:
            print(profile_text(result["profile"]))
        m = result["machine"]
        print(
            f"\n(wall time {result['wall_time_s']:.0f} s; load average before "
            f"{' '.join(map(str, m['load_average_before']))}, after "
            f"{' '.join(map(str, m['load_average_after']))})"
        )
    return 0 if result["checks"]["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
