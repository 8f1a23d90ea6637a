"""Collision geometry that means what the scenario means, and the environment it touches.

On the robot (attached to the body of the frame's parent joint, placed at the stance):
- one box per contact rectangle: its face on the contact plane, its size the rectangle's,
  its thickness inside the robot, with the contact's friction;
- one sphere per point contact (size ``[0, 0]``): its surface touches the contact point, its
  centre ``point_radius`` inside the robot along the contact normal (a ball foot: it rolls
  without moving the point it touches by more than its radius times the roll);
- a small sphere at the impact point: its surface touches the impact point, its centre is
  ``radius`` inside the robot along the impact normal, with the impact's friction.

In the world:
- the ground, a plane through the lowest horizontal contact (z = 0 for the bundled ones);
- under every contact that does not lie on the ground (a foot on a ramp, a hand on a wall,
  a foot on a step), a block whose face is the contact plane (its normal the contact's);
- the impacted surface: a block whose face passes through the impact point with the impact
  normal.

Only the pairs the scenario means collide, declared as explicit MuJoCo contact pairs (every
geom has ``contype = conaffinity = 0``): each contact box with its own support (and with the
ground, should a foot on a ramp slip down to it), the impact sphere with the impacted
surface. A pair carries its contact's friction (sliding only, ``condim`` 3) and solver
parameters. Explicit pairs keep a support block from catching a neighbouring foot.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
import pinocchio as pin

from impact_balance.contacts.stance import Contact, Stance
from impact_balance.impact.model import ImpactSpec, cone_tangents

__all__ = ["CONTACT_GROUP", "ENVIRONMENT_GROUP", "ContactParameters", "Geometry", "add_geometry"]

#: Geom group of the contact geometry (robot side) and of the environment.
CONTACT_GROUP = 3
ENVIRONMENT_GROUP = 0

_HORIZONTAL = np.cos(
    np.radians(1.0)
)  # a contact within 1 degree of horizontal may rest on the ground


@dataclass(frozen=True)
class ContactParameters:
    """Geometry and MuJoCo contact parameters.

    Attributes:
        box_half_thickness: Half thickness of a sustained-contact box, m.
        impact_radius: Radius of the impact sphere, m.
        point_radius: Radius of a point contact's sphere, m.
        support_margin: How far a support block extends beyond its contact rectangle, m.
        contact_solref: ``(timeconst s, dampratio)`` of the sustained contacts.
        impact_solref: ``(timeconst s, dampratio)`` of the impact. A damping ratio >= 2 keeps
            MuJoCo's soft contact from bouncing (its restitution cannot be set directly).
        solimp: MuJoCo impedance of every contact (``solimp`` 5-vector).
    """

    box_half_thickness: float = 0.01
    impact_radius: float = 0.01
    point_radius: float = 0.01
    support_margin: float = 0.1
    contact_solref: tuple[float, float] = (0.01, 1.0)
    impact_solref: tuple[float, float] = (0.004, 2.0)
    solimp: tuple[float, float, float, float, float] = (0.95, 0.99, 0.001, 0.5, 2.0)


@dataclass(frozen=True)
class Geometry:
    """Names of the geoms :func:`add_geometry` made (ids are looked up after compiling).

    Attributes:
        contacts: Robot box of each scenario contact, in scenario order.
        supports: Environment geom under each contact (the ground's name when on the ground).
        ground: The ground plane.
        impact: The impact sphere, or None without an impact.
        surface: The impacted surface, or None without an impact.
    """

    contacts: tuple[str, ...]
    supports: tuple[str, ...]
    ground: str
    impact: str | None
    surface: str | None


def _quat(rotation: np.ndarray) -> np.ndarray:
    """MuJoCo quaternion (w, x, y, z) of a rotation matrix."""
    q = np.empty(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(rotation, dtype=float).ravel())
    return q


def _in_joint(stance: Stance, joint_id: int, world: pin.SE3) -> pin.SE3:
    """``world`` pose expressed in the frame of pinocchio joint ``joint_id`` at the stance."""
    return stance.data.oMi[joint_id].actInv(world)


def _pair(
    spec: mujoco.MjSpec,
    robot_geom: str,
    world_geom: str,
    mu: float,
    solref: tuple[float, float],
    params: ContactParameters,
) -> None:
    spec.add_pair(
        name=f"{robot_geom}-{world_geom}",
        geomname1=world_geom,
        geomname2=robot_geom,
        condim=3,
        friction=[mu, mu, 0.0, 0.0, 0.0],
        solref=list(solref),
        solimp=list(params.solimp),
    )


def add_geometry(
    spec: mujoco.MjSpec,
    stance: Stance,
    bodies: dict[int, mujoco.MjsBody],
    impact: ImpactSpec | None,
    params: ContactParameters,
) -> Geometry:
    """Add the contact boxes, the impact sphere and the environment to ``spec``.

    Args:
        spec: The robot's specification (see :func:`.urdf.robot_spec`).
        stance: The scenario's stance (contacts resolved in world).
        bodies: MuJoCo body of each pinocchio joint id (1 = the root).
        impact: The scenario's :class:`impact_balance.impact.model.ImpactSpec`, or None.
        params: Sizes and contact parameters.

    Returns:
        The names of the geoms added.
    """
    ground, ground_z = _add_ground(spec, stance)
    contacts, supports = [], []
    for i, contact in enumerate(stance.contacts):
        name, support = _add_contact(spec, stance, bodies, i, contact, ground, ground_z, params)
        contacts.append(name)
        supports.append(support)
    impact_name = surface_name = None
    if impact is not None:
        impact_name, surface_name = _add_impact(spec, stance, bodies, impact, params)
    return Geometry(tuple(contacts), tuple(supports), ground, impact_name, surface_name)


def _add_ground(spec: mujoco.MjSpec, stance: Stance) -> tuple[str, float]:
    """The ground plane: its name and height (m).

    The ground plane, through the lowest horizontal contact (or the lowest contact corner if none
    is); its name and height (m).
    """
    horizontal = [c for c in stance.contacts if c.normal[2] > _HORIZONTAL]
    heights = [c.position[2] for c in horizontal] or [stance.lowest_contact_height()]
    ground_z = float(min(heights)) if heights and np.isfinite(min(heights)) else 0.0
    ground = "ground"
    spec.worldbody.add_geom(
        name=ground,
        type=mujoco.mjtGeom.mjGEOM_PLANE,
        size=[0.0, 0.0, 1.0],
        pos=[0.0, 0.0, ground_z],
        contype=0,
        conaffinity=0,
        group=ENVIRONMENT_GROUP,
        rgba=[0.6, 0.6, 0.6, 1.0],
    )
    return ground, ground_z


def _add_contact(
    spec: mujoco.MjSpec,
    stance: Stance,
    bodies: dict[int, mujoco.MjsBody],
    i: int,
    contact: Contact,
    ground: str,
    ground_z: float,
    params: ContactParameters,
) -> tuple[str, str]:
    """The robot box of contact ``i`` and what supports it: their names.

    The support is the ground, or a block of its own.
    """
    spec_i = contact.spec
    frame = stance.model.frames[stance.robot.frame_id(spec_i.frame)]
    joint_pose = frame.placement * spec_i.offset  # contact in its parent joint's frame
    if contact.is_point:  # a ball foot touching the contact point
        t = params.point_radius
        shape, size = mujoco.mjtGeom.mjGEOM_SPHERE, [t, 0.0, 0.0]
    else:
        t = params.box_half_thickness
        shape, size = mujoco.mjtGeom.mjGEOM_BOX, [contact.half_length, contact.half_width, t]
    box = pin.SE3(joint_pose.rotation, joint_pose.act(np.array([0.0, 0.0, t])))
    name = f"contact_{i}"
    bodies[frame.parentJoint].add_geom(
        name=name,
        type=shape,
        size=size,
        pos=box.translation,
        quat=_quat(box.rotation),
        contype=0,
        conaffinity=0,
        condim=3,
        friction=[spec_i.friction, 0.0, 0.0],
        solref=list(params.contact_solref),
        solimp=list(params.solimp),
        group=CONTACT_GROUP,
        rgba=[0.1, 0.6, 0.1, 0.8],
    )
    _pair(spec, name, ground, spec_i.friction, params.contact_solref, params)
    on_ground = contact.normal[2] > _HORIZONTAL and abs(contact.position[2] - ground_z) < 1e-3
    if on_ground:
        return name, ground
    # A block whose face is the contact plane: centred half a thickness behind it.
    depth = 0.05
    centre = contact.position - depth * contact.normal
    support = f"support_{i}"
    spec.worldbody.add_geom(
        name=support,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[
            contact.half_length + params.support_margin,
            contact.half_width + params.support_margin,
            depth,
        ],
        pos=centre,
        quat=_quat(contact.rotation),
        contype=0,
        conaffinity=0,
        group=ENVIRONMENT_GROUP,
        rgba=[0.55, 0.5, 0.45, 1.0],
    )
    _pair(spec, name, support, spec_i.friction, params.contact_solref, params)
    return name, support


def _add_impact(
    spec: mujoco.MjSpec,
    stance: Stance,
    bodies: dict[int, mujoco.MjsBody],
    impact: ImpactSpec,
    params: ContactParameters,
) -> tuple[str, str]:
    """The impact sphere on the robot and the impacted surface; their names."""
    frame = stance.model.frames[stance.robot.frame_id(impact.frame, "impact.frame")]
    point = stance.point(impact.frame, impact.offset, field="impact.frame")[0].translation
    n = np.asarray(impact.normal, dtype=float) / np.linalg.norm(impact.normal)
    r = params.impact_radius
    centre = _in_joint(stance, frame.parentJoint, pin.SE3(np.eye(3), point + r * n)).translation
    impact_name = "impact"
    bodies[frame.parentJoint].add_geom(
        name=impact_name,
        type=mujoco.mjtGeom.mjGEOM_SPHERE,
        size=[r, 0.0, 0.0],
        pos=centre,
        contype=0,
        conaffinity=0,
        condim=3,
        friction=[impact.friction, 0.0, 0.0],
        solref=list(params.impact_solref),
        solimp=list(params.solimp),
        group=CONTACT_GROUP,
        rgba=[0.9, 0.1, 0.1, 1.0],
    )
    t1, t2 = cone_tangents(n)
    depth = 0.05
    surface_name = "impact_surface"
    spec.worldbody.add_geom(
        name=surface_name,
        type=mujoco.mjtGeom.mjGEOM_BOX,
        size=[0.25, 0.25, depth],
        pos=point - depth * n,
        quat=_quat(np.column_stack([t1, t2, n])),
        contype=0,
        conaffinity=0,
        group=ENVIRONMENT_GROUP,
        rgba=[0.7, 0.45, 0.3, 0.6],
    )
    _pair(spec, impact_name, surface_name, impact.friction, params.impact_solref, params)
    return impact_name, surface_name
