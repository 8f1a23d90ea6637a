"""``impact-balance scenarios`` and ``impact-balance robots``: what loads by name."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = ["KNOWN_FEET", "KNOWN_SOLES", "add_parser", "robot_rows", "run"]

#: Soles measured on the meshes (``examples/robot_sizes.py``, docs/robots.md): full length x
#: width (m) in the sole frame, by robot. Other robots' soles are "unknown".
KNOWN_SOLES: dict[str, str] = {
    "talos": "0.211 x 0.124 m",
    "g1": "0.17 x 0.05 m (collision spheres)",
    "romeo": "0.194 x 0.125 m",
    "icub": "0.061 x 0.156 m",
}


#: Foot frames that no link name says (a bundled robot's sole frame, docs/robots.md).
KNOWN_FEET: dict[str, tuple[str, ...]] = {"g1": ("left_ankle_roll_link", "right_ankle_roll_link")}


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``scenarios``, ``robots`` commands to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    sub.add_parser("scenarios", help="list the bundled scenarios")
    r = sub.add_parser("robots", help="list the bundled robots (--all: every robot by name)")
    r.add_argument(
        "--all",
        action="store_true",
        help="every robot `robot: NAME` loads (example-robot-data's floating-base robots "
        "too), with its mass, standing configuration, foot frames and sole size",
    )
    return ["scenarios", "robots"]


def robot_rows() -> list[tuple[str, str, str, str, str, str]]:
    """One row per robot loadable by name: name, mass, standing, feet, sole, description.

    The feet are the links named as feet (``Robot.foot_frames``), "unknown" when no name
    says it; the sole size is known for the bundled robots only.
    """
    from impact_balance.robot.robot import load_robot, robot_names

    rows = []
    for name, spec in robot_names().items():
        robot = load_robot(name)
        mass = sum(float(inertia.mass) for inertia in robot.model.inertias)
        feet = ", ".join(robot.foot_frames or KNOWN_FEET.get(name, ())) or "unknown"
        sole = KNOWN_SOLES.get(name, "unknown")
        rows.append((name, f"{mass:.2f} kg", robot.standing, feet, sole, spec.description))
    return rows


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
    elif getattr(args, "all", False):
        header = ("robot", "mass", "standing", "foot frames", "sole", "description")
        rows = [header, *robot_rows()]
        widths = [max(len(row[i]) for row in rows) for i in range(5)]
        for row in rows:
            cells = [cell.ljust(width) for cell, width in zip(row, widths, strict=False)]
            print("  ".join([*cells, row[5]]).rstrip())
    else:
        from impact_balance.robot.robot import BUNDLED_ROBOTS, EXAMPLE_ROBOTS

        for name, spec in BUNDLED_ROBOTS.items():
            print(f"{name:<6}  {spec.description}")
        others = len(set(EXAMPLE_ROBOTS) - set(BUNDLED_ROBOTS))
        print(f"({others} more by name from example-robot-data: impact-balance robots --all)")
    return 0
