"""Place frames by whole-body IK, contacts kept, and write the posed scenario.

``impact-balance pose SCENARIO --place FRAME X Y Z [--normal NX NY NZ] [--com X Y] --out FILE``:

- ``--place FRAME X Y Z`` puts a point at world (X, Y, Z), m: the centre of the contact on
  FRAME if the scenario has one (its offset applied), else FRAME's origin.
- ``--normal NX NY NZ`` (after a ``--place``) also turns it so that the contact's normal
  (or the frame's z axis) points along N, by the smallest rotation from where it is now;
  without it the orientation is kept.
- Every other contact stays where it is; ``--com X Y`` moves the CoM's horizontal position
  (kept free otherwise).
- A frame on a chain of fewer than 6 joints from the base (a quadruped's 3-joint leg) cannot
  hold an orientation: its position alone is placed or kept (a point foot). So is a point
  contact (``size: [0, 0]``) given by its world ``normal:``. ``--normal`` on such a frame's
  contact, or on any point contact, is the surface's normal, written as the contact's
  ``normal:``.
- A point foot on the ground (either kind) is written flat, ``normal: [0, 0, 1]``
  (:func:`flat_feet`).

The IK is :func:`impact_balance.robot.ik.solve_stance` (pink, as the GUI's drags), started from the
scenario's stance and pulled towards it. The result is the scenario with an explicit ``base``
and the joints that differ from its reference configuration; a contact given by its world
normal gets the new normal.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import yaml

from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.spatial import aligning_rotation, unit
from impact_balance.robot.ik import IKOptions, chain_dofs, solve_stance, stance_residuals
from impact_balance.scenario import Scenario

__all__ = [
    "DIGITS",
    "GROUND_BAND",
    "Placement",
    "PoseResult",
    "flat_feet",
    "pose_scenario",
    "posed_mapping",
    "scenario_yaml",
]

#: Decimals kept in the written base pose and joint values (1e-6 m, 1e-6 rad).
DIGITS = 6

#: A point foot whose contact centre lies within this height (m) of the lowest contact's is
#: on the ground, and written flat (``normal: [0, 0, 1]``) by :func:`posed_mapping`.
GROUND_BAND = 0.01


@dataclass(frozen=True)
class Placement:
    """Where to put one frame (see the module docstring).

    Attributes:
        frame: Frame name.
        position: World target of the contact centre (or frame origin), m.
        normal: World direction of the contact normal (or frame z axis), or None to keep it.
    """

    frame: str
    position: tuple[float, float, float]
    normal: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class PoseResult:
    """A solved pose.

    Attributes:
        q: The configuration (nq).
        targets: World targets of the frames (placed and kept), by frame name.
        residuals: Errors at ``q`` (``FRAME.position`` m, ``FRAME.orientation`` rad, ``com_xy`` m).
        com: CoM at ``q``, world, m.
        contact_normals: New world normals of placed contacts given by their normal, by index.
        position_only: Frames whose orientation was left free (chains of fewer than 6 joints).
    """

    q: np.ndarray
    targets: dict[str, pin.SE3]
    residuals: dict[str, float]
    com: np.ndarray
    contact_normals: dict[int, tuple[float, float, float]] = field(default_factory=dict)
    position_only: tuple[str, ...] = ()


def pose_scenario(
    scenario: Scenario,
    placements: Sequence[Placement],
    com_xy: Sequence[float] | None = None,
    *,
    tolerance: float = 1e-6,
    max_iterations: int = 2000,
) -> PoseResult:
    """Solve the whole-body IK that meets ``placements`` (and ``com_xy``), other contacts kept.

    Args:
        scenario: The scenario whose stance is the start and the posture target.
        placements: Where to put frames (see the module docstring).
        com_xy: The CoM's horizontal target (m, world); None to leave it free.
        tolerance: The IK's convergence tolerance (m, rad).
        max_iterations: The IK's iteration budget.

    Returns:
        The solved configuration, its targets and residuals.

    Raises:
        ScenarioError: a frame is placed twice, a normal is zero.
        UnknownFrameError: a placed frame is not in the robot.
        IKError: the targets cannot be met (out of reach, joint limits).
    """
    stance = scenario.build_stance()
    robot = stance.robot
    targets: dict[str, pin.SE3] = {}
    normals: dict[int, tuple[float, float, float]] = {}
    for p in placements:
        robot.frame_id(p.frame, field="--place")
        if p.frame in targets:
            raise ScenarioError("--place", p.frame, "the frame is placed twice")
        index = next((i for i, c in enumerate(stance.contacts) if c.spec.frame == p.frame), None)
        if index is not None:
            contact = stance.contacts[index]
            current, offset = pin.SE3(contact.rotation, contact.position), contact.spec.offset
        else:
            current, offset = stance.frame_pose(p.frame), pin.SE3.Identity()
        rotation = current.rotation
        if p.normal is not None:
            try:
                n = unit(p.normal)
            except ValueError:
                raise ScenarioError(
                    "--normal", list(p.normal), "must be a non-zero vector"
                ) from None
            point_foot = index is not None and (
                chain_dofs(robot, p.frame) < 6 or stance.contacts[index].is_point
            )
            if not point_foot:
                rotation = aligning_rotation(rotation[:, 2], n) @ rotation
            if index is not None and (point_foot or scenario.contacts[index].normal is not None):
                # a point foot cannot turn: N is its surface's normal, written on its contact
                normals[index] = (float(n[0]), float(n[1]), float(n[2]))
        targets[p.frame] = pin.SE3(rotation, np.asarray(p.position, dtype=float)) * offset.inverse()
    contact_frames = {c.spec.frame for c in stance.contacts}
    kept = sorted(contact_frames - set(targets))
    all_targets = dict(targets)
    all_targets.update({f: stance.frame_pose(f) for f in kept})
    # A point contact given by its world normal has no orientation to hold: position only.
    points = {
        c.spec.frame
        for c, config in zip(stance.contacts, scenario.contacts, strict=True)
        if c.is_point and config.normal is not None
    }
    free = tuple(f for f in all_targets if chain_dofs(robot, f) < 6 or f in points)
    for p in placements:
        if p.normal is not None and p.frame in free and p.frame not in contact_frames:
            raise ScenarioError(
                "--normal",
                list(p.normal),
                f"{p.frame} is on a chain of {chain_dofs(robot, p.frame)} "
                "joints from the base: it cannot be turned, only placed",
            )
    q = solve_stance(
        robot,
        stance.q,
        all_targets,
        com_xy,
        position_only=free,
        posture_target=stance.q,
        options=IKOptions(tolerance=tolerance, max_iterations=max_iterations),
    )
    residuals = stance_residuals(robot, q, all_targets, com_xy, free)
    com = pin.centerOfMass(robot.model, robot.model.createData(), q)
    return PoseResult(q, all_targets, residuals, np.array(com), normals, free)


def _rounded(x: float) -> float:
    value = round(float(x), DIGITS)
    return 0.0 if value == 0 else value


def flat_feet(scenario: Scenario, result: PoseResult) -> dict[int, tuple[float, float, float]]:
    """The contacts to lay flat on the ground: ``{index: (0, 0, 1)}``.

    A contact is laid flat when its frame is on a chain of fewer than 6 joints (a point foot,
    ``result.position_only``: its frame's orientation is the leg's, not the ground's) or it is
    a point contact (``size: [0, 0]``), its
    orientation is not given (no ``normal``, no ``offset.rpy``) and its centre lies within
    :data:`GROUND_BAND` of the lowest contact centre at ``result.q``.
    """
    robot = scenario.load_robot()
    data = robot.model.createData()
    pin.framesForwardKinematics(robot.model, data, result.q)
    heights = [
        float(data.oMf[robot.frame_id(c.frame)].act(np.asarray(c.offset.position))[2])
        for c in scenario.contacts
    ]
    lowest = min(heights, default=0.0)
    return {
        i: (0.0, 0.0, 1.0)
        for i, c in enumerate(scenario.contacts)
        if (c.frame in result.position_only or all(x == 0 for x in c.size))
        and c.normal is None
        and not any(c.offset.rpy)
        and heights[i] <= lowest + GROUND_BAND
    }


def posed_mapping(
    raw: Mapping[str, Any],
    scenario: Scenario,
    result: PoseResult,
    out_dir: str | Path | None = None,
    *,
    flat: bool = True,
) -> dict[str, Any]:
    """The scenario mapping ``raw`` (as read, ``extends`` merged) with the posed base and joints.

    Joint values are rounded to 1e-6 rad and kept within their limits; robot file paths are
    rewritten relative to ``out_dir`` (the written file's folder). With ``flat``, the point
    feet on the ground are written with ``normal: [0, 0, 1]`` (:func:`flat_feet`): the
    ground's normal, not their frame's tilted z axis.
    """
    robot = scenario.load_robot()
    out: dict[str, Any] = {}
    for key, value in dict(
        raw
    ).items():  # base and joints right after the configuration, as in bundled files
        if key in ("base", "joints", "name"):
            continue
        out[key] = value
        if key == "configuration" or (key == "robot" and "configuration" not in raw):
            out["base"], out["joints"] = None, None
    q = result.q
    rpy = pin.rpy.matrixToRpy(pin.Quaternion(np.asarray(q[3:7])).normalized().matrix())
    out["base"] = {"position": [_rounded(v) for v in q[:3]], "rpy": [_rounded(v) for v in rpy]}
    reference = robot.joint_values(robot.configuration(scenario.configuration))
    joints = {}
    for name, value in robot.joint_values(q).items():
        slot = robot.joint_slot(name)
        if (
            slot.nq == 1
            and np.isfinite(slot.lower)
            and np.isfinite(slot.upper)
            and slot.lower < slot.upper
        ):
            value = min(max(value, slot.lower), slot.upper)
        if abs(value - reference[name]) > 0.5 * 10.0**-DIGITS:
            rounded = _rounded(value)
            if slot.nq == 1 and slot.lower < slot.upper and not slot.lower <= rounded <= slot.upper:
                rounded = value  # rounding would leave the limits
            joints[name] = rounded
    out["joints"] = joints
    normals = {**(flat_feet(scenario, result) if flat else {}), **result.contact_normals}
    if normals:
        contacts = [dict(c) for c in out["contacts"]]
        for i, n in normals.items():
            contacts[i]["normal"] = [_rounded(v) for v in n]
        out["contacts"] = contacts
    robot_entry = out.get("robot")
    if isinstance(robot_entry, Mapping) and scenario.source:
        source_dir = Path(scenario.source).parent
        entry = dict(robot_entry)
        for key in ("urdf", "srdf"):
            if entry.get(key):
                path = (source_dir / entry[key]).resolve()
                entry[key] = (
                    os.path.relpath(path, Path(out_dir).resolve())
                    if out_dir is not None
                    else str(path)
                )
        out["robot"] = entry
    return out


class _Dumper(yaml.SafeDumper):  # type: ignore[misc]
    """YAML as the bundled scenarios are written: mappings in block style, vectors on one line."""


_Dumper.add_representer(
    list,
    lambda dumper, data: dumper.represent_sequence(
        "tag:yaml.org,2002:seq", data, flow_style=all(not isinstance(x, (dict, list)) for x in data)
    ),
)
_Dumper.add_representer(
    tuple, lambda dumper, data: _Dumper.yaml_representers[list](dumper, list(data))
)


def scenario_yaml(mapping: Mapping[str, Any], header: str = "") -> str:
    """A scenario mapping as YAML text (block mappings, one-line vectors).

    Args:
        mapping: The scenario, as :func:`posed_mapping` gives it.
        header: Text written first, each line as a comment.

    Returns:
        The YAML text.
    """
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    text: str = yaml.dump(
        dict(mapping), Dumper=_Dumper, sort_keys=False, width=100, allow_unicode=True
    )
    return comment + text
