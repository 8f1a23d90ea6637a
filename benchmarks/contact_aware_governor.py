#!/usr/bin/env python
"""The contact-aware governor option (experimental): every table of docs/contact_aware_governor.md.

    python benchmarks/contact_aware_governor.py score --out DIR [--variant aware|cold|off]
            [--scenarios ...] [--references 0.5 1 2] [--distances 0.12 0.15 0.18]
    python benchmarks/contact_aware_governor.py sweep --out DIR [--scenarios ...] [--references ...]
    python benchmarks/contact_aware_governor.py bounds [--scenarios ...] [--margins 0 0.01]
    python benchmarks/contact_aware_governor.py preload --out DIR [--scenarios ...] [--speeds ...]
    python benchmarks/contact_aware_governor.py trace --out DIR [--scenario S] [--governor com|none] [--contact-aware]
            [--reference R] [--wall D] [--every MS] [--branches]

Every simulated trial is the ``approach`` command's (``id`` controller, ``servo`` joints held
through the impact: ``--rigid-impact``; the governor uses the areas inset by the controller's
10 mm ZMP margin), run in this process with the library calls the command makes, as
``benchmarks/governor_study.py`` does.

- ``score``: the governed trials, ``impact-balance approach SCEN --reference R --governor com
  --rigid-impact --contact-aware --wall-distance-range 0.12 0.18 --json`` for the wall study's
  four stances and references 0.5, 1, 2 m/s (36 trials, ~2 min). One governor serves the three
  walls of a reference, in order, as in that command (the option's warm start carries over).
  ``--variant cold``: the post hoc cold start (the contact-aware fixed point starts from gauges 0
  at every recomputation, a new governor per wall; not frozen); ``--variant off``: without the
  option (the study's ``com`` governor).
- ``sweep``: ungoverned approaches (``--governor none``, wall 15 cm) over references around each
  stance's fall (33 trials on four stances, ~2 min): the outcome against the post-impact CoM
  velocity's margin (m/s) in the CoM velocity area ("raw", the trial's own) and in the area inset
  by the controller's ZMP margin ("inset"), both from the measured CoM velocity at the end of the
  impact; then per stance the fastest trial that did not fall and the slowest that fell.
- ``bounds``: no simulation. The maximum approach speed at each scenario's posture (pre-impact
  CoM velocity 0) of the governor without and with the option, in the area without margin and
  inset by 10 mm, and the bound the rejected preload model would give (10 mm).
- ``preload``: the preload model (gravity acts over the impact's duration T, the scenario's
  ``impact.duration``: every point's pre-impact velocity is shifted by ``-g T e_z``) against the
  training stances' rigid-impact trials of ``benchmarks/contact_impact.py`` (the error of the
  predicted CoM velocity jump with T = 0 and T = duration), and the ramp's jumps with and
  without it at the speeds of its fall.
- ``trace``: one recorded approach (log and summary kept in ``--out``; rerun reads them back):
  from the contact on, each support's force, the CoM velocity, the desired and measured ZMP and
  the DCM margin; with ``--branches``, along the approach before the contact, the floating cap
  and the contact-aware jump and cap with the fixed point warm-started from the previous posture
  and cold (the frictional LCP's two solutions near the ramp's wall).

Trials go to journals under ``--out`` (``DIR/journals/``) as they finish: a crash or one failing
trial loses nothing else (the failure is printed, the exit status is 1) and the same command
resumes. The tables (markdown) go to stdout, progress to stderr, and ``DIR/<command>.json`` holds
every row. Results and their reading: docs/contact_aware_governor.md.
"""

from __future__ import annotations

import argparse
import json
import sys
import traceback
from pathlib import Path
from typing import Any, Callable, Iterable

import numpy as np

import impact_balance as ib
from contact_impact import one_row
from governor_study import SCENARIOS, _f, _load, governed_setup
from impact_balance.contact_impact import PointContact, _unique_columns, corner_contacts, rigid_body_impact
from impact_balance.governor import Governor
from impact_balance.impact import ImpactSpec, impact_cone
from impact_balance.scenario import load_scenario
from impact_balance.sim import SimOptions, build_model
from impact_balance.sim.balance_trial import TRIAL_VERSION
from impact_balance.sim.journal import TrialJournal, journal_digest
from impact_balance.sim.wall import WallOptions, run_wall_trial
from impact_balance.stance import Stance

