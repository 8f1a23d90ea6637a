"""``impact-balance phase-portrait``: the LIPM phase portrait and CoM velocity bounds.

The paper's sec. III-B.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

from impact_balance.cli._options import output_file

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = ["add_parser", "run"]


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``phase-portrait`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    pp = sub.add_parser(
        "phase-portrait", help="LIPM phase portrait and CoM velocity bounds (paper sec. III-B)"
    )
    pp.add_argument(
        "--com-height",
        type=float,
        required=True,
        metavar="H",
        help="CoM height above the ZMP plane, m",
    )
    pp.add_argument(
        "--zmp-range",
        type=float,
        nargs=2,
        required=True,
        metavar=("LO", "HI"),
        help="ZMP interval, m",
    )
    pp.add_argument("--gravity", type=float, default=9.81, help="m/s^2 (default: %(default)s)")
    pp.add_argument("--json", action="store_true", help="print one JSON object")
    pp.add_argument(
        "--plot",
        metavar="FILE",
        type=output_file("--plot", (".png", ".pdf", ".svg")),
        help="write the phase portrait figure (.png, .pdf or .svg)",
    )
    return ["phase-portrait"]


def run(args: argparse.Namespace) -> int:
    """Run ``phase-portrait`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.balance.lipm import phase_portrait

    portrait = phase_portrait(args.com_height, tuple(args.zmp_range), args.gravity)
    if args.plot:
        from impact_balance.cli.output_paths import writing
        from impact_balance.plots import plot_phase_portrait

        fig = plot_phase_portrait(portrait)
        with writing("--plot", args.plot):
            Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
            fig.savefig(args.plot, dpi=120)
    if args.json:
        from impact_balance.cli.output import print_json

        print_json(
            {
                "omega": portrait.omega,
                "com_height": args.com_height,
                "zmp_range": list(portrait.zmp_range),
                "gravity": args.gravity,
                "com_velocity_bounds": list(portrait.com_velocity_bounds),
            }
        )
    else:
        lo, hi = portrait.com_velocity_bounds
        print(
            f"omega = {portrait.omega:.4f} 1/s; CoM velocity bounds at c = 0: [{lo:.4f}, {hi:.4f}] "
            "m/s"
        )
        if args.plot:
            print(f"figure: {args.plot}")
    return 0
