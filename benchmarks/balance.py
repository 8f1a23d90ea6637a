"""Issue 10 measurements: fall thresholds against both criteria, push recovery, speed of a trial.

    python benchmarks/balance.py [--scenarios NAME ...] [--joints servo rigid] [--push-scenario palm_push_ramp]
                                 [--directions 16] [--magnitudes 10 20 30 40 50 60] [--json FILE]
                                 [--controller ik|id]

Prints a markdown table per part and, with ``--json``, writes every number to FILE. It takes minutes
(every trial simulates about 3 s); it is a measurement, not a test.
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import numpy as np

from impact_balance.scenario import bundled_scenarios, load_scenario
from impact_balance.sim.balance_trial import BalanceSetup, BalanceTrialOptions, Push, run_balance_trial
from impact_balance.sim.push import DEFAULT_MAGNITUDES, push_test
from impact_balance.sim.validate import validate


def speed(scenario: str, repeats: int = 3, controller: str = "ik") -> dict:
    """Wall time of a 3 s trial standing with the controller on (500 Hz control, 1 ms steps)."""
    setup = BalanceSetup.create(scenario, options=BalanceTrialOptions(controller=controller))
    ratios = []
    for _ in range(repeats):
        r = run_balance_trial(setup, push=Push(0.0, 1e-6, 0.01, start=0.0),
                              options=BalanceTrialOptions(after=2.99, controller=controller))
        ratios.append(r.sim_time / r.wall_time)
    return {"scenario": scenario, "sim_time": r.sim_time, "real_time_factor": ratios, "median": float(np.median(ratios))}


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenarios", nargs="*", help="impact scenarios (default: every bundled one)")
    p.add_argument("--joints", nargs="+", default=["servo", "rigid"])
    p.add_argument("--push-scenario", default="palm_push_ramp")
    p.add_argument("--push-body", default=None, help="MuJoCo body pushed (default: the torso)")
    p.add_argument("--directions", type=int, default=16)
    p.add_argument("--magnitudes", type=float, nargs="+", default=list(DEFAULT_MAGNITUDES))
    p.add_argument("--skip", nargs="*", default=[], choices=["speed", "validate", "push"])
    p.add_argument("--json", metavar="FILE")
    p.add_argument("--controller", default="ik", choices=["ik", "id"],
                   help="ik: pink IK -> position servos; id: inverse-dynamics QP -> torque motors")
    args = p.parse_args()
    out: dict = {"controller": args.controller}
    options = BalanceTrialOptions(controller=args.controller)
    if "speed" not in args.skip:
        out["speed"] = speed("palm_push_two_feet", controller=args.controller)
        print(f"## Speed\n\n3 s trial, controller on: {out['speed']['median']:.2f}x real time "
              f"(runs: {', '.join(f'{x:.2f}' for x in out['speed']['real_time_factor'])})\n", flush=True)
    if "validate" not in args.skip:
        names = args.scenarios or [n for n in bundled_scenarios() if load_scenario(n).impact is not None]
        rows = []
        print("## Fall thresholds (m/s, commanded approach speed)\n")
        print("| scenario | joints | CoM crit. composite | CoM crit. joint_space | ZMP crit. composite | ZMP crit. joint_space "
              "| survived | fell | approach measured at 'fell' | reason | fastest survived: measured, CoM vel. margin "
              "| trials | wall s |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
        for name in names:
            for joints in args.joints:
                t0 = time.perf_counter()
                r = validate(name, joints, options=options).to_dict()
                r.pop("controller", None)
                rows.append(r)
                pc, pz = r["predicted"]["com_criterion"], r["predicted"]["zmp_criterion"]
                e = r["empirical"]
                at_fell = [t for t in r["trials"] if t["fell"] and t["speed"] == e["fell"]]
                meas = at_fell[0]["approach_speed_measured"] if at_fell else None
                reason = at_fell[0]["reason"] if at_fell else "-"
                f = lambda x: "-" if x is None else f"{x:.3f}"
                # The fastest survived trial: how fast the limb really went, and how close the CoM came.
                ok = [t for t in r["trials"] if not t["fell"]]
                best = max(ok, key=lambda t: t["speed"]) if ok else None
                fastest = (f"{f(best['approach_speed_measured'])}, {f(best['min_com_velocity_margin'])}"
                           if best else "-")
                print(f"| {name} | {joints} | {f(pc['composite'])} | {f(pc['joint_space'])} | {f(pz['composite'])} | "
                      f"{f(pz['joint_space'])} | {f(e['survived'])} | {f(e['fell'])} | {f(meas)} | {reason} | {fastest} | "
                      f"{len(r['trials'])} | {time.perf_counter() - t0:.0f} |", flush=True)
        out["validate"] = rows
    if "push" not in args.skip:
        t0 = time.perf_counter()
        r = push_test(args.push_scenario, args.directions, args.magnitudes, 0.05, args.push_body, options=options)
        d = r.to_dict()
        out["push"] = d
        print(f"\n## Pushes on {args.push_scenario} at {args.push_body or 'the torso'} ({len(r.outcomes)} pushes, 50 ms, {time.perf_counter() - t0:.0f} s)\n")
        print("| magnitude (N s) | fell | CoM criterion safe | ZMP criterion safe | reasons |")
        print("|---|---|---|---|---|")
        for m in args.magnitudes:
            g = [p for p in d["pushes"] if p["magnitude"] == m]
            reasons = {}
            for p in g:
                if p["fell"]:
                    reasons[p["reason"]] = reasons.get(p["reason"], 0) + 1
            print(f"| {m:g} | {sum(p['fell'] for p in g)}/{len(g)} | {sum(bool(p['com_criterion_safe']) for p in g)} | "
                  f"{sum(bool(p['zmp_criterion_safe']) for p in g)} | {reasons} |")
        for k in ("com", "zmp"):
            c = d["confusion"][k]
            print(f"\n{k.upper()} criterion: accuracy {100 * c['accuracy']:.1f} %, predicted safe & fell {c['safe_fell']} "
                  f"({100 * c['safe_fell_rate']:.1f} %), safe & survived {c['safe_survived']}, unsafe & survived "
                  f"{c['unsafe_survived']}, unsafe & fell {c['unsafe_fell']}")
    if args.json:
        from impact_balance.cli._common import strict_json

        with open(args.json, "w") as fh:
            fh.write(strict_json(out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
