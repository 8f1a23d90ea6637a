"""A stance: a robot at a configuration with its sustained contacts, all in world frame.

This is the model-update step of the pipeline (kinematics, Jacobians, gravity torques,
composite-rigid-body inertia), computed once with pinocchio and then read by the
constraint, area and impact steps.
"""

from __future__ import annotations

import functools
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import UnknownFrameError
from impact_balance.geometry.spatial import skew
from impact_balance.robot.robot import Robot, Scratch

__all__ = [
    "Contact",
    "ContactSpec",
    "Stance",
    "frame_point",
    "has_free_flyer",
]

_IDENTITY = pin.SE3.Identity()
_POSITION = pin.KinematicLevel.POSITION
_WORLD = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@functools.lru_cache(maxsize=16)
def _zero_velocity(nv: int) -> np.ndarray:
    """A read-only zero velocity (nv,): ccrba's, which it only reads."""
    zero = np.zeros(nv)
    zero.setflags(write=False)
    return zero


#: :func:`has_free_flyer`'s answers by model (``id``): the model (weakly) and its joint count
#: when answered, and the answer.
_FREE_FLYER: dict[int, tuple[weakref.ref[pin.Model], int, bool]] = {}


def has_free_flyer(model: pin.Model) -> bool:
    """Whether the model's first joint is a free flyer (then q[:3] is the base position).

    Answered once per model (and joint count): every stance asks it.
    """
    entry = _FREE_FLYER.get(id(model))
    njoints = model.njoints
    if entry is not None and entry[0]() is model and entry[1] == njoints:
        return entry[2]
    answer = bool(njoints > 1 and model.joints[1].shortname() == "JointModelFreeFlyer")
    if len(_FREE_FLYER) >= 64:
        _FREE_FLYER.clear()
    _FREE_FLYER[id(model)] = (weakref.ref(model), njoints, answer)
    return answer


def frame_point(
    model: pin.Model, data: pin.Data, fid: int, offset: pin.SE3 | None, jacobian: bool = True
) -> tuple[pin.SE3, np.ndarray | None]:
    """Pose of frame ``fid`` times ``offset`` and its 6 x nv Jacobian in world-aligned axes.

    The Jacobian has its linear rows first, at the offset point; ``data`` holds the joint
    placements and joint Jacobians (in the frame of those placements); the Jacobian is skipped
    (None) without ``jacobian``. The pose may be ``data``'s own: copy what you keep.
    """
    frame_pose = pin.updateFramePlacement(model, data, fid)
    J = pin.getFrameJacobian(model, data, fid, _WORLD) if jacobian else None
    if offset is None or offset == _IDENTITY:  # exact test: contacts mostly have no offset
        return frame_pose, J
    placement = frame_pose * offset
    if J is not None:
        # Shift the reference point from the frame origin to the offset point: v_p = v_o + w x r.
        J[:3] -= skew(placement.translation - frame_pose.translation) @ J[3:]
    return placement, J


@dataclass(frozen=True)
class ContactSpec:
    """A rectangular sustained contact on a robot frame, or a point contact.

    A contact of size ``(0, 0)`` is a *point* (a point foot): its wrench cone is the friction
    cone of a force at the point, with no torque (the rectangle's centre-of-pressure and yaw
    rows with zero half sizes, :func:`impact_balance.contacts.cwc.cwc_faces`).

    Attributes:
        frame: Robot frame name; its z axis (after ``offset``) is the surface normal,
            pointing from the environment into the robot.
        friction: Coulomb friction coefficient mu (> 0).
        size: Full length (local x) and width (local y) of the rectangle, m; ``(0, 0)`` for
            a point.
        offset: Fixed pose of the contact in the frame.
    """

    frame: str
    friction: float
    size: tuple[float, float]
    offset: pin.SE3 = field(default_factory=pin.SE3.Identity)

    @property
    def is_point(self) -> bool:
        """Whether the contact is a point (size ``(0, 0)``): a force, no torque."""
        return float(self.size[0]) == 0.0 and float(self.size[1]) == 0.0


@dataclass(frozen=True)
class Contact:
    """A contact resolved at a configuration.

    Attributes:
        spec: The contact's specification.
        rotation: Contact-to-world rotation (3 x 3).
        position: Contact centre in world, m.
        jacobian: 6 x nv Jacobian of the contact point in world-aligned axes
            (linear rows first), so that ``jacobian.T @ [f; tau]`` is the generalized force.
        local_position: Contact centre in the stance frame (world axes, origin at the
            stance's ``origin``), m; None for contacts built without a stance (then
            ``position`` is used).
    """

    spec: ContactSpec
    rotation: np.ndarray
    position: np.ndarray
    jacobian: np.ndarray
    local_position: np.ndarray | None = None

    @property
    def half_length(self) -> float:
        """Half the rectangle's length (contact x axis), m."""
        return 0.5 * float(self.spec.size[0])

    @property
    def half_width(self) -> float:
        """Half the rectangle's width (contact y axis), m."""
        return 0.5 * float(self.spec.size[1])

    @property
    def is_point(self) -> bool:
        """Whether the contact is a point (:attr:`ContactSpec.is_point`)."""
        return self.spec.is_point

    @property
    def normal(self) -> np.ndarray:
        """Surface normal in world (contact z axis)."""
        return self.rotation[:, 2]

    def corners(self) -> np.ndarray:
        """The 4 rectangle corners in world (4 x 3), counter-clockwise in the contact plane.

        A point contact's 4 corners are its centre.
        """
        X, Y = self.half_length, self.half_width
        local = np.array([[X, Y, 0], [-X, Y, 0], [-X, -Y, 0], [X, -Y, 0]], dtype=float)
        out: npt.NDArray[np.float64] = self.position + local @ self.rotation.T
        return out


