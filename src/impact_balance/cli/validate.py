"""``impact-balance validate SCENARIO``: the impact's empirical fall threshold, and predictions.

The threshold is bracketed in MuJoCo and shown beside the criteria's predictions.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from impact_balance.cli._options import (
    DEFAULT_CONTROLLER,
    TRIAL_JOINTS,
    add_controller_option,
    add_impact_model_option,
    add_output_options,
    add_trial_joints_option,
    add_trial_options,
    open_journal,
    scoring_margin,
    with_margins,
)
from impact_balance.cli.angular_momentum import add_angular_momentum_option, for_trials
from impact_balance.cli.calibrate import add_calibration_option, apply_calibration_option
from impact_balance.cli.friction_scale import add_friction_scale_option, friction_scale_for_trials
from impact_balance.cli.touch_contact import add_touch_contact_option, impact_trial_options

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.scenario import Scenario
    from impact_balance.sim.studies.validate import ValidationResult, ValidationTrial

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``validate`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "validate", help="bisect the approach speed at which the simulated robot falls (MuJoCo)"
    )
    a.add_argument("scenario", help="YAML file or bundled scenario name (must have an impact)")
    add_trial_joints_option(a)
    add_controller_option(
        a,
        DEFAULT_CONTROLLER,
        "it places the ZMP anywhere in the support area, as the criterion assumes, and holds the "
        "commanded approach speed",
    )
    a.add_argument(
        "--tolerance", type=float, default=0.05, help="relative width of the bracket (default 0.05)"
    )
    a.add_argument(
        "--max-speed", type=float, default=4.0, help="largest approach speed tried, m/s (default 4)"
    )
    add_trial_options(a, impact=True)
    a.add_argument(
        "--com-reach",
        action="store_true",
        help="score the verdict against the default's maximum contact velocity within the CoM's "
        "reach at constant height (whole-body IK once before the trials, a few seconds; "
        "docs/com-reach.md)",
    )
    add_impact_model_option(
        a,
        "also the held-stance model's maximum contact velocity (the contact-aware jump at the "
        "restitution bounds, the paper's answer where its fixed point is not reached), "
        "computed before the trials, with each trial's call against it",
    )
    add_calibration_option(a)
    add_output_options(a, "of the fastest trial survived")
    add_angular_momentum_option(a, controller=True)
    add_friction_scale_option(a, controller=True)
    add_touch_contact_option(a)
    return ["validate"]


def run(args: argparse.Namespace) -> int:
    """Run ``validate`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.cli.output import print_json, progress_bar
    from impact_balance.cli.output_paths import writing
    from impact_balance.sim.studies.validate import validate
    from impact_balance.sim.trials.aborts import check_not_all_aborted
    from impact_balance.sim.trials.balance_trial import write_trial_log

    scenario, calibration = _checked_scenario(args)
    options = impact_trial_options(args.controller, args.rigid_impact, args.touch_contact)
    joints = TRIAL_JOINTS[args.joints]  # the study's name (the journals' digests keep it)
    judged = for_trials(scenario, args.angular_momentum_damping_time, options)
    judged = friction_scale_for_trials(judged, args.friction_scale, options)
    journal = open_journal(
        args,
        "validate",
        scenario,
        joints,
        options,
        {"tolerance": args.tolerance, "max_speed": args.max_speed},
    )
    scenario = judged  # the trials journal keys the scenario without the option
    bar = progress_bar(f"validate {scenario.name}")

    def progress(trial: ValidationTrial, stood: float | None, fell: float | None) -> None:
        """Advance the progress bar by one trial, with the bracket so far."""
        bar.update(1)
        lo = "?" if stood is None else f"{stood:.3f}"
        hi = "?" if fell is None else f"{fell:.3f}"
        bar.set_postfix_str(
            f"{trial.speed:.3f} m/s {trial.outcome}; bracket (commanded) [{lo}, {hi}]"
        )

    try:
        result = validate(
            scenario,
            joints,
            tolerance=args.tolerance,
            max_speed=args.max_speed,
            progress=progress,
            options=options,
            zmp_margin=scoring_margin(scenario),
            journal=journal,
            com_reach=args.com_reach,
            impact_model=args.impact_model,
        )
    finally:
        bar.close()
        journal.close()
    out = result.to_dict()
    out["joints"] = args.joints
    if scenario.friction_scale != 1.0:
        out["friction_scale"] = scenario.friction_scale
    if calibration is not None:
        out["calibration"] = calibration
    written = []
    e = out["empirical"]
    if args.log:
        speed = (
            e["survived_commanded"] if e["survived_commanded"] is not None else e["fell_commanded"]
        )
        if speed is not None:
            with writing("--log", args.log):
                written.append(
                    write_trial_log(
                        result.extra["setup"],
                        args.log,
                        args.controller,
                        {"approach_speed": speed, "joints": joints},
                        impact_speed=speed,
                        rigid_impact=args.rigid_impact,
                        id_gains=options.id_gains,
                    )
                )
            out["log"] = {"file": str(args.log), "approach_speed": speed}
    if args.plots:
        with writing("--plots", args.plots):
            written += _plots(result, Path(args.plots))
    if args.json:
        print_json(out)
    else:
        print(_text(out, args, len(result.trials)))
        for path in written:
            print(f"  wrote {path}")
    check_not_all_aborted("validate", out["scenario"], out["trials"])
    return 0


def _checked_scenario(args: argparse.Namespace) -> tuple[Scenario, dict[str, Any] | None]:
    """The scenario with its margins and calibration, and every option checked before a trial."""
    from impact_balance.exceptions import SimulationError
    from impact_balance.logs import check_log_path
    from impact_balance.ranges import check_tolerance
    from impact_balance.scenario import load_scenario

    scenario = with_margins(load_scenario(args.scenario), args.zmp_margin)
    scenario, calibration = apply_calibration_option(args, scenario)
    if scenario.impact is None:
        raise SimulationError(
            "impact", None, f"scenario {scenario.name!r} has no impact: validate needs one"
        )
    if not (0 < args.max_speed <= 5.0):
        raise SimulationError("--max-speed", args.max_speed, "must be in (0, 5] m/s")
    check_tolerance(args.tolerance)
    if args.log:
        check_log_path(args.log)
    return scenario, calibration


def _f(x: float | None) -> str:
    """A speed (m/s) with 3 decimals, or "-" when there is none."""
    return "-" if x is None else f"{x:.3f} m/s"


def _verdict_line(v: dict[str, Any]) -> str:
    """``fall bracket / prediction: [low, high] (...): verdict`` (see ``fall_verdict``)."""
    r = v["fall_over_predicted"]
    low = "-" if r["low"] is None else f"{r['low']:.2f}"
    high = "-" if r["high"] is None else f"{r['high']:.2f}"
    return (
        f"  fall bracket / prediction ({_f(v['predicted'])}, the governor's cap): "
        f"[{low}, {high}]: {v['text']}"
    )


def _text(out: dict[str, Any], args: argparse.Namespace, n: int) -> str:
    """The text report of ``validate``: the fall bracket, the verdict and the predictions."""
    from impact_balance.sim.trials.aborts import aborted_lines

    e, p, pm = out["empirical"], out["predicted"], out["predicted_with_margin"]
    impact = (
        "rigid impact (joints held through the impact)" if out["rigid_impact"] else "free impact"
    ) + (", touch contact" if args.touch_contact else "")
    lines = [
        f"{out['scenario']}: fall threshold of the impact ({args.joints} joints, {args.controller} "
        "controller, "
        f"{impact}, {n} trials)",
        f"  measured approach speed: stood at {_f(e['survived'])}, fell at {_f(e['fell'])}"
        f" (commanded {_f(e['survived_commanded'])} / {_f(e['fell_commanded'])})"
        + ("" if e["monotonic"] else "; NOT monotonic in measured speed"),
        _verdict_line(out["verdict"]),
    ]
    lines.append(
        f"  strict (fell, or a contact beyond the strict bounds): stood at "
        f"{_f(e['strict_stood'])}, failed at {_f(e['strict_failed'])}"
    )
    brk = e["first_contact_break"]
    if brk is not None:
        lines.append(
            f"  first contact break (bisected): {brk['contact']} {brk['kind']} at "
            f"{_f(brk['measured'])} measured, none at {_f(brk['no_break_below'])} "
            f"({brk['outcome']})"
        )
    else:
        lines.append("  no contact broke")
    lines.append(
        f"  predicted maximum contact velocity (ZMP margin 0 / {1000 * out['zmp_margin']:g} mm):"
    )
    for crit, label in (("com_criterion", "CoM criterion"), ("zmp_criterion", "ZMP criterion")):
        lines.append(
            f"    {label:14s} composite {_f(p[crit]['composite'])} / {_f(pm[crit]['composite'])}, "
            f"joint_space {_f(p[crit]['joint_space'])} / {_f(pm[crit]['joint_space'])}"
        )
    lines.append(f"    default (the governor's cap) {_f(p['default'])}")
    if "com_reach" in p:
        lines.append(_reach_line(p["com_reach"]))
    if "held_stance" in p:
        lines.append(_held_stance_line(p["held_stance"], out["zmp_margin"]))
    lines.append("  trials (commanded -> measured: outcome):")
    for t in out["trials"]:
        why = f" {t['reason']}" if t["reason"] else ""
        call = {True: "CoM criterion: safe", False: "CoM criterion: unsafe", None: ""}[
            t["com_criterion_safe"]
        ]
        strict = "; strict fail" if t["strict_fail"] else ""
        if t.get("com_reach_safe") is not None:
            call += "; within reach: " + ("safe" if t["com_reach_safe"] else "unsafe")
        if t.get("held_stance_safe") is not None:
            call += "; held stance: " + ("safe" if t["held_stance_safe"] else "unsafe")
        lines.append(
            f"    {t['speed']:.3f} -> {_f(t['approach_speed_measured'])}: {t['outcome']}{why}"
            f"{strict}   {call}"
        )
    lines += aborted_lines(out["trials"])
    lines.append(
        f"  controller: {out['controller'].get('name', args.controller)}; joint armature: "
        f"{out['controller'].get('armature')}"
    )
    if out["journal"]:
        lines.append(f"  trials journal: {out['journal']} ({out['reused_trials']} reused)")
    return "\n".join(lines)


def _reach_line(reach: dict[str, Any]) -> str:
    """One line of ``validate --com-reach``: the reach and the prediction within it."""
    radii = reach["radii"]
    return (
        f"    within the CoM's reach ({1000 * min(radii):.0f} to {1000 * max(radii):.0f} mm at "
        f"constant height) {_f(reach['max_contact_velocity'])}: the verdict's prediction"
    )


def _held_stance_line(held: dict[str, Any], zmp_margin: float) -> str:
    """One line of ``validate --impact-model held-stance``: its maximum and how it was reached.

    ``zmp_margin``: the scoring ZMP margin it was computed at, m.
    """
    if held["fell_back"]:
        how = "the paper's answer: the fixed point was not reached"
    elif held["binding_restitution"] is None:
        how = "no approach speed leaves the area"
    else:
        how = f"binding restitution {held['binding_restitution']:g}"
    line = f"    held stance ({1000 * zmp_margin:g} mm) {_f(held['max_contact_velocity'])} ({how})"
    term = held.get("angular_momentum")
    if term is not None:
        line += (
            f"; with the angular momentum it leaves (tau {term['damping_time']:g} s) "
            f"{_f(term['max_contact_velocity'])}"
        )
    return line


def _plots(result: ValidationResult, out: Path) -> list[Path]:
    """Write the validation figures into ``out``; returns their paths."""
    from impact_balance.plots.balance import plot_impact_trajectories, plot_validation
    from impact_balance.plots.save import figure_prefix

    out.mkdir(parents=True, exist_ok=True)
    setup = result.extra["setup"]
    prefix = figure_prefix(setup.analysis)
    paths = [out / f"{prefix}_validation.png", out / f"{prefix}_validation_com_velocity.png"]
    plot_validation(result).savefig(paths[0])
    plot_impact_trajectories(result, setup.analysis).savefig(paths[1])
    return paths
