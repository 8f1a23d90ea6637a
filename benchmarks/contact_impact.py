"""The contact-aware impact model (``impact_balance.impact.contact_aware``) against MuJoCo.

    python benchmarks/contact_impact.py [--speeds 0.25,0.5,0.75] [--out rows.jsonl] [--resume]
                                        [--scenarios NAME ...]

For every bundled scenario with an impact and every commanded approach speed: one ``servo``
trial with ``--rigid-impact`` (every joint keeps its velocity from the contact to the end of the
compression: the composite model's robot, standing on its contacts), measured by
``impact_balance.sim.trials.measure`` (the trial ``impact-balance simulate SCENARIO --joints servo
--rigid-impact`` runs). Reported per row:

- the measured CoM velocity jump (xy) and the impulse the sustained contacts took (force before
  the impact subtracted);
- the floating composite model (the paper's): the distance of the measured jump to its
  predicted set, at the measured approach speed and restitution (what ``simulate`` prints);
- the contact-aware model at the same measured speed and restitution, on the same stance: its
  jump, the error ``|predicted - measured|`` and the sustained contacts' predicted impulse;
- the same Coulomb impact model without the sustained contacts (the floating robot, one point
  prediction inside the floating set): what the contacts change at equal friction law.

Nothing is fitted: both models take the stance, the scenario's impact (normal, friction) and the
two measured numbers. Rows are appended to ``--out`` as JSON lines as they finish (``--resume``
skips the rows already there); the markdown table and the load average are printed at the end,
with the maximum contact velocity each model's jump gives (no simulation; compare with the
measured fall brackets in docs/validation.md).
One trial at a time (one process).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from impact_balance.contacts.stance import Stance
from impact_balance.criteria.com import max_contact_velocity
from impact_balance.impact.contact_aware import contact_impact
from impact_balance.scenario import bundled_scenarios, load_scenario
from impact_balance.sim import SimOptions, build_model
from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
from impact_balance.sim.trials.measure import measure


def impact_scenarios() -> list[str]:
    return [name for name in bundled_scenarios() if load_scenario(name).impact is not None]


def one_row(sim, name: str, speed: float) -> dict:
    """One rigid-impact trial at commanded ``speed`` and both models' predictions."""
    start = time.perf_counter()
    result = measure(sim, run_trial(sim, TrialOptions(speed, after=0.05, rigid_impact=True)), speed)
    v_n, e = result.approach_speed_measured, result.restitution_measured
    measured = np.asarray(result.com_velocity_jump_measured, dtype=float)
    floating = result.predicted["composite"]
    model = contact_impact(sim.stance, sim.scenario.impact.spec(), v_n, restitution=e)
    error = float(np.linalg.norm(model.com_velocity_jump - measured))
    # The same Coulomb impact without the sustained contacts: what the contacts change, at equal
    # friction law.
    free = contact_impact(
        Stance(sim.stance.robot, sim.stance.q, []), sim.scenario.impact.spec(), v_n, restitution=e
    )
    sustained = (
        np.sum(list(result.sustained_impulses.values()), axis=0)
        if result.sustained_impulses
        else np.zeros(3)
    )
    return {
        "scenario": name,
        "speed": speed,
        "approach_measured": v_n,
        "restitution_measured": e,
        "slip": result.slip_speed,
        "contacts_kept": result.contacts_kept,
        "jump_measured": measured.tolist(),
        "impact_impulse_measured": result.impulse_measured.tolist(),
        "sustained_impulse_measured": sustained.tolist(),
        "sustained_impulses_measured": {
            k: v.tolist() for k, v in result.sustained_impulses.items()
        },
        "floating_distance": floating.distance,
        "floating_jump_x_range": [
            float(floating.com_velocity_jumps[:, 0].min()),
            float(floating.com_velocity_jumps[:, 0].max()),
        ],
        "contact_jump": model.com_velocity_jump.tolist(),
        "contact_error": error,
        "contact_relative_error": error / float(np.linalg.norm(measured))
        if np.linalg.norm(measured) > 0
        else None,
        "contact_impact_impulse": model.impact_impulse.tolist(),
        "contact_sustained_impulse": model.contact_impulses.sum(axis=0).tolist(),
        "contact_impulses": model.contact_impulses.tolist(),
        "free_jump": free.com_velocity_jump.tolist(),
        "free_error": float(np.linalg.norm(free.com_velocity_jump - measured)),
        "contact_converged": model.converged,
        "contact_iterations": model.iterations,
        "hold": result.hold,
        "wall_time": time.perf_counter() - start,
        "loadavg": os.getloadavg(),
    }


