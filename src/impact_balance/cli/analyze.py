"""``impact-balance analyze SCENARIO``: one scenario, as text or one JSON object."""

from __future__ import annotations

import argparse
import dataclasses
import math
from pathlib import Path
from typing import TYPE_CHECKING

from impact_balance.cli._options import (
    add_impact_model_option,
    add_velocity_margin_option,
    add_zmp_margin_option,
    output_folder,
    with_margins,
)
from impact_balance.cli.angular_momentum import add_angular_momentum_option, with_angular_momentum
from impact_balance.cli.calibrate import add_calibration_option, apply_calibration_option
from impact_balance.cli.friction_scale import add_friction_scale_option, with_friction_scale

if TYPE_CHECKING:
    from impact_balance.analysis.held_stance import HeldStanceLimit
    from impact_balance.analysis.reach import ReachAnswer
    from impact_balance.analysis.result import Diagnostic
    from impact_balance.cli._options import Subcommands

__all__ = ["INTERPRETED", "USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True
#: One analysis per process: interpreted kernels beat loading numba's cache (see
#: ``impact_balance._jit``).
INTERPRETED = True


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``analyze`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser("analyze", help="analyze one scenario (file or bundled name)")
    a.add_argument(
        "scenario",
        help="YAML file, or the name of a bundled scenario (see `impact-balance scenarios`)",
    )
    a.add_argument("--json", action="store_true", help="print one JSON object")
    a.add_argument(
        "--plots",
        metavar="DIR",
        type=output_folder("--plots"),
        help="write the scenario's figures to DIR",
    )
    a.add_argument(
        "--qp", action="store_true", help="also solve the paper's QP in joint velocities"
    )
    a.add_argument("--strict", action="store_true", help="treat warnings as errors (exit status 2)")
    a.add_argument(
        "--com-reach",
        action="store_true",
        help="also answer within the CoM's reach at constant height (whole-body IK, a few "
        "seconds; docs/com-reach.md)",
    )
    add_impact_model_option(
        a,
        "also the held-stance model's maximum contact velocity (the contact-aware jump at the "
        "restitution bounds, the paper's answer where its fixed point is not reached)",
    )
    add_zmp_margin_option(a, "default: the scenario's zmp_margin, 0 unless set")
    add_velocity_margin_option(a, "CoM criterion")
    add_calibration_option(a)
    add_angular_momentum_option(a, controller=False)
    add_friction_scale_option(a, controller=False)
    return ["analyze"]


def run(args: argparse.Namespace) -> int:
    """Run ``analyze`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.analysis.analyze import analyze
    from impact_balance.analysis.report import format_analysis
    from impact_balance.cli.calibrate import calibration_line
    from impact_balance.cli.output import print_json
    from impact_balance.exceptions import StrictWarningsError

    scenario = args.scenario
    calibration = None
    if args.zmp_margin is not None or args.velocity_margin is not None or args.calibration:
        from impact_balance.scenario import load_scenario

        scenario = with_margins(load_scenario(scenario), args.zmp_margin, args.velocity_margin)
        scenario, calibration = apply_calibration_option(args, scenario)
    if args.angular_momentum_damping_time is not None:
        from impact_balance.scenario import load_scenario

        scenario = with_angular_momentum(
            load_scenario(scenario) if isinstance(scenario, str) else scenario,
            args.angular_momentum_damping_time,
        )
    if args.friction_scale is not None:
        from impact_balance.scenario import load_scenario

        scenario = with_friction_scale(
            load_scenario(scenario) if isinstance(scenario, str) else scenario,
            args.friction_scale,
        )
    analysis = analyze(scenario, solve_qp=True if args.qp else None)
    if args.strict and analysis.warnings:
        raise StrictWarningsError(analysis.warnings)
    written = []
    if args.plots:
        from impact_balance.cli.output_paths import writing
        from impact_balance.plots import save_figures

        skipped: list[Diagnostic] = []
        with writing("--plots", args.plots):
            written = save_figures(analysis, Path(args.plots), skipped=skipped)
        analysis = dataclasses.replace(analysis, warnings=analysis.warnings + tuple(skipped))
        if args.strict and skipped:
            raise StrictWarningsError(skipped)
    reach = None
    if args.com_reach:
        from impact_balance.analysis.reach import reach_answer

        reach = reach_answer(analysis)
    held = None
    if args.impact_model == "held-stance":
        from impact_balance.analysis.held_stance import held_stance_max_contact_velocity

        held = held_stance_max_contact_velocity(analysis)
    if args.json:
        out = analysis.to_dict()
        if calibration is not None:
            out["calibration"] = calibration
        if reach is not None:
            out["com_reach"] = reach.to_dict()
        if held is not None:
            out["held_stance"] = held.to_dict()
        print_json(out)
    else:
        print(format_analysis(analysis))
        if calibration is not None:
            print(calibration_line(calibration))
        if reach is not None:
            print(_reach_line(reach))
        if held is not None:
            print(_held_stance_line(held))
        for path in written:
            print(f"  figure: {path}")
    return 0


def _reach_line(reach: ReachAnswer) -> str:
    """One line of ``analyze --com-reach``: the reach and the maximum within it."""
    radii = reach.reach.radii
    line = f"CoM reach at constant height: {1000 * radii.min():.0f} to {1000 * radii.max():.0f} mm"
    if reach.max_contact_velocity is not None:
        line += (
            f"; max contact velocity within reach {reach.max_contact_velocity:.3f} m/s "
            f"(without: {reach.default_max_contact_velocity:.3f})"
        )
    return line


def _held_stance_line(held: HeldStanceLimit) -> str:
    """One line of ``analyze --impact-model held-stance``: its maximum and how it was reached."""
    speed = held.max_contact_velocity
    value = f"{speed:.3f} m/s" if math.isfinite(speed) else "unbounded"
    if held.fell_back:
        how = "the paper's answer: the fixed point was not reached"
    elif held.binding_restitution is None:
        how = "no approach speed leaves the area"
    else:
        how = f"binding restitution {held.binding_restitution:g}"
    line = f"held-stance max contact velocity {value} ({how})"
    term = held.angular_momentum
    if term is not None:
        speed = term.max_contact_velocity
        with_term = f"{speed:.3f} m/s" if math.isfinite(speed) else "unbounded"
        line += f"; with the angular momentum it leaves (tau {term.damping_time:g} s) {with_term}"
    return line
