"""``impact-balance calibrate FILE...``: the ZMP margin that brings the false-safe rate to a target.

Also the ``--calibration FILE`` option of the commands that read a calibration
(:func:`add_calibration_option`, :func:`apply_calibration_option`).
"""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING, Any

from impact_balance.cli._options import number, output_file

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.scenario import Scenario
    from impact_balance.sim.studies.calibrate import Calibration

__all__ = [
    "add_calibration_option",
    "add_parser",
    "apply_calibration_option",
    "calibration_line",
    "run",
]


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``calibrate`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "calibrate",
        help="the smallest ZMP margin that brings P(fell | predicted safe) to a target, from "
        "push-test --json outputs",
    )
    a.add_argument(
        "files",
        nargs="+",
        metavar="FILE",
        help="push-test --json outputs of one robot and one controller (pooled)",
    )
    a.add_argument(
        "--target",
        type=number("--target", 0.0, 1.0, lo_open=True),
        default=0.05,
        help="false-safe rate P(failed | predicted safe) aimed at (default 0.05)",
    )
    a.add_argument(
        "--upper-target",
        type=number("--upper-target", 0.0, 1.0, lo_open=True),
        default=0.12,
        help="also the smallest margin whose upper 95 %% Wilson bound reaches this (default 0.12)",
    )
    a.add_argument(
        "--floor",
        type=_floor_value,
        default="controller",
        metavar="M|controller",
        help="smallest margin the answer may take, m (default controller: the margin the "
        "trials' controller keeps, recorded in the files; 0: no floor)",
    )
    a.add_argument(
        "--lenient",
        action="store_true",
        help="score the lenient outcome (fell) instead of the strict one (fell, or a contact "
        "broken beyond the strict bounds)",
    )
    a.add_argument(
        "--out",
        metavar="FILE",
        type=output_file("--out", (".yaml", ".yml")),
        help="write the calibration file (YAML), read by --calibration",
    )
    a.add_argument("--json", action="store_true", help="print one JSON object")
    return ["calibrate"]


def _floor_value(text: str) -> float | str:
    if text == "controller":
        return text
    return number("--floor", 0.0, 1.0)(text)


def add_calibration_option(parser: argparse.ArgumentParser) -> None:
    """Add ``--calibration FILE``: the ZMP margin of a calibration file (``calibrate --out``)."""
    parser.add_argument(
        "--calibration",
        metavar="FILE",
        default=None,
        help="use the ZMP margin calibrated in FILE (impact-balance calibrate --out); an "
        "explicit --zmp-margin wins",
    )


def apply_calibration_option(
    args: argparse.Namespace, scenario: Scenario
) -> tuple[Scenario, dict[str, Any] | None]:
    """The scenario with ``--calibration``'s margin, and what the JSON says of it.

    Call it after ``--zmp-margin`` was applied. An explicit ``--zmp-margin`` wins: the
    calibration's robot is still checked, a warning line says it is not used, and the JSON's
    ``calibration.applied`` is false.

    Returns:
        The scenario to use, and the ``calibration`` entry of the JSON (None without the option).

    Raises:
        ScenarioError: An unreadable or bad file, or another robot's calibration (exit 2).
    """
    path = getattr(args, "calibration", None)
    if path is None:
        return scenario, None
    from impact_balance.scenario.calibration import (
        apply_calibration,
        calibration_in_use,
        read_calibration,
    )

    calibration = read_calibration(path)
    calibrated = apply_calibration(scenario, calibration, path)
    if getattr(args, "zmp_margin", None) is not None:
        print(
            f"impact-balance: warning: --zmp-margin {args.zmp_margin:g} given: the calibrated "
            f"ZMP margin {calibration.zmp_margin:g} m of {path} is not used",
            file=sys.stderr,
        )
        return scenario, calibration_in_use(calibration, path, False, scenario.zmp_margin)
    return calibrated, calibration_in_use(calibration, path, True, calibrated.zmp_margin)


def calibration_line(calibration: dict[str, Any]) -> str:
    """One text line on the calibration in use (from :func:`apply_calibration_option`)."""
    c = calibration
    used = "in use" if c["applied"] else "not used (--zmp-margin given)"
    return (
        f"  calibration {c['file']}: ZMP margin {1000 * c['zmp_margin']:g} mm for robot "
        f"{c['robot']} (target P(failed | safe) {100 * c['target']:g} %, {c['outcome']}), {used}"
    )


def run(args: argparse.Namespace) -> int:
    """Run ``calibrate`` with the parsed command line.

    Returns:
        The exit status (0, also when no margin reaches the target: that is an answer).
    """
    from impact_balance.cli.output import print_json
    from impact_balance.sim.studies.calibrate import calibrate

    result = calibrate(
        args.files,
        target=args.target,
        strict=not args.lenient,
        upper_target=args.upper_target,
        floor=args.floor,
    )
    out = result.to_dict()
    out["out"] = None
    if args.out and result.zmp_margin is not None:
        from impact_balance.cli.output_paths import writing
        from impact_balance.scenario.calibration import write_calibration

        with writing("--out", args.out):
            write_calibration(_file_model(result), args.out)
        out["out"] = args.out
    if args.json:
        print_json(out)
        return 0
    print(_text(result, out, args))
    return 0


def _file_model(result: Calibration) -> Any:
    """The calibration file of ``result`` (its margin must exist)."""
    import datetime
    import importlib.metadata

    from impact_balance.scenario.calibration import (
        CALIBRATION_VERSION,
        CalibrationFile,
        CalibrationRate,
        RemovalAxis,
        TrainingFile,
    )
    from impact_balance.sim.studies.calibrate import angular_momentum_removal

    assert result.zmp_margin is not None
    chosen = result.at(result.zmp_margin)
    removal = angular_momentum_removal([p for s in result.sets for p in s.pushes], result.strict)
    first = result.sets[0]
    return CalibrationFile(
        version=CALIBRATION_VERSION,
        robot=first.robot,
        controller=first.controller,
        criterion=first.criterion,
        outcome_criteria=first.outcome_criteria,
        outcome="strict" if result.strict else "lenient",
        target=result.target,
        zmp_margin=result.zmp_margin,
        fell_given_safe=CalibrationRate(**_rate(chosen["fell_given_safe"])),
        safe_given_stood=CalibrationRate(**_rate(chosen["safe_given_stood"])),
        upper_target=result.upper_target,
        upper_margin=result.upper_margin,
        margin_floor=result.floor,
        unfloored_margin=result.unfloored_margin,
        angular_momentum_removal={
            "x": RemovalAxis(**removal["x"]),
            "y": RemovalAxis(**removal["y"]),
        },
        training=[
            TrainingFile(
                file=s.file,
                sha256=s.sha256 or "0" * 64,
                scenario=s.scenario,
                body=s.body,
                pushes=len(s.pushes),
            )
            for s in result.sets
        ],
        created=datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        impact_balance_version=_package_version(importlib.metadata),
    )


def _package_version(metadata: Any) -> str:
    try:
        return str(metadata.version("impact-balance"))
    except metadata.PackageNotFoundError:  # pragma: no cover - run from a source tree
        return "unknown"


def _rate(r: dict[str, Any]) -> dict[str, Any]:
    ci = r["ci95"]
    return {
        "rate": r["rate"],
        "ci95": None if ci is None else list(ci),
        "count": r["count"],
        "of": r["of"],
    }


def _pct(r: dict[str, Any] | None) -> str:
    if r is None or r["rate"] is None:
        return "-"
    lo, hi = r["ci95"]
    return f"{100 * r['rate']:.1f} % [{100 * lo:.0f}, {100 * hi:.0f}] ({r['count']}/{r['of']})"


def _answer_mm(margin: float | None) -> str:
    return "no margin reaches the target" if margin is None else f"{1000 * margin:g} mm"


def _removal_line(out: dict[str, Any]) -> str:
    """The controller's realised angular momentum removal, per axis, against its declared K_L."""
    parts = []
    for axis, name in (("x", "roll"), ("y", "pitch")):
        r = out["angular_momentum_removal"][axis]
        if r["share"] is None:
            parts.append(f"{name} not measured")
            continue
        tau = "never" if r["damping_time"] is None else f"tau {r['damping_time']:.3f} s"
        parts.append(f"{name} {tau} (share {r['share']:.2f}, {r['pushes']} pushes)")
    gain = out["controller"].get("gains", {}).get("angular_momentum_damping")
    declared = (
        f"; declared 1/K_L {1.0 / gain:.3f} s"
        if isinstance(gain, (int, float)) and not isinstance(gain, bool) and gain > 0
        else ""
    )
    return "  angular momentum removal realised: " + ", ".join(parts) + declared


def _text(result: Calibration, out: dict[str, Any], args: argparse.Namespace) -> str:
    name = out["controller"].get("name", "?")
    lines = [
        f"calibrate: {out['pushes']} pushes of robot {out['robot']} ({name}) in "
        f"{len(result.sets)} file(s); {out['outcome']} outcome, target P(failed | safe) <= "
        f"{100 * result.target:g} %",
    ]
    floor = f"{1000 * result.floor:g} mm"
    lines.append(
        f"  floor {floor} (the smallest margin answered); without it: "
        + _answer_mm(result.unfloored_margin)
    )
    if result.zmp_margin is None:
        lines.append(f"  {out['answer']} from {floor} up to {1000 * result.grid[-1]:g} mm")
    else:
        lines += [
            f"  ZMP margin {out['answer']}: P(failed | safe) {_pct(out['fell_given_safe'])}, "
            f"stood called safe {_pct(out['safe_given_stood'])}",
            "  per file at that margin (what the margin absorbs):",
        ]
        for row in out["per_file"]:
            lines.append(
                f"    {row['scenario']} ({row['body']}, {row['pushes']} pushes): P(failed | safe) "
                f"{_pct(row['fell_given_safe'])}, stood called safe {_pct(row['safe_given_stood'])}"
            )
    upper = out["upper_margin"]
    lines.append(
        f"  upper 95 % bound <= {100 * result.upper_target:g} %: "
        + ("no margin up to the grid's end" if upper is None else f"{1000 * upper:g} mm")
    )
    lines.append(_removal_line(out))
    if out["out"]:
        lines.append(f"  wrote {out['out']}")
    elif args.out:
        lines.append(f"  {args.out} not written: no margin reaches the target")
    return "\n".join(lines)
