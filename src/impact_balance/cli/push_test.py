"""``impact-balance push-test SCENARIO``: impulsive pushes, predicted, then scored.

Each push is predicted before its trial and scored after it.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING, Any

from impact_balance.cli._options import (
    DEFAULT_CONTROLLER,
    add_controller_option,
    add_output_options,
    add_trial_options,
    open_journal,
    scoring_margin,
    with_margins,
)
from impact_balance.cli.angular_momentum import add_angular_momentum_option, for_trials
from impact_balance.cli.calibrate import add_calibration_option, apply_calibration_option
from impact_balance.cli.friction_scale import add_friction_scale_option, friction_scale_for_trials

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.sim.studies.push import PushOutcome, PushTestResult

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def add_parser(sub: Subcommands) -> list[str]:
    # No import of the simulation here: mujoco is imported only when a simulation command runs.
    """Add the ``push-test`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "push-test", help="push the simulated robot in every direction; score both criteria"
    )
    a.add_argument("scenario", help="YAML file or bundled scenario name")
    a.add_argument(
        "--directions", type=int, default=16, help="number of push directions (default 16)"
    )
    a.add_argument(
        "--magnitudes",
        type=float,
        nargs="+",
        default=None,
        metavar="NS",
        help="impulses, N s (default 5 10 15 20 25 30)",
    )
    a.add_argument(
        "--relative",
        type=float,
        nargs="+",
        default=None,
        metavar="F",
        help="impulses as fractions of each direction's boundary impulse (the one that puts the "
        "predicted CoM velocity on the CoM velocity area's boundary), e.g. 0.6 0.8 1.0 1.2 1.4",
    )
    a.add_argument(
        "--band",
        type=float,
        nargs=2,
        default=None,
        metavar=("LO", "HI"),
        help="sample the band LO..HI of each direction's boundary impulse densely, where the "
        "criterion decides (e.g. 0.75 1.05); scores are given on the band and overall",
    )
    a.add_argument(
        "--band-step",
        type=float,
        default=None,
        metavar="F",
        help="step of --band, in boundary fractions (default 0.03)",
    )
    a.add_argument(
        "--far",
        type=float,
        nargs="+",
        default=None,
        metavar="F",
        help="a few far points beside --band, in boundary fractions (e.g. 0.5 1.3)",
    )
    a.add_argument("--duration", type=float, default=0.05, help="push duration, s (default 0.05)")
    a.add_argument("--body", help="MuJoCo body pushed (default: the torso)")
    a.add_argument(
        "--com-reach",
        action="store_true",
        help="the default prediction also asks the capture to stay within the CoM's reach at "
        "constant height with every contact kept (whole-body IK; docs/com-reach.md)",
    )
    a.add_argument(
        "--finite-push",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="the default prediction counts the push's duration (on by default): a constant "
        "force for --duration with the ZMP under the starting CoM, the impulse's CoM velocity "
        "scaled by kappa = (exp(omega T) - 1) / (omega T); --no-finite-push predicts the push "
        "as the paper's impulse (docs/simulation.md)",
    )
    add_controller_option(
        a,
        DEFAULT_CONTROLLER,
        "it places the ZMP anywhere in the support area, as the criterion assumes",
    )
    add_trial_options(a, impact=False)
    add_calibration_option(a)
    add_output_options(a, "of one telling push")
    add_angular_momentum_option(a, controller=True)
    add_friction_scale_option(a, controller=True)
    return ["push-test"]


def run(args: argparse.Namespace) -> int:
    """Run ``push-test`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.cli.output import print_json, progress_bar
    from impact_balance.cli.output_paths import writing
    from impact_balance.logs import check_log_path
    from impact_balance.scenario import load_scenario
    from impact_balance.sim.studies.push import check_push_arguments, push_test
    from impact_balance.sim.trials.aborts import check_not_all_aborted
    from impact_balance.sim.trials.balance_trial import BalanceTrialOptions, write_trial_log

    scenario = with_margins(load_scenario(args.scenario), args.zmp_margin)
    scenario, calibration = apply_calibration_option(args, scenario)
    if args.log:
        check_log_path(args.log)
    relative = _relative_levels(args)
    check_push_arguments(args.directions, args.magnitudes, args.duration, relative)
    options = BalanceTrialOptions(controller=args.controller)
    judged = for_trials(scenario, args.angular_momentum_damping_time, options)
    judged = friction_scale_for_trials(judged, args.friction_scale, options)
    journal = open_journal(args, "push-test", scenario, "servo", options, {"body": args.body})
    scenario = judged  # the trials journal keys the scenario without the option
    levels = len(relative or args.magnitudes or [0] * 6)
    bar = progress_bar(f"push-test {scenario.name}", args.directions * levels)

    def progress(outcome: PushOutcome) -> None:
        """Advance the progress bar by one push, with its magnitude and outcome."""
        bar.update(1)
        bar.set_postfix_str(f"{outcome.push.magnitude:.1f} N s {outcome.outcome}")

    try:
        result = push_test(
            scenario,
            args.directions,
            args.magnitudes,
            args.duration,
            args.body,
            progress=progress,
            options=options,
            relative=relative,
            zmp_margin=scoring_margin(scenario),
            journal=journal,
            band=args.band,
            reach=args.com_reach,
            finite_push=args.finite_push,
        )
    finally:
        bar.close()
        journal.close()
    out = result.to_dict()
    # The option as given ("controller", a number, "off" or null): a criterion setting of the
    # predictions that a calibration records and requires to agree between its files.
    out["angular_momentum_option"] = args.angular_momentum_damping_time
    if scenario.friction_scale != 1.0:
        out["friction_scale"] = scenario.friction_scale
    if calibration is not None:
        out["calibration"] = calibration
    written = []
    if args.log:
        chosen = _telling(result)
        with writing("--log", args.log):
            written.append(
                write_trial_log(
                    result.setup,
                    args.log,
                    args.controller,
                    {
                        "push_direction": chosen.push.direction,
                        "push_magnitude": chosen.push.magnitude,
                    },
                    push=chosen.push,
                )
            )
        out["log"] = {
            "file": str(args.log),
            "direction": chosen.push.direction,
            "magnitude": chosen.push.magnitude,
        }
    if args.plots:
        with writing("--plots", args.plots):
            written += _plots(result, Path(args.plots))
    summaries = [o.summary for o in result.outcomes]
    if args.json:
        print_json(out)
    else:
        print(_text(result, out, args))
        for path in written:
            print(f"  wrote {path}")
    check_not_all_aborted("push-test", result.scenario, summaries)
    return 0