class Stance:
    """Robot configuration + contacts, with everything the criteria need from the model.

    The kinematics are computed in the robot's per-thread scratch Data (see
    :class:`impact_balance.robot.robot.ThreadData`), or in ``workspace`` when given (a
    :class:`impact_balance.robot.robot.Scratch` of the caller's, e.g. a governor's own Data), and
    every attribute is a copy, so stances of the same robot never alias. :meth:`point`
    recomputes the joint placements and Jacobians when another stance has used the
    scratch Data since.

    Precision far from the origin: the kinematics are computed with the free-flyer's
    translation set to zero, in the *stance frame* (world axes, origin at ``origin``, the
    base position of ``q``), and world positions are that plus ``origin``. The constraint and
    impact steps use differences of stance-frame positions (contact or impact point minus
    CoM), which do not depend on where the robot stands: translating the whole stance by
    1e6 m changes no area and no maximum (at 1e15 m a double's spacing is 0.125 m, and world
    coordinates would lose the lever arms).

    Attributes:
        robot: The robot.
        q: Configuration (nq); read-only in spirit: everything below was computed from it.
        origin: The stance frame's origin in world (the free-flyer position of ``q``, or 0
            for a fixed base), m.
        contacts: The sustained contacts, resolved.
        com: Centre of mass in world, m.
        com_local: Centre of mass in the stance frame, m.
        mass: Total mass, kg.
        gravity_torques: Generalized gravity vector g(q) (nv), N and N m.
        com_inertia: Composite rotational inertia about the CoM, world axes, kg m^2.
    """

    def __init__(
        self,
        robot: Robot,
        q: np.ndarray,
        contacts: Sequence[ContactSpec] = (),
        workspace: Scratch | None = None,
    ):
        model = robot.model
        self.robot = robot
        # An explicit scratch Data is kept; else the robot's per-thread one is looked up at
        # each use (a stance may be read from another thread than the one that built it).
        self._scratch = workspace
        self.q = q = np.array(q, dtype=float)
        if has_free_flyer(model):
            self.origin = q[:3].copy()
            self._q_local = q_local = q.copy()
            q_local[:3] = 0.0
        else:
            self.origin = np.zeros(3)
            self._q_local = q_local = q
        scratch = workspace if workspace is not None else robot.thread_data()
        data = scratch.data
        # ccrba runs the forward kinematics and also fills the joint Jacobians data.J (as
        # computeJointJacobians does) and data.Ig, the centroidal composite inertia in world axes.
        pin.ccrba(model, data, q_local, _zero_velocity(model.nv))
        scratch.holder = q_local.tobytes()
        self.com_local = np.array(pin.centerOfMass(model, data, _POSITION, False), dtype=float)
        self.com = self.com_local + self.origin
        Ig = data.Ig
        self.mass = float(Ig.mass)
        self.com_inertia = np.array(Ig.inertia, dtype=float)
        # g(q) does not depend on the base position (its base rows are moments about the base).
        self.gravity_torques = np.array(
            pin.computeGeneralizedGravity(model, data, q_local), dtype=float
        )
        self.contacts: list[Contact] = [
            self._contact(data, i, spec) for i, spec in enumerate(contacts)
        ]

    def _contact(self, data: pin.Data, i: int, spec: ContactSpec) -> Contact:
        """Contact ``i`` of ``spec`` resolved in ``data`` (this stance's kinematics)."""
        robot = self.robot
        try:  # the field named only in the error (its string costs as much as the look-up)
            fid = robot.frame_id(spec.frame)
        except UnknownFrameError:
            fid = robot.frame_id(spec.frame, f"contacts[{i}].frame")
        placement, jacobian = self._point(data, fid, spec.offset)
        local = placement.translation.copy()
        return Contact(spec, placement.rotation.copy(), local + self.origin, jacobian, local)

    def moved_to(self, q: np.ndarray) -> Stance:
        """This stance's robot and contacts at configuration ``q``: ``Stance(robot, q, specs)``.

        Where ``q`` differs from :attr:`q` only in the free flyer's position ``q[:3]`` (world,
        m), the kinematics, computed without it in the stance frame, are this stance's: they are
        copied, not computed again, and the world positions (:attr:`com`, the contacts'
        ``position``) are the stance frame's plus the new :attr:`origin`, as a new stance makes
        them (the same numbers). Else a new stance is computed.

        Args:
            q: Configuration (nq).

        Returns:
            The stance at ``q`` (it shares no array with this one).
        """
        q = np.array(q, dtype=float)
        if not (
            has_free_flyer(self.model)
            and q.shape == self.q.shape
            and q[3:].tobytes() == self.q[3:].tobytes()
        ):
            return Stance(self.robot, q, [c.spec for c in self.contacts], self._scratch)
        moved = Stance.__new__(Stance)
        moved.robot, moved._scratch, moved.q = self.robot, self._scratch, q
        moved.origin = q[:3].copy()
        moved._q_local = self._q_local.copy()
        moved.com_local = self.com_local.copy()
        moved.com = moved.com_local + moved.origin
        moved.mass = self.mass
        moved.com_inertia = self.com_inertia.copy()
        moved.gravity_torques = self.gravity_torques.copy()
        moved.contacts = []
        for c in self.contacts:
            assert c.local_position is not None  # a stance's contacts have it
            local = np.array(c.local_position, dtype=float)
            moved.contacts.append(
                Contact(c.spec, c.rotation.copy(), local + moved.origin, c.jacobian.copy(), local)
            )
        return moved

    @property
    def model(self) -> pin.Model:
        """The robot's pinocchio model."""
        return self.robot.model

    @functools.cached_property
    def data(self) -> pin.Data:
        """A pinocchio Data of this stance's own, made on first access.

        It holds the joint and frame placements, Jacobians, composite inertia, CoM and
        gravity at ``q``, for callers that read the model directly (plots, GUI meshes);
        the pipeline never needs it.
        """
        model, data = self.model, self.model.createData()
        pin.computeJointJacobians(model, data, self.q)
        pin.updateFramePlacements(model, data)
        pin.ccrba(model, data, self.q, np.zeros(model.nv))
        pin.centerOfMass(model, data, self.q, False)
        pin.computeGeneralizedGravity(model, data, self.q)
        return data

    def workspace(self) -> Scratch:
        """The scratch Data this stance computes in.

        The one it was given, else the robot's (per thread,
        :meth:`impact_balance.robot.robot.Robot.thread_data`).
        """
        return self._scratch if self._scratch is not None else self.robot.thread_data()

    def _kinematics(self) -> pin.Data:
        """The scratch Data holding this stance's joint placements and joint Jacobians."""
        workspace = self.workspace()
        key = self._q_local.tobytes()
        if workspace.holder != key:
            pin.computeJointJacobians(self.model, workspace.data, self._q_local)
            workspace.holder = key
        return workspace.data

    def point(
        self, frame: str, offset: pin.SE3 | None = None, field: str = "frame"
    ) -> tuple[pin.SE3, np.ndarray]:
        """World pose of ``frame * offset`` and its 6 x nv world-aligned Jacobian (linear first)."""
        placement, J = self.local_point(frame, offset, field)
        return pin.SE3(placement.rotation, placement.translation + self.origin), J

    def local_point(
        self, frame: str, offset: pin.SE3 | None = None, field: str = "frame"
    ) -> tuple[pin.SE3, np.ndarray]:
        """:meth:`point` in the stance frame (world axes, origin at :attr:`origin`)."""
        fid = self.robot.frame_id(frame, field)
        return self._point(self._kinematics(), fid, offset)

    def _point(
        self, data: pin.Data, fid: int, offset: pin.SE3 | None
    ) -> tuple[pin.SE3, np.ndarray]:
        """:meth:`point` of frame ``fid`` from ``data`` holding this stance's kinematics.

        Returns copies.
        """
        placement, J = frame_point(self.model, data, fid, offset)
        assert J is not None  # asked for (jacobian=True)
        return placement, J

    def frame_pose(self, frame: str, field: str = "frame") -> pin.SE3:
        """World pose of a frame (a copy); ``field`` names it in an unknown-frame error."""
        fid = self.robot.frame_id(frame, field=field)
        placement = pin.updateFramePlacement(self.model, self._kinematics(), fid)
        return pin.SE3(placement.rotation, placement.translation + self.origin)

    def local_frame_position(self, frame: str, field: str = "frame") -> np.ndarray:
        """A frame's origin in the stance frame (world axes, origin at :attr:`origin`), m.

        A new array; ``field`` names the frame in an unknown-frame error.
        """
        fid = self.robot.frame_id(frame, field=field)
        placement = pin.updateFramePlacement(self.model, self._kinematics(), fid)
        position: npt.NDArray[np.float64] = placement.translation.copy()
        return position

    def lowest_contact_height(self) -> float:
        """Lowest z of any contact corner, m (nan without contacts)."""
        if not self.contacts:
            return float("nan")
        return float(min(c.corners()[:, 2].min() for c in self.contacts))
