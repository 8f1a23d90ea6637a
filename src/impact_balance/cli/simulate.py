"""``impact-balance simulate SCENARIO``: the scenario's impact in MuJoCo.

The simulated impact is measured against the impact model.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import TYPE_CHECKING

from impact_balance.cli._options import (
    LOG_SUFFIXES,
    import_mujoco,
    number,
    output_file,
    output_folder,
)
from impact_balance.cli.calibrate import add_calibration_option, apply_calibration_option
from impact_balance.cli.output import print_json
from impact_balance.cli.output_paths import writing

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.sim.trials.measure import TrialResult

__all__ = ["MAX_SPEEDS", "add_parser", "parse_speeds", "run"]

#: Most approach speeds in one ``simulate`` run (each is one trial, and one file per output).
MAX_SPEEDS = 100

USES_KERNEL = False


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``simulate`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "simulate",
        help="simulate the scenario's impact in MuJoCo and compare with the impact model",
    )
    a.add_argument("scenario", help="YAML file, or the name of a bundled scenario with an impact")
    a.add_argument(
        "--speed",
        default="0.3",
        metavar="V[,V...]",
        help="approach speed(s) of the impact point along the normal, m/s (default 0.3)",
    )
    a.add_argument(
        "--joints",
        default="rigid",
        metavar="rigid|servo",
        help="joint model: rigid (welded at the stance, the paper's model) or servo (position "
        "servos)",
    )
    a.add_argument(
        "--armature",
        type=number("--armature", 0.0, 100.0, "kg m^2"),
        default=None,
        metavar="KG_M2",
        help="servo only: rotor inertia of every joint, kg m^2 (default: what the robot files "
        "declare, "
        "the SRDF's rotor_params; 0 where they declare none)",
    )
    a.add_argument(
        "--rigid-impact",
        action="store_true",
        help="servo only: hold every joint's velocity from the contact to the end of the "
        "compression "
        "(the paper's rigid robot at the impact)",
    )
    a.add_argument(
        "--duration",
        type=number("--duration", 0.0, 10.0, "s", lo_open=True),
        default=0.15,
        metavar="S",
        help="simulated time kept after the impact begins, s (default 0.15)",
    )
    a.add_argument(
        "--json", action="store_true", help="print one JSON object (a list for several speeds)"
    )
    a.add_argument(
        "--plots", metavar="DIR", type=output_folder("--plots"), help="write the figures to DIR"
    )
    a.add_argument(
        "--log",
        metavar="FILE",
        type=output_file("--log", LOG_SUFFIXES),
        help="write the time series (.parquet or .csv); one file per speed",
    )
    a.add_argument(
        "--video",
        metavar="FILE",
        type=output_file("--video", (".mp4",)),
        help="render an MP4 (offscreen, EGL); one file per speed",
    )
    add_calibration_option(a)
    return ["simulate"]


def parse_speeds(text: str) -> list[float]:
    """Approach speeds from ``"0.1,0.3"``.

    :class:`SimulationError` on a bad one (see :mod:`impact_balance.ranges` for the range).
    """
    from impact_balance.exceptions import SimulationError
    from impact_balance.ranges import check_approach_speed

    parts = str(text).split(",")
    if len(parts) > MAX_SPEEDS:
        raise SimulationError("--speed", text, f"at most {MAX_SPEEDS} speeds in one run")
    speeds = []
    for part in parts:
        try:
            value = float(part)
        except ValueError:
            raise SimulationError("--speed", part.strip(), "not a number") from None
        speeds.append(check_approach_speed(value))
    return speeds


def _per_speed(path: str, speed: float, several: bool) -> Path:
    """The output path of one speed: ``name_<speed>.ext`` when several are simulated."""
    p = Path(path)
    return p.with_name(f"{p.stem}_{speed:g}{p.suffix}") if several else p


def _table(name: str, r: TrialResult) -> str:
    """The text report of one trial: the measured CoM velocity jump against each prediction."""
    jump = r.com_velocity_jump_measured
    size = float(math.hypot(*jump))
    lines = [
        f"{name}: {r.joints} joints, approach speed {r.approach_speed:.3f} m/s "
        f"(measured {r.approach_speed_measured:.3f}), restitution measured "
        f"{r.restitution_measured:.3f}, "
        f"slip {r.slip_speed:.3f} m/s",
        f"  {'':<26}{'CoM velocity jump x, y (m/s)':<34}{'distance to set (m/s)':>22}",
        f"  {'measured':<26}{jump[0]:+10.5f} {jump[1]:+10.5f}",
    ]
    for model, p in r.predicted.items():
        lo, hi = p.com_velocity_jumps.min(axis=0), p.com_velocity_jumps.max(axis=0)
        span = f"x [{lo[0]:+.4f}, {hi[0]:+.4f}] y [{lo[1]:+.4f}, {hi[1]:+.4f}]"
        rel = f" ({100 * p.distance / size:.2f} % of |jump|)" if size > 0 else ""
        lines.append(f"  {model + ' (predicted)':<26}{span:<34}{p.distance:>10.5f}{rel}")
    i = r.impulse_measured
    kept = "n/a (floating)" if r.contacts_kept is None else ("yes" if r.contacts_kept else "NO")
    lines.append(
        f"  impulse {i[0]:+.3f} {i[1]:+.3f} {i[2]:+.3f} N s; contacts kept: {kept}; "
        f"simulated/wall time {r.sim_time_ratio:.1f}x"
    )
    if r.sustained_impulses:
        parts = [
            f"{name} ({v[0]:+.2f}, {v[1]:+.2f}, {v[2]:+.2f})"
            for name, v in r.sustained_impulses.items()
        ]
        lines.append(
            "  impulse at the sustained contacts (force before the impact subtracted), N s: "
            f"{'; '.join(parts)}"
        )
    if r.hold is not None and r.hold["duration"] is not None:
        lines.append(
            f"  joints held through the impact for {1e3 * r.hold['duration']:.1f} ms (largest "
            "joint velocity "
            f"change {r.hold['max_joint_velocity_change']:.2g} rad/s)"
        )
    if r.joints == "servo":
        lines.append(f"  joint armature: {r.armature}")
    if r.saturated_joints:
        lines.append(f"  at their effort limit during the impact: {', '.join(r.saturated_joints)}")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    """Run ``simulate`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.exceptions import SimulationError

    speeds = parse_speeds(args.speed)  # before MuJoCo loads: a bad speed is refused at once
    import_mujoco(bool(args.video))
    from impact_balance.logs import check_log_path
    from impact_balance.scenario import load_scenario
    from impact_balance.sim import JOINT_MODELS, build_model
    from impact_balance.sim.trials.impact_trial import TrialOptions, run_trial
    from impact_balance.sim.trials.measure import measure

    if args.joints not in JOINT_MODELS:
        raise SimulationError(
            "--joints", args.joints, f"unknown joint model; valid: {', '.join(JOINT_MODELS)}"
        )
    if args.log:
        check_log_path(args.log)
    # simulate's predictions (the impact's jump sets) use no ZMP margin: a calibration is
    # checked against the scenario's robot and recorded in the JSON.
    scenario, calibration = apply_calibration_option(args, load_scenario(args.scenario))
    if scenario.impact is None:
        raise SimulationError(
            "impact", None, f"scenario {args.scenario!r} has no impact to simulate"
        )
    from impact_balance.sim import ServoOptions, SimOptions

    options = SimOptions(meshes=bool(args.video), servo=ServoOptions(armature=args.armature))
    sim = build_model(scenario, args.joints, options)
    name = scenario.name or Path(str(args.scenario)).stem
    several = len(speeds) > 1
    results, written = [], []
    for speed in speeds:
        record = run_trial(
            sim, TrialOptions(speed, after=args.duration, rigid_impact=args.rigid_impact)
        )
        result = measure(sim, record, speed)
        results.append(result)
        if args.log:
            from impact_balance.logs import write_log
            from impact_balance.sim.trials.log import log_frame

            with writing("--log", args.log):
                written.append(
                    write_log(
                        log_frame(sim, record),
                        _per_speed(args.log, speed, several),
                        {"scenario": name, "joints": args.joints, "approach_speed": str(speed)},
                    )
                )
        if args.video:
            from impact_balance.sim.trials.video import write_video

            with writing("--video", args.video):
                written.append(write_video(sim, record, _per_speed(args.video, speed, several)))
        if args.plots:
            from impact_balance.plots.simulation import plot_jump_on_sets, plot_time_series
            from impact_balance.plots.style import DPI

            title = (
                f"{name}: {args.joints} joints, approach {speed:g} m/s, "
                f"restitution {result.restitution_measured:.2f}"
            )
            out = Path(args.plots)
            with writing("--plots", args.plots):
                out.mkdir(parents=True, exist_ok=True)
                for kind, fig in (
                    ("jump", plot_jump_on_sets(result, title)),
                    ("time", plot_time_series(result, title)),
                ):
                    path = out / f"{name}_simulate_{args.joints}_{speed:g}_{kind}.png"
                    fig.savefig(path, dpi=DPI)
                    written.append(path)
    if args.json:
        docs = [r.to_dict() for r in results]
        for d in docs:
            if calibration is not None:
                d["calibration"] = calibration
        print_json(docs if several else docs[0])
    else:
        print("\n\n".join(_table(name, r) for r in results))
        for path in written:
            print(f"  wrote: {path}")
    return 0
