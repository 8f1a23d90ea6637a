"""The scenario YAML schema: one pydantic model per mapping, strict and bounded.

Every model refuses unknown keys, NaN and infinities; :class:`Scenario` resolves itself
against a robot model into a :class:`~impact_balance.contacts.stance.Stance`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
import pinocchio as pin
from pydantic import (
    AfterValidator,
    Field,
    PrivateAttr,
    ValidationError,
    ValidationInfo,
    field_validator,
)

from impact_balance.constants import (
    DEFAULT_ANGULAR_MOMENTUM_DAMPING_TIME,
    GRAVITY_RANGE,
    MAX_ANGLE,
    MAX_ANGULAR_MOMENTUM_DAMPING_TIME,
    MAX_DESCRIPTION,
    MAX_DURATION,
    MAX_FRICTION,
    MAX_NAME,
    MAX_PEAK_FACTOR,
    MAX_POSITION,
    MAX_SIZE,
    MAX_VELOCITY_MARGIN,
)
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.spatial import pose, surface_rotation
from impact_balance.impact.model import ImpactSpec
from impact_balance.robot.robot import Robot, RobotFileReader, load_robot
from impact_balance.scenario.errors import scenario_error
from impact_balance.scenario.fields import (
    Angles,
    Flag,
    Friction,
    Integer,
    Number,
    Position,
    Vec2,
    Vec3,
    _coordinates,
    _finite,
    _Model,
    _scalar,
    _speed,
)
from impact_balance.scenario.reader import check_path_text, check_structure
from impact_balance.scenario.specs import _contact_spec, _impact_spec, _quaternion

__all__ = [
    "BasePose",
    "ContactConfig",
    "ImpactConfig",
    "Offset",
    "QPConfig",
    "RobotFiles",
    "Scenario",
    "with_source",
]


class Offset(_Model):
    """Fixed pose in a robot frame: position (m) and roll-pitch-yaw (rad)."""

    position: Position = (0.0, 0.0, 0.0)
    rpy: Angles = (0.0, 0.0, 0.0)

    def se3(self) -> pin.SE3:
        """The pose as a pinocchio SE3 (translation m, rotation from roll-pitch-yaw)."""
        return pose(self.position, self.rpy)


class ContactConfig(_Model):
    """A sustained rectangular contact (see :class:`impact_balance.contacts.stance.ContactSpec`).

    Its orientation is either ``offset.rpy`` (in the frame) or ``normal`` (the surface
    normal in the world, from the surface into the robot) with an optional ``angle`` (rad)
    about it: see :func:`impact_balance.geometry.spatial.surface_rotation`. The normal form is
    resolved at the scenario's configuration (:meth:`Scenario.contact_specs`).
    """

    frame: str
    friction: Friction
    size: Vec2
    offset: Offset = Offset()
    normal: Annotated[Vec3, _coordinates(1e6, "(any scale; it is normalised)")] | None = None
    angle: Annotated[Number, _scalar(-MAX_ANGLE, MAX_ANGLE, "rad")] | None = None

    @field_validator("size")
    @classmethod
    def _size(cls, v: Vec2) -> Vec2:
        if all(x == 0 for x in v):
            return v  # a point contact: a force cone at the point, no torque
        if not all(0 < x <= MAX_SIZE for x in v):
            raise ValueError(
                f"size must be [length, width], both in (0, {MAX_SIZE:g}] m (a sole), "
                "or [0, 0] (a point foot)"
            )
        return v

    @field_validator("normal")
    @classmethod
    def _normal(cls, v: Vec3 | None, info: ValidationInfo) -> Vec3 | None:
        if v is None:
            return v
        _finite(v, "normal")
        if float(np.linalg.norm(v)) < 1e-9:
            raise ValueError("normal must be a non-zero vector")
        offset = info.data.get("offset")
        if offset is not None and any(offset.rpy):
            raise ValueError(
                "give the contact's orientation either as offset.rpy (in the frame) or as normal "
                "(in the world, with angle about it), not both"
            )
        return v

    @field_validator("angle")
    @classmethod
    def _angle(cls, v: float | None, info: ValidationInfo) -> float | None:
        if v is not None and info.data.get("normal") is None:
            raise ValueError("angle turns the contact about its world normal: give normal too")
        return v

    def spec(self, frame_rotation: np.ndarray | None = None) -> ContactSpec:
        """The contact's :class:`ContactSpec` (cached by content: treat it as immutable).

        Args:
            frame_rotation: The frame's world rotation at the scenario's configuration;
                needed (and only used) when the contact is given by its ``normal``.
        """
        if self.normal is None:
            return _contact_spec(
                self.frame, self.friction, tuple(self.size), self.offset.position, self.offset.rpy
            )
        if frame_rotation is None:
            raise ScenarioError(
                "normal",
                self.normal,
                "a contact given by its world normal needs the configuration "
                "(use Scenario.contact_specs)",
            )
        world = surface_rotation(frame_rotation, self.normal, self.angle or 0.0)
        offset = pin.SE3(
            np.asarray(frame_rotation).T @ world, np.asarray(self.offset.position, dtype=float)
        )
        length, width = self.size
        return ContactSpec(self.frame, self.friction, (length, width), offset)


class QPConfig(_Model):
    """The paper's QP in joint velocities (optional; the exact answer never needs it)."""

    solve: Flag = False
    joint_velocity_limits: Flag = False
    impulsive_torque_limits: Flag = False
    peak_factor: Annotated[Number, _scalar(0.0, MAX_PEAK_FACTOR, lo_open=True)] = 1.0
    solver: str = "daqp"