def _relative_levels(args: argparse.Namespace) -> list[float] | None:
    """The impulses as fractions of the boundary impulse: ``--relative``, or ``--band``'s levels."""
    from impact_balance.exceptions import SimulationError
    from impact_balance.sim.studies.push import band_levels, check_band_arguments

    if args.band is None and args.band_step is not None:
        raise SimulationError("--band-step", args.band_step, "needs --band (the step of the band)")
    step = 0.03 if args.band_step is None else args.band_step
    check_band_arguments(args.band, step, args.far)
    if args.band is None:
        return args.relative  # type: ignore[no-any-return]
    if args.relative is not None or args.magnitudes is not None:
        given = "--relative" if args.relative is not None else "--magnitudes"
        raise SimulationError(
            given, args.relative or args.magnitudes, f"give {given} or --band, not both"
        )
    return band_levels(args.band, step, args.far or ())


def _pct(x: float | None) -> str:
    """A fraction as a percentage with 1 decimal, or "-" when there is none."""
    return "-" if x is None else f"{100 * x:.1f} %"


def _ci(c: list[float] | None) -> str:
    """A Wilson interval as `` [lo, hi]`` in percent, or "" when there is none."""
    return "" if c is None else f" [{100 * c[0]:.0f}, {100 * c[1]:.0f}]"


def _rate(r: dict[str, Any]) -> str:
    """A rate of :func:`~impact_balance.sim.studies.scores.rate`: percent, interval, counts."""
    return f"{_pct(r['rate'])}{_ci(r['ci95'])} ({r['count']}/{r['of']})"


_CRITERIA_LABELS = (
    ("com", "CoM criterion, before the trial"),
    ("paper_com", "paper's CoM criterion"),
    ("com_in_trial", "CoM criterion, in the trial"),
    ("zmp", "ZMP criterion, before the trial"),
    ("zmp_in_trial", "ZMP criterion, in the trial"),
)


def _score_lines(scores: dict[str, Any], title: str) -> list[str]:
    """The conditional rates of every criterion, lenient and strict."""
    lines = [f"  {title}"]
    for key, label in _CRITERIA_LABELS:
        k = scores[key]
        for outcome, c in (("fell", k), ("strict", k["strict"])):
            lines.append(
                f"    {label:32s} {outcome:6s} P(fell | safe) {_rate(c['fell_given_safe'])}, "
                f"P(stood | unsafe) {_rate(c['stood_given_unsafe'])}, "
                f"stood called safe {_pct(c['safe_given_stood']['rate'])}"
            )
    return lines


