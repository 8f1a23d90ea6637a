"""Rerun a held-out set's pushes the default criterion called safe, with the tree's controller.

Reads a set's ``pushes.csv`` (``studies/held_out_results_9/``), keeps one stance's pelvis pushes
with ``default_safe`` 1 and ``relative`` in the band (or all with ``--all``), runs each as
``push-test --controller id`` runs it (``hand_contact.py``'s trial: the push's 0.05 s at 0.3 s,
2.5 s after it) and prints one JSON line per push: the record's outcome beside this tree's.

    python benchmarks/hand_hold_band.py studies/held_out_results_9/pushes.csv \
        studies/held_out_9/g1_right_foot_right_hand_table_left_toe_front.yaml --body pelvis
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

from impact_balance.sim.trials.balance_trial import run_balance_trial
from impact_balance.sim.trials.setup import BalanceSetup, BalanceTrialOptions, Push


def main(argv: list[str] | None = None) -> int:
    """Run the pushes and print one line each, then the counts."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("records")
    p.add_argument("scenario")
    p.add_argument("--body", default="base_link")
    p.add_argument("--band", nargs=2, type=float, default=(0.75, 1.05))
    p.add_argument("--all", action="store_true", help="every pelvis push, not only band safe")
    p.add_argument("--after", type=float, default=2.5)
    args = p.parse_args(argv)
    stance = Path(args.scenario).stem
    rows = [
        r
        for r in csv.DictReader(open(args.records))
        if r["stance"] == stance
        and r["body"] == "pelvis"
        and (
            args.all
            or (
                r["default_safe"] == "1"
                and args.band[0] - 1e-9 <= float(r["relative"]) <= args.band[1] + 1e-9
            )
        )
    ]
    options = BalanceTrialOptions(controller="id", after=args.after)
    setup = BalanceSetup.create(args.scenario, "servo", options)
    failed = 0
    for r in rows:
        push = Push(
            math.radians(float(r["direction_deg"])),
            float(r["impulse_Ns"]),
            0.05,
            options.settle,
            args.body,
        )
        s = run_balance_trial(setup, push=push, options=options).summary()
        failed += bool(s["strict_fail"])
        print(
            json.dumps(
                {
                    "direction_deg": float(r["direction_deg"]),
                    "relative": float(r["relative"]),
                    "record": [r["outcome"], r["strict_fail"] == "1"],
                    "now": [s["outcome"], s["strict_fail"], s.get("reason")],
                    "events": [(e["contact"], e["kind"], round(e["time"], 3)) for e in s["events"]][
                        :3
                    ],
                }
            ),
            flush=True,
        )
    print(json.dumps({"stance": stance, "pushes": len(rows), "failed_strictly": failed}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