class ImpactConfig(_Model):
    """The intended impact (see :class:`impact_balance.impact.model.ImpactSpec`)."""

    frame: str
    offset: Offset = Offset()
    normal: Annotated[Vec3, _coordinates(1e6, "(any scale; it is normalised)")]
    friction: Annotated[Number, _scalar(0.0, MAX_FRICTION)] = 0.24
    restitution: Vec2 = (0.0, 0.2)
    cone_edges: Integer = Field(16, ge=3, le=1024)
    reference_velocity: Annotated[Vec3, AfterValidator(_speed)] | None = None
    duration: Annotated[Number, _scalar(0.0, MAX_DURATION, "s", lo_open=True)] = 0.005
    inertia: Literal["composite", "joint_space"] = "composite"
    qp: QPConfig = QPConfig()

    @field_validator("normal")
    @classmethod
    def _normal(cls, v: Vec3) -> Vec3:
        _finite(v, "normal")
        if float(np.linalg.norm(v)) < 1e-9:
            raise ValueError("normal must be a non-zero vector")
        return v

    @field_validator("restitution")
    @classmethod
    def _restitution(cls, v: Vec2) -> Vec2:
        lo, hi = v
        if not (0.0 <= lo <= 1.0 and 0.0 <= hi <= 1.0):
            raise ValueError("restitution values must lie in [0, 1]")
        if lo > hi:
            raise ValueError("restitution must be [lo, hi] with lo <= hi")
        return v

    def spec(self) -> ImpactSpec:
        """The impact's :class:`ImpactSpec` (cached by content: treat it as immutable)."""
        return _impact_spec(
            self.frame,
            tuple(self.normal),
            self.friction,
            tuple(self.restitution),
            self.cone_edges,
            None if self.reference_velocity is None else tuple(self.reference_velocity),
            self.duration,
            self.offset.position,
            self.offset.rpy,
            self.inertia,
        )


class RobotFiles(_Model):
    """A robot given by files (paths relative to the scenario file)."""

    urdf: str
    srdf: str | None = None
    standing: str | None = None


class BasePose(_Model):
    """Free-flyer pose override in world: position (m), roll-pitch-yaw (rad)."""

    position: Position | None = None
    rpy: Angles | None = None


