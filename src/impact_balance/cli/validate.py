"""``impact-balance validate SCENARIO``: the empirical fall threshold of the impact beside the predictions."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._options import add_controller_option, add_output_options

__all__ = ["add_parser", "run", "USES_KERNEL"]

USES_KERNEL = True


def add_parser(sub) -> list[str]:
    a = sub.add_parser("validate", help="bisect the approach speed at which the simulated robot falls (MuJoCo)")
    a.add_argument("scenario", help="YAML file or bundled scenario name (must have an impact)")
    a.add_argument("--joints", default="servo", choices=("rigid", "servo"),
                   help="servo: URDF effort limits, 15 Hz servos; rigid: stiff 30 Hz servos, no effort limits")
    add_controller_option(a, "ik", "a kinematically controlled robot, as the paper's impact model assumes")
    a.add_argument("--tolerance", type=float, default=0.05, help="relative width of the bracket (default 0.05)")
    a.add_argument("--max-speed", type=float, default=4.0, help="largest approach speed tried, m/s (default 4)")
    add_output_options(a, "of the fastest trial survived")
    return ["validate"]


def run(args: argparse.Namespace) -> int:
    from ..exceptions import SimulationError
    from ..logs import check_log_path
    from ..scenario import load_scenario
    from ..sim.balance_trial import BalanceTrialOptions, write_trial_log
    from ..sim.validate import validate
    from .output import print_json, progress_bar

    scenario = load_scenario(args.scenario)
    if scenario.impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact: validate needs one")
    if not (0 < args.max_speed <= 5.0):
        raise SimulationError("--max-speed", args.max_speed, "must be in (0, 5] m/s")
    if args.log:
        check_log_path(args.log)
    bar = progress_bar(f"validate {scenario.name}")

    def progress(speed, result, survived, fell):
        bar.update(1)
        lo = "?" if survived is None else f"{survived:.3f}"
        hi = "?" if fell is None else f"{fell:.3f}"
        bar.set_postfix_str(f"{speed:.3f} m/s {'fell' if result.fell else 'ok'}; bracket [{lo}, {hi}]")

    try:
        result = validate(scenario, args.joints, tolerance=args.tolerance, max_speed=args.max_speed, progress=progress,
                          options=BalanceTrialOptions(controller=args.controller))
    finally:
        bar.close()
    out = result.to_dict()
    written = []
    if args.log:
        speed = result.survived if result.survived is not None else result.fell
        written.append(write_trial_log(result.extra["setup"], args.log, args.controller,
                                       {"approach_speed": speed, "joints": args.joints}, impact_speed=speed))
        out["log"] = {"file": str(args.log), "approach_speed": speed}
    if args.plots:
        written += _plots(result, Path(args.plots))
    if args.json:
        print_json(out)
        return 0
    p = out["predicted"]
    print(f"{scenario.name}: empirical fall threshold ({args.joints} joints, {args.controller} controller,"
          f" {len(result.trials)} trials)")
    print(f"  survived at {_f(result.survived)}, fell at {_f(result.fell)} (commanded approach speed)")
    print("  predicted maximum contact velocity:")
    for crit in ("com_criterion", "zmp_criterion"):
        print(f"    {crit.replace('_', ' '):14s} composite {_f(p[crit]['composite'])}, joint_space {_f(p[crit]['joint_space'])}")
    print("  trials:")
    for t in out["trials"]:
        meas = t["approach_speed_measured"]
        print(f"    {t['speed']:.3f} m/s (measured {_f(meas)}): {'FELL ' + str(t['reason']) if t['fell'] else 'ok'}"
              f"  max CoM velocity excursion {_f(t['max_com_velocity_excursion'])}")
    for path in written:
        print(f"  wrote {path}")
    return 0


def _f(x) -> str:
    return "-" if x is None else f"{x:.3f} m/s"


def _plots(result, out: Path) -> list[Path]:
    from ..plots.balance import plot_com_velocity_trajectories, plot_validation
    from ..plots.save import figure_prefix

    out.mkdir(parents=True, exist_ok=True)
    setup = result.extra["setup"]
    prefix = figure_prefix(setup.analysis)
    speeds = [v for v, _ in result.trials]
    fell = [r.fell for _, r in result.trials]
    paths = []
    fig = plot_validation(speeds, fell, result.predicted, f"{result.scenario}: trials and predictions ({result.joints})")
    paths.append(out / f"{prefix}_validation.png")
    fig.savefig(paths[-1])
    traj = [r.series["com_velocity"][:, :2] for _, r in result.trials if len(r.series.get("com_velocity", []))]
    fig = plot_com_velocity_trajectories(setup.analysis.areas.com_velocity_area, traj, fell,
                                         f"{result.scenario}: CoM velocity of every trial")
    paths.append(out / f"{prefix}_validation_com_velocity.png")
    fig.savefig(paths[-1])
    return paths
