"""Every frame's world pose at a configuration, for writing contacts by hand.

A contact's normal is its frame's z axis (after the offset), so a user choosing a frame and an
offset needs to see where each frame's axes point at the stance: ``impact-balance frames``
prints this table.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.contacts.stance import Stance
from impact_balance.robot.robot import Robot

__all__ = ["FramePose", "contact_poses", "frame_poses"]


@dataclass(frozen=True)
class FramePose:
    """One frame at a configuration.

    Attributes:
        name: Frame name; kind: pinocchio's frame type (BODY, JOINT, FIXED_JOINT, OP_FRAME...).
        parent_joint: Name of the joint that moves it.
        position: Origin in world, m.
        rotation: Frame-to-world rotation; its columns are the frame's x, y, z axes in world.
    """

    name: str
    kind: str
    parent_joint: str
    position: npt.NDArray[np.float64]
    rotation: npt.NDArray[np.float64]

    @property
    def rpy(self) -> npt.NDArray[np.float64]:
        """Roll, pitch, yaw of ``rotation``, rad (R = Rz(y) Ry(p) Rx(r))."""
        rpy: npt.NDArray[np.float64] = pin.rpy.matrixToRpy(self.rotation)
        return rpy

    @property
    def tilt(self) -> float:
        """Angle of the z axis from the world vertical, degrees (0: z up)."""
        return float(np.degrees(np.arccos(np.clip(self.rotation[2, 2], -1.0, 1.0))))

    def to_dict(self) -> dict[str, Any]:
        """The frame as JSON values: position (m), axes in world, rpy (rad), z tilt (deg)."""
        R = self.rotation
        return {
            "name": self.name,
            "type": self.kind,
            "parent_joint": self.parent_joint,
            "position": self.position.tolist(),
            "axes": {"x": R[:, 0].tolist(), "y": R[:, 1].tolist(), "z": R[:, 2].tolist()},
            "rpy": self.rpy.tolist(),
            "z_tilt_deg": self.tilt,
        }


def frame_poses(robot: Robot, q: npt.ArrayLike, names: list[str] | None = None) -> list[FramePose]:
    """World poses of the frames ``names`` (default: all, in model order) at configuration ``q``.

    Args:
        robot: The robot.
        q: Its configuration (nq, pinocchio's convention).
        names: Frame names; None for every frame.

    Returns:
        One pose per frame, in the order of ``names`` (or the model's).

    Raises:
        UnknownFrameError: a name is not a frame of the robot (with the closest names).
    """
    model = robot.model
    ids = [robot.frame_id(n, field="--frame") for n in names] if names else range(len(model.frames))
    data = model.createData()
    pin.framesForwardKinematics(model, data, np.asarray(q, dtype=float))
    out = []
    for fid in ids:
        frame = model.frames[fid]
        placement = data.oMf[fid]
        out.append(
            FramePose(
                frame.name,
                str(frame.type).rsplit(".", 1)[-1],
                model.names[frame.parentJoint],
                np.array(placement.translation),
                np.array(placement.rotation),
            )
        )
    return out


def contact_poses(stance: Stance) -> list[dict[str, Any]]:
    """Each contact of a stance: frame, centre (m), normal and x axis in world, tilt (deg)."""
    out = []
    for c in stance.contacts:
        tilt = float(np.degrees(np.arccos(np.clip(c.normal[2], -1.0, 1.0))))
        out.append(
            {
                "frame": c.spec.frame,
                "centre": c.position.tolist(),
                "normal": c.normal.tolist(),
                "x_axis": c.rotation[:, 0].tolist(),
                "size": list(c.spec.size),
                "normal_tilt_deg": tilt,
            }
        )
    return out