class Scenario(_Model):
    """One situation. See README, "Scenario files", for every key."""

    #: How its robot files are read (None: by path, with the package's file-reading rule); a
    #: confined reader (the GUI's workspace) travels with the scenario and its replacements.
    _robot_reader: RobotFileReader | None = PrivateAttr(default=None)

    name: Annotated[str, Field(max_length=MAX_NAME)] | None = None
    description: Annotated[str, Field(max_length=MAX_DESCRIPTION)] | None = None
    robot: str | RobotFiles = "talos"
    configuration: str | None = None
    joints: dict[str, Number] = Field(default_factory=dict)
    base: BasePose | None = None
    com_velocity: Annotated[Vec2, AfterValidator(_speed)] = (0.0, 0.0)
    plane_height: Annotated[Number, _scalar(-MAX_POSITION, MAX_POSITION, "m")] = 0.0
    #: The ZMP support area is shrunk by this margin (m), and the CoM velocity area with it.
    zmp_margin: Annotated[Number, _scalar(0.0, MAX_SIZE, "m")] = 0.0
    #: Every post-impact CoM velocity must lie this far (m/s) inside the CoM velocity area
    #: (the CoM criterion): a margin for the impact model's error. 0 is the paper's criterion.
    velocity_margin: Annotated[Number, _scalar(0.0, MAX_VELOCITY_MARGIN, "m/s")] = 0.0
    #: tau (s): the centroidal angular momentum the impulse leaves is removed by the contacts
    #: with this time constant, and the CoM criterion sees the effective post-impact CoM
    #: velocity (docs/angular-momentum.md). None: the paper's criterion (it is ignored).
    angular_momentum_damping_time: (
        Annotated[Number, _scalar(0.0, MAX_ANGULAR_MOMENTUM_DAMPING_TIME, "s")] | None
    ) = DEFAULT_ANGULAR_MOMENTUM_DAMPING_TIME
    #: The criterion sees every contact's friction times this factor, in (0, 1]: the balance a
    #: controller that keeps its contact forces within that share of the friction cone can
    #: realise (docs/robots.md). 1 is the paper's criterion. The simulated contacts keep theirs.
    friction_scale: Annotated[Number, _scalar(0.0, 1.0, lo_open=True)] = 1.0
    torque_limits: Flag = True
    gravity: Annotated[Number, _scalar(*GRAVITY_RANGE, "m/s^2")] = 9.81
    contacts: list[ContactConfig] = Field(min_length=1)
    impact: ImpactConfig | None = None
    source: str | None = Field(None, exclude=True)

    @field_validator("joints")
    @classmethod
    def _joint_values(cls, joints: dict[str, float]) -> dict[str, float]:
        bad = [name for name, value in joints.items() if not math.isfinite(value)]
        if bad:
            raise ValueError(f"joint values must be finite (not {', '.join(bad)})")
        return joints

    @classmethod
    def from_mapping(
        cls, raw: dict[str, Any], source: str | None = None, check_size: bool = True
    ) -> Scenario:
        """Validate a scenario mapping; raises :class:`ScenarioError` on the first bad field.

        Args:
            raw: The mapping (top-level keys of a scenario file, ``extends:`` merged).
            source: The file it came from, if any (named in errors, and the base of the
                robot files' relative paths).
            check_size: ``False`` skips the nesting and expanded-size check of
                :func:`~impact_balance.scenario.reader.check_structure`.

        Returns:
            The validated scenario.

        Raises:
            ScenarioError: The first bad field, naming it, its value and the reason (an
                :class:`~impact_balance.exceptions.UnknownKeyError` for an unknown key).
        """
        if check_size:
            check_structure(raw, source)
        try:
            return cls.model_validate({**raw, "source": source})
        except ValidationError as exc:
            raise scenario_error(exc, raw, cls, source) from None
        except ScenarioError as exc:
            raise ScenarioError(exc.field, exc.value, exc.reason, source) from None

    def replace(self, **changes: Any) -> Scenario:
        """A copy with the top-level keys ``changes`` replaced, validated as a file's keys are.

        The one way to override a scenario's value (``zmp_margin``, ``velocity_margin``,
        ``com_velocity``...): unlike pydantic's ``model_copy``, it refuses what the schema
        refuses. The keys the scenario set (:attr:`set_keys`) stay set, and the changed ones
        become set.

        Args:
            **changes: Top-level keys and their new values, in the file's units.

        Returns:
            The new scenario (same ``source``); this one when ``changes`` is empty.

        Raises:
            ScenarioError: A value the schema refuses, or an unknown key, naming the field.
        """
        if not changes:
            return self
        raw = self.model_dump(exclude_unset=True)
        raw.pop("source", None)
        raw.update(changes)
        return Scenario.from_mapping(raw, self.source).with_robot_reader(self._robot_reader)

    @property
    def robot_reader(self) -> RobotFileReader | None:
        """How its robot files are read (see :meth:`with_robot_reader`); None: by path."""
        return self._robot_reader

    def with_robot_reader(self, reader: RobotFileReader | None) -> Scenario:
        """A copy whose robot files are read by ``reader`` (path -> bytes) instead of by path.

        The GUI gives its workspace's reader (no link followed, relative to the workspace's
        folder descriptors), so that a robot file swapped for a link after the workspace
        checked it is refused, never read.

        Args:
            reader: Reads a robot file's bytes, raising an
                :class:`~impact_balance.exceptions.ImpactBalanceError` naming it; None: by path.

        Returns:
            The copy (this scenario when the reader is already the same).
        """
        if reader is self._robot_reader:
            return self
        copy = self.model_copy()
        copy._robot_reader = reader
        return copy

    @property
    def set_keys(self) -> frozenset[str]:
        """The top-level keys the file (with its ``extends:`` chain) or an override set."""
        return frozenset(self.model_fields_set - {"source"})

    # -- resolution against a robot model -------------------------------------------------
    def load_robot(self) -> Robot:
        """The scenario's robot: a bundled name, or files relative to the scenario file.

        Returns:
            The robot model (cached after its first load).

        Raises:
            ScenarioError: A bad robot file path, or an unknown robot name.
        """
        if isinstance(self.robot, RobotFiles):
            check_path_text("robot.urdf", self.robot.urdf, self.source)
            if self.robot.srdf:
                check_path_text("robot.srdf", self.robot.srdf, self.source)
            base = Path(self.source).parent if self.source else Path.cwd()
            # With a confined reader, the paths stay as written (made absolute, no link
            # resolved): the reader decides what a link means.
            absolute = Path.absolute if self._robot_reader is not None else Path.resolve
            urdf = absolute(base / self.robot.urdf)
            srdf = absolute(base / self.robot.srdf) if self.robot.srdf else None
            return load_robot(None, urdf, srdf, self.robot.standing, read_file=self._robot_reader)
        return load_robot(self.robot)

    def configuration_vector(self, robot: Robot) -> np.ndarray:
        """Q from the named configuration, the joint overrides and the base override."""
        q = robot.configuration(self.configuration)
        indices, values = robot.joint_assignment(self.joints, field="joints")
        q[indices] = values
        if self.base is not None:
            if self.base.position is not None:
                q[:3] = self.base.position
            if self.base.rpy is not None:
                q[3:7] = _quaternion(self.base.rpy)
        return q

    def contact_specs(self, robot: Robot, q: np.ndarray) -> list[ContactSpec]:
        """The contacts' specs at configuration ``q``.

        The configuration resolves the contacts given by a world normal.
        """
        if all(c.normal is None for c in self.contacts):
            return [c.spec() for c in self.contacts]
        frames = Stance(robot, q, [])
        specs = []
        for i, c in enumerate(self.contacts):
            rotation = None
            if c.normal is not None:
                rotation = frames.frame_pose(c.frame, field=f"contacts[{i}].frame").rotation
            specs.append(c.spec(rotation))
        return specs

    def build_stance(self, robot: Robot | None = None) -> Stance:
        """Resolve robot, configuration and contacts into a :class:`Stance`.

        Without a ``base`` key the robot is translated vertically so that its lowest contact
        corner touches z = 0.

        Args:
            robot: The robot (default: the scenario's, loaded).

        Returns:
            The stance.

        Raises:
            ScenarioError: An unknown frame or joint, a plane at or above the CoM (with the
                scenario's file named).
        """
        try:
            return self._build_stance(robot)
        except ScenarioError as exc:
            raise with_source(exc, self.source) from None

    def _build_stance(self, robot: Robot | None = None) -> Stance:
        """Resolve robot, configuration and contacts into a :class:`Stance`.

        Without a ``base`` key the robot is translated vertically so that its lowest contact
        corner touches z = 0 (robots' neutral configurations often float or sink).
        """
        robot = robot or self.load_robot()
        q = self.configuration_vector(robot)
        specs = self.contact_specs(robot, q)
        stance = Stance(robot, q, specs)
        if self.base is None:
            lift = -stance.lowest_contact_height()
            if abs(lift) > 1e-12:
                q = q.copy()
                q[2] += lift
                stance = stance.moved_to(q)  # the same kinematics, lifted
        if not stance.com[2] > self.plane_height:
            raise ScenarioError(
                "plane_height",
                self.plane_height,
                f"must be below the CoM height {stance.com[2]:.4g} m",
            )
        return stance


def with_source(exc: ScenarioError, source: str | None) -> ScenarioError:
    """Prefix a scenario error found after loading (unknown frame...) with its file name."""
    if source and exc.source is None:
        exc.source = source
        exc.args = (f"{source}: {exc.args[0]}", *exc.args[1:])
    return exc