GRAVITY = 9.81  # m/s^2
SWEEP_WALL = 0.15  # m
#: The ungoverned sweeps' commanded references (m/s), around each stance's fall.
SWEEP_REFERENCES = {
    "palm_push_two_feet": (0.42, 0.44, 0.46, 0.48, 0.5, 0.52, 0.55),
    "palm_push_ramp": (0.55, 0.6, 0.62, 0.64, 0.66, 0.68, 0.7, 0.72, 0.74, 0.76, 0.8),
    "kick_one_foot": (1.3, 1.4, 1.45, 1.5, 1.55, 1.6, 1.7),
    "g1_two_feet": (0.38, 0.4, 0.42, 0.44, 0.46, 0.48, 0.5, 0.55),
}
#: The stances the preload model was tried on before scoring (never scored).
TRAINING = ("palm_push_two_feet", "talos_tuning_stagger")
OUTCOMES = ("balanced", "contact_broken", "fell")


# -- journalled trials ----------------------------------------------------------------------------
def journalled(journal: TrialJournal, keys: Iterable[dict], run: Callable[[dict], dict], label: str) -> tuple[list, int]:
    """``[(key, entry)]`` for every key: the journal's entry, else ``run(key)``'s, journalled at once.

    A key whose run raises is printed and left out (a rerun tries it again). Returns the pairs
    and the number of failures."""
    pairs, failed = [], 0
    for key in keys:
        entry = journal.get(key)
        if entry is None:
            try:
                entry = run(key)
            except Exception:  # noqa: BLE001 - one bad trial must not lose the others
                failed += 1
                print(f"  FAILED {label} {key}:\n{traceback.format_exc()}", file=sys.stderr, flush=True)
                continue
            journal.add(key, entry)
        pairs.append((key, entry))
    return pairs, failed


def open_journal(out: Path, command: str, name: str, parts: dict[str, Any]) -> TrialJournal:
    """The journal of ``command`` on scenario ``name`` under ``out/journals``; ``parts``: what
    else decides the trials' outcome (a rerun with other parts starts another journal)."""
    digest = journal_digest({"trial_version": TRIAL_VERSION, "benchmark": "contact_aware_governor",
                             "command": command, "scenario": name, **parts})
    return TrialJournal.open(out / "journals" / f"{command}_{name}_{digest[:12]}.jsonl", digest)


def slim(trial_dict: dict) -> dict:
    """A wall trial's summary (``WallTrial.to_dict()``) without its long trajectory fields: the
    approach's numbers, and from the trial the margin at the end (m/s), the slip (m) and the
    impact's measurements."""
    trial = trial_dict["trial"]
    out = {k: v for k, v in trial_dict.items() if k != "trial"}
    out["margin_raw"] = trial["com_velocity_margin_at_end"]
    out["max_slip"] = trial["max_slip"]
    impact = trial.get("impact") or {}
    for k in ("com_velocity_after", "com_velocity_jump", "sustained_impulses", "impulse"):
        out[k] = impact.get(k)
    return out


# -- score: the governed trials -------------------------------------------------------------------
def _cold_start(governor: Governor) -> Governor:
    """``governor`` with the contact-aware fixed point started from gauges 0 at every
    recomputation (no continuation from the previous posture; the post hoc variant)."""
    support = governor._support
    inner = support.new_posture

    def cold(stance_of: Callable[[], Stance]) -> None:
        support._warm = None
        inner(stance_of)

    support.new_posture = cold
    return governor