def table(rows: list[dict]) -> str:
    head = (
        "| scenario | v cmd | v_n meas. | e meas. | jump measured x, y | floating: distance (x "
        "range) | same law, no sustained contacts: jump x, y (error) | contact-aware: jump x, y | "
        "error (rel.) | sustained impulse x, z: measured / predicted (N s) |"
    )
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        jm, jc = r["jump_measured"], r["contact_jump"]
        lo, hi = r["floating_jump_x_range"]
        rel = r["contact_relative_error"]
        sm, sp = r["sustained_impulse_measured"], r["contact_sustained_impulse"]
        lines.append(
            f"| {r['scenario']} | {r['speed']:g} | {r['approach_measured']:.3f} | "
            f"{r['restitution_measured']:.2f} | {jm[0]:+.3f}, {jm[1]:+.3f} | "
            f"{r['floating_distance']:.3f} ({lo:+.3f} to {hi:+.3f}) | {r['free_jump'][0]:+.3f}, "
            f"{r['free_jump'][1]:+.3f} ({r['free_error']:.3f}) | {jc[0]:+.3f}, "
            f"{jc[1]:+.3f}{'' if r['contact_converged'] else ' (not converged)'} | "
            f"{r['contact_error']:.3f} ({100 * rel:.0f} %) | {sm[0]:+.2f}, {sm[2]:+.2f} / "
            f"{sp[0]:+.2f}, {sp[2]:+.2f} |"
        )
    return "\n".join(lines)


def _first_exit(area, com_velocity: np.ndarray, rate: np.ndarray) -> float:
    """Largest t with ``com_velocity + t rate`` in ``area`` (the criterion's ray, m/s)."""
    G, h = area.halfplanes
    margins, rates = h - G @ com_velocity, G @ rate
    leaving = rates > 1e-15
    return float(np.min(margins[leaving] / rates[leaving])) if leaving.any() else float("inf")


def criterion_table(names: list[str], margin: float) -> str:
    """The maximum contact velocity with either model's CoM velocity jump (no simulation): the
    floating model's (the criterion's own), and the contact-aware jump's at both ends of the
    restitution range (the smaller), in the area and in the area inset by ``margin`` (the
    balance controller's ZMP margin, m)."""
    import impact_balance as ib

    lines = [
        f"| scenario | floating: max v_n, m/s (no margin / {1e3 * margin:g} mm) | contact-aware "
        f"(no margin / {1e3 * margin:g} mm) |",
        "|---|---|---|",
    ]
    for name in names:
        a = ib.analyze(name)
        spec, c0 = a.scenario.impact.spec(), np.asarray(a.com_velocity, dtype=float)
        floating = [a.impact.max_contact_velocity]
        inset = a.areas.com_velocity_area_inset(margin)

        floating.append(max_contact_velocity(inset, a.impact.model, c0).max_contact_velocity)
        rates = [
            contact_impact(a.stance, spec, 1.0, restitution=c).com_velocity_jump
            for c in spec.restitution
        ]
        aware = [
            min(_first_exit(area, c0, r) for r in rates)
            for area in (a.areas.com_velocity_area, inset)
        ]
        lines.append(
            f"| {name} | {floating[0]:.3f} / {floating[1]:.3f} | {aware[0]:.3f} / {aware[1]:.3f} |"
        )
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--speeds", default="0.25,0.5,0.75", help="commanded approach speeds, m/s")
    parser.add_argument(
        "--out", default="contact_impact_rows.jsonl", help="JSON lines, appended as rows finish"
    )
    parser.add_argument(
        "--resume", action="store_true", help="skip the (scenario, speed) rows already in --out"
    )
    parser.add_argument(
        "--scenarios", nargs="*", help="default: every bundled scenario with an impact"
    )
    parser.add_argument(
        "--margin",
        type=float,
        default=0.01,
        help="ZMP margin of the criterion table, m (default 0.01)",
    )
    args = parser.parse_args()
    speeds = [float(s) for s in args.speeds.split(",")]
    out = Path(args.out)
    done = []
    if args.resume and out.exists():
        done = [json.loads(line) for line in out.read_text().splitlines() if line.strip()]
    elif out.exists():
        out.unlink()
    seen = {(r["scenario"], r["speed"]) for r in done}
    load_before = os.getloadavg()
    start = time.perf_counter()
    rows = list(done)
    for name in args.scenarios or impact_scenarios():
        todo = [s for s in speeds if (name, s) not in seen]
        if not todo:
            continue
        sim = build_model(name, "servo", SimOptions(meshes=False))
        for speed in todo:
            try:
                row = one_row(sim, name, speed)
            except Exception as exc:
                row = {"scenario": name, "speed": speed, "error": f"{type(exc).__name__}: {exc}"}
            with out.open("a") as f:
                f.write(json.dumps(row) + "\n")
            rows.append(row)
            status = row.get("error") or f"error {row['contact_error']:.3f} m/s"
            print(f"{name} {speed:g}: {status} ({row.get('wall_time', 0):.1f} s)", flush=True)
    ok = [r for r in rows if "error" not in r]
    failed = [r for r in rows if "error" in r]
    print()
    print(table(ok))
    for r in failed:
        print(f"\nfailed: {r['scenario']} {r['speed']:g}: {r['error']}")
    print("\nThe maximum contact velocity with each model's jump (no simulation):\n")
    print(criterion_table(args.scenarios or impact_scenarios(), args.margin))
    print(
        f"\nload average (1, 5, 15 min) before: {', '.join(f'{x:.2f}' for x in load_before)}; "
        f"after: {', '.join(f'{x:.2f}' for x in os.getloadavg())}; {os.cpu_count()} cores; "
        f"run {time.perf_counter() - start:.0f} s"
    )


if __name__ == "__main__":
    main()
