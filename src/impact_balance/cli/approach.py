"""``impact-balance approach SCENARIO``.

The impacting point sent at an unknown wall, its speed capped every tick by a governor (the paper's
Experiment 1, in MuJoCo).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from impact_balance.cli._options import (
    DEFAULT_CONTROLLER,
    add_controller_option,
    add_impact_model_option,
    add_velocity_margin_option,
    add_zmp_margin_option,
    import_mujoco,
    number,
    output_file,
    output_folder,
    scoring_margin,
    with_margins,
)
from impact_balance.cli.angular_momentum import add_angular_momentum_option, for_trials
from impact_balance.cli.calibrate import add_calibration_option, apply_calibration_option
from impact_balance.cli.friction_scale import add_friction_scale_option, friction_scale_for_trials
from impact_balance.cli.touch_contact import add_touch_contact_option, impact_trial_options

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.governor import Governor
    from impact_balance.impact.held_stance import HeldStanceJumps
    from impact_balance.scenario import Scenario
    from impact_balance.sim.studies.wall import WallTrial
    from impact_balance.sim.trials.balance_trial import BalanceSetup, BalanceTrialOptions

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``approach`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "approach",
        help="send the impact point at an unknown wall, its speed capped by a governor (MuJoCo)",
    )
    a.add_argument("scenario", help="YAML file or bundled scenario name (must have an impact)")
    a.add_argument(
        "--reference",
        type=number("--reference", 0.0, 5.0, "m/s", lo_open=True),
        required=True,
        metavar="V",
        help="reference approach speed, m/s (the paper's 0.8)",
    )
    a.add_argument(
        "--governor",
        default="com",
        choices=("com", "zmp", "none"),
        help="com: the CoM criterion's maximum contact velocity (default); zmp: the ZMP "
        "criterion's; "
        "none: the reference alone",
    )
    where = a.add_mutually_exclusive_group()
    where.add_argument(
        "--wall-distance",
        type=number("--wall-distance", 0.0, 1.0, "m", lo_open=True),
        default=None,
        metavar="D",
        help="distance of the wall from the point's start, m (default 0.15: the scenario's impact "
        "point)",
    )
    where.add_argument(
        "--wall-distance-range",
        type=number("--wall-distance-range", 0.0, 1.0, "m", lo_open=True),
        nargs=2,
        default=None,
        metavar=("LO", "HI"),
        help="one trial at LO, the middle and HI, m",
    )
    a.add_argument(
        "--contact-aware",
        action="store_true",
        help="com governor: also bound the speed by the contact-aware impact model (the robot "
        "standing "
        "on its supports; experimental, see docs/contact_aware_governor.md)",
    )
    a.add_argument(
        "--contact-aware-async",
        action="store_true",
        help="with --contact-aware: compute its rates in a worker process, off the tick (the tick "
        "never "
        "waits; the rates are one recomputation old)",
    )
    add_velocity_margin_option(a, "com governor")
    a.add_argument(
        "--com-reach",
        action="store_true",
        help="com governor: also cap within the CoM's reach at constant height, computed once "
        "from the scenario's posture (whole-body IK, a few seconds; docs/com-reach.md)",
    )
    _add_impact_model_option(a)
    a.add_argument(
        "--rigid-impact",
        action="store_true",
        help="hold every joint's velocity through the impact (the paper's rigid robot)",
    )
    add_controller_option(
        a, DEFAULT_CONTROLLER, "it puts the ZMP anywhere in the support area after the impact"
    )
    add_zmp_margin_option(a, "the governor's; default: the ZMP margin the trial's controller keeps")
    add_calibration_option(a)
    a.add_argument(
        "--max-time",
        type=number("--max-time", 0.0, 120.0, "s", lo_open=True),
        default=30.0,
        metavar="S",
        help="longest approach before giving up, s (default 30: a ZMP governor is slow)",
    )
    a.add_argument("--json", action="store_true", help="print one JSON object")
    a.add_argument(
        "--plots",
        metavar="DIR",
        type=output_folder("--plots"),
        help="write the figure of each trial to DIR",
    )
    a.add_argument(
        "--video",
        metavar="FILE",
        type=output_file("--video", (".mp4",)),
        help="render an MP4 of the trial (one trial: give --wall-distance)",
    )
    add_angular_momentum_option(a, controller=True)
    return ["approach"]


def _add_impact_model_option(a: argparse.ArgumentParser) -> None:
    """Add ``--impact-model``, ``--friction-scale`` and ``--touch-contact`` to parser ``a``."""
    add_friction_scale_option(a, controller=True)
    add_touch_contact_option(a)
    add_impact_model_option(
        a,
        "the com governor caps with the held-stance jumps of the scenario's posture, computed "
        "once, in place of the floating model's (the floating answer where its fixed point is "
        "not reached)",
    )


def run(args: argparse.Namespace) -> int:
    """Run ``approach``: one governed trial per wall distance, as text or JSON.

    Args:
        args: The parsed command line.

    Returns:
        The exit status, 0.

    Raises:
        SimulationError: Options that do not go together, a scenario without an impact, a
            wall closer than the approach needs.
        ScenarioError: A margin the schema refuses (naming its option).
    """
    from impact_balance.exceptions import SimulationError
    from impact_balance.sim.trials.aborts import check_not_all_aborted

    if args.video and args.wall_distance_range is not None:
        raise SimulationError(
            "--video", args.video, "one .mp4 for one trial (give --wall-distance, not a range)"
        )
    if args.contact_aware_async and not args.contact_aware:
        raise SimulationError("--contact-aware-async", True, "needs --contact-aware")
    if args.com_reach and args.governor != "com":
        raise SimulationError("--com-reach", True, f"needs --governor com, not {args.governor}")
    _check_impact_model(args)
    import_mujoco(bool(args.video))  # before anything imports MuJoCo: the GL backend is read then
    from impact_balance.cli.output import print_json
    from impact_balance.scenario import load_scenario
    from impact_balance.sim.trials.balance_trial import (
        BalanceSetup,
        controller_margin,
    )

    scenario = with_margins(load_scenario(args.scenario), args.zmp_margin, args.velocity_margin)
    scenario, calibration = apply_calibration_option(args, scenario)
    if scenario.impact is None:
        raise SimulationError(
            "impact", None, f"scenario {scenario.name!r} has no impact: approach needs one"
        )
    distances = _distances(args)
    _check_distances(args, distances)
    options = impact_trial_options(args.controller, args.rigid_impact, args.touch_contact)
    scenario = for_trials(scenario, args.angular_momentum_damping_time, options)
    scenario = friction_scale_for_trials(scenario, args.friction_scale, options)
    own = scoring_margin(scenario)
    margin = controller_margin(options) if own is None else own
    # The governor's view: the area the controller can use.
    governed = scenario.replace(zmp_margin=margin)
    setup = BalanceSetup.create(scenario, "servo", options, meshes=bool(args.video))  # visual
    governor = _governor(args, governed)
    try:
        trials, written = _trials(args, setup, options, governor, distances, margin)
    finally:
        if governor is not None:
            governor.close()  # its worker process, if any
    docs = [t.to_dict() for t in trials]
    for d in docs:
        d["controller"] = args.controller
        d["rigid_impact"] = args.rigid_impact
        d["zmp_margin"] = margin
        d["contact_aware"] = bool(args.contact_aware and governor is not None)
        d["velocity_margin"] = governed.velocity_margin if governor is not None else None
        d["angular_momentum_damping_time"] = (
            governed.angular_momentum_damping_time if governor is not None else None
        )
        d["contact_aware_async"] = bool(args.contact_aware_async and governor is not None)
        if governed.friction_scale != 1.0 and governor is not None:
            d["friction_scale"] = governed.friction_scale
        if calibration is not None:
            d["calibration"] = calibration
    from impact_balance.sim.studies.wall import pooled_tick_statistics

    out = (
        docs[0]
        if len(docs) == 1
        else {
            "governor": args.governor,
            "reference": args.reference,
            "tick_us": pooled_tick_statistics(trials),  # over the ticks of every trial
            "trials": docs,
        }
    )
    once = _record_once(out, governor)
    if args.json:
        print_json(out)
    else:
        _print_text(scenario.name, args, docs, written)
        for line in once:
            print(f"  {line}")
        if len(docs) > 1 and out["tick_us"]["median"] is not None:
            t = out["tick_us"]
            print(
                f"  governor over all {t['count']} ticks: median {t['median']:.0f} us, "
                f"p99 {t['p99']:.0f} us"
            )
    check_not_all_aborted("approach", scenario.name, docs)
    return 0


def _distances(args: argparse.Namespace) -> list[float]:
    """The wall distances of the trials (m), from ``--wall-distance(-range)``."""
    from impact_balance.exceptions import SimulationError

    if args.wall_distance_range is None:
        return [0.15 if args.wall_distance is None else args.wall_distance]
    lo, hi = args.wall_distance_range
    if lo > hi:
        raise SimulationError("--wall-distance-range", [lo, hi], "must be 0 < LO <= HI <= 1 m")
    return [lo, 0.5 * (lo + hi), hi] if hi > lo else [lo]


def _check_distances(args: argparse.Namespace, distances: list[float]) -> None:
    """Refuse, before any trial, a wall closer than the approach needs (naming the option)."""
    from impact_balance.sim.studies.wall import check_wall_distance

    field = "--wall-distance" if args.wall_distance_range is None else "--wall-distance-range"
    for distance in distances:
        check_wall_distance(distance, args.reference, field=field)


def _governor(args: argparse.Namespace, governed: Scenario) -> Governor | None:
    """The trials' governor (None with ``--governor none``), margins from ``governed``."""
    if args.governor == "none":
        return None
    from impact_balance.governor import ContactAwareOptions, Governor

    aware = ContactAwareOptions(asynchronous=args.contact_aware_async)
    return Governor(
        governed,
        args.governor,
        contact_aware=aware if args.contact_aware else None,
        com_reach=bool(args.com_reach),
        impact_model=args.impact_model,
    )