def score(args: argparse.Namespace, out: Path) -> tuple[list[dict], int]:
    """The governed trials of ``args.variant`` (module docstring); rows and failures."""
    rows, failures = [], 0
    for name in args.scenarios:
        options, margin, governed, setup = governed_setup(name, rigid=True)
        journal = open_journal(out, "score", name, {"variant": args.variant, "margin": margin})

        def new_governor() -> Governor:
            governor = Governor(governed, criterion="com", contact_aware=args.variant != "off")
            return _cold_start(governor) if args.variant == "cold" else governor

        def run(key: dict) -> dict:
            governor, trials = new_governor(), []  # one governor for the walls of a reference, as the command
            for distance in key["distances"]:
                if args.variant == "cold":
                    governor = new_governor()
                wall = WallOptions(reference=key["reference"], governor="com", wall_distance=distance)
                trials.append(slim(run_wall_trial(setup, wall, options, governor=governor).to_dict()))
                d = trials[-1]
                print(f"  {name} {key['reference']:g} m/s {100 * distance:g} cm: {d['outcome']} speed "
                      f"{_f(d['speed_at_contact'])} cap {_f(d['cap_at_contact'])}", file=sys.stderr, flush=True)
            return {"trials": trials}

        keys = [{"reference": r, "distances": list(args.distances)} for r in args.references]
        pairs, failed = journalled(journal, keys, run, f"score {name}")
        journal.close()
        failures += failed
        rows += [{"scenario": name, "variant": args.variant, **t} for _, e in pairs for t in e["trials"]]
    return rows, failures


def _signed(x: float | None, digits: int = 4) -> str:
    return "-" if x is None else f"{x:+.{digits}f}"


def _span(values: list[float], digits: int = 3) -> str:
    return "-" if not values else f"{min(values):.{digits}f} to {max(values):.{digits}f}"