def _text(result: PushTestResult, out: dict[str, Any], args: argparse.Namespace) -> str:
    """The text report of a push test: outcomes, scores and the table per push level."""
    from impact_balance.sim.trials.aborts import aborted_lines

    counts = out["counts"]
    o = counts["outcomes"]
    controller = out["controller"].get("name", args.controller)
    lines = [
        f"{result.scenario}: {len(result.outcomes)} pushes ({args.directions} directions, "
        f"{args.duration * 1e3:.0f} ms) "
        f"with the {args.controller} controller ({controller})",
        f"  outcomes: {o['balanced']} balanced, {o['contact_broken']} contact broken (came to "
        "rest), "
        f"{o['fell']} fell, {o['aborted']} aborted; {counts['strict_fail']} failed strictly (fell, "
        "or a contact beyond the strict bounds)",
    ]
    if counts["reasons"]:
        lines.append("  " + ", ".join(f"{k}: {v}" for k, v in sorted(counts["reasons"].items())))
    lines += aborted_lines(t.summary for t in result.outcomes)
    margin = 1000 * out["zmp_margin"]
    lines.append(
        f"  {'magnitude':>14s} {'balanced':>8s} {'broken':>6s} {'fell':>5s} {'strict':>6s} "
        f"{'CoM safe':>8s} {'ZMP safe':>8s}"
    )
    for row in _by_level(result):
        lines.append(
            f"  {row['label']:>14s} {row['balanced']:8d} {row['contact_broken']:6d} "
            f"{row['fell']:5d} {row['strict']:6d} "
            f"{row['com']:8d} {row['zmp']:8d}"
        )
    head = f"ZMP margin {margin:g} mm; 95 % Wilson intervals"
    if out["band_scores"] is not None:
        lo, hi = out["band"]
        n = len(result.in_band)
        lines += _score_lines(
            out["band_scores"],
            f"scores on the band {lo:g}-{hi:g} of the boundary ({n} pushes, {head}):",
        )
    lines += _score_lines(out["scores"], f"scores over all {len(result.scored)} pushes ({head}):")
    study = out["margin_study"]
    for key, outcome in (("smallest_margin", "fell"), ("smallest_margin_strict", "strict")):
        smallest = study[key]["com"]
        lines.append(
            f"  smallest ZMP margin that brings the CoM criterion's P(fell | safe) ({outcome}) to "
            "5 % or less: " + ("none up to 6 cm" if smallest is None else f"{1000 * smallest:g} mm")
        )
    if result.finite_push is not None:
        kappa = result.finite_push[1]
        lines.append(
            f"  the default predicts the push's duration: CoM velocity x{kappa:.4f} (kappa)"
        )
    if out["journal"]:
        lines.append(f"  trials journal: {out['journal']} ({out['reused_trials']} reused)")
    if out.get("calibration") is not None:
        from impact_balance.cli.calibrate import calibration_line

        lines.append(calibration_line(out["calibration"]))
    return "\n".join(lines)


def _by_level(result: PushTestResult) -> list[dict[str, Any]]:
    """The outcomes counted per push level (fraction of the boundary, or N s)."""
    rows: dict[float, dict[str, Any]] = {}
    for o in result.outcomes:
        level = o.relative if o.relative is not None else o.push.magnitude
        label = (
            f"x{o.relative:g} boundary" if o.relative is not None else f"{o.push.magnitude:g} N s"
        )
        row = rows.setdefault(
            level,
            {
                "label": label,
                "balanced": 0,
                "contact_broken": 0,
                "fell": 0,
                "strict": 0,
                "com": 0,
                "zmp": 0,
            },
        )
        if o.outcome in row:
            row[o.outcome] += 1
        row["strict"] += o.strict_fail
        row["com"] += o.safe("com", result.zmp_margin, result.omega)
        row["zmp"] += o.safe("zmp", result.zmp_margin, result.omega)
    return [rows[k] for k in sorted(rows)]


def _telling(result: PushTestResult) -> PushOutcome:
    """The push of the paper's Exp.

    2 if there is one (ZMP outside in the trial, no fall), else the largest that did not fall,
    else the first.
    """
    stood = [o for o in result.scored if not o.fell]
    exp2 = [o for o in stood if not o.safe("zmp_in_trial", 0.0, result.omega)]
    if exp2:
        return max(exp2, key=lambda o: o.push.magnitude)
    return max(stood, key=lambda o: o.push.magnitude) if stood else result.outcomes[0]


def _plots(result: PushTestResult, out: Path) -> list[Path]:
    """Write the push figures (ZMP and CoM velocity) into ``out``; returns their paths."""
    from impact_balance.plots.balance import PushView, plot_push_trajectories
    from impact_balance.plots.save import figure_prefix

    out.mkdir(parents=True, exist_ok=True)
    prefix = figure_prefix(result.setup.analysis)
    paths = [out / f"{prefix}_push_zmp.png", out / f"{prefix}_push_com_velocity.png"]
    views: tuple[PushView, ...] = ("zmp", "com_velocity")
    for path, kind in zip(paths, views, strict=True):
        plot_push_trajectories(result, kind).savefig(path)
    return paths