def _check_impact_model(args: argparse.Namespace) -> None:
    """Refuse ``--impact-model held-stance`` without the com governor or with another cap."""
    from impact_balance.exceptions import SimulationError

    if args.impact_model == "floating":
        return
    if args.governor != "com":
        raise SimulationError(
            "--impact-model", args.impact_model, f"needs --governor com, not {args.governor}"
        )
    for option, on in (("--com-reach", args.com_reach), ("--contact-aware", args.contact_aware)):
        if on:
            raise SimulationError("--impact-model", args.impact_model, f"not with {option}")


def _record_once(out: dict[str, Any], governor: Governor | None) -> list[str]:
    """Add what the governor computed once (the reach, the held-stance jumps) to ``out``.

    Returns:
        The text report's lines about them.
    """
    lines = []
    reach = None if governor is None else governor.com_reach
    if reach is not None:  # once: the reach of the scenario's posture, the governor's
        out["com_reach"] = reach.to_dict()
        lines.append(
            f"capped within the CoM's reach ({1000 * reach.radii.min():.0f} to "
            f"{1000 * reach.radii.max():.0f} mm at constant height, the scenario's posture)"
        )
    held = None if governor is None else governor.held_stance
    if held is not None:  # once: the jumps of the scenario's posture, the governor's
        out["held_stance"] = _held_stance_dict(held)
        lines.append(_held_stance_line(held))
    return lines