def score_table(rows: list[dict]) -> str:
    """Outcome counts and ranges per scenario (the table of docs/contact_aware_governor.md)."""
    lines = ["| scenario | variant | trials | balanced / contact broken / fell | measured speed at contact (m/s) "
             "| cap at contact (m/s) | speed / min(ref, cap) | tick median (us) | tick p99 (us) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name]
        counts = " / ".join(str(sum(r["outcome"] == o for r in group)) for o in OUTCOMES)
        speeds = [r["speed_at_contact"] for r in group if r["speed_at_contact"] is not None]
        caps = [r["cap_at_contact"] for r in group if r["cap_at_contact"] is not None]
        ratios = [r["speed_at_contact"] / min(r["reference"], r["cap_at_contact"]) for r in group
                  if r["speed_at_contact"] is not None and r["cap_at_contact"] is not None]
        ticks = [r["tick_us"] for r in group if r["tick_us"]["median"] is not None]
        lines.append(f"| {name} | {group[0]['variant']} | {len(group)} | {counts} | {_span(speeds)} | {_span(caps)} "
                     f"| {_span(ratios, 2)} | {_span([t['median'] for t in ticks], 0)} "
                     f"| {_span([t['p99'] for t in ticks], 0)} |")
    lines += ["", "| scenario | reference (m/s) | wall (cm) | outcome | speed at contact (m/s) | cap at contact (m/s) "
              "| raw margin at end (m/s) | slip (cm) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scenario']} | {r['reference']:g} | {100 * r['wall_distance']:g} | {r['outcome']} "
                     f"| {_f(r['speed_at_contact'])} | {_f(r['cap_at_contact'])} | {r['margin_raw']:+.3f} "
                     f"| {100 * r['max_slip']:.1f} |")
    return "\n".join(lines)


# -- sweep: ungoverned approaches and the inset rule ----------------------------------------------
def sweep(args: argparse.Namespace, out: Path) -> tuple[list[dict], int]:
    """Ungoverned approaches at wall 15 cm with the inset margin at the end of the impact."""
    rows, failures = [], 0
    for name in args.scenarios:
        options, margin, _, setup = governed_setup(name, rigid=True)
        inset = setup.analysis.areas.com_velocity_area_inset(margin)
        journal = open_journal(out, "sweep", name, {"wall": SWEEP_WALL, "margin": margin})

        def run(key: dict) -> dict:
            wall = WallOptions(reference=key["reference"], governor="none", wall_distance=SWEEP_WALL)
            d = slim(run_wall_trial(setup, wall, options).to_dict())
            after = np.asarray(d["com_velocity_after"] if d["com_velocity_after"] is not None else [np.nan] * 2)
            d["margin_inset"] = float(inset.margins(after)[0]) if np.isfinite(after).all() else None
            print(f"  {name} {key['reference']:g} m/s: {d['outcome']} speed {_f(d['speed_at_contact'])} "
                  f"inset margin {_signed(d['margin_inset'])}", file=sys.stderr, flush=True)
            return d

        references = args.references or SWEEP_REFERENCES[name]
        pairs, failed = journalled(journal, [{"reference": r} for r in references], run, f"sweep {name}")
        journal.close()
        failures += failed
        rows += [{"scenario": name, **e} for _, e in pairs]
    return rows, failures


def sweep_table(rows: list[dict]) -> str:
    """Every trial, then per stance the fastest that did not fall and the slowest that fell."""
    lines = ["| scenario | reference (m/s) | measured v_n (m/s) | outcome | raw margin | inset margin | slip (cm) "
             "| sustained impulse z per contact (N s) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        sustained = ", ".join(f"{k} {v[2]:+.2f}" for k, v in (r["sustained_impulses"] or {}).items())
        lines.append(f"| {r['scenario']} | {r['reference']:g} | {_f(r['speed_at_contact'])} | {r['outcome']} "
                     f"| {r['margin_raw']:+.3f} | {_signed(r['margin_inset'])} | {100 * r['max_slip']:.2f} | {sustained} |")
    lines += ["", "| scenario | trials | stood: largest v_n (inset margin) | fell: smallest v_n (inset margin) |",
              "|---|---|---|---|"]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name and r["speed_at_contact"] is not None]
        stood = [r for r in group if r["outcome"] != "fell"]
        fell = [r for r in group if r["outcome"] == "fell"]
        best = max(stood, key=lambda r: r["speed_at_contact"], default=None)
        worst = min(fell, key=lambda r: r["speed_at_contact"], default=None)
        cell = (lambda r: "-" if r is None else f"{r['speed_at_contact']:.3f} ({_signed(r['margin_inset'])})")  # noqa: E731
        lines.append(f"| {name} | {len(group)} | {cell(best)} | {cell(worst)} |")
    stood = [r["margin_inset"] for r in rows if r["outcome"] != "fell" and r["margin_inset"] is not None]
    fell = [r["margin_inset"] for r in rows if r["outcome"] == "fell" and r["margin_inset"] is not None]
    lines.append(f"\nThe inset rule over {len(rows)} trials: the trials that did not fall end with inset margins "
                 f">= {_signed(min(stood, default=None))} m/s; those that fell <= {_signed(max(fell, default=None))} m/s.")
    return "\n".join(lines)


# -- the preload model (rejected on the training stances) -----------------------------------------
def preload_jump(stance: Stance, spec: ImpactSpec, approach_speed: float, restitution: float, duration: float
                 ) -> tuple[np.ndarray, list[np.ndarray], bool]:
    """The contact-aware CoM velocity jump with preload: gravity acts over ``duration`` (s), so
    every point's pre-impact velocity is shifted by ``-g duration e_z`` (the supports' impulses
    are then totals, preload included); ``duration`` 0 is the model without preload.

    Returns ``(jump xy (m/s), impulses per point (N s; 0: the impact point, then the support
    corners in order), converged)``.
    """
    placement, _ = stance.local_point(spec.frame, spec.offset, field="impact.frame")
    normal, cone = impact_cone(spec)
    shift = np.array([0.0, 0.0, -GRAVITY * duration])
    impact = PointContact(placement.translation - stance.com_local, normal, _unique_columns(cone),
                          -approach_speed * normal + shift, restitution)
    corners = [PointContact(p.arm, p.normal, p.generators, shift.copy()) for c in corner_contacts(stance) for p in c]
    dxi, impulses, _, converged = rigid_body_impact(stance.mass, stance.com_inertia, [impact] + corners,
                                                    tolerance=1e-9 * max(approach_speed, 1e-3))
    return dxi[:2], impulses, converged


def preload_bound(stance: Stance, spec: ImpactSpec, area, com_velocity: np.ndarray, duration: float) -> float:
    """The largest approach speed (m/s, to 2e-6) keeping the preload jump at both restitution
    bounds inside ``area``: bisection on [0, 2] m/s (the jump is affine, not linear, in the speed)."""
    def inside(speed: float) -> bool:
        return all(area.margins(com_velocity[:2] + preload_jump(stance, spec, speed, c, duration)[0])[0] >= 0
                   for c in spec.restitution)

    lo, hi = 0.0, 2.0
    for _ in range(20):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if inside(mid) else (lo, mid)
    return lo


def preload(args: argparse.Namespace, out: Path) -> tuple[list[dict], int]:
    """The training stances' rigid-impact trials (``benchmarks/contact_impact.py``'s rows) and
    the preload model's jump error on them."""
    rows, failures = [], 0
    for name in args.scenarios:
        sim = build_model(name, "servo", SimOptions(meshes=False))
        spec = sim.scenario.impact.spec()
        journal = open_journal(out, "preload", name, {})
        pairs, failed = journalled(journal, [{"speed": s} for s in args.speeds],
                                   lambda key: one_row(sim, name, key["speed"]), f"preload {name}")
        journal.close()
        failures += failed
        for _, row in pairs:
            measured = np.asarray(row["jump_measured"])
            errors = [float(np.linalg.norm(preload_jump(sim.stance, spec, row["approach_measured"],
                                                        row["restitution_measured"], t)[0] - measured))
                      for t in (0.0, spec.duration)]
            rows.append({**row, "error_no_preload": errors[0], "error_preload": errors[1], "duration": spec.duration})
    return rows, failures


def preload_table(rows: list[dict]) -> str:
    """|predicted - measured| of the CoM velocity jump per stance at each speed, then the ramp's jumps."""
    lines = ["| stance | commanded speeds (m/s) | no preload | preload T = impact.duration |", "|---|---|---|---|"]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name]
        join = lambda k: " / ".join(f"{r[k]:.3f}" for r in group)  # noqa: E731
        speeds = " / ".join(f"{r['speed']:g}" for r in group)
        lines.append(f"| {name} | {speeds} | {join('error_no_preload')} "
                     f"| {join('error_preload')} (T = {1e3 * group[0]['duration']:g} ms) |")
    return "\n".join(lines)


