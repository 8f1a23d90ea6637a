"""Library objects built from scenario values, cached by content.

The schema's models hand out :class:`~impact_balance.contacts.stance.ContactSpec`,
:class:`~impact_balance.impact.model.ImpactSpec` and base quaternions through these functions.
"""

from __future__ import annotations

import functools

import numpy as np
import pinocchio as pin

from impact_balance.contacts.stance import ContactSpec
from impact_balance.geometry.spatial import pose
from impact_balance.impact.model import ImpactSpec
from impact_balance.scenario.fields import Vec2, Vec3

__all__: list[str] = []


# Specs are cached by content, not on the models (pydantic's model_copy would carry a cached
# value over to an updated copy): a scenario is analysed again and again, and building the
# offset SE3 through pinocchio costs more than the rest of the model update's bookkeeping.
@functools.lru_cache(maxsize=256)
def _contact_spec(
    frame: str, friction: float, size: Vec2, position: Vec3, rpy: Vec3
) -> ContactSpec:
    return ContactSpec(frame, friction, size, pose(position, rpy))


@functools.lru_cache(maxsize=64)
def _impact_spec(
    frame: str,
    normal: Vec3,
    friction: float,
    restitution: Vec2,
    cone_edges: int,
    reference_velocity: Vec3 | None,
    duration: float,
    position: Vec3,
    rpy: Vec3,
    inertia: str,
) -> ImpactSpec:
    return ImpactSpec(
        frame=frame,
        normal=normal,
        friction=friction,
        restitution=restitution,
        cone_edges=cone_edges,
        reference_velocity=reference_velocity,
        duration=duration,
        offset=pose(position, rpy),
        inertia=inertia,
    )


@functools.lru_cache(maxsize=256)
def _quaternion(rpy: Vec3) -> np.ndarray:
    """Quaternion coefficients (x, y, z, w) of roll-pitch-yaw angles (rad), read-only."""
    coeffs = np.array(pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs(), dtype=float)
    coeffs.setflags(write=False)
    return coeffs
