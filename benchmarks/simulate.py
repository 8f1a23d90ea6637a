"""Issue 9 targets: the impact model against MuJoCo, and the simulation speed.

    python benchmarks/simulate.py [--json] [--speeds 0.1,0.3,0.6] [--joints rigid,servo,held]

For every bundled scenario with an impact, every approach speed and joint model, one trial
(``impact_balance.sim``): the measured CoM velocity jump, its distance to the predicted
``composite`` and ``joint_space`` sets (at the measured speed and restitution), relative to
the jump's magnitude, and where the jump falls between the two models (its magnitude over
each set's size, the largest norm of its vertices). ``servo`` joints carry the rotor
inertia the robot files declare (the SRDF's rotor_params; ``--armature`` sets one value for every
joint instead); ``held`` is ``servo`` with ``--rigid-impact`` (every joint keeps its velocity
through the impact). The impulse the sustained contacts take is reported too. Then the speed:
standing Talos (``servo``, holding ``palm_push_two_feet``) stepped for 2 s of simulated time,
bare ``mj_step`` and with the trial's recording.

Targets: ``rigid``: distance to ``composite`` <= 2 % of the jump everywhere; standing Talos
>= 5x faster than real time.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import sys
import time

import mujoco
import numpy as np

from impact_balance.scenario import bundled_scenarios, load_scenario
from impact_balance.sim import ServoOptions, SimOptions, build_model
from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
from impact_balance.sim.trials.measure import measure


def impact_scenarios() -> list[str]:
    return [name for name in bundled_scenarios() if load_scenario(name).impact is not None]


def accuracy(
    speeds: list[float],
    joints: list[str],
    armature: float | None = None,
    scenarios: list[str] | None = None,
) -> list[dict]:
    rows = []
    options = SimOptions(meshes=False, servo=ServoOptions(armature=armature))
    for name in scenarios or impact_scenarios():
        for joint_model in joints:
            held = joint_model == "held"
            sim = build_model(name, "servo" if held else joint_model, options)
            for speed in speeds:
                result = measure(
                    sim, run_trial(sim, TrialOptions(speed, after=0.05, rigid_impact=held)), speed
                )
                jump = result.com_velocity_jump_measured
                size = float(np.linalg.norm(jump))
                row = {
                    "scenario": name,
                    "joints": joint_model,
                    "speed": speed,
                    "approach_measured": result.approach_speed_measured,
                    "restitution": result.restitution_measured,
                    "slip": result.slip_speed,
                    "jump": jump.tolist(),
                    "jump_norm": size,
                    "contacts_kept": result.contacts_kept,
                    "sim_time_ratio": result.sim_time_ratio,
                    "armature": result.armature,
                    "robot": sim.robot.name,
                    "palm_impulse": float(np.linalg.norm(result.impulse_measured)),
                    "sustained_impulse": float(
                        sum(np.linalg.norm(v) for v in result.sustained_impulses.values())
                    ),
                    "hold_ms": None
                    if not result.hold or result.hold["duration"] is None
                    else 1e3 * result.hold["duration"],
                }
                for model, p in result.predicted.items():
                    extent = float(np.linalg.norm(p.com_velocity_jumps, axis=1).max())
                    row[f"{model}_distance"] = p.distance
                    row[f"{model}_relative"] = p.distance / size if size > 0 else float("nan")
                    row[f"jump_over_{model}"] = size / extent if extent > 0 else float("nan")
                rows.append(row)
                print(
                    f"  {name} {joint_model} {speed}: composite {row['composite_relative']:.2%}, "
                    f"joint_space {row['joint_space_relative']:.2%}",
                    file=sys.stderr,
                    flush=True,
                )
    return rows


def speed(seconds: float = 2.0) -> dict:
    sim = build_model("palm_push_two_feet", "servo", SimOptions(meshes=False))
    m, d = sim.model, sim.data
    steps = round(seconds / m.opt.timestep)
    start = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(m, d)
    bare = seconds / (time.perf_counter() - start)
    drift = float(np.linalg.norm(sim.com() - sim.stance.com))
    # The trial loop (servo commands + recording every step), at 0.3 m/s.
    record = run_trial(sim, TrialOptions(0.3, after=seconds))
    return {
        "timestep": m.opt.timestep,
        "simulated_s": seconds,
        "bare_ratio": bare,
        "trial_ratio": record.simulated_time / record.wall_time,
        "standing_com_drift_m": drift,
    }


def markdown(rows: list[dict], perf: dict) -> str:
    out = [
        "| scenario (robot) | joints | v (m/s) | e | |jump| (m/s) | to composite | to "
        "joint_space | |jump| / composite size | |jump| / joint_space size | impulse: impact / "
        "sustained (N s) | contacts kept |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        kept = "n/a" if r["contacts_kept"] is None else ("yes" if r["contacts_kept"] else "no")
        out.append(
            f"| {r['scenario']} ({r['robot']}) | {r['joints']} | {r['speed']:g} | "
            f"{r['restitution']:.2f} | {r['jump_norm']:.4f} | {r['composite_relative']:.2%} | "
            f"{r['joint_space_relative']:.0%} | {r['jump_over_composite']:.3f} | "
            f"{r['jump_over_joint_space']:.2f} | {r['palm_impulse']:.2f} / "
            f"{r['sustained_impulse']:.2f} | {kept} |"
        )
    sources = sorted({(r["robot"], r["armature"]) for r in rows if r["joints"] != "rigid"})
    out += [f"\narmature of {robot}: {source}" for robot, source in sources]
    rigid = [r for r in rows if r["joints"] == "rigid"]
    if rigid:
        worst = max(r["composite_relative"] for r in rigid)
        out.append(
            f"\nrigid: worst distance to the composite set {worst:.2%} of the jump (target <= 2 "
            f"%): {'pass' if worst <= 0.02 else 'FAIL'}"
        )
    if perf is None:
        return "\n".join(out)
    out.append(
        f"standing Talos (servo, step {perf['timestep'] * 1e3:g} ms): bare mj_step "
        f"{perf['bare_ratio']:.1f}x real time, trial loop with recording "
        f"{perf['trial_ratio']:.1f}x (target >= 5x): "
        f"{'pass' if perf['bare_ratio'] >= 5 else 'FAIL'}; CoM drift over {perf['simulated_s']:g} "
        f"s {perf['standing_com_drift_m'] * 1e3:.2f} mm"
    )
    return "\n".join(out)


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--json", action="store_true")
    p.add_argument("--speeds", default="0.1,0.3,0.6")
    p.add_argument("--joints", default="rigid,servo,held")
    p.add_argument(
        "--armature",
        type=float,
        default=None,
        help="servo rotor inertia of every joint, kg m^2 (default: what the robot files declare)",
    )
    p.add_argument(
        "--scenarios",
        default=None,
        help="comma-separated (default: every bundled one with an impact)",
    )
    p.add_argument("--no-speed", action="store_true", help="skip the speed measurement")
    args = p.parse_args()
    scenarios = args.scenarios.split(",") if args.scenarios else None
    load_before = [
        round(x, 2) for x in os.getloadavg()
    ]  # the machine is shared: say how busy it was
    rows = accuracy(
        [float(s) for s in args.speeds.split(",")], args.joints.split(","), args.armature, scenarios
    )
    perf = None if args.no_speed else speed()
    load_after = [round(x, 2) for x in os.getloadavg()]
    if args.json:
        print(
            json.dumps(
                {
                    "machine": platform.processor() or platform.machine(),
                    "mujoco": mujoco.__version__,
                    "load_average_before": load_before,
                    "load_average_after": load_after,
                    "trials": rows,
                    "speed": perf,
                }
            )
        )
    else:
        print(markdown(rows, perf))
        print(
            f"\nload average before {' '.join(map(str, load_before))}, after "
            f"{' '.join(map(str, load_after))}"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