def ramp_jumps(speeds: Iterable[float] = (0.66, 0.7), margin: float = 0.01) -> str:
    """The ramp's contact-aware jump with and without preload at its scenario posture (pre-impact
    CoM velocity 0): jump (m/s), margin in the area inset by ``margin`` (m/s), and the impulses of
    the two soles (N s, summed over their corners)."""
    analysis = ib.analyze("palm_push_ramp")
    spec, stance = analysis.scenario.impact.spec(), analysis.stance
    inset = analysis.areas.com_velocity_area_inset(margin)
    names = [c.frame for c in analysis.scenario.contacts]
    heads = " | ".join(f"{n} impulse x, y, z (N s)" for n in names)
    lines = [f"| v_n (m/s) | c_r | T (ms) | jump x, y (m/s) | inset margin (m/s) | {heads} |",
             "|---|---|---|---|---|" + "---|" * len(names)]
    for speed in speeds:
        for c_r in spec.restitution:
            for duration in (0.0, spec.duration):
                jump, impulses, _ = preload_jump(stance, spec, speed, c_r, duration)
                per_contact = np.asarray(impulses[1:]).reshape(len(names), -1, 3).sum(axis=1)
                cells = " | ".join(", ".join(f"{x:+.2f}" for x in p) for p in per_contact)
                lines.append(f"| {speed:g} | {c_r:g} | {1e3 * duration:g} | {jump[0]:+.3f}, {jump[1]:+.3f} "
                             f"| {inset.margins(jump)[0]:+.4f} | {cells} |")
    return "\n".join(lines)


# -- bounds: no simulation ------------------------------------------------------------------------
def bounds(args: argparse.Namespace) -> list[dict]:
    """The governor's maximum approach speed at each scenario's posture without and with the
    option, per ZMP margin, and the preload model's bound at the largest margin."""
    from impact_balance.cli._options import with_zmp_margin

    rows = []
    for name in args.scenarios:
        scenario = load_scenario(name)
        row: dict[str, Any] = {"scenario": name}
        for margin in args.margins:
            governed = with_zmp_margin(scenario, margin)
            floating = Governor(governed, criterion="com")
            q, v = floating.configuration, np.zeros(floating.robot.model.nv)
            union = Governor(governed, criterion="com", contact_aware=True).limit(q, v)
            row[f"{1e3 * margin:g} mm"] = {"floating": floating.limit(q, v).max_approach_speed,
                                           "union": union.max_approach_speed, "binding": union.binding}
        analysis = ib.analyze(name)
        spec = analysis.scenario.impact.spec()
        inset = analysis.areas.com_velocity_area_inset(max(args.margins))
        row["preload"] = preload_bound(analysis.stance, spec, inset, np.asarray(analysis.com_velocity, dtype=float),
                                       spec.duration)
        rows.append(row)
        print(f"  {name}: {row}", file=sys.stderr, flush=True)
    return rows


