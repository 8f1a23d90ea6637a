"""``impact-balance frames ROBOT``: every frame and joint of a robot (names for contacts and joints)."""

from __future__ import annotations

import argparse
from pathlib import Path

__all__ = ["add_parser", "run", "robot_listing"]


def add_parser(sub) -> list[str]:
    f = sub.add_parser("frames", help="list a robot's frames and joints (the names scenario files use)")
    f.add_argument("robot", help="a bundled robot (see `impact-balance robots`), a URDF file, or a scenario")
    f.add_argument("--json", action="store_true", help="print one JSON object")
    return ["frames"]


def _robot(name: str):
    from ..exceptions import UnknownRobotError, UnknownScenarioError
    from ..robot import BUNDLED_ROBOTS, load_robot
    from ..scenario import load_scenario

    if name in BUNDLED_ROBOTS:
        return load_robot(name)
    if name.endswith(".urdf"):
        return load_robot(None, name)
    try:
        return load_scenario(name).load_robot()  # a scenario file or a bundled scenario's name
    except UnknownScenarioError:  # neither: say which robots there are
        raise UnknownRobotError("robot", name, BUNDLED_ROBOTS) from None


def robot_listing(robot) -> dict:
    """Frames (name, type, parent joint) and actuated joints (limits) of a robot, as a mapping."""
    model = robot.model
    frames = [
        {"name": f.name, "type": str(f.type).rsplit(".", 1)[-1], "parent_joint": model.names[f.parentJoint]}
        for f in model.frames
    ]
    effort = dict(zip(*(list(x) for x in robot.effort_limits)))
    joints = []
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        joint = model.joints[slot.id]
        finite = slot.lower < slot.upper and abs(slot.lower) < 1e30 and abs(slot.upper) < 1e30
        joints.append({
            "name": name,
            "nq": slot.nq,
            "lower": slot.lower if finite and slot.nq == 1 else None,
            "upper": slot.upper if finite and slot.nq == 1 else None,
            "effort": effort.get(joint.idx_v),
        })
    return {"robot": robot.name, "urdf": str(Path(robot.urdf_path)), "frames": frames, "joints": joints}


def run(args: argparse.Namespace) -> int:
    listing = robot_listing(_robot(args.robot))
    if args.json:
        from .output import print_json

        print_json(listing)
        return 0
    print(f"{listing['robot']}: {len(listing['frames'])} frames, {len(listing['joints'])} joints ({listing['urdf']})")
    print("frames (name, type, parent joint):")
    width = max(len(f["name"]) for f in listing["frames"])
    for f in listing["frames"]:
        print(f"  {f['name']:<{width}}  {f['type']:<12} {f['parent_joint']}")
    print("joints (name, position limits, effort limit):")
    width = max((len(j["name"]) for j in listing["joints"]), default=0)
    for j in listing["joints"]:
        limits = f"[{j['lower']:+.4g}, {j['upper']:+.4g}]" if j["lower"] is not None else "unlimited"
        effort = f"{j['effort']:g} N m" if j["effort"] is not None else "no effort limit"
        print(f"  {j['name']:<{width}}  {limits:<20} {effort}")
    return 0
