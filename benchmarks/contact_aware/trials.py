"""The simulated trials of ``score`` (governed, with or without the option: union, warm or cold
starts) and ``sweep`` (ungoverned, wall 15 cm, the inset rule), and their tables."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.contact_aware.journal import journalled, open_journal, slim
from benchmarks.governor_study import _f, governed_setup
from impact_balance.contacts.stance import Stance
from impact_balance.governor import ContactAwareOptions, Governor
from impact_balance.sim.studies.wall import WallOptions, run_wall_trial

__all__ = [
    "OUTCOMES",
    "SWEEP_REFERENCES",
    "SWEEP_WALL",
    "VARIANTS",
    "score",
    "score_table",
    "sweep",
    "sweep_table",
]

SWEEP_WALL = 0.15  # m
#: The ungoverned sweeps' commanded references (m/s), around each stance's fall.
SWEEP_REFERENCES = {
    "palm_push_two_feet": (0.42, 0.44, 0.46, 0.48, 0.5, 0.52, 0.55),
    "palm_push_ramp": (0.55, 0.6, 0.62, 0.64, 0.66, 0.68, 0.7, 0.72, 0.74, 0.76, 0.8),
    "kick_one_foot": (1.3, 1.4, 1.45, 1.5, 1.55, 1.6, 1.7),
    "g1_two_feet": (0.38, 0.4, 0.42, 0.44, 0.46, 0.48, 0.5, 0.55),
}
OUTCOMES = ("balanced", "contact_broken", "fell")


# -- score: the governed trials -------------------------------------------------------------------
#: ``--variant``: the option's starts (governor/support.py), or "off" (without the option).
VARIANTS = ("union", "warm", "cold", "off", "async")


def _timed(governor: Governor) -> list[tuple[float, int, int]]:
    """Record, for every recomputation of ``governor``'s contact-aware rates, ``(ms, rows of
    the rates, QP solves)``; returns the (live) list, which the caller empties per trial."""
    support, record = governor._support, []
    inner = support._solve

    def solve(stance: Stance, kept):
        t0 = time.perf_counter()
        solutions = inner(stance, kept)
        record.append(
            (1e3 * (time.perf_counter() - t0), len(solutions.rates), solutions.iterations)
        )
        return solutions

    support._solve = solve
    return record


def _adoptions(governor: Governor) -> list[int]:
    """Record the age (postures) of the rates each time the worker's answer replaces them
    (``contact_aware_async``); returns the (live) list."""
    support, ages = governor._support, []
    inner = support.adopt

    def adopt(solutions):
        ages.append(support._age)
        inner(solutions)

    support.adopt = adopt
    return ages


def score(args: argparse.Namespace, out: Path) -> tuple[list[dict], int]:
    """The governed trials of ``args.variant`` (module docstring); rows and failures."""
    rows, failures = [], 0
    for name in args.scenarios:
        pairs, failed = _score_scenario(args, out, name)
        failures += failed
        rows += [
            {
                "scenario": name,
                "variant": args.variant,
                "velocity_margin": args.velocity_margin,
                **t,
            }
            for _, e in pairs
            for t in e["trials"]
        ]
    return rows, failures


def _score_scenario(args: argparse.Namespace, out: Path, name: str) -> tuple[list, int]:
    """The journalled governed trials of ``name``: ``(key, entry)`` pairs and failures."""
    options, margin, governed, setup = governed_setup(name, rigid=True)
    parts = {"variant": args.variant, "margin": margin}
    if args.velocity_margin:  # keeps the journals of the runs without one
        parts["velocity_margin"] = args.velocity_margin
    journal = open_journal(out, "score", name, parts)

    def new_governor() -> Governor:
        if args.variant == "off":
            return Governor(governed, criterion="com", velocity_margin=args.velocity_margin)
        if args.variant == "async":
            # the union's starts, recomputed by a worker process off the tick
            return Governor(
                governed,
                criterion="com",
                contact_aware=ContactAwareOptions(asynchronous=True),
                velocity_margin=args.velocity_margin,
            )
        return Governor(
            governed,
            criterion="com",
            contact_aware=ContactAwareOptions(starts=args.variant),
            velocity_margin=args.velocity_margin,
        )

    def run(key: dict) -> dict:
        # one governor for the walls of a reference, as the command
        governor, trials = new_governor(), []
        record = [] if governor._support is None else _timed(governor)
        ages = [] if governor._worker is None else _adoptions(governor)
        for distance in key["distances"]:
            if args.variant == "cold":
                governor = new_governor()  # as the post hoc cold variant of section 4 was run
                record = _timed(governor)
            del record[:]  # this trial's recomputations only
            del ages[:]
            wall = WallOptions(reference=key["reference"], governor="com", wall_distance=distance)
            trials.append(slim(run_wall_trial(setup, wall, options, governor=governor).to_dict()))
            d = trials[-1]
            ms = np.array([r[0] for r in record]) if record else np.zeros(0)
            d["recompute"] = (
                None
                if not record
                else {
                    "count": len(record),
                    "ms_median": float(np.median(ms)),
                    "ms_max": float(ms.max()),
                    "ms_p90": float(np.percentile(ms, 90)),
                    "rows_max": max(r[1] for r in record),
                    "solves_median": float(np.median([r[2] for r in record])),
                }
            )
            if ages:
                # async: postures between two answers of the worker (the rates' age when replaced)
                d["rates_age"] = {
                    "median": float(np.median(ages)),
                    "max": int(max(ages)),
                    "answers": len(ages),
                }
            print(
                f"  {name} {key['reference']:g} m/s {100 * distance:g} cm: {d['outcome']} speed "
                f"{_f(d['speed_at_contact'])} cap {_f(d['cap_at_contact'])}",
                file=sys.stderr,
                flush=True,
            )
        governor.close()  # a worker process, with "async"
        return {"trials": trials}

    keys = [{"reference": r, "distances": list(args.distances)} for r in args.references]
    pairs, failed = journalled(journal, keys, run, f"score {name}")
    journal.close()
    return pairs, failed


def _signed(x: float | None, digits: int = 4) -> str:
    return "-" if x is None else f"{x:+.{digits}f}"


def _span(values: list[float], digits: int = 3) -> str:
    return "-" if not values else f"{min(values):.{digits}f} to {max(values):.{digits}f}"


def score_table(rows: list[dict]) -> str:
    """Outcome counts and ranges per scenario (the table of docs/contact_aware_governor.md)."""
    lines = [
        "| scenario | variant | trials | balanced / contact broken / fell | measured speed at "
        "contact (m/s) | cap at contact (m/s) | speed / min(ref, cap) | tick median (us) | tick "
        "p99 (us) | recomputation median / max (ms) | rows of the rates (most) |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name]
        counts = " / ".join(str(sum(r["outcome"] == o for r in group)) for o in OUTCOMES)
        speeds = [r["speed_at_contact"] for r in group if r["speed_at_contact"] is not None]
        caps = [r["cap_at_contact"] for r in group if r["cap_at_contact"] is not None]
        ratios = [
            r["speed_at_contact"] / min(r["reference"], r["cap_at_contact"])
            for r in group
            if r["speed_at_contact"] is not None and r["cap_at_contact"] is not None
        ]
        ticks = [r["tick_us"] for r in group if r["tick_us"]["median"] is not None]
        recomputes = [r["recompute"] for r in group if r.get("recompute")]
        costs = (
            "-"
            if not recomputes
            else (
                f"{np.median([c['ms_median'] for c in recomputes]):.1f} / "
                f"{max(c['ms_max'] for c in recomputes):.1f}"
            )
        )
        most = "-" if not recomputes else str(max(c["rows_max"] for c in recomputes))
        lines.append(
            f"| {name} | {group[0]['variant']} | {len(group)} | {counts} | {_span(speeds)} | "
            f"{_span(caps)} | {_span(ratios, 2)} | {_span([t['median'] for t in ticks], 0)} | "
            f"{_span([t['p99'] for t in ticks], 0)} | {costs} | {most} |"
        )
    lines += [
        "",
        "| scenario | reference (m/s) | wall (cm) | outcome | speed at contact (m/s) | cap at "
        "contact (m/s) | speed / cap | raw margin at end (m/s) | slip (cm) | tick median / p99 "
        "(us) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        ratio = (
            "-"
            if r["speed_at_contact"] is None or r["cap_at_contact"] is None
            else f"{r['speed_at_contact'] / r['cap_at_contact']:.4f}"
        )
        tick = r["tick_us"]
        ticks = "-" if tick["median"] is None else f"{tick['median']:.0f} / {tick['p99']:.0f}"
        lines.append(
            f"| {r['scenario']} | {r['reference']:g} | {100 * r['wall_distance']:g} | "
            f"{r['outcome']} | {_f(r['speed_at_contact'])} | {_f(r['cap_at_contact'])} | {ratio} | "
            f"{r['margin_raw']:+.3f} | {100 * r['max_slip']:.1f} | {ticks} |"
        )
    return "\n".join(lines)


# -- sweep: ungoverned approaches and the inset rule ----------------------------------------------
def sweep(args: argparse.Namespace, out: Path) -> tuple[list[dict], int]:
    """Ungoverned approaches at wall 15 cm with the inset margin at the end of the impact."""
    rows, failures = [], 0
    for name in args.scenarios:
        pairs, failed = _sweep_scenario(args, out, name)
        failures += failed
        rows += [{"scenario": name, **e} for _, e in pairs]
    return rows, failures


def _sweep_scenario(args: argparse.Namespace, out: Path, name: str) -> tuple[list, int]:
    """The journalled ungoverned trials of ``name``: ``(key, entry)`` pairs and failures."""
    options, margin, _, setup = governed_setup(name, rigid=True)
    inset = setup.analysis.areas.com_velocity_area_inset(margin)
    journal = open_journal(out, "sweep", name, {"wall": SWEEP_WALL, "margin": margin})

    def run(key: dict) -> dict:
        wall = WallOptions(reference=key["reference"], governor="none", wall_distance=SWEEP_WALL)
        d = slim(run_wall_trial(setup, wall, options).to_dict())
        after = np.asarray(
            d["com_velocity_after"] if d["com_velocity_after"] is not None else [np.nan] * 2
        )
        d["margin_inset"] = float(inset.margins(after)[0]) if np.isfinite(after).all() else None
        print(
            f"  {name} {key['reference']:g} m/s: {d['outcome']} speed {_f(d['speed_at_contact'])} "
            f"inset margin {_signed(d['margin_inset'])}",
            file=sys.stderr,
            flush=True,
        )
        return d

    references = args.references or SWEEP_REFERENCES[name]
    pairs, failed = journalled(
        journal, [{"reference": r} for r in references], run, f"sweep {name}"
    )
    journal.close()
    return pairs, failed


def _trial_cell(r: dict | None) -> str:
    """A trial's speed at contact (m/s) and inset margin (m/s), or "-" without a trial."""
    return "-" if r is None else f"{r['speed_at_contact']:.3f} ({_signed(r['margin_inset'])})"


