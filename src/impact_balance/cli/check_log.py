"""``impact-balance check-log LOG --scenario S``: a recorded motion against the balance criteria."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from impact_balance.cli._options import output_folder

if TYPE_CHECKING:
    from impact_balance.analysis.result import Diagnostic
    from impact_balance.cli._options import Subcommands
    from impact_balance.logs.check import LogCheck

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``check-log`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    a = sub.add_parser(
        "check-log", help="check a recorded time series (.parquet or .csv) against both criteria"
    )
    a.add_argument("log", help="the log file (columns: see impact_balance.logs.schema)")
    a.add_argument(
        "--scenario", required=True, help="YAML file or bundled scenario name (robot and contacts)"
    )
    a.add_argument("--json", action="store_true", help="print one JSON object")
    a.add_argument(
        "--samples", action="store_true", help="with --json, include every sample's values"
    )
    a.add_argument(
        "--plots", metavar="DIR", type=output_folder("--plots"), help="write the figures to DIR"
    )
    return ["check-log"]


def run(args: argparse.Namespace) -> int:
    """Run ``check-log`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.cli.output import print_json
    from impact_balance.logs import check_log, read_log

    notes: list[Diagnostic] = []
    frame = read_log(args.log, warnings=notes)
    check = check_log(frame, args.scenario, source=str(args.log)[:80])
    out = check.to_dict(samples=args.samples)
    out["log"] = str(args.log)
    out["warnings"] = [n.to_dict() for n in notes]
    written = []
    if args.plots and not check.floating:
        from impact_balance.cli.output_paths import writing

        with writing("--plots", args.plots):
            written = _plots(check, Path(args.plots))
    if args.json:
        print_json(out)
        return 0
    print(
        f"{args.log}: {out['samples']} samples over {out['duration']:.3f} s, scenario "
        f"{check.scenario},"
        f" {len(check.segments)} stance(s)"
    )
    if check.floating:
        print(f"  {check.note}")
        if args.plots:
            print("  no margins figure: no area to measure margins against")
        return 0
    mv, mz = out["min_com_velocity_margin"], out["min_zmp_margin"]
    print(f"  smallest CoM velocity margin: {'-inf (no area)' if mv is None else f'{mv:.3f} m/s'}")
    if check.has_zmp:
        print(f"  smallest ZMP margin: {'-inf (no area)' if mz is None else f'{mz:.4f} m'}")
    else:
        print("  no ZMP columns: ZMP criterion not checked")
    if check.ok:
        print(
            "  no violation: the CoM velocity stayed in the CoM velocity area"
            + (" and the ZMP in its area" if check.has_zmp else "")
        )
    else:
        print(f"  {len(check.violations)} violation(s):")
        for v in check.violations:
            unit = "m/s" if v.kind == "com_velocity" else "m"
            print(
                f"    {v.kind:12s} {v.start:8.3f} s to {v.end:8.3f} s ({v.samples} samples), worst "
                f"{v.worst_margin:.4g} {unit}"
                f" at {v.worst_time:.3f} s"
            )
    for note in notes:
        print(f"  warning: {note}")
    for path in written:
        print(f"  wrote {path}")
    return 0


def _plots(check: LogCheck, out: Path) -> list[Path]:
    """Write the log's margin figure into ``out``; returns the paths written."""
    from impact_balance.plots.balance import plot_log_margins

    out.mkdir(parents=True, exist_ok=True)
    s = check.samples
    fig = plot_log_margins(
        s["time"].to_numpy(),
        s["com_velocity_margin"].to_numpy(),
        s["zmp_margin"].to_numpy() if check.has_zmp else None,
        f"{check.scenario}: margins",
    )
    path = out / "log_margins.png"
    fig.savefig(path)
    return [path]
