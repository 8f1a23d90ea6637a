"""A stance: a robot at a configuration with its sustained contacts, all in world frame.

This is the model-update step of the pipeline (kinematics, Jacobians, gravity torques,
composite-rigid-body inertia), computed once with pinocchio and then read by the
constraint, area and impact steps.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from .robot import Robot
from .spatial import skew

__all__ = ["ContactSpec", "Contact", "Stance"]


@dataclass(frozen=True)
class ContactSpec:
    """A rectangular sustained contact on a robot frame.

    Attributes:
        frame: Robot frame name; its z axis (after ``offset``) is the surface normal,
            pointing from the environment into the robot.
        friction: Coulomb friction coefficient mu (> 0).
        size: Full length (local x) and width (local y) of the rectangle, m.
        offset: Fixed pose of the contact in the frame.
    """

    frame: str
    friction: float
    size: tuple[float, float]
    offset: pin.SE3 = field(default_factory=pin.SE3.Identity)


@dataclass(frozen=True)
class Contact:
    """A contact resolved at a configuration.

    Attributes:
        spec: The contact's specification.
        rotation: Contact-to-world rotation (3 x 3).
        position: Contact centre in world, m.
        jacobian: 6 x nv Jacobian of the contact point in world-aligned axes
            (linear rows first), so that ``jacobian.T @ [f; tau]`` is the generalized force.
    """

    spec: ContactSpec
    rotation: np.ndarray
    position: np.ndarray
    jacobian: np.ndarray

    @property
    def half_length(self) -> float:
        return 0.5 * float(self.spec.size[0])

    @property
    def half_width(self) -> float:
        return 0.5 * float(self.spec.size[1])

    @property
    def normal(self) -> np.ndarray:
        """Surface normal in world (contact z axis)."""
        return self.rotation[:, 2]

    def corners(self) -> np.ndarray:
        """The 4 rectangle corners in world (4 x 3), counter-clockwise in the contact plane."""
        X, Y = self.half_length, self.half_width
        local = np.array([[X, Y, 0], [-X, Y, 0], [-X, -Y, 0], [X, -Y, 0]], dtype=float)
        return self.position + local @ self.rotation.T


class Stance:
    """Robot configuration + contacts, with everything the criteria need from the model.

    Attributes:
        robot: The robot.
        q: Configuration (nq).
        contacts: The sustained contacts, resolved.
        com: Centre of mass in world, m.
        mass: Total mass, kg.
        gravity_torques: Generalized gravity vector g(q) (nv), N and N m.
        com_inertia: Composite rotational inertia about the CoM, world axes, kg m^2.
    """

    def __init__(self, robot: Robot, q: np.ndarray, contacts: Sequence[ContactSpec] = ()):
        model = robot.model
        self.robot = robot
        self.q = np.asarray(q, dtype=float).copy()
        self.data = model.createData()
        data = self.data
        v0 = np.zeros(model.nv)
        pin.computeJointJacobians(model, data, self.q)
        pin.updateFramePlacements(model, data)
        pin.ccrba(model, data, self.q, v0)  # data.Ig: centroidal composite inertia, world axes
        self.com = np.array(pin.centerOfMass(model, data, self.q, False), dtype=float)
        self.mass = float(data.Ig.mass)
        self.com_inertia = np.array(data.Ig.inertia, dtype=float)
        self.gravity_torques = np.array(pin.computeGeneralizedGravity(model, data, self.q), dtype=float)
        self.contacts: list[Contact] = [self._resolve(spec, i) for i, spec in enumerate(contacts)]

    @property
    def model(self) -> pin.Model:
        return self.robot.model

    def _resolve(self, spec: ContactSpec, index: int) -> Contact:
        placement, jacobian = self.point(spec.frame, spec.offset, field=f"contacts[{index}].frame")
        return Contact(spec, placement.rotation.copy(), placement.translation.copy(), jacobian)

    def point(self, frame: str, offset: pin.SE3 | None = None, field: str = "frame") -> tuple[pin.SE3, np.ndarray]:
        """World pose of ``frame * offset`` and its 6 x nv world-aligned Jacobian (linear first)."""
        fid = self.robot.frame_id(frame, field)
        offset = pin.SE3.Identity() if offset is None else offset
        placement = self.data.oMf[fid] * offset
        J = pin.getFrameJacobian(self.model, self.data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED).copy()
        # Shift the reference point from the frame origin to the offset point: v_p = v_o + w x r.
        r = placement.translation - self.data.oMf[fid].translation
        J[:3] -= skew(r) @ J[3:]
        return placement, J

    def frame_pose(self, frame: str) -> pin.SE3:
        """World pose of a frame (a copy)."""
        return pin.SE3(self.data.oMf[self.robot.frame_id(frame)])

    def lowest_contact_height(self) -> float:
        """Lowest z of any contact corner, m (nan without contacts)."""
        if not self.contacts:
            return float("nan")
        return float(min(c.corners()[:, 2].min() for c in self.contacts))

