#!/usr/bin/env python
"""Do the balance controllers keep each robot standing, and how many trials abort?

    python scripts/robots_standing.py [--controller id|ik] [--stand S] [--robots NAME ...]
        [--directions N] [--relative F ...] [--fixed-gains] [--json]

For each robot's bundled stance (the table below), with the controller's gains derived from the
robot (``impact_balance.sim.control.gains``):

1. one trial standing unpushed for ``--stand`` seconds (5 by default; a push of 1 micro-N s
   marks the start): its outcome, the largest base drop, trunk tilt and contact slip;
2. a small push grid (``impact_balance.sim.studies.push.push_test``): ``--directions``
   directions at each fraction ``--relative`` of the direction's boundary impulse (the one
   that puts the predicted CoM velocity on the CoM velocity area's boundary, so every robot
   gets the same test), each trial 1.5 s after its push: the share of aborted trials (the
   target is under 5 %) and the outcomes at each fraction.

The numbers of docs/studies/robots-standing.md come from this script. A small grid: about a
minute of CPU per robot on a 2-core machine.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from typing import Any

import numpy as np

from impact_balance.sim.studies.push import push_test
from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push

#: Robot name -> its bundled stance.
STANCES = {
    "go2": "go2_kick_three_feet",
    "anymal_c": "anymal_c_kick_three_feet",
    "solo12": "solo12_kick_three_feet",
    "jvrc1": "jvrc1_palm_push_two_feet",
    "talos": "palm_push_two_feet",
    "g1": "g1_two_feet",
    "romeo": "romeo_two_feet",
    "icub": "icub_two_feet",
}


def _trial_row(result: Any) -> dict[str, Any]:
    return {
        "outcome": result.outcome,
        "reason": result.reason,
        "detail": result.detail,
        "max_drop": float(result.max_drop),
        "max_trunk_tilt_deg": float(np.rad2deg(result.max_trunk_tilt)),
        "max_slip": float(result.max_slip),
    }


def measure(robot: str, args: argparse.Namespace) -> dict[str, Any]:
    """The standing trial and the push grid of one robot."""
    start = time.perf_counter()
    derived = not args.fixed_gains
    stand = BalanceTrialOptions(controller=args.controller, after=args.stand, robot_gains=derived)
    setup = BalanceSetup.create(STANCES[robot], options=stand)
    standing = _trial_row(run_balance_trial(setup, push=Push(0.0, 1e-6), options=stand))
    grid = BalanceTrialOptions(controller=args.controller, after=1.5, robot_gains=derived)
    result = push_test(
        setup.scenario, args.directions, relative=args.relative, options=grid, setup=setup
    )
    rows = [
        {
            "relative": o.relative,
            "outcome": o.outcome,
            "why": o.summary["detail"] or o.summary["reason"],
        }
        for o in result.outcomes
    ]
    outcomes = Counter(r["outcome"] for r in rows)
    by_level = {
        f"{level:g}": dict(Counter(r["outcome"] for r in rows if r["relative"] == level))
        for level in args.relative
    }
    aborted = [r["why"] for r in rows if r["outcome"] == "aborted"]
    mass = setup.analysis.stance.mass
    return {
        "robot": robot,
        "scenario": STANCES[robot],
        "mass": mass,
        "controller": args.controller,
        "standing": standing,
        "pushes": len(rows),
        "outcomes": dict(outcomes),
        "by_level": by_level,
        "aborted_share": outcomes["aborted"] / len(rows) if rows else 0.0,
        "aborted_reasons": dict(Counter(aborted)),
        "wall_time": time.perf_counter() - start,
    }


def main(argv: list[str] | None = None) -> int:
    """Run the measurement; print a Markdown table (or JSON)."""
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--controller", choices=("id", "ik"), default="id")
    p.add_argument("--stand", type=float, default=5.0, help="standing time, s (default 5)")
    p.add_argument("--robots", nargs="+", choices=sorted(STANCES), default=list(STANCES))
    p.add_argument("--directions", type=int, default=4)
    p.add_argument(
        "--relative", type=float, nargs="+", default=[0.5, 0.8], help="boundary fractions"
    )
    p.add_argument(
        "--fixed-gains",
        action="store_true",
        help="the gains' defaults (tuned on Talos) on every robot, not derived from it",
    )
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    results = []
    for robot in args.robots:
        results.append(measure(robot, args))
        print(f"{robot}: done in {results[-1]['wall_time']:.0f} s", file=sys.stderr)
    if args.json:
        print(json.dumps(results, indent=1))
        return 0
    levels = " ".join(f"{x:g}" for x in args.relative)
    gains = "fixed (Talos')" if args.fixed_gains else "derived from the robot"
    print(
        f"controller {args.controller}, gains {gains}; {args.directions} directions x boundary "
        f"{levels}"
    )
    print(
        f"| robot | scenario | standing {args.stand:g} s | drop / trunk / slip | pushes | aborted "
        "| outcomes by boundary fraction |"
    )
    print("|---|---|---|---|---|---|---|")
    for r in results:
        s = r["standing"]
        outcomes = "; ".join(
            f"x{level}: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items()))
            for level, counts in r["by_level"].items()
        )
        print(
            f"| {r['robot']} | `{r['scenario']}` | {s['outcome']} | "
            f"{100 * s['max_drop']:.1f} cm / {s['max_trunk_tilt_deg']:.1f}° / "
            f"{100 * s['max_slip']:.1f} cm | {r['pushes']} | {100 * r['aborted_share']:.0f} % | "
            f"{outcomes} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
