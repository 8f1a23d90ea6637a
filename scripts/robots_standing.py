#!/usr/bin/env python
"""Do the balance controllers keep each robot standing, and how many trials abort?

    python scripts/robots_standing.py [--controller id|ik] [--stand S] [--robots NAME ...]
        [--directions N] [--speeds V ...] [--json]

For each robot's bundled stance (the table below), with the controller's gains derived from the
robot (``impact_balance.sim.control.gains``):

1. one trial standing unpushed for ``--stand`` seconds (5 by default; a push of 1 micro-N s
   marks the start): its outcome, the largest base drop, trunk tilt and contact slip;
2. a small push grid: ``--directions`` directions at each of ``--speeds`` CoM velocity jumps
   (the impulse is the robot's mass times the speed, so every robot gets the same test), each
   trial 1.5 s after its push: the share of aborted trials (the target is under 5 %) and
   the outcomes.

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
    stand = BalanceTrialOptions(controller=args.controller, after=args.stand)
    setup = BalanceSetup.create(STANCES[robot], options=stand)
    standing = _trial_row(run_balance_trial(setup, push=Push(0.0, 1e-6), options=stand))
    grid = BalanceTrialOptions(controller=args.controller, after=1.5)
    mass = setup.analysis.stance.mass
    rows = []
    for speed in args.speeds:
        for k in range(args.directions):
            push = Push(2 * np.pi * k / args.directions, mass * speed)
            row = _trial_row(run_balance_trial(setup, push=push, options=grid))
            rows.append({"speed": speed, "direction": push.direction, **row})
    outcomes = Counter(r["outcome"] for r in rows)
    aborted = [r["detail"] or r["reason"] for r in rows if r["outcome"] == "aborted"]
    return {
        "robot": robot,
        "scenario": STANCES[robot],
        "mass": mass,
        "controller": args.controller,
        "standing": standing,
        "pushes": len(rows),
        "outcomes": dict(outcomes),
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
    p.add_argument("--speeds", type=float, nargs="+", default=[0.05, 0.1], help="m/s")
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    results = []
    for robot in args.robots:
        results.append(measure(robot, args))
        print(f"{robot}: done in {results[-1]['wall_time']:.0f} s", file=sys.stderr)
    if args.json:
        print(json.dumps(results, indent=1))
        return 0
    print(
        f"controller {args.controller}; push grid {args.directions} directions x {args.speeds} m/s"
    )
    print("| robot | scenario | standing 5 s | drop / trunk / slip | pushes | aborted | outcomes |")
    print("|---|---|---|---|---|---|---|")
    for r in results:
        s = r["standing"]
        outcomes = ", ".join(f"{k} {v}" for k, v in sorted(r["outcomes"].items()))
        print(
            f"| {r['robot']} | `{r['scenario']}` | {s['outcome']} | "
            f"{100 * s['max_drop']:.1f} cm / {s['max_trunk_tilt_deg']:.1f}° / "
            f"{100 * s['max_slip']:.1f} cm | {r['pushes']} | {100 * r['aborted_share']:.0f} % | "
            f"{outcomes} |"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