def sweep_table(rows: list[dict]) -> str:
    """Every trial, then per stance the fastest that did not fall and the slowest that fell."""
    lines = [
        "| scenario | reference (m/s) | measured v_n (m/s) | outcome | raw margin | inset margin "
        "| slip (cm) | sustained impulse z per contact (N s) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        sustained = ", ".join(
            f"{k} {v[2]:+.2f}" for k, v in (r["sustained_impulses"] or {}).items()
        )
        lines.append(
            f"| {r['scenario']} | {r['reference']:g} | {_f(r['speed_at_contact'])} | "
            f"{r['outcome']} | {r['margin_raw']:+.3f} | {_signed(r['margin_inset'])} | "
            f"{100 * r['max_slip']:.2f} | {sustained} |"
        )
    lines += [
        "",
        "| scenario | trials | stood: largest v_n (inset margin) | fell: smallest v_n (inset "
        "margin) |",
        "|---|---|---|---|",
    ]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name and r["speed_at_contact"] is not None]
        stood = [r for r in group if r["outcome"] != "fell"]
        fell = [r for r in group if r["outcome"] == "fell"]
        best = max(stood, key=lambda r: r["speed_at_contact"], default=None)
        worst = min(fell, key=lambda r: r["speed_at_contact"], default=None)
        lines.append(f"| {name} | {len(group)} | {_trial_cell(best)} | {_trial_cell(worst)} |")
    stood = [
        r["margin_inset"] for r in rows if r["outcome"] != "fell" and r["margin_inset"] is not None
    ]
    fell = [
        r["margin_inset"] for r in rows if r["outcome"] == "fell" and r["margin_inset"] is not None
    ]
    lines.append(
        f"\nThe inset rule over {len(rows)} trials: the trials that did not fall end with inset "
        f"margins >= {_signed(min(stood, default=None))} m/s; those that fell <= "
        f"{_signed(max(fell, default=None))} m/s."
    )
    return "\n".join(lines)
