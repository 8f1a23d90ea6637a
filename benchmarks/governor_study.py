"""Issue 15's study: the governed approach to an unknown wall, on four stances.

    python benchmarks/governor.py --study [--out DIR] [--scenarios ...]
                                        [--references 0.2 0.5 1.0 2.0] [--distances 0.12 0.15 0.18]
                                        [--governors com zmp none] [--impacts rigid free]

For every scenario, reference speed, wall distance, governor and impact model (``rigid``: every
joint held through the impact, the paper's robot; ``free``: the torque-controlled robot as it
is), one ``approach`` trial with the ``id`` controller; the governor uses the scenario's areas
shrunk by the controller's 10 mm ZMP margin. Trials go to journals under ``--out`` as they finish
(a rerun resumes). Prints the outcome counts per governor, the measured contact speed against
min(reference, the cap at contact), the time to contact, the governor's time per tick, and writes
``DIR/governor_study.json`` and the figure of the paper's case (0.8 m/s reference, 15 cm) per
governor.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

import numpy as np

from impact_balance.governor import Governor
from impact_balance.scenario import load_scenario
from impact_balance.sim.studies.journal import TrialJournal, journal_digest
from impact_balance.sim.studies.wall import APPROACH_VERSION, WallOptions, run_wall_trial
from impact_balance.sim.trials.balance_trial import (
    TRIAL_VERSION,
    BalanceSetup,
    BalanceTrialOptions,
    controller_margin,
)

SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.2f}"


def _f(x, d: int = 3) -> str:
    return "-" if x is None else f"{x:.{d}f}"


def governed_setup(name: str, rigid: bool):
    """One stance of the study: the ``id`` controller's options (joints held through the impact
    or not), its ZMP margin (m), the scenario the governor uses (areas shrunk by that margin)
    and the MuJoCo setup. Returns ``(options, margin, governed, setup)``."""
    options = BalanceTrialOptions(controller="id", rigid_impact=rigid)
    margin = controller_margin(options)
    scenario = load_scenario(name)
    return (
        options,
        margin,
        scenario.model_copy(update={"zmp_margin": margin}),
        BalanceSetup.create(scenario, "servo", options),
    )


def study(args, out: Path) -> list[dict]:
    rows = []
    for name in args.scenarios:
        for impact in args.impacts:
            options, margin, governed, setup = governed_setup(name, impact == "rigid")
            governors = {
                g: (None if g == "none" else Governor(governed, criterion=g))
                for g in args.governors
            }
            digest = journal_digest(
                {
                    "trial_version": TRIAL_VERSION,
                    "approach_version": APPROACH_VERSION,
                    "scenario": name,
                    "impact": impact,
                    "margin": margin,
                }
            )
            journal = TrialJournal.open(
                out / "journals" / f"approach_{name}_{impact}_{digest[:12]}.jsonl", digest
            )
            for g in args.governors:
                for reference in args.references:
                    for distance in args.distances:
                        key = {"governor": g, "reference": reference, "distance": distance}
                        entry = journal.get(key)
                        if entry is None:
                            wall = WallOptions(
                                reference=reference,
                                governor=g,
                                wall_distance=distance,
                                max_time=args.max_time,
                            )
                            trial = run_wall_trial(setup, wall, options, governor=governors[g])
                            entry = trial.to_dict()
                            entry.pop("trial", None)
                            journal.add(key, entry)
                        rows.append({"scenario": name, "impact": impact, **entry})
                        d = rows[-1]
                        print(
                            f"  {name} {impact} {g} {reference:g} m/s {100 * distance:g} cm: "
                            f"{d['outcome']} speed {_f(d['speed_at_contact'])} cap "
                            f"{_f(d['cap_at_contact'])} t {_f(d['time_to_contact'], 2)}",
                            file=sys.stderr,
                            flush=True,
                        )
            journal.close()
    return rows


def tables(rows: list[dict]) -> None:
    print("\n## Outcomes per governor (all references and wall distances)\n")
    print(
        "| scenario | impact | governor | trials | balanced / contact broken / fell / aborted | "
        "measured speed at contact (m/s) | cap at contact (m/s) | time to contact (s) | speed / "
        "min(reference, cap): worst | governor tick median / p99 (us) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    keys = sorted(
        {(r["scenario"], r["impact"], r["governor"]) for r in rows},
        key=lambda k: (k[0], k[1], "czn".index(k[2][0])),
    )
    for scenario, impact, g in keys:
        group = [
            r for r in rows if (r["scenario"], r["impact"], r["governor"]) == (scenario, impact, g)
        ]
        counts = {
            o: sum(r["outcome"] == o for r in group)
            for o in ("balanced", "contact_broken", "fell", "aborted")
        }
        speeds = [r["speed_at_contact"] for r in group if r["speed_at_contact"] is not None]
        caps = [r["cap_at_contact"] for r in group if r["cap_at_contact"] is not None]
        times = [r["time_to_contact"] for r in group if r["time_to_contact"] is not None]
        ratios = [
            r["speed_at_contact"]
            / min(
                r["reference"], r["cap_at_contact"] if r["cap_at_contact"] is not None else np.inf
            )
            for r in group
            if r["speed_at_contact"] is not None
        ]
        ticks = [r["tick_us"] for r in group if r["tick_us"]["median"] is not None]
        tick = (
            f"{np.median([t['median'] for t in ticks]):.0f} / {max(t['p99'] for t in ticks):.0f}"
            if ticks
            else "-"
        )
        span = lambda v, d=3: "-" if not v else f"{min(v):.{d}f} to {max(v):.{d}f}"  # noqa: E731
        print(
            f"| {scenario} | {impact} | {g} | {len(group)} | {counts['balanced']} / "
            f"{counts['contact_broken']} / {counts['fell']} / {counts['aborted']} | {span(speeds)} "
            f"| {span(caps)} | {span(times, 2)} | {_f(min(ratios) if ratios else None, 2)} | "
            f"{tick} |"
        )


def figures(args, out: Path) -> list[Path]:
    from impact_balance.plots.approach import plot_approach

    paths = []
    name = args.scenarios[0]
    options, margin, governed, setup = governed_setup(name, True)
    margin_area = setup.analysis.areas.com_velocity_area_inset(margin)
    for g in args.governors:
        governor = None if g == "none" else Governor(governed, criterion=g)
        trial = run_wall_trial(
            setup,
            WallOptions(reference=0.8, governor=g, wall_distance=0.15, max_time=args.max_time),
            options,
            governor=governor,
        )
        path = out / f"{name}_approach_{g}_0.8_15cm.png"
        plot_approach(trial, setup.analysis, margin_area).savefig(path)
        paths.append(path)
    return paths


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="governor-study")
    p.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    p.add_argument("--references", type=float, nargs="+", default=[0.2, 0.5, 1.0, 2.0])
    p.add_argument("--distances", type=float, nargs="+", default=[0.12, 0.15, 0.18])
    p.add_argument(
        "--governors", nargs="+", default=["com", "zmp", "none"], choices=["com", "zmp", "none"]
    )
    p.add_argument("--impacts", nargs="+", default=["rigid", "free"], choices=["rigid", "free"])
    p.add_argument("--max-time", type=float, default=30.0)
    p.add_argument("--no-figures", action="store_true")
    args = p.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"{_load()} at the start", flush=True)
    rows = study(args, out)
    tables(rows)
    if not args.no_figures:
        for path in figures(args, out):
            print(f"wrote {path}")
    print(f"\n{_load()} at the end")
    (out / "governor_study.json").write_text(json.dumps(rows, allow_nan=False))
    return 0


if __name__ == "__main__":
    sys.exit(main())
