"""``impact-balance frames ROBOT|SCENARIO``: every frame's pose and axes, every joint.

For a scenario, the poses are at its stance (and its contacts are listed, resolved); for a
robot, at its standing configuration (the free-flyer as the configuration gives it).
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from impact_balance.cli._options import Subcommands
    from impact_balance.contacts.stance import Stance
    from impact_balance.robot.robot import Robot

__all__ = ["add_parser", "robot_listing", "run"]


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``frames`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    f = sub.add_parser("frames", help="list a robot's frames (world position and axes) and joints")
    f.add_argument(
        "robot", help="a bundled robot (see `impact-balance robots`), a URDF file, or a scenario"
    )
    f.add_argument("--frame", action="append", metavar="NAME", help="only this frame (repeatable)")
    f.add_argument("--json", action="store_true", help="print one JSON object")
    return ["frames"]


def _robot_and_stance(name: str) -> tuple[Robot, npt.NDArray[np.float64], str, Stance | None]:
    """(robot, configuration, configuration label, stance or None)."""
    from impact_balance.exceptions import UnknownRobotError, UnknownScenarioError
    from impact_balance.robot.robot import load_robot, robot_names
    from impact_balance.scenario import load_scenario

    names = robot_names()
    if name in names or name.endswith(".urdf"):
        robot = load_robot(name) if name in names else load_robot(None, name)
        return robot, robot.configuration(), f"configuration {robot.standing}", None
    try:
        scenario = load_scenario(name)  # a scenario file or a bundled scenario's name
    except UnknownScenarioError:  # neither: say which robots there are
        raise UnknownRobotError("robot", name, names) from None
    stance = scenario.build_stance()
    return stance.robot, stance.q, f"stance of scenario {scenario.name or name}", stance


def robot_listing(
    robot: Robot, q: npt.NDArray[np.float64] | None = None, frames: list[str] | None = None
) -> dict[str, Any]:
    """A robot's frames and actuated joints.

    Frames: name, type, parent joint, world pose at ``q``; joints: their limits.
    """
    from impact_balance.authoring import frame_poses

    q = robot.configuration() if q is None else q
    effort = dict(zip(*(list(x) for x in robot.effort_limits), strict=True))
    joints = []
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        joint = robot.model.joints[slot.id]
        finite = slot.lower < slot.upper and abs(slot.lower) < 1e30 and abs(slot.upper) < 1e30
        joints.append(
            {
                "name": name,
                "nq": slot.nq,
                "lower": slot.lower if finite and slot.nq == 1 else None,
                "upper": slot.upper if finite and slot.nq == 1 else None,
                "effort": effort.get(joint.idx_v),
            }
        )
    return {
        "robot": robot.name,
        "urdf": str(Path(robot.urdf_path)),
        "frames": [f.to_dict() for f in frame_poses(robot, q, frames)],
        "joints": joints,
    }


def _vec(v: Sequence[float]) -> str:
    """A vector as ``[+x.xxx +y.yyy ...]`` (3 decimals, signed)."""
    return "[" + " ".join(f"{x:+.3f}" for x in v) + "]"


def run(args: argparse.Namespace) -> int:
    """Run ``frames`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    robot, q, label, stance = _robot_and_stance(args.robot)
    listing = robot_listing(robot, q, args.frame)
    listing["configuration"] = label
    if stance is not None:
        from impact_balance.authoring import contact_poses

        listing["contacts"] = contact_poses(stance)
    if args.json:
        from impact_balance.cli.output import print_json

        print_json(listing)
        return 0
    print(
        f"{listing['robot']}: {len(listing['frames'])} frames, {len(listing['joints'])} joints "
        f"({listing['urdf']})"
    )
    print(f"poses at the {label}; world axes, m; each axis is a unit vector in world coordinates")
    rows = listing["frames"]
    width = max((len(f["name"]) for f in rows), default=4)
    print(
        f"  {'frame':<{width}}  {'type':<12} {'position':<22}  {'x axis':<22}  {'z axis':<22}  "
        f"{'z tilt':>6}  parent joint"
    )
    for f in rows:
        print(
            f"  {f['name']:<{width}}  {f['type']:<12} {_vec(f['position']):<22}  "
            f"{_vec(f['axes']['x']):<22}  "
            f"{_vec(f['axes']['z']):<22}  {f['z_tilt_deg']:5.1f}°  {f['parent_joint']}"
        )
    for i, c in enumerate(listing.get("contacts", [])):
        if i == 0:
            print("contacts (centre, normal, tilt from vertical):")
        print(
            f"  [{i}] {c['frame']}: centre {_vec(c['centre'])}, normal {_vec(c['normal'])}, "
            f"{c['normal_tilt_deg']:.1f}°, {_size(c['size'])}"
        )
    if args.frame:
        return 0
    print("joints (name, position limits, effort limit):")
    width = max((len(j["name"]) for j in listing["joints"]), default=0)
    for j in listing["joints"]:
        limits = (
            f"[{j['lower']:+.4g}, {j['upper']:+.4g}]" if j["lower"] is not None else "unlimited"
        )
        effort = f"{j['effort']:g} N m" if j["effort"] is not None else "no effort limit"
        print(f"  {j['name']:<{width}}  {limits:<20} {effort}")
    return 0


def _size(size: list[float]) -> str:
    """A contact's size in words: ``size L x W m``, or ``point`` for ``[0, 0]``."""
    if size[0] == 0 and size[1] == 0:
        return "point (size 0 x 0)"
    return f"size {size[0]:g} x {size[1]:g} m"
