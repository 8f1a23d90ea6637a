"""Physics evidence: every table of README's and docs/validation.md's balance sections.

    python benchmarks/balance.py [--parts speed impacts pushes] [--out DIR] [--directions 8]
                                 [--relative 0.5 0.7 0.85 1.0 1.15 1.3 1.5]
                                 [--scenarios ...] [--push-scenarios ...]

Held-out protocol (docs/validation.md): the controllers' gains are frozen (benchmarks/tune_id.py
tuned the ``id`` controller's margins on ``talos_tuning_stagger``, which is never scored); every
push is predicted before its trial and scored after, on grids that straddle the boundary
(fractions of each direction's boundary impulse); rates come with 95 % Wilson intervals. Trials
are written to journals under ``--out`` as they finish: a second run resumes and recomputes only
the scores. It takes tens of minutes on 2 cores; it prints markdown tables and writes every
number to ``DIR/balance.json``.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from impact_balance.sim.studies.journal import TrialJournal, journal_digest
from impact_balance.sim.studies.push import push_test
from impact_balance.sim.studies.validate import validate
from impact_balance.sim.trials.balance_trial import (
    TRIAL_VERSION,
    BalanceSetup,
    BalanceTrialOptions,
    Push,
    controller_margin,
    run_balance_trial,
)

IMPACT_SCENARIOS = (
    "palm_push_two_feet",
    "palm_push_ramp",
    "kick_one_foot",
    "g1_two_feet",
    "talos_three_contacts",
    "talos_side_slope",
)
PUSH_SCENARIOS = (
    "palm_push_two_feet",
    "palm_push_ramp",
    "g1_two_feet",
    "talos_three_contacts",
    "talos_side_slope",
)
#: (controller, joints, rigid impact) of the impact rows.
IMPACT_SETUPS = (
    ("id", "servo", True),
    ("id", "servo", False),
    ("ik", "rigid", True),
    ("ik", "servo", False),
)


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.2f}"


def _f(x, digits: int = 3) -> str:
    return "-" if x is None else f"{x:.{digits}f}"


def _pct(x) -> str:
    return "-" if x is None else f"{100 * x:.1f}"


def _ci(c) -> str:
    return "" if c is None else f" [{100 * c[0]:.0f}, {100 * c[1]:.0f}]"


def _journal(out: Path, name: str, parts: dict) -> TrialJournal:
    digest = journal_digest({"trial_version": TRIAL_VERSION, **parts})
    return TrialJournal.open(
        out / "journals" / f"{name}_{digest[:12]}.jsonl", digest, {"name": name}
    )


def speed(controller: str, repeats: int = 3) -> dict:
    """Wall time of a 3 s trial standing with the controller on (500 Hz control, 1 ms steps)."""
    options = BalanceTrialOptions(controller=controller, after=2.99)
    setup = BalanceSetup.create("palm_push_two_feet", options=options)
    ratios = []
    for _ in range(repeats):
        r = run_balance_trial(setup, push=Push(0.0, 1e-6, 0.01, start=0.0), options=options)
        ratios.append(r.sim_time / r.wall_time)
    return {
        "controller": controller,
        "real_time_factor": ratios,
        "median": float(np.median(ratios)),
        "load": _load(),
    }


def impacts(names, out: Path) -> list[dict]:
    rows = []
    print("\n## Impacts: fall threshold in measured approach speed (m/s)\n")
    print(
        "| scenario | controller, joints | impact | CoM crit. (0 / margin) | stood / fell, "
        "measured | commanded | fell / predicted | first contact break | palm impulse at 'fell' "
        "(N s) | sustained contacts' impulse | trials |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for name in names:
        for controller, joints, rigid in IMPACT_SETUPS:
            options = BalanceTrialOptions(controller=controller, rigid_impact=rigid)
            journal = _journal(
                out,
                f"validate_{name}_{controller}_{joints}_{'rigid' if rigid else 'free'}",
                {"scenario": name, "controller": controller, "joints": joints, "rigid": rigid},
            )
            r = validate(name, joints, options=options, journal=journal)
            journal.close()
            d = r.to_dict()
            rows.append(d)
            e, p, pm = (
                d["empirical"],
                d["predicted"]["com_criterion"],
                d["predicted_with_margin"]["com_criterion"],
            )
            ratio = None if e["fell"] is None or not p["composite"] else e["fell"] / p["composite"]
            brk = d["contact_break"]
            brk_text = (
                "-"
                if brk is None
                else f"{brk['contact']} {brk['kind']} at {brk['measured']:.2f} ({brk['outcome']})"
            )
            at_fell = [
                t for t in d["trials"] if t["fell"] and t["approach_speed_measured"] == e["fell"]
            ]
            imp = at_fell[0]["trial"].get("impact") if at_fell else None
            palm = (
                "-"
                if imp is None or imp["impulse"] is None
                else f"{np.linalg.norm(imp['impulse']):.1f}"
            )
            sustained = (
                "-"
                if imp is None
                else ", ".join(
                    f"{np.linalg.norm(v):.1f}"
                    for v in imp["sustained_impulses"].values()
                    if v is not None
                )
            )
            stood = _f(e["survived"]) + ("" if e["monotonic"] else " (non-monotonic)")
            print(
                f"| {name} | {controller}, {joints} | {'rigid' if rigid else 'free'} | "
                f"{_f(p['composite'])} / {_f(pm['composite'])} | {stood} / {_f(e['fell'])} | "
                f"{_f(e['survived_commanded'])} / {_f(e['fell_commanded'])} | {_f(ratio, 2)} | "
                f"{brk_text} | {palm} | {sustained} | {len(d['trials'])} |",
                flush=True,
            )
    return rows


def pushes(
    names, directions: int, relative: list[float], out: Path, bodies: list[str]
) -> list[dict]:
    rows = []
    options = BalanceTrialOptions(controller="id")
    own = controller_margin(options)
    print(
        f"\n## Pushes (id controller, {directions} directions x {relative} of the boundary "
        "impulse, 50 ms)\n"
    )
    print(
        "| scenario | body | pushes | balanced / contact broken / fell / aborted | margin (mm) | "
        "CoM criterion before: right / safe & fell (%) | CoM in trial | ZMP before | ZMP in trial "
        "| smallest margin (CoM, <= 5 %) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|", flush=True)
    for name, which in ((n, b) for n in names for b in bodies):
        setup = BalanceSetup.create(name, "servo", options)
        # "torso": the push-test default; "base": the root body (Talos' base_link, G1's pelvis),
        # near the CoM.
        body = None if which == "torso" else setup.sim.model.body(setup.sim.root_body).name
        journal = _journal(
            out,
            f"push_{name}_{which}_id",
            {"scenario": name, "controller": "id", "directions": directions, "body": body},
        )
        t0 = time.perf_counter()
        r = push_test(
            name,
            directions,
            relative=relative,
            options=options,
            journal=journal,
            body=body,
            setup=setup,
        )
        journal.close()
        d = r.to_dict()
        d["body"] = body or "torso"
        d["wall"] = time.perf_counter() - t0
        study = r.margin_study()
        d["margin_study"] = study
        rows.append(d)
        o = d["counts"]["outcomes"]
        counts = " / ".join(str(o[k]) for k in ("balanced", "contact_broken", "fell", "aborted"))
        smallest = study["smallest_margin"]["com"]
        for m in study["margins"]:
            s = study["scores"][f"{m:g}"]
            cells = [
                f"{_pct(s[k]['accuracy'])}{_ci(s[k]['accuracy_ci95'])} / "
                f"{_pct(s[k]['safe_and_fell_share'])}{_ci(s[k]['safe_and_fell_share_ci95'])}"
                for k in ("com", "com_in_trial", "zmp", "zmp_in_trial")
            ]
            first = m == study["margins"][0]
            print(
                f"| {name if first else ''} | {d['body'] if first else ''} | "
                f"{len(r.outcomes) if first else ''} | "
                f"{counts if first else ''} "
                f"| {1e3 * m:g}{' (own)' if m == own else ''} | {' | '.join(cells)} | "
                f"{('-' if smallest is None else f'{1e3 * smallest:g} mm') if first else ''} |",
                flush=True,
            )
    print("\nContact breaks (no fall) and falls by fraction of the boundary impulse:\n")
    print("| scenario | body | fraction | pushes | contact broken | fell | first event (count) |")
    print("|---|---|---|---|---|---|---|")
    for d in rows:
        by: dict[float, dict] = {}
        for p in d["pushes"]:
            row = by.setdefault(p["relative"], {"n": 0, "broken": 0, "fell": 0, "first": {}})
            row["n"] += 1
            row["fell"] += p["fell"]
            row["broken"] += p["outcome"] == "contact_broken"
            if p["events"]:
                e = min(p["events"], key=lambda e: e["time"])
                key = f"{e['contact']} {e['kind']}"
                row["first"][key] = row["first"].get(key, 0) + 1
        for frac in sorted(by):
            row = by[frac]
            first = (
                ", ".join(
                    f"{k} ({v})" for k, v in sorted(row["first"].items(), key=lambda kv: -kv[1])
                )
                or "-"
            )
            print(
                f"| {d['scenario']} | {d['body']} | {frac:g} | {row['n']} | {row['broken']} | "
                f"{row['fell']} | {first} |"
            )
    return rows


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--parts",
        nargs="+",
        default=["speed", "impacts", "pushes"],
        choices=["speed", "impacts", "pushes"],
    )
    p.add_argument(
        "--out", default="balance-benchmark", help="folder of the journals and of balance.json"
    )
    p.add_argument("--scenarios", nargs="+", default=list(IMPACT_SCENARIOS))
    p.add_argument("--push-scenarios", nargs="+", default=list(PUSH_SCENARIOS))
    p.add_argument("--directions", type=int, default=8)
    p.add_argument(
        "--relative", type=float, nargs="+", default=[0.5, 0.7, 0.85, 0.95, 1.05, 1.15, 1.3, 1.5]
    )
    p.add_argument("--bodies", nargs="+", default=["torso", "base"], choices=["torso", "base"])
    args = p.parse_args()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    result: dict = {"started": _load()}
    print(f"{_load()} at the start", flush=True)
    if "speed" in args.parts:
        result["speed"] = [speed(c) for c in ("ik", "id")]
        for s in result["speed"]:
            print(
                f"3 s trial, {s['controller']} controller: {s['median']:.2f}x real time "
                f"(runs {', '.join(f'{x:.2f}' for x in s['real_time_factor'])}; {s['load']})",
                flush=True,
            )
    if "impacts" in args.parts:
        result["impacts"] = impacts(args.scenarios, out)
    if "pushes" in args.parts:
        result["pushes"] = pushes(
            args.push_scenarios, args.directions, args.relative, out, args.bodies
        )
    result["finished"] = _load()
    print(f"\n{_load()} at the end")
    (out / "balance.json").write_text(json.dumps(result, allow_nan=False, default=float))
    return 0


if __name__ == "__main__":
    sys.exit(main())
