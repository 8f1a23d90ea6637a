"""``trace``: one logged approach (log and summary kept in ``--out``), from the contact on
(forces, CoM velocity, ZMP, DCM margin), the margins at the contact posture, and (``--branches``)
the contact-aware jump's warm- and cold-started answers along the approach."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from benchmarks.governor_study import _f, governed_setup
from impact_balance.governor import Governor
from impact_balance.sim.studies.wall import WallOptions, run_wall_trial

__all__ = [
    "after_impact_table",
    "branches_table",
    "configuration",
    "contact_posture_table",
    "logged_trial",
    "trace",
]


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

    aware = "_aware" if args.contact_aware else ""
    tag = f"{args.scenario}_{args.governor}{aware}_{args.reference:g}_{args.wall:g}"
    summary_path, log_path = out / f"trace_{tag}.json", out / f"trace_{tag}.parquet"
    if summary_path.exists() and log_path.exists():
        saved = json.loads(summary_path.read_text())
        return saved["summary"], pd.read_parquet(log_path), saved["series"]
    options, _, governed, setup = governed_setup(args.scenario, rigid=True)
    options = dataclasses.replace(options, record=True)
    governor = (
        None
        if args.governor == "none"
        else Governor(governed, criterion="com", contact_aware=args.contact_aware)
    )
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
    supports = sorted(
        {c[len("force_") : -2] for c in log.columns if c.startswith("force_")} - {"impact"}
    )
    lines = [
        f"| t - contact (s) | {' | '.join(f'{n} force x, y, z (N)' for n in supports)} | CoM "
        "velocity x, y | ZMP desired x, y | ZMP measured x, y | DCM margin (m/s) |",
        "|---" * (5 + len(supports)) + "|",
    ]
    records = [r for r in log.to_dict("records") if 0.0 <= r["time"] - contact <= span]
    stride = max(1, round(1e-3 * step_ms / float(np.median(np.diff(log["time"])))))
    for row in records[::stride]:
        dt = row["time"] - contact
        k = int(np.argmin(np.abs(t_series - row["time"])))
        forces = " | ".join(
            ", ".join(f"{row[f'force_{n}_{c}']:+.0f}" for c in "xyz") for n in supports
        )
        zd, zm = series["zmp_desired"][k], series["zmp"][k]
        lines.append(
            f"| {dt:+.3f} | {forces} | {row['comd_x']:+.3f}, {row['comd_y']:+.3f} | {zd[0]:+.3f}, "
            f"{zd[1]:+.3f} | {zm[0]:+.3f}, {zm[1]:+.3f} | {series['com_velocity_margin'][k]:+.3f} |"
        )
    return "\n".join(lines)


def branches_table(
    args: argparse.Namespace, summary: dict, log, window: float = 0.2, every: int = 5
) -> str:
    """Along the logged approach up to the contact: the floating cap, and the contact-aware jump
    per m/s (upper restitution bound) and cap with the fixed point warm-started from the
    previous logged posture (continued from the first) or cold (gauges 0), and the union's
    (``starts="union"``: its distinct solutions at the upper bound, its cap and the time of its
    recomputation, ms), computed at every logged posture; printed for the last ``window`` s before
    the contact, every ``every``-th logged posture counted back from the contact."""
    import time

    from impact_balance.governor.support import ContactAwareLimit

    _, _, governed, _ = governed_setup(args.scenario, rigid=True)
    floating = Governor(governed, criterion="com")
    spec = governed.impact.spec()
    upper = float(spec.restitution[-1])
    warm, cold, union = (
        ContactAwareLimit(spec, every=1, starts=s) for s in ("warm", "cold", "union")
    )
    contact = summary["trial"]["impact"]["contact_time"]
    lines = [
        "| t - contact (s) | floating cap (m/s) | cold: jump per m/s x, y | cold cap | warm: "
        "jump per m/s x, y | warm cap | union: jumps per m/s x, y (upper c_r) | union cap | "
        "union ms |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    rows: list[str] = []
    costs: list[float] = []  # the union's recomputation, ms
    warm_costs: list[float] = []  # the frozen warm start's, ms
    for row in log.to_dict("records"):
        dt = row["time"] - contact
        if dt >= 0.0:
            break
        answer = floating.limit_com(
            configuration(floating.robot, row), (row["comd_x"], row["comd_y"])
        )
        posture = floating.posture
        t0 = time.perf_counter()
        warm.new_posture(lambda posture=posture: posture.stance)
        t1 = time.perf_counter()
        union.new_posture(lambda posture=posture: posture.stance)
        warm_costs.append(1e3 * (t1 - t0))
        costs.append(1e3 * (time.perf_counter() - t1))
        if dt < -window:
            continue
        cold.new_posture(lambda posture=posture: posture.stance)
        a, b, u = (
            s.answer(posture.com_criterion, answer.com_velocity) for s in (cold, warm, union)
        )
        jumps = "; ".join(
            f"{x:+.3f}, {y:+.3f}"
            for (x, y), c in zip(u.rates, u.restitution, strict=True)
            if c == upper
        )
        rows.append(
            f"| {dt:+.3f} | {answer.max_contact_velocity:.3f} | {a.rates[-1][0]:+.3f}, "
            f"{a.rates[-1][1]:+.3f} | {a.limit.max_contact_velocity:.3f} | {b.rates[-1][0]:+.3f}, "
            f"{b.rates[-1][1]:+.3f} | {b.limit.max_contact_velocity:.3f} | {jumps} | "
            f"{u.limit.max_contact_velocity:.3f} | {costs[-1]:.1f} |"
        )
    tail = (
        f"\nThe union's recomputation over the {len(costs)} logged postures of the approach: "
        f"median {np.median(costs):.1f} ms, p99 {np.percentile(costs, 99):.1f} ms, max "
        f"{max(costs):.1f} ms (the warm start's: median {np.median(warm_costs):.1f} ms, p99 "
        f"{np.percentile(warm_costs, 99):.1f} ms)."
    )
    return "\n".join(lines + rows[::-every][::-1]) + "\n" + tail


def contact_posture_table(args: argparse.Namespace, summary: dict, log) -> str:
    """At the last logged posture before the contact, with the measured approach speed and the
    logged CoM velocity before the impact: the margin (m/s) in the CoM velocity area inset by the
    controller's margin of the measured post-impact CoM velocity, of the floating set's worst
    vertex and of the contact-aware jump (cold start) at both restitution bounds."""
    from impact_balance.impact.contact_aware import contact_impact

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
    cases = [
        ("measured", np.asarray(impact["com_velocity_after"], dtype=float)),
        ("floating, worst vertex", worst),
    ]
    cases += [
        (
            f"contact-aware, c_r {c:g}",
            contact_impact(
                posture.stance, spec, speed, com_velocity=before, restitution=float(c)
            ).post_impact_com_velocity,
        )
        for c in spec.restitution
    ]
    lines = [
        f"At the contact posture (t = {row['time']:.3f} s), v_n {speed:.3f} m/s, area inset by "
        "the controller's margin:",
        "",
        "| post-impact CoM velocity | x, y (m/s) | inset margin (m/s) |",
        "|---|---|---|",
    ]
    lines += [
        f"| {name} | {v[0]:+.3f}, {v[1]:+.3f} | {area.margins(v[:2])[0]:+.4f} |"
        for name, v in cases
    ]
    return "\n".join(lines)


def trace(args: argparse.Namespace, out: Path) -> None:
    """One logged approach: its outcome, the table after the impact, and (``--branches``) the
    contact-aware jump's warm and cold answers along the approach."""
    summary, log, series = logged_trial(args, out)
    trial = summary["trial"]
    print(
        f"{args.scenario} {args.governor} {args.reference:g} m/s, wall {100 * args.wall:g} cm: "
        f"{summary['outcome']} ({summary['reason']}), speed at contact "
        f"{_f(summary['speed_at_contact'])}, cap at contact {_f(summary['cap_at_contact'])}, raw "
        f"margin at the end {trial['com_velocity_margin_at_end']:+.3f} m/s\n"
    )
    print(after_impact_table(summary, log, series, args.every))
    if summary["speed_at_contact"] is not None:
        print("\n" + contact_posture_table(args, summary, log))
    if args.branches:
        print("\n" + branches_table(args, summary, log))