def _held_stance_dict(held: HeldStanceJumps) -> dict[str, Any]:
    """``approach --impact-model held-stance``'s ``held_stance``: the governor's jumps."""
    return {
        "restitution": list(held.restitution),
        "jumps": held.jumps.tolist(),
        "converged": held.all_converged,
        "fell_back": not held.all_converged,
        "iterations": held.iterations,
    }


def _held_stance_line(held: HeldStanceJumps) -> str:
    """One line of ``approach --impact-model held-stance``: what the governor answers with."""
    if not held.all_converged:
        return (
            "held stance: the fixed point was not reached; the governor answers the floating model"
        )
    return (
        "governed with the held-stance jumps of the scenario's posture (restitution "
        f"{held.restitution[0]:g} and {held.restitution[1]:g})"
    )


def _trials(
    args: argparse.Namespace,
    setup: BalanceSetup,
    options: BalanceTrialOptions,
    governor: Governor | None,
    distances: list[float],
    margin: float,
) -> tuple[list[WallTrial], list[Path]]:
    """Run one trial per wall distance; the trials and the files written (figures, video)."""
    from impact_balance.cli.output_paths import writing
    from impact_balance.sim.studies.wall import WallOptions, run_wall_trial, write_wall_video

    trials, written = [], []
    for distance in distances:
        wall = WallOptions(
            reference=args.reference,
            governor=args.governor,
            wall_distance=distance,
            max_time=args.max_time,
        )
        trial = run_wall_trial(setup, wall, options, governor=governor, frames=bool(args.video))
        trials.append(trial)
        if args.plots:
            with writing("--plots", args.plots):
                written.append(_plot(trial, setup, Path(args.plots), margin))
        if args.video:
            title = f"{setup.scenario.name}: {args.governor} governor"
            with writing("--video", args.video):
                written.append(write_wall_video(setup, trial, args.video, title=title))
    return trials, written


