"""Stance authoring without code: where every frame is, and whole-body IK that writes scenarios.

- :mod:`.frames`: each frame's world position and axes at a configuration
  (``impact-balance frames``).
- :mod:`.pose`: place frames (and the CoM) by whole-body IK with the contacts kept, and the
  posed scenario as a YAML mapping (``impact-balance pose``).
"""

from impact_balance.authoring.frames import FramePose, contact_poses, frame_poses
from impact_balance.authoring.pose import (
    Placement,
    PoseResult,
    pose_scenario,
    posed_mapping,
    scenario_yaml,
)

__all__ = [
    "FramePose",
    "Placement",
    "PoseResult",
    "contact_poses",
    "frame_poses",
    "pose_scenario",
    "posed_mapping",
    "scenario_yaml",
]
