"""The governor's ``posture_tolerance`` in the wall experiment: tick time against the cap's error.

    python benchmarks/governor.py --tolerance [--tolerances 0.001 0.003 0.01 0.03]
                                              [--scenarios ...] [--json]

For each scenario and tolerance, one ``approach`` trial (``id`` controller, joints held through the
impact, 2 m/s reference so that the cap binds, wall at 15 cm, the controller's 10 mm ZMP
margin). Every tick the governor with the tolerance gives the cap the trial uses, and a second
governor without tolerance (posture recomputed at every tick) answers the same ``(q, v)``; only
the first call is timed. Reported: the ticks' median and 99th percentile (us), the cap's
difference from the exact cap of the same state (%, min and max: positive is on the unsafe
side), the outcome and the speed at contact.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.governor_study import SCENARIOS, governed_setup
from impact_balance.governor import Governor
from impact_balance.sim.studies.wall import WallOptions, run_wall_trial


class _Paired:
    """Duck-types the governor for :func:`run_wall_trial`: answers with ``tolerant``, times it,
    and compares each answer with ``exact``'s for the same state."""

    def __init__(self, tolerant: Governor, exact: Governor):
        self.tolerant, self.exact = tolerant, exact
        self.us: list[float] = []
        self.errors: list[float] = []

    def limit(self, q, v):
        t0 = time.perf_counter()
        answer = self.tolerant.limit(q, v)
        self.us.append(1e6 * (time.perf_counter() - t0))
        reference = self.exact.limit(q, v).ceiling
        if np.isfinite(answer.ceiling) and np.isfinite(reference) and reference > 0.0:
            self.errors.append((answer.ceiling - reference) / reference)
        return answer


def run(scenarios, tolerances) -> list[dict]:
    rows = []
    for name in scenarios:
        options, _, governed, setup = governed_setup(name, True)
        for tolerance in tolerances:
            paired = _Paired(Governor(governed, posture_tolerance=tolerance), Governor(governed))
            trial = run_wall_trial(
                setup,
                WallOptions(reference=2.0, governor="com", wall_distance=0.15),
                options,
                governor=paired,
            )
            us, errors = np.asarray(paired.us), 100.0 * np.asarray(paired.errors)
            rows.append(
                {
                    "scenario": name,
                    "tolerance": tolerance,
                    "ticks": int(us.size),
                    "median_us": float(np.median(us)),
                    "p99_us": float(np.percentile(us, 99)),
                    "cap_error_pct": [float(errors.min()), float(errors.max())],
                    "outcome": trial.result.summary()["outcome"],
                    "speed_at_contact": trial.speed_at_contact,
                }
            )
            r = rows[-1]
            print(
                f"  {name} tolerance {tolerance:g}: median {r['median_us']:.0f} us, p99 "
                f"{r['p99_us']:.0f} us, cap {r['cap_error_pct'][0]:+.2f} to "
                f"{r['cap_error_pct'][1]:+.2f} % of the exact",
                file=sys.stderr,
                flush=True,
            )
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    p.add_argument("--tolerances", type=float, nargs="+", default=[0.001, 0.003, 0.01, 0.03])
    p.add_argument("--json", action="store_true")
    args = p.parse_args(argv)
    before = os.getloadavg()[0]
    rows = run(args.scenarios, args.tolerances)
    load = f"load average {before:.2f} at the start, {os.getloadavg()[0]:.2f} at the end"
    if args.json:
        print(json.dumps({"rows": rows, "load": load}, allow_nan=False))
        return 0
    print(
        "| scenario | posture_tolerance | ticks | median / p99 (us) | cap minus the exact cap (%) "
        "| outcome, speed at contact (m/s) |"
    )
    print("|---|---|---|---|---|---|")
    for r in rows:
        print(
            f"| {r['scenario']} | {r['tolerance']:g} | {r['ticks']} | {r['median_us']:.0f} / "
            f"{r['p99_us']:.0f} | {r['cap_error_pct'][0]:+.2f} to {r['cap_error_pct'][1]:+.2f} | "
            f"{r['outcome']}, {r['speed_at_contact']:.3f} |"
        )
    print(f"\n{load}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