def bounds_table(rows: list[dict], margins: list[float]) -> str:
    tags = [f"{1e3 * m:g} mm" for m in margins]
    lines = [f"| scenario | floating ({' / '.join(tags)}) | union ({' / '.join(tags)}), binding model "
             f"| preload ({tags[-1] if margins == sorted(margins) else max(margins)}) |", "|---|---|---|---|"]
    for r in rows:
        floating = " / ".join(f"{r[t]['floating']:.3f}" for t in tags)
        union = " / ".join(f"{r[t]['union']:.3f}" for t in tags)
        lines.append(f"| {r['scenario']} | {floating} | {union}, {r[tags[-1]]['binding']} | {r['preload']:.3f} |")
    return "\n".join(lines)


# -- trace: one logged approach, after the impact and (governed) the warm/cold branches -----------
def configuration(robot, row: dict) -> np.ndarray:
    """The configuration (nq) of one row of a trial's log (base pose and joint positions)."""
    import pinocchio as pin

    q = pin.neutral(robot.model)
    q[:7] = [row[f"base_{k}"] for k in ("x", "y", "z", "qx", "qy", "qz", "qw")]
    for name in robot.joint_names:
        q[robot.joint_slot(name).idx_q] = row[f"q_{name}"]
    return q


def logged_trial(args: argparse.Namespace, out: Path) -> tuple[dict, Any, dict]:
    """``(summary, log (DataFrame), series)`` of one recorded approach, read back from ``out``
    when it ran before (``trace_<tag>.json`` and ``.parquet``, written when it ends)."""
    import dataclasses

    import pandas as pd

    tag = f"{args.scenario}_{args.governor}{'_aware' if args.contact_aware else ''}_{args.reference:g}_{args.wall:g}"
    summary_path, log_path = out / f"trace_{tag}.json", out / f"trace_{tag}.parquet"
    if summary_path.exists() and log_path.exists():
        saved = json.loads(summary_path.read_text())
        return saved["summary"], pd.read_parquet(log_path), saved["series"]
    options, _, governed, setup = governed_setup(args.scenario, rigid=True)
    options = dataclasses.replace(options, record=True)
    governor = None if args.governor == "none" else Governor(governed, criterion="com", contact_aware=args.contact_aware)
    wall = WallOptions(reference=args.reference, governor=args.governor, wall_distance=args.wall)
    trial = run_wall_trial(setup, wall, options, governor=governor)
    summary = trial.to_dict()
    series = {k: np.asarray(v).tolist() for k, v in trial.result.series.items()}
    trial.result.log.to_parquet(log_path)
    summary_path.write_text(json.dumps({"summary": summary, "series": series}, default=float))
    return summary, trial.result.log, series


def after_impact_table(summary: dict, log, series: dict, step_ms: float, span: float = 2.0) -> str:
    """From the contact to ``span`` s after it, every ``step_ms``: each support's force (N,
    world), the CoM velocity (m/s), the controller's ZMP (desired, measured; m) and the DCM margin
    (omega times the DCM's distance to the ZMP area's edge, m/s)."""
    contact = summary["trial"]["impact"]["contact_time"]
    t_series = np.asarray(series["time"], dtype=float)
    supports = sorted({c[len("force_"):-2] for c in log.columns if c.startswith("force_")} - {"impact"})
    lines = [f"| t - contact (s) | {' | '.join(f'{n} force x, y, z (N)' for n in supports)} | CoM velocity x, y "
             "| ZMP desired x, y | ZMP measured x, y | DCM margin (m/s) |", "|---" * (5 + len(supports)) + "|"]
    records = [r for r in log.to_dict("records") if 0.0 <= r["time"] - contact <= span]
    stride = max(1, round(1e-3 * step_ms / float(np.median(np.diff(log["time"])))))
    for row in records[::stride]:
        dt = row["time"] - contact
        k = int(np.argmin(np.abs(t_series - row["time"])))
        forces = " | ".join(", ".join(f"{row[f'force_{n}_{c}']:+.0f}" for c in "xyz") for n in supports)
        zd, zm = series["zmp_desired"][k], series["zmp"][k]
        lines.append(f"| {dt:+.3f} | {forces} | {row['comd_x']:+.3f}, {row['comd_y']:+.3f} "
                     f"| {zd[0]:+.3f}, {zd[1]:+.3f} | {zm[0]:+.3f}, {zm[1]:+.3f} | {series['com_velocity_margin'][k]:+.3f} |")
    return "\n".join(lines)


