"""How the ``id`` controller's margins were chosen: on the tuning stance only, before any score.

    python benchmarks/tune_id.py [--scenario talos_tuning_stagger] [--directions 8]
                                 [--relative 0.7 0.85 1.0]

The held-out protocol (docs/validation.md): the balance controller's gains are frozen before any
scenario is scored, and nothing is tuned on a scenario whose score is reported. This script is the
only tuning: the inverse-dynamics QP's centre-of-pressure margin (soles shrunk by it) and its ZMP
margin, each in {0, 5, 10} mm, on ``talos_tuning_stagger`` (a stance that is never scored), with
pushes at the torso and at the pelvis at 0.7, 0.85 and 1.0 of each direction's boundary impulse
(48 pushes per pair). The margins with the fewest falls win (ties: fewer broken contacts, then the
smaller margins). Every other gain keeps the value it had.
It takes a few minutes; it prints a markdown table and the chosen margins.
"""

from __future__ import annotations

import argparse
import dataclasses
import itertools
import os
import sys
import time

from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.studies.push import push_test
from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

MARGINS = (0.0, 0.005, 0.01)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenario", default="talos_tuning_stagger")
    p.add_argument("--directions", type=int, default=8)
    p.add_argument("--relative", type=float, nargs="+", default=[0.7, 0.85, 1.0])
    p.add_argument("--bodies", nargs="+", default=["torso", "base_link"])
    args = p.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}", flush=True)
    rows = []
    print("| CoP margin (mm) | ZMP margin (mm) | pushes | fell | contact broken | wall s |")
    print("|---|---|---|---|---|---|", flush=True)
    for cop, zmp in itertools.product(MARGINS, MARGINS):
        gains = dataclasses.replace(InverseDynamicsGains(), cop_margin=cop, zmp_margin=zmp)
        options = BalanceTrialOptions(controller="id", id_gains=gains)
        t0 = time.perf_counter()
        setup = BalanceSetup.create(args.scenario, "servo", options)
        fell = broken = n = 0
        for body in args.bodies:
            r = push_test(
                args.scenario,
                args.directions,
                relative=args.relative,
                options=options,
                setup=setup,
                body=None if body == "torso" else body,
            )
            counts = r.counts()["outcomes"]
            fell, broken, n = (
                fell + counts["fell"],
                broken + counts["contact_broken"],
                n + len(r.outcomes),
            )
        rows.append((fell, broken, cop + zmp, cop, zmp))
        print(
            f"| {1e3 * cop:g} | {1e3 * zmp:g} | {n} | {fell} | {broken} | "
            f"{time.perf_counter() - t0:.0f} |",
            flush=True,
        )
    best = min(rows)
    print(
        f"\nchosen: CoP margin {1e3 * best[3]:g} mm, ZMP margin {1e3 * best[4]:g} mm "
        f"({best[0]} falls, {best[1]} contact breaks)"
    )
    print(f"load average after: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
