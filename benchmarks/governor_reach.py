#!/usr/bin/env python
"""The governor's tick with the CoM's reach (``Governor(com_reach=...)``) beside the tick without.

    python benchmarks/governor_reach.py [--ticks N] [--scenarios NAME ...] [--json]

For each scenario, the moving 500 Hz trajectory of ``benchmarks/governor.py`` (a new posture
every tick, the CoM moving), timed tick by tick in alternation: ``plain`` (``Governor``) and
``reach`` (``Governor(com_reach=reach)``, the reach of the scenario's posture computed once
before timing, not timed), each tick a new posture; and ``reach_velocity`` (the same posture, a
new velocity: the bound reused). The load average is printed beside the times (the machine is
shared). Exit status 0.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.speed.ticks import trajectory
from impact_balance.balance.reach import com_reach
from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario

SCENARIOS = ("palm_push_two_feet", "g1_two_feet")


def _time(call) -> float:
    t0 = time.perf_counter()
    call()
    return time.perf_counter() - t0


def bench(name: str, ticks: int) -> dict[str, object]:
    """Median and p99 (us) of each kind of tick on ``name``'s trajectory."""
    scenario = load_scenario(name)
    t0 = time.perf_counter()
    reach = com_reach(scenario.build_stance(scenario.load_robot()))
    reach_s = time.perf_counter() - t0
    plain, within = Governor(scenario), Governor(scenario, com_reach=reach)
    steady = Governor(scenario, com_reach=reach)
    qs, vs = trajectory(plain, ticks)
    for g in (plain, within, steady):  # warm up
        g.limit(qs[0], vs[0])
    times: dict[str, list[float]] = {"plain": [], "reach": [], "reach_velocity": []}
    binding = 0
    for q, v in zip(qs[1:], vs[1:], strict=True):
        times["plain"].append(_time(lambda q=q, v=v: plain.limit(q, v)))
        times["reach"].append(_time(lambda q=q, v=v: within.limit(q, v)))
        times["reach_velocity"].append(_time(lambda v=v: steady.limit(qs[0], v)))
        binding += within.last is not None and within.last.binding == "com_reach"
    out: dict[str, object] = {"scenario": name, "ticks": ticks - 1, "reach_seconds": reach_s}
    for key, values in times.items():
        us = 1e6 * np.asarray(values)
        out[key] = {"median": float(np.median(us)), "p99": float(np.percentile(us, 99))}
    out["reach_binding_ticks"] = binding
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ticks", type=int, default=400)
    ap.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    ap.add_argument("--json", action="store_true")
    args = ap.parse_args()
    results = [bench(name, args.ticks) for name in args.scenarios]
    load = os.getloadavg()
    if args.json:
        print(json.dumps({"load_average": load, "results": results}, indent=1))
        return 0
    print(f"load average {load[0]:.2f} {load[1]:.2f} {load[2]:.2f}")
    for r in results:
        p, w, rv = r["plain"], r["reach"], r["reach_velocity"]
        print(
            f"{r['scenario']}: posture tick median {p['median']:.0f} us (p99 {p['p99']:.0f}); "
            f"with the reach {w['median']:.0f} us (p99 {w['p99']:.0f}); velocity-only with the "
            f"reach {rv['median']:.0f} us; reach binding on {r['reach_binding_ticks']} of "
            f"{r['ticks']} ticks; reach search {r['reach_seconds']:.1f} s (once)"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