def branches_table(args: argparse.Namespace, summary: dict, log, window: float = 0.2, every: int = 5) -> str:
    """Along the logged approach up to the contact: the floating cap, and the contact-aware jump
    per m/s (upper restitution bound) and cap with the fixed point warm-started from the
    previous logged posture (continued from the first) or cold (gauges 0), computed at every
    logged posture; printed for the last ``window`` s before the contact, every ``every``-th
    logged posture counted back from the contact."""
    from impact_balance.governor.support import ContactAwareLimit

    _, _, governed, _ = governed_setup(args.scenario, rigid=True)
    floating = Governor(governed, criterion="com")
    spec = governed.impact.spec()
    warm, cold = ContactAwareLimit(spec, every=1), ContactAwareLimit(spec, every=1)
    contact = summary["trial"]["impact"]["contact_time"]
    lines = ["| t - contact (s) | floating cap (m/s) | cold: jump per m/s x, y | cold cap | warm: jump per m/s x, y "
             "| warm cap |", "|---|---|---|---|---|---|"]
    rows: list[str] = []
    for row in log.to_dict("records"):
        dt = row["time"] - contact
        if dt >= 0.0:
            break
        answer = floating.limit_com(configuration(floating.robot, row), (row["comd_x"], row["comd_y"]))
        posture = floating.posture
        warm.new_posture(lambda: posture.stance)
        if dt < -window:
            continue
        cold._warm = None
        cold.new_posture(lambda: posture.stance)
        area = posture.areas.com_velocity_area
        a, b = (s.answer(area, answer.com_velocity) for s in (cold, warm))
        rows.append(f"| {dt:+.3f} | {answer.max_approach_speed:.3f} | {a.rates[-1][0]:+.3f}, {a.rates[-1][1]:+.3f} "
                    f"| {a.limit.max_approach_speed:.3f} | {b.rates[-1][0]:+.3f}, {b.rates[-1][1]:+.3f} "
                    f"| {b.limit.max_approach_speed:.3f} |")
    return "\n".join(lines + rows[::-every][::-1])


def contact_posture_table(args: argparse.Namespace, summary: dict, log) -> str:
    """At the last logged posture before the contact, with the measured approach speed and the
    logged CoM velocity before the impact: the margin (m/s) in the CoM velocity area inset by the
    controller's margin of the measured post-impact CoM velocity, of the floating set's worst
    vertex and of the contact-aware jump (cold start) at both restitution bounds."""
    from impact_balance.contact_impact import contact_impact

    impact = summary["trial"]["impact"]
    speed = summary["speed_at_contact"]
    row = [r for r in log.to_dict("records") if r["time"] < impact["contact_time"]][-1]
    _, _, governed, _ = governed_setup(args.scenario, rigid=True)
    governor = Governor(governed, criterion="com")
    before = np.array([row["comd_x"], row["comd_y"]])
    governor.limit_com(configuration(governor.robot, row), before)
    posture = governor.posture
    area, spec = posture.areas.com_velocity_area, governed.impact.spec()
    floating = posture.impact.post_impact_com_velocities(before, speed)
    worst = floating[int(np.argmin(area.margins(floating)))]
    cases = [("measured", np.asarray(impact["com_velocity_after"], dtype=float)), ("floating, worst vertex", worst)]
    cases += [(f"contact-aware, c_r {c:g}", contact_impact(posture.stance, spec, speed, com_velocity=before,
                                                          restitution=float(c)).post_impact_com_velocity)
              for c in spec.restitution]
    lines = [f"At the contact posture (t = {row['time']:.3f} s), v_n {speed:.3f} m/s, area inset by the controller's margin:",
             "", "| post-impact CoM velocity | x, y (m/s) | inset margin (m/s) |", "|---|---|---|"]
    lines += [f"| {name} | {v[0]:+.3f}, {v[1]:+.3f} | {area.margins(v[:2])[0]:+.4f} |" for name, v in cases]
    return "\n".join(lines)


