"""``impact-balance push-test SCENARIO``: impulsive pushes at the torso, outcome against both criteria."""

from __future__ import annotations

import argparse
from pathlib import Path

from ._options import add_controller_option, add_output_options

__all__ = ["add_parser", "run", "USES_KERNEL"]

USES_KERNEL = True


def add_parser(sub) -> list[str]:
    # No import of the simulation here: mujoco is imported only when a simulation command runs.
    a = sub.add_parser("push-test", help="push the simulated robot in every direction; confusion matrices of both criteria")
    a.add_argument("scenario", help="YAML file or bundled scenario name")
    a.add_argument("--directions", type=int, default=16, help="number of push directions (default 16)")
    a.add_argument("--magnitudes", type=float, nargs="+", default=None, metavar="NS",
                   help="impulses, N s (default 5 10 15 20 25 30)")
    a.add_argument("--duration", type=float, default=0.05, help="push duration, s (default 0.05)")
    a.add_argument("--body", help="MuJoCo body pushed (default: the torso)")
    add_controller_option(a, "id", "it places the ZMP anywhere in the support area, as the criterion assumes")
    add_output_options(a, "of one telling push")
    return ["push-test"]


def run(args: argparse.Namespace) -> int:
    from ..logs import check_log_path
    from ..scenario import load_scenario
    from ..sim.balance_trial import BalanceTrialOptions, write_trial_log
    from ..sim.push import DEFAULT_MAGNITUDES, check_push_arguments, push_test
    from .output import print_json, progress_bar

    scenario = load_scenario(args.scenario)
    if args.magnitudes is None:
        args.magnitudes = list(DEFAULT_MAGNITUDES)
    if args.log:
        check_log_path(args.log)
    check_push_arguments(args.directions, args.magnitudes, args.duration)
    bar = progress_bar(f"push-test {scenario.name}", args.directions * len(args.magnitudes))

    def progress(outcome):
        bar.update(1)
        bar.set_postfix_str(f"{outcome.push.magnitude:g} N s {'fell' if outcome.result.fell else 'ok'}")

    try:
        result = push_test(scenario, args.directions, args.magnitudes, args.duration, args.body, progress=progress,
                           options=BalanceTrialOptions(controller=args.controller))
    finally:
        bar.close()
    out = result.to_dict()
    written = []
    if args.log:
        chosen = _telling(result.outcomes)
        written.append(write_trial_log(result.setup, args.log, args.controller, {
            "push_direction": chosen.push.direction, "push_magnitude": chosen.push.magnitude}, push=chosen.push))
        out["log"] = {"file": str(args.log), "direction": chosen.push.direction, "magnitude": chosen.push.magnitude}
    if args.plots:
        written += _plots(result, Path(args.plots))
    if args.json:
        print_json(out)
        return 0
    c = out["confusion"]
    print(f"{scenario.name}: {len(result.outcomes)} pushes ({args.directions} directions x {len(args.magnitudes)} magnitudes,"
          f" {args.duration * 1e3:.0f} ms), {sum(o.result.fell for o in result.outcomes)} falls")
    print(f"  {'magnitude':>9s} {'fell':>5s} {'CoM safe':>8s} {'ZMP safe':>8s}")
    for m in args.magnitudes:
        group = [o for o in result.outcomes if o.push.magnitude == m]
        print(f"  {m:7g} Ns {sum(o.result.fell for o in group):5d} {sum(bool(o.result.com_criterion_safe) for o in group):8d}"
              f" {sum(bool(o.result.zmp_criterion_safe) for o in group):8d}")
    for name in ("com", "zmp"):
        k = c[name]
        print(f"  {name.upper()} criterion: predicted the outcome for {100 * k['accuracy']:.0f} % of pushes;"
              f" safe & survived {k['safe_survived']}, safe & fell {k['safe_fell']} ({100 * k['safe_fell_rate']:.0f} %),"
              f" unsafe & survived {k['unsafe_survived']}, unsafe & fell {k['unsafe_fell']}")
    for path in written:
        print(f"  wrote {path}")
    return 0


def _telling(outcomes):
    """The push of the paper's Exp. 2 if there is one (ZMP outside, no fall), else the largest survived, else the first."""
    exp2 = [o for o in outcomes if not o.result.fell and not o.result.zmp_criterion_safe]
    if exp2:
        return max(exp2, key=lambda o: o.result.max_zmp_excursion)
    survived = [o for o in outcomes if not o.result.fell]
    return max(survived, key=lambda o: o.push.magnitude) if survived else outcomes[0]


def _plots(result, out: Path) -> list[Path]:
    from ..plots.balance import plot_com_velocity_trajectories, plot_zmp_trajectories
    from ..plots.save import figure_prefix

    out.mkdir(parents=True, exist_ok=True)
    analysis = result.setup.analysis
    prefix = figure_prefix(analysis)
    fell = [o.result.fell for o in result.outcomes]
    zmp, vel = [], []
    for o in result.outcomes:
        s = o.result.series
        t = s["time"]
        # From the push to half a second after it (the paper's figures show the reaction to the push).
        window = (t >= o.push.start) & (t <= o.push.start + o.push.duration + 0.5)
        zmp.append(s["zmp"][window])
        vel.append(s["com_velocity"][window][:, :2])
    paths = [out / f"{prefix}_push_zmp.png", out / f"{prefix}_push_com_velocity.png"]
    plot_zmp_trajectories(analysis.areas.zmp_area, zmp, fell, f"{result.scenario}: ZMP after each push").savefig(paths[0])
    plot_com_velocity_trajectories(analysis.areas.com_velocity_area, vel, fell,
                                   f"{result.scenario}: CoM velocity after each push").savefig(paths[1])
    return paths
