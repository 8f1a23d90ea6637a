"""The preload model (rejected on the training stances): the contact-aware jump with gravity
acting over the impact's duration, its error on the training stances' rigid-impact trials, the
ramp's jumps with and without it, and ``bounds``, the caps at the scenario postures (no
simulation) beside the preload model's bound."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

import impact_balance as ib
from benchmarks.contact_aware.journal import journalled, open_journal
from benchmarks.contact_impact import one_row
from impact_balance.contacts.stance import Stance
from impact_balance.governor import Governor
from impact_balance.impact.contact_aware import (
    PointContact,
    _unique_columns,
    corner_contacts,
    rigid_body_impact,
)
from impact_balance.impact.model import ImpactSpec, impact_cone
from impact_balance.scenario import load_scenario
from impact_balance.sim import SimOptions, build_model

__all__ = [
    "GRAVITY",
    "TRAINING",
    "bounds",
    "bounds_table",
    "preload",
    "preload_bound",
    "preload_jump",
    "preload_table",
    "ramp_jumps",
]

GRAVITY = 9.81  # m/s^2
#: The stances the preload model was tried on before scoring (never scored).
TRAINING = ("palm_push_two_feet", "talos_tuning_stagger")


# -- the preload model (rejected on the training stances) -----------------------------------------
def preload_jump(
    stance: Stance, spec: ImpactSpec, approach_speed: float, restitution: float, duration: float
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
    impact = PointContact(
        placement.translation - stance.com_local,
        normal,
        _unique_columns(cone),
        -approach_speed * normal + shift,
        restitution,
    )
    corners = [
        PointContact(p.arm, p.normal, p.generators, shift.copy())
        for c in corner_contacts(stance)
        for p in c
    ]
    dxi, impulses, _, converged = rigid_body_impact(
        stance.mass,
        stance.com_inertia,
        [impact, *corners],
        tolerance=1e-9 * max(approach_speed, 1e-3),
    )
    return dxi[:2], impulses, converged


def preload_bound(
    stance: Stance, spec: ImpactSpec, area, com_velocity: np.ndarray, duration: float
) -> float:
    """The largest approach speed (m/s, to 2e-6) keeping the preload jump at both restitution
    bounds inside ``area``: bisection on [0, 2] m/s (the jump is affine, not linear, in the
    speed)."""

    def inside(speed: float) -> bool:
        return all(
            area.margins(com_velocity[:2] + preload_jump(stance, spec, speed, c, duration)[0])[0]
            >= 0
            for c in spec.restitution
        )

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
        pairs, failed = journalled(
            journal,
            [{"speed": s} for s in args.speeds],
            lambda key, sim=sim, name=name: one_row(sim, name, key["speed"]),
            f"preload {name}",
        )
        journal.close()
        failures += failed
        for _, row in pairs:
            measured = np.asarray(row["jump_measured"])
            errors = [
                float(
                    np.linalg.norm(
                        preload_jump(
                            sim.stance,
                            spec,
                            row["approach_measured"],
                            row["restitution_measured"],
                            t,
                        )[0]
                        - measured
                    )
                )
                for t in (0.0, spec.duration)
            ]
            rows.append(
                {
                    **row,
                    "error_no_preload": errors[0],
                    "error_preload": errors[1],
                    "duration": spec.duration,
                }
            )
    return rows, failures


def _joined(group: list[dict], key: str) -> str:
    """``group``'s values of ``key``, 3 decimals, joined by " / "."""
    return " / ".join(f"{r[key]:.3f}" for r in group)


def preload_table(rows: list[dict]) -> str:
    """|predicted - measured| of the CoM velocity jump per stance at each speed, then the ramp's
    jumps."""
    lines = [
        "| stance | commanded speeds (m/s) | no preload | preload T = impact.duration |",
        "|---|---|---|---|",
    ]
    for name in dict.fromkeys(r["scenario"] for r in rows):
        group = [r for r in rows if r["scenario"] == name]
        speeds = " / ".join(f"{r['speed']:g}" for r in group)
        lines.append(
            f"| {name} | {speeds} | {_joined(group, 'error_no_preload')} "
            f"| {_joined(group, 'error_preload')} (T = {1e3 * group[0]['duration']:g} ms) |"
        )
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
    lines = [
        f"| v_n (m/s) | c_r | T (ms) | jump x, y (m/s) | inset margin (m/s) | {heads} |",
        "|---|---|---|---|---|" + "---|" * len(names),
    ]
    for speed in speeds:
        for c_r in spec.restitution:
            for duration in (0.0, spec.duration):
                jump, impulses, _ = preload_jump(stance, spec, speed, c_r, duration)
                per_contact = np.asarray(impulses[1:]).reshape(len(names), -1, 3).sum(axis=1)
                cells = " | ".join(", ".join(f"{x:+.2f}" for x in p) for p in per_contact)
                lines.append(
                    f"| {speed:g} | {c_r:g} | {1e3 * duration:g} | {jump[0]:+.3f}, {jump[1]:+.3f} "
                    f"| {inset.margins(jump)[0]:+.4f} | {cells} |"
                )
    return "\n".join(lines)


# -- bounds: no simulation ------------------------------------------------------------------------
def bounds(args: argparse.Namespace) -> list[dict]:
    """The governor's maximum approach speed at each scenario's posture without and with the
    option, per ZMP margin (and ``args.velocity_margin``), and the preload model's bound at the
    largest ZMP margin (without the velocity margin)."""
    rows = []
    for name in args.scenarios:
        scenario = load_scenario(name)
        row: dict[str, Any] = {"scenario": name}
        for margin in args.margins:
            governed = scenario.replace(zmp_margin=margin)
            floating = Governor(governed, criterion="com", velocity_margin=args.velocity_margin)
            q, v = floating.configuration, np.zeros(floating.robot.model.nv)
            union = Governor(
                governed, criterion="com", contact_aware=True, velocity_margin=args.velocity_margin
            ).limit(q, v)
            row[f"{1e3 * margin:g} mm"] = {
                "floating": floating.limit(q, v).max_contact_velocity,
                "union": union.max_contact_velocity,
                "binding": union.binding,
            }
        analysis = ib.analyze(name)
        spec = analysis.scenario.impact.spec()
        inset = analysis.areas.com_velocity_area_inset(max(args.margins))
        row["preload"] = preload_bound(
            analysis.stance,
            spec,
            inset,
            np.asarray(analysis.com_velocity, dtype=float),
            spec.duration,
        )
        rows.append(row)
        print(f"  {name}: {row}", file=sys.stderr, flush=True)
    return rows


def bounds_table(rows: list[dict], margins: list[float]) -> str:
    tags = [f"{1e3 * m:g} mm" for m in margins]
    lines = [
        f"| scenario | floating ({' / '.join(tags)}) | union ({' / '.join(tags)}), binding model "
        f"| preload ({tags[-1] if margins == sorted(margins) else max(margins)}) |",
        "|---|---|---|---|",
    ]
    for r in rows:
        floating = " / ".join(f"{r[t]['floating']:.3f}" for t in tags)
        union = " / ".join(f"{r[t]['union']:.3f}" for t in tags)
        lines.append(
            f"| {r['scenario']} | {floating} | {union}, {r[tags[-1]]['binding']} | "
            f"{r['preload']:.3f} |"
        )
    return "\n".join(lines)