def trace(args: argparse.Namespace, out: Path) -> None:
    """One logged approach: its outcome, the table after the impact, and (``--branches``) the
    contact-aware jump's warm and cold answers along the approach."""
    summary, log, series = logged_trial(args, out)
    trial = summary["trial"]
    print(f"{args.scenario} {args.governor} {args.reference:g} m/s, wall {100 * args.wall:g} cm: {summary['outcome']} "
          f"({summary['reason']}), speed at contact {_f(summary['speed_at_contact'])}, cap at contact "
          f"{_f(summary['cap_at_contact'])}, raw margin at the end {trial['com_velocity_margin_at_end']:+.3f} m/s\n")
    print(after_impact_table(summary, log, series, args.every))
    if summary["speed_at_contact"] is not None:
        print("\n" + contact_posture_table(args, summary, log))
    if args.branches:
        print("\n" + branches_table(args, summary, log))


# -- command line ---------------------------------------------------------------------------------
def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("score", help="the governed trials (36 with the defaults)")
    s.add_argument("--out", default="contact-aware-governor", help="folder of the journals and score.json")
    s.add_argument("--variant", choices=("aware", "cold", "off"), default="aware",
                   help="aware: --contact-aware as frozen (default); cold: post hoc cold start; off: without it")
    s.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    s.add_argument("--references", type=float, nargs="+", default=[0.5, 1.0, 2.0], help="m/s")
    s.add_argument("--distances", type=float, nargs="+", default=[0.12, 0.15, 0.18], help="walls, m, in this order")
    w = sub.add_parser("sweep", help="ungoverned approaches at wall 15 cm (33 with the defaults)")
    w.add_argument("--out", default="contact-aware-governor", help="folder of the journals and sweep.json")
    w.add_argument("--scenarios", nargs="+", default=list(SWEEP_REFERENCES))
    w.add_argument("--references", type=float, nargs="+", help="m/s (default: each stance's own, SWEEP_REFERENCES)")
    b = sub.add_parser("bounds", help="the caps at the scenario postures (no simulation)")
    b.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    b.add_argument("--margins", type=float, nargs="+", default=[0.0, 0.01], help="ZMP margins, m, ascending")
    r = sub.add_parser("preload", help="the preload model against the training stances' trials, the ramp's jumps")
    r.add_argument("--out", default="contact-aware-governor", help="folder of the journals and preload.json")
    r.add_argument("--scenarios", nargs="+", default=list(TRAINING))
    r.add_argument("--speeds", type=float, nargs="+", default=[0.25, 0.5, 0.75], help="commanded, m/s")
    t = sub.add_parser("trace", help="one logged approach: after the impact, and the warm/cold branches")
    t.add_argument("--out", default="contact-aware-governor", help="folder of the trial's log and summary")
    t.add_argument("--scenario", default="palm_push_ramp")
    t.add_argument("--governor", choices=("com", "none"), default="com")
    t.add_argument("--contact-aware", action="store_true", help="the governor with the option")
    t.add_argument("--reference", type=float, default=1.0, help="m/s")
    t.add_argument("--wall", type=float, default=0.12, help="m")
    t.add_argument("--every", type=float, default=50.0, help="rows of the table after the impact, ms")
    t.add_argument("--branches", action="store_true", help="warm and cold contact-aware answers before the contact")
    args = p.parse_args(argv)
    print(f"{_load()} at the start", file=sys.stderr, flush=True)
    if args.command == "bounds":
        print(bounds_table(bounds(args), args.margins))
        print(f"\n{_load()} at the end")
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.command == "trace":
        trace(args, out)
        return 0
    run, table = {"score": (score, score_table), "sweep": (sweep, sweep_table),
                  "preload": (preload, preload_table)}[args.command]
    rows, failures = run(args, out)
    print(table(rows))
    if args.command == "preload":
        print("\nThe ramp (palm_push_ramp, scenario posture, 10 mm inset):\n")
        print(ramp_jumps())
    print(f"\n{_load()} at the end; {len(rows)} trials, {failures} failed")
    (out / f"{args.command}{'_' + args.variant if args.command == 'score' else ''}.json").write_text(
        json.dumps(rows, allow_nan=False, default=float))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
