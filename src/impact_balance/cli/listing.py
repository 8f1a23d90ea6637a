"""``impact-balance scenarios`` and ``impact-balance robots``: what is bundled."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = ["add_parser", "run"]


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``scenarios``, ``robots`` commands to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    sub.add_parser("scenarios", help="list the bundled scenarios")
    sub.add_parser("robots", help="list the bundled robots")
    return ["scenarios", "robots"]


def run(args: argparse.Namespace) -> int:
    """Run ``scenarios`` or ``robots`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    if args.command == "scenarios":
        from impact_balance.scenario import bundled_scenarios

        items = bundled_scenarios()
        width = max(map(len, items), default=0)
        for name, description in items.items():
            print(f"{name:<{width}}  {description}")
    else:
        from impact_balance.robot.robot import BUNDLED_ROBOTS

        for name, spec in BUNDLED_ROBOTS.items():
            print(f"{name:<6}  {spec.description}")
    return 0