def _print_text(
    name: str | None, args: argparse.Namespace, docs: list[dict[str, Any]], written: list[Path]
) -> None:
    """Print the trials as text: one line per wall, then the files written."""
    from impact_balance.sim.trials.aborts import aborted_lines

    print(
        f"{name}: approach at {args.reference:g} m/s reference, {args.governor} governor, "
        f"{args.controller} controller{', rigid impact' if args.rigid_impact else ''}"
    )
    for d in docs:
        tick = d["tick_us"]
        ticks = (
            ""
            if tick["median"] is None
            else f"; governor {tick['median']:.0f} us per tick (p99 {tick['p99']:.0f})"
        )
        reason = "" if d["reason"] is None else f" ({d['reason']})"
        strict = (
            f"; strict fail ({d['strict_reason']})"
            if d["strict_fail"] and d["outcome"] != "fell"
            else ""
        )
        print(
            f"  wall {100 * d['wall_distance']:g} cm: speed at contact "
            f"{_f(d['speed_at_contact'])}, cap at contact {_f(d['cap_at_contact'])}, "
            f"time to contact {_s(d['time_to_contact'])}: {d['outcome']}{reason}{strict}{ticks}"
        )
    for line in aborted_lines(docs):
        print(line)
    for path in written:
        print(f"  wrote {path}")


def _f(x: float | None) -> str:
    """A speed (m/s) with 3 decimals, or "-" when there is none."""
    return "-" if x is None else f"{x:.3f} m/s"


def _s(x: float | None) -> str:
    """A time (s) with 2 decimals, or "never (gave up)" when there is none."""
    return "never (gave up)" if x is None else f"{x:.2f} s"


def _plot(trial: WallTrial, setup: BalanceSetup, out: Path, zmp_margin: float) -> Path:
    """Write the trial's approach figure into ``out``; returns its path."""
    from impact_balance.plots.approach import plot_approach
    from impact_balance.plots.save import figure_prefix

    out.mkdir(parents=True, exist_ok=True)
    margin = setup.analysis.areas.com_velocity_area_inset(zmp_margin) if zmp_margin > 0 else None
    o = trial.options
    path = (
        out / f"{figure_prefix(setup.analysis)}_approach_{o.governor}_{o.reference:g}_"
        f"{100 * o.wall_distance:g}cm.png"
    )
    plot_approach(trial, setup.analysis, margin).savefig(path)
    return path
