"""``impact-balance pose SCENARIO --place FRAME X Y Z [--normal NX NY NZ] [--com X Y] --out FILE``.

Whole-body IK (contacts kept) that writes a new scenario file; see
:mod:`impact_balance.authoring.pose`.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = ["add_parser", "run"]


class _Place(argparse.Action):
    """``--place FRAME X Y Z`` starts a placement; ``--normal NX NY NZ`` completes the last one."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        """Record ``--place`` or complete the last placement with ``--normal``."""
        items: Sequence[Any] = (
            [] if values is None else [values] if isinstance(values, str) else values
        )
        places = list(getattr(namespace, "places", None) or [])
        if option_string == "--place":
            frame, *xyz = items
            places.append(
                {"frame": frame, "position": _numbers(parser, "--place", xyz), "normal": None}
            )
        else:
            if not places:
                parser.error("--normal comes after the --place it turns")
            if places[-1]["normal"] is not None:
                parser.error(f"--normal given twice for --place {places[-1]['frame']}")
            places[-1]["normal"] = _numbers(parser, "--normal", items)
        namespace.places = places


def _numbers(
    parser: argparse.ArgumentParser, option: str, texts: Sequence[Any]
) -> tuple[float, ...]:
    """``texts`` as finite numbers within +-1e4 (a usage error otherwise)."""
    try:
        values = tuple(float(t) for t in texts)
    except ValueError:
        parser.error(f"{option}: expected numbers, got {' '.join(texts)}")
    if not all(math.isfinite(v) and abs(v) <= 1e4 for v in values):
        parser.error(f"{option}: each number must be finite and within +-1e4")
    return values


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``pose`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    p = sub.add_parser(
        "pose", help="place frames by whole-body IK (contacts kept) and write the scenario"
    )
    p.add_argument("scenario", help="YAML file, or the name of a bundled scenario")
    p.add_argument(
        "--place",
        nargs=4,
        action=_Place,
        dest="places",
        metavar=("FRAME", "X", "Y", "Z"),
        help="put FRAME's contact centre (or origin) at world X Y Z, m (repeatable)",
    )
    p.add_argument(
        "--normal",
        nargs=3,
        action=_Place,
        dest="places",
        metavar=("NX", "NY", "NZ"),
        help="after --place: turn that contact's normal (or the frame's z axis) to this world "
        "direction",
    )
    p.add_argument(
        "--com", nargs=2, type=float, metavar=("X", "Y"), help="horizontal CoM target, world, m"
    )
    p.add_argument("--out", required=True, metavar="FILE", help="scenario file to write (.yaml)")
    p.add_argument(
        "--no-flat",
        dest="flat",
        action="store_false",
        help="leave point feet on the ground as their frames are (by default their contacts "
        "are written flat: normal: [0, 0, 1])",
    )
    p.add_argument("--force", action="store_true", help="replace FILE if it exists")
    p.add_argument("--json", action="store_true", help="print one JSON object")
    return ["pose"]


def run(args: argparse.Namespace) -> int:
    """Run ``pose`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from pathlib import Path

    from impact_balance.authoring import Placement, pose_scenario, posed_mapping, scenario_yaml
    from impact_balance.cli.output_paths import check_output_file
    from impact_balance.exceptions import ScenarioError, WorkspaceError
    from impact_balance.gui.workspace import Workspace
    from impact_balance.scenario import (
        load_scenario,
        read_mapping,
        scenario_from_dict,
        scenario_path,
    )

    places = getattr(args, "places", None) or []
    if not places and args.com is None:
        raise ScenarioError(
            "--place", None, "nothing to do: give --place FRAME X Y Z and/or --com X Y"
        )
    if args.com is not None and not all(math.isfinite(v) and abs(v) <= 1e4 for v in args.com):
        raise ScenarioError("--com", list(args.com), "must be finite, within +-1e4 m")
    out = Path(args.out)
    workspace = Workspace(out.parent if str(out.parent) else ".")
    workspace.resolve(
        out.name, for_write=True, overwrite=True, field="--out"
    )  # a bad name fails before the IK
    # ... and a folder nothing can be written in (/proc, /sys, a read-only file system): exit 1
    check_output_file(args.out, "--out")
    if not args.force and (out.exists() or out.is_symlink()):
        raise WorkspaceError("--out", str(out), "the file exists (--force replaces it)")
    scenario = load_scenario(args.scenario)
    placements = [Placement(p["frame"], p["position"], p["normal"]) for p in places]
    result = pose_scenario(scenario, placements, args.com)
    mapping = posed_mapping(
        read_mapping(scenario_path(args.scenario)),
        scenario,
        result,
        out.parent,
        flat=getattr(args, "flat", True),
    )
    posed = scenario_from_dict(mapping, str(out))
    posed.build_stance()  # what is written loads
    argv = " ".join(
        f"--place {p.frame} {' '.join(f'{x:g}' for x in p.position)}"
        + (f" --normal {' '.join(f'{x:g}' for x in p.normal)}" if p.normal else "")
        for p in placements
    )
    if args.com is not None:
        argv += f" --com {args.com[0]:g} {args.com[1]:g}"
    text = scenario_yaml(
        mapping,
        f"Posed by `impact-balance pose {scenario.name or args.scenario} {argv.strip()}`\n"
        "(whole-body IK, the other contacts kept).",
    )
    written = _write(workspace, out, text, args.force)
    _report(args, placements, result, mapping, (scenario, posed), written)
    return 0


def _report(
    args: argparse.Namespace,
    placements: Sequence[Any],
    result: Any,
    mapping: dict[str, Any],
    scenarios: tuple[Any, Any],
    written: Any,
) -> None:
    """Print what ``pose`` did (text or JSON), ending with the verdict of the written stance.

    ``scenarios``: the scenario posed and the one written.
    """
    scenario, posed = scenarios
    worst = max(result.residuals.values(), default=0.0)
    verdict = _verdict(posed)
    if args.json:
        from impact_balance.cli.output import print_json

        print_json(
            {
                "out": str(written),
                "residuals": result.residuals,
                "largest_residual": worst,
                "com": result.com.tolist(),
                "base": mapping["base"],
                "joints": mapping["joints"],
                "flat": sorted(
                    c["frame"]
                    for i, c in enumerate(mapping["contacts"])
                    if "normal" in c and not scenario.contacts[i].normal
                ),
                **verdict,
            }
        )
        return
    for p in placements:
        target = result.targets[p.frame]
        print(
            f"{p.frame}: placed, residual {result.residuals[p.frame + '.position']:.1e} m"
            + (
                f", {result.residuals[p.frame + '.orientation']:.1e} rad"
                if p.frame + ".orientation" in result.residuals
                else ""
            )
            + f" (frame origin at [{', '.join(f'{x:.4f}' for x in target.translation)}])"
        )
    kept = [f for f in result.targets if f not in {p.frame for p in placements}]
    if kept:
        drift = max(result.residuals[f + ".position"] for f in kept)
        print(f"contacts kept: {', '.join(kept)} (largest drift {drift:.1e} m)")
    print(
        f"CoM at [{', '.join(f'{x:.4f}' for x in result.com)}] m"
        + (
            f", {result.residuals['com_xy']:.1e} m from the --com target"
            if "com_xy" in result.residuals
            else ""
        )
    )
    flat = [
        c["frame"]
        for i, c in enumerate(mapping["contacts"])
        if "normal" in c and not scenario.contacts[i].normal
    ]
    if flat:
        print(f"laid flat (normal: [0, 0, 1]): {', '.join(flat)}")
    print(f"wrote: {written}")
    for warning in verdict["warnings"]:
        print(f"warning: {warning}")
    print(f"verdict: {verdict['summary']}")


def _verdict(scenario: Any) -> dict[str, Any]:
    """The analysis of the written stance: can it balance, why not, its max contact velocity."""
    from impact_balance.analysis.analyze import analyze

    analysis = analyze(scenario)
    reason = analysis.cannot_balance_reason
    line = analysis.verdict
    if not analysis.areas.can_balance:
        line = "CANNOT BALANCE: the contacts cannot hold the robot at rest" + (
            f"; {reason}" if reason is not None else ""
        )
    elif analysis.com_velocity_inside:
        line = "can balance (" + line + " at rest)"
    else:
        com = analysis.stance.com[:2]
        outside = not analysis.areas.zmp_area.contains(com, 1e-10)
        line = (
            "CANNOT BALANCE: "
            + line
            + (
                f"; the CoM ({com[0]:.3f}, {com[1]:.3f}) m is outside the ZMP support area "
                "(move it with --com)"
                if outside
                else ""
            )
        )
    speed = None
    if analysis.impact is not None and analysis.com_velocity_inside:
        speed = float(analysis.impact.max_contact_velocity)
        line += f"; max contact velocity {speed:.3f} m/s (CoM criterion)"
    return {
        "warnings": [str(d) for d in analysis.warnings],
        "can_balance": bool(analysis.com_velocity_inside),
        "verdict": analysis.verdict,
        "reason": None if reason is None else str(reason),
        "max_contact_velocity": speed,
        "summary": line,
    }


def _write(workspace: Any, out: Any, text: str, force: bool) -> Any:
    """Write the scenario; a refusal of the system (a full disk) is exit status 1, naming --out."""
    from impact_balance.exceptions import OutputError, WorkspaceError

    try:
        return workspace.write_text(out.name, text, overwrite=force, field="--out")
    except WorkspaceError as exc:
        cause = exc.__context__
        if isinstance(cause, OSError) and not isinstance(cause, FileExistsError):
            reason = cause.strerror or type(cause).__name__
            raise OutputError("--out", str(out), f"cannot write: {reason}") from None
        raise
