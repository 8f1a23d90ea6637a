"""``impact-balance scenarios`` and ``impact-balance robots``: what loads by name."""

from __future__ import annotations

import argparse
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.robot.robot import Robot

__all__ = [
    "KNOWN_FEET",
    "KNOWN_SOLES",
    "POINT_SOLE",
    "add_parser",
    "is_point_foot",
    "robot_rows",
    "run",
]

#: Soles measured on the meshes (``examples/robot_sizes.py``, docs/robots.md): full length x
#: width (m) in the sole frame, by robot. Other robots' soles are "point" (:data:`POINT_SOLE`)
#: or "unknown".
KNOWN_SOLES: dict[str, str] = {
    "talos": "0.211 x 0.124 m",
    "g1": "0.17 x 0.05 m (collision spheres)",
    "romeo": "0.194 x 0.125 m",
    "icub": "0.061 x 0.156 m",
    "jvrc1": "0.225 x 0.084 m",
}

#: The sole column of a robot whose every foot frame is a point foot (:func:`is_point_foot`):
#: write its contacts with ``size: [0, 0]`` (docs/robots.md, "Point feet and quadrupeds").
POINT_SOLE = "point"

#: Foot frames that no link name says (a bundled robot's sole frame, docs/robots.md).
KNOWN_FEET: dict[str, tuple[str, ...]] = {
    "g1": ("left_ankle_roll_link", "right_ankle_roll_link"),
    "jvrc1": ("l_ankle", "r_ankle"),
}


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


def is_point_foot(robot: Robot, frame: str) -> bool:
    """Whether ``frame`` of ``robot`` is a point foot: on a chain of fewer than 6 joints.

    A leg of fewer than 6 joints from the floating base (a quadruped's 3-joint leg, Bolt's)
    cannot hold its foot's orientation, so its foot is a point (a ball): the rule by which
    ``pose`` places such a frame by position only (:func:`impact_balance.robot.ik.chain_dofs`).

    Args:
        robot: The robot.
        frame: A frame of its model.

    Returns:
        True when the joints between the base and ``frame`` have fewer than 6 degrees of
        freedom in all.
    """
    from impact_balance.robot.ik import chain_dofs

    return chain_dofs(robot, frame) < 6


def robot_rows() -> list[tuple[str, str, str, str, str, str]]:
    """One row per robot loadable by name: name, mass, standing, feet, sole, description.

    The feet are the links named as feet (``Robot.foot_frames``), "unknown" when no name
    says it. The sole is the measured size for the bundled robots, "point" when every foot
    is a point foot (:func:`is_point_foot`), else "unknown".
    """
    from impact_balance.robot.robot import load_robot, robot_names

    rows = []
    for name, spec in robot_names().items():
        robot = load_robot(name)
        mass = sum(float(inertia.mass) for inertia in robot.model.inertias)
        frames = robot.foot_frames or KNOWN_FEET.get(name, ())
        feet = ", ".join(frames) or "unknown"
        points = bool(frames) and all(is_point_foot(robot, frame) for frame in frames)
        sole = KNOWN_SOLES.get(name, POINT_SOLE if points else "unknown")
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
