"""Joints grouped by limb, for the GUI's sliders.

A limb is a chain of the kinematic tree: it starts at a child of the floating base or at a
branching joint (a joint with several child joints) and follows single children. Its label
comes from the joint names ("left leg", "torso"...), so that any URDF gets sensible groups.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.robot.robot import Robot

__all__ = ["JointSlider", "joint_groups", "joint_values"]

_KINDS = (
    ("leg", ("leg", "hip", "knee", "ankle", "foot", "toe")),
    ("hand", ("hand", "finger", "thumb")),
    ("arm", ("arm", "shoulder", "elbow", "wrist", "gripper")),
    ("head", ("head", "neck")),
    ("torso", ("torso", "waist", "chest", "trunk", "spine", "back")),
)


@dataclass(frozen=True)
class JointSlider:
    """One 1-dof joint as a slider.

    Attributes:
        name: Joint name.
        lower: Lower end of the range, rad (the URDF limit; -pi for continuous or unlimited
            joints).
        upper: Upper end of the range, rad (+pi for continuous or unlimited joints).
    """

    name: str
    lower: float
    upper: float


def _side(name: str) -> str | None:
    words = re.split(r"[_\W\d]+", name.lower())
    for side in ("left", "right"):
        # left_hip, hip_left, l_hip, LHipYaw (CamelCase with a one-letter prefix)
        if side in words or words[0] == side[0] or re.match(rf"{side[0].upper()}[A-Z]", name):
            return side
    return None


def _kind(name: str) -> str | None:
    low = name.lower()
    for kind, words in _KINDS:
        if any(w in low for w in words):
            return kind
    return None


def _common_prefix(names: list[str]) -> str:
    """The longest string every name starts with (character by character)."""
    if not names:
        return ""
    first, last = min(names), max(names)
    n = 0
    while n < min(len(first), len(last)) and first[n] == last[n]:
        n += 1
    return first[:n]


def _label(names: list[str]) -> str:
    sides = {_side(n) for n in names} - {None}
    kinds = [_kind(n) for n in names]
    known = [k for k in kinds if k is not None]
    if known:
        kind = max(set(known), key=known.count)
        side = next(iter(sides)) if len(sides) == 1 else None
        return f"{side} {kind}" if side else kind
    prefix = _common_prefix(names).rstrip("_0123456789")
    return prefix if len(prefix) >= 3 else re.sub(r"(_joint)?$", "", names[0])


def _range(model: pin.Model, joint: pin.JointModel) -> tuple[float, float]:
    if joint.nq == 1:
        lo = float(model.lowerPositionLimit[joint.idx_q])
        hi = float(model.upperPositionLimit[joint.idx_q])
        if math.isfinite(lo) and math.isfinite(hi) and lo < hi:
            return lo, hi
    return -math.pi, math.pi


def joint_groups(robot: Robot) -> dict[str, list[JointSlider]]:
    """The robot's 1-dof joints grouped by limb, in model order: ``{label: sliders}``.

    Chains that get the same label (the fingers of one hand) are merged.
    """
    model = robot.model
    children: dict[int, list[int]] = {}
    for jid in range(2, model.njoints):
        children.setdefault(model.parents[jid], []).append(jid)
    group_of: dict[int, int] = {}
    groups: list[list[int]] = []
    for jid in range(2, model.njoints):  # parents come before children in pinocchio
        parent = model.parents[jid]
        if parent <= 1 or len(children.get(parent, [])) > 1 or parent not in group_of:
            group_of[jid] = len(groups)
            groups.append([jid])
        else:
            group_of[jid] = group_of[parent]
            groups[group_of[parent]].append(jid)
    out: dict[str, list[JointSlider]] = {}
    for members in groups:
        sliders = []
        for jid in members:
            joint = model.joints[jid]
            if joint.nv != 1:  # spherical and other multi-dof joints have no single value
                continue
            sliders.append(JointSlider(model.names[jid], *_range(model, joint)))
        if not sliders:
            continue
        out.setdefault(_label([s.name for s in sliders]), []).extend(sliders)
    return out


def joint_values(robot: Robot, q: npt.ArrayLike) -> dict[str, float]:
    """Values of the 1-dof joints at configuration ``q``, rad (continuous joints by their angle).

    Args:
        robot: The robot.
        q: Its configuration (nq), as pinocchio orders it.

    Returns:
        The value of each 1-dof joint, by joint name.
    """
    return robot.joint_values(np.asarray(q, dtype=float))
