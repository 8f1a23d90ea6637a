"""Robot models: bundled humanoids from example-robot-data, or any URDF + SRDF.

Models are loaded with pinocchio, with a free-flyer root joint (the robot is floating).
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import math
import os
import re
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import (
    RobotLoadError,
    ScenarioError,
    UnknownConfigurationError,
    UnknownFrameError,
    UnknownJointError,
    UnknownRobotError,
)
from impact_balance.geometry.spatial import aligning_rotation
from impact_balance.robot.urdf_check import check_srdf, check_urdf, read_robot_file

__all__ = [
    "BUNDLED_ROBOTS",
    "EXAMPLE_ROBOTS",
    "JointSlot",
    "Robot",
    "RobotFileReader",
    "RobotSpec",
    "Scratch",
    "ThreadData",
    "example_robot_data_root",
    "load_robot",
    "robot_names",
]

#: Reads a robot file's bytes (path -> bytes), raising an error that names the file.
RobotFileReader = Callable[[Path], bytes]

_FloatArray = npt.NDArray[np.float64]

#: Words of a link name (split at ``_``, ``-``, digits) that say it is no foot.
_NOT_FOOT = frozenset({"imu", "sensor", "ft", "virtual", "adapter", "dh", "fixed", "joint"})
_WORD = re.compile(r"[^a-z]+")


@dataclass(frozen=True)
class RobotSpec:
    """Where a bundled robot's files live, relative to the example-robot-data root.

    Attributes:
        urdf: URDF path.
        srdf: SRDF path (reference configurations), or None.
        standing: Name of the default standing configuration ("neutral" if no SRDF has one).
        description: One line for listings.
    """

    urdf: str
    srdf: str | None
    standing: str
    description: str


def _jvrc_description_file(relative: str) -> str:
    """Absolute path of a file of the jvrc-description wheel (found without importing it)."""
    import importlib.util

    spec = importlib.util.find_spec("jvrc_description")
    if spec is None or spec.origin is None:  # pragma: no cover - install issue
        return f"jvrc_description/{relative}"  # missing: the load names the file
    return str(Path(spec.origin).parent / relative)


BUNDLED_ROBOTS: dict[str, RobotSpec] = {
    "talos": RobotSpec(
        "talos_data/robots/talos_reduced.urdf",
        "talos_data/srdf/talos.srdf",
        "half_sitting",
        "PAL Robotics TALOS, 90 kg humanoid (reduced model, 32 actuated joints)",
    ),
    "g1": RobotSpec(
        "g1_description/urdf/g1_29dof_rev_1_0.urdf",
        None,
        "neutral",
        "Unitree G1, 33 kg humanoid (29 actuated joints); no SRDF: neutral configuration",
    ),
    "romeo": RobotSpec(
        "romeo_description/urdf/romeo.urdf",
        "romeo_description/srdf/romeo.srdf",
        "half_sitting",
        "Aldebaran Romeo, 41 kg humanoid",
    ),
    "icub": RobotSpec(
        "icub_description/robots/icub_reduced.urdf",
        "icub_description/srdf/icub.srdf",
        "half_sitting",
        "IIT iCub, 28 kg humanoid (reduced model)",
    ),
    # Not in example-robot-data: the jvrc-description wheel's URDF, as an absolute path (a
    # path joined to an absolute one is that one). No SRDF: the stance is in the scenarios.
    "jvrc1": RobotSpec(
        _jvrc_description_file("urdf/jvrc1.urdf"),
        None,
        "neutral",
        "JVRC-1 (jvrc-description), 62 kg HRP-class humanoid; no SRDF: neutral configuration",
    ),
}


#: Every other floating-base robot example-robot-data ships, loadable by name
#: (``robot: go2``): its files as example-robot-data's own loader (``robots_loader.py``)
#: names them, relative to its ``robots/`` folder, and its SRDF's standing posture.
EXAMPLE_ROBOTS: dict[str, RobotSpec] = {
    "a1": RobotSpec(
        "a1_description/urdf/a1.urdf", "a1_description/srdf/a1.srdf", "standing", "Unitree A1"
    ),
    "alex": RobotSpec(
        "alex_description/urdf/alex_nub_hands.urdf",
        "alex_description/srdf/alex_nub_hands.srdf",
        "default",
        "IHMC Alex humanoid (nub hands)",
    ),
    "alexander": RobotSpec(
        "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
        "alexander_description/srdf/alexander.srdf",
        "default",
        "IHMC Alexander, lower body",
    ),
    "anymal_b": RobotSpec(
        "anymal_b_simple_description/robots/anymal.urdf",
        "anymal_b_simple_description/srdf/anymal.srdf",
        "standing",
        "ANYbotics ANYmal B",
    ),
    "anymal_c": RobotSpec(
        "anymal_c_simple_description/urdf/anymal.urdf",
        "anymal_c_simple_description/srdf/anymal.srdf",
        "standing",
        "ANYbotics ANYmal C",
    ),
    "b1": RobotSpec(
        "b1_description/urdf/b1.urdf", "b1_description/srdf/b1.srdf", "standing", "Unitree B1"
    ),
    "bolt": RobotSpec(
        "bolt_description/robots/bolt.urdf",
        "bolt_description/srdf/bolt.srdf",
        "standing",
        "ODRI Bolt biped",
    ),
    "centauro": RobotSpec(
        "centauro_description/urdf/centauro.urdf",
        "centauro_description/srdf/centauro.srdf",
        "homing_nominal",
        "IIT Centauro, wheeled quadruped with two arms",
    ),
    "go1": RobotSpec(
        "go1_description/urdf/go1.urdf", "go1_description/srdf/go1.srdf", "standing", "Unitree Go1"
    ),
    "go2": RobotSpec(
        "go2_description/urdf/go2.urdf", "go2_description/srdf/go2.srdf", "standing", "Unitree Go2"
    ),
    "human": RobotSpec(
        "human_description/robots/human.urdf", None, "neutral", "Human body model (y up)"
    ),
    "hyq": RobotSpec(
        "hyq_description/robots/hyq_no_sensors.urdf",
        "hyq_description/srdf/hyq.srdf",
        "standing",
        "IIT HyQ",
    ),
    "laikago": RobotSpec(
        "laikago_description/urdf/laikago.urdf", None, "neutral", "Unitree Laikago"
    ),
    "quadruped": RobotSpec(
        "quadruped_description/urdf/quadruped.urdf", None, "neutral", "A generic quadruped"
    ),
    "simple_humanoid": RobotSpec(
        "simple_humanoid_description/urdf/simple_humanoid.urdf",
        "simple_humanoid_description/srdf/simple_humanoid.srdf",
        "half_sitting",
        "A toy humanoid",
    ),
    "solo8": RobotSpec(
        "solo_description/robots/solo.urdf",
        "solo_description/srdf/solo.srdf",
        "standing",
        "ODRI Solo 8",
    ),
    "solo12": RobotSpec(
        "solo_description/robots/solo12.urdf",
        "solo_description/srdf/solo.srdf",
        "standing",
        "ODRI Solo 12",
    ),
}


def robot_names() -> dict[str, RobotSpec]:
    """Every robot loadable by name: the bundled ones first, then example-robot-data's others."""
    others = {name: spec for name, spec in EXAMPLE_ROBOTS.items() if name not in BUNDLED_ROBOTS}
    return {**BUNDLED_ROBOTS, **others}


def example_robot_data_root() -> Path:
    """Folder holding example-robot-data's ``robots/`` tree (installed by its wheel)."""
    import importlib.metadata  # here: `impact-balance robots` lists names without it

    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError as exc:  # pragma: no cover - install issue
        raise RobotLoadError("example-robot-data", "package not installed") from exc
    root = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    if not root.is_dir():  # pragma: no cover - install issue
        raise RobotLoadError(str(root), "example-robot-data's robots folder not found")
    return root


class JointSlot(NamedTuple):
    """Where a non-root joint sits in the configuration vector.

    Attributes:
        id: Joint index in the model.
        idx_q: First configuration index; nq, nv: configuration and velocity sizes.
        lower, upper: Position limits of its first configuration coordinate (rad or m).
    """

    id: int
    idx_q: int
    nq: int
    nv: int
    lower: float
    upper: float


class Scratch:
    """One pinocchio ``Data`` for one owner, and the key of the configuration it holds.

    What :class:`ThreadData` is per thread, for an owner that serialises its own calls (a
    :class:`~impact_balance.governor.Governor` and its lock):
    :class:`~impact_balance.contacts.stance.Stance` computes in it when given one.

    Attributes:
        data: The Data.
        holder: Key of the configuration whose joint placements (``oMi``) and joint
            Jacobians (``J``) ``data`` holds, or None when unknown.
    """

    def __init__(self, model: pin.Model):
        self.data = model.createData()
        self.holder: bytes | None = None


class ThreadData(threading.local, Scratch):
    """One pinocchio ``Data`` per robot and per thread, reused by every :class:`Stance`.

    A :class:`Scratch` of its own in every thread: ``model.createData()`` allocates a large
    Data and costs far more than the kinematics themselves, so stances compute in this scratch
    Data and copy out what they keep. Thread-local so that concurrent analyses never overwrite
    each other's kinematics.

    Attributes:
        data: The scratch Data (this thread's).
        holder: Key of the configuration whose joint placements (``oMi``) and joint
            Jacobians (``J``) ``data`` holds, or None when unknown.
    """

    def __init__(self, model: pin.Model):
        Scratch.__init__(self, model)


class _JointPlan:
    """:meth:`Robot.joint_assignment`'s plan for one set of 1-dof joint names.

    Attributes:
        indices: Their configuration indices (read-only).
        low, high: The lowest and highest value each accepts (its limits with their 1e-9
            slack; -inf and inf where the limits are not checked).
        last: The last values accepted, as given and as a read-only array (one tuple,
            replaced whole: a thread reads both of the same call).
    """

    __slots__ = ("high", "indices", "last", "low")

    def __init__(self, indices: np.ndarray, low: np.ndarray, high: np.ndarray) -> None:
        self.indices, self.low, self.high = indices, low, high
        self.last: tuple[tuple[Any, ...] | None, np.ndarray] = (None, np.zeros(0))


@dataclass
class Robot:
    """A floating-base robot model.

    Name, joint and limit look-ups are computed once from the model and cached: treat the
    model as read-only once loaded.

    Attributes:
        name: Bundled name, or the URDF file stem.
        model: pinocchio model with a free-flyer root (nq = 7 + joints, nv = 6 + joints).
        reference_configurations: Named configurations from the SRDF, plus "neutral".
        standing: Name of the default standing configuration.
        urdf_path, srdf_path: Source files (meshes are resolved relative to the URDF's package).
        armature_source: Where ``model.armature`` (the reflected rotor inertia of each joint,
            kg m^2, which pinocchio's mass matrix includes) comes from: the SRDF's
            ``rotor_params`` (armature = gear ratio^2 x rotor inertia), or None when the robot
            files declare none (armature 0).
    """

    name: str
    model: pin.Model
    reference_configurations: dict[str, np.ndarray]
    standing: str
    urdf_path: Path
    srdf_path: Path | None = None
    package_dirs: list[str] = field(default_factory=list)
    armature_source: str | None = None

    def __getstate__(self) -> dict[str, Any]:
        # The caches (thread-local Data, look-up tables) are rebuilt on demand, never copied.
        return {f.name: self.__dict__[f.name] for f in fields(self)}

    def __setattr__(self, name: str, value: Any) -> None:
        # Every cache is computed from the model: another model drops them all (rebuilt on
        # demand), so a robot given a new model never answers from the old one.
        if name == "model" and self.__dict__.get("model", value) is not value:
            kept = {f.name for f in fields(self)}
            for key in [k for k in self.__dict__ if k not in kept]:
                del self.__dict__[key]
        object.__setattr__(self, name, value)

    @property
    def mass(self) -> float:
        """Total mass, kg."""
        return float(sum(inertia.mass for inertia in self.model.inertias))

    @property
    def frame_names(self) -> list[str]:
        """Names of all frames of the model."""
        return [f.name for f in self.model.frames]

    @property
    def joint_names(self) -> list[str]:
        """Names of the actuated (non-root) joints."""
        return list(self._joint_slots)

    @property
    def listing_command(self) -> str:
        """The command that lists this robot's frames and joints (named in error messages)."""
        bundled = self.name in BUNDLED_ROBOTS and self.urdf_path == _bundled_urdf(self.name)
        named = self.name in EXAMPLE_ROBOTS and self.urdf_path == (
            example_robot_data_root() / EXAMPLE_ROBOTS[self.name].urdf
        )
        bundled = bundled or named
        return f"impact-balance frames {self.name if bundled else self.urdf_path}"

    @functools.cached_property
    def foot_frames(self) -> tuple[str, ...]:
        """The feet, inferred from the link names: ``*sole*`` links, else ``*foot*`` links.

        A link named like ``l_sole``, ``left_sole_link``, ``FL_foot``, ``LF_FOOT`` (``foot`` or
        ``sole`` as a word of the name, sensors, IMUs and virtual links left out). Empty when
        no name says it (the feet are then unknown: nothing is guessed).
        """
        names = [f.name for f in self.model.frames if f.type == pin.FrameType.BODY]
        words = [(n, set(_WORD.split(n.lower()))) for n in names]
        usable = [(n, w) for n, w in words if not w & _NOT_FOOT]
        soles = tuple(n for n, w in usable if "sole" in w)
        return soles or tuple(n for n, w in usable if "foot" in w)

    def up_direction(self, q: np.ndarray) -> np.ndarray | None:
        """The unit vector from the feet's mean position to the CoM at ``q``, world frame.

        The robot's up axis as it stands at ``q`` (+z for a robot upright in the world); None
        when its feet are unknown (:attr:`foot_frames`).
        """
        feet_ids = self._foot_frame_ids
        if not feet_ids:
            return None
        model = self.model
        data = self._up_data.data  # this thread's (a Data of its own: no Stance reads it)
        com = pin.centerOfMass(model, data, q)
        # The feet's placements alone (updateFramePlacements' numbers, without the other frames)
        feet = pin.updateFramePlacement(model, data, feet_ids[0]).translation.copy()
        for i in feet_ids[1:]:
            feet += pin.updateFramePlacement(model, data, i).translation
        feet /= len(feet_ids)  # their mean, summed in order as np.mean sums a few rows
        direction = np.asarray(com - feet, dtype=float)
        length = math.sqrt(float(direction @ direction))  # np.linalg.norm's numbers
        return direction / length if length > 1e-9 else None

    def up_axis_problem(self, q: np.ndarray) -> str | None:
        """Why the robot does not stand upright at ``q``, with the base rotation that would.

        The feet-to-CoM axis (:meth:`up_direction`) more than 45 degrees from the world's +z
        means a model whose up axis is not z (the y-up ``human`` of example-robot-data lies
        on its side, and every contact looks short of friction). Returns one line naming the
        axis and the scenario key that stands it up (``base: {position: ..., rpy: ...}``: the
        nearest world axis turned to +z, or the axis itself when none is within 10 degrees;
        the lowest foot frame at z = 0), or None when it stands (or its feet are unknown).
        """
        key = np.asarray(q, dtype=float).tobytes()
        cache = self._up_axis_answers
        if key not in cache:
            if len(cache) >= 64:
                cache.clear()
            cache[key] = self._up_axis_line(np.asarray(q, dtype=float))
        return cache[key]

    @functools.cached_property
    def _up_axis_answers(self) -> dict[bytes, str | None]:
        return {}

    @functools.cached_property
    def _foot_frame_ids(self) -> tuple[int, ...]:
        return tuple(self.frame_id(f) for f in self.foot_frames)

    @functools.cached_property
    def _up_data(self) -> ThreadData:
        # up_direction's Data (a large allocation, made once per thread and robot).
        return ThreadData(self.model)

    def _up_axis_line(self, q: np.ndarray) -> str | None:
        up = self.up_direction(q)
        if up is None or up[2] >= math.cos(math.radians(45.0)):
            return None
        axis = int(np.argmax(np.abs(up)))
        name = ("+" if up[axis] > 0 else "-") + "xyz"[axis]
        axis_vector = np.zeros(3)
        axis_vector[axis] = math.copysign(1.0, up[axis])
        if abs(up[axis]) < math.cos(math.radians(10.0)):  # not along a world axis: turn it all
            axis_vector = up
        base = pin.Quaternion(np.asarray(q[3:7])).normalized().matrix()
        upright = aligning_rotation(axis_vector, (0.0, 0.0, 1.0)) @ base
        stood = np.array(q, dtype=float)
        stood[3:7] = pin.Quaternion(upright).coeffs()
        data = self._up_data.data
        pin.framesForwardKinematics(self.model, data, stood)
        lowest = min(float(data.oMf[i].translation[2]) for i in self._foot_frame_ids)
        position = [round(float(q[0]), 4), round(float(q[1]), 4), round(float(q[2]) - lowest, 4)]
        rpy = [round(float(v), 4) + 0.0 for v in pin.rpy.matrixToRpy(upright)]
        tilt = math.degrees(math.acos(max(-1.0, min(1.0, float(up[2])))))
        return (
            f"robot {self.name!r} is not z-up: its feet-to-CoM axis points along {name} "
            f"in the world ({tilt:.0f} deg from +z), so it does not stand on its feet; stand it up "
            f"with base: {{position: {position}, rpy: {rpy}}}"
        )

    @functools.cached_property
    def _frame_ids(self) -> dict[str, int]:
        ids: dict[str, int] = {}
        for i, f in enumerate(self.model.frames):
            ids.setdefault(f.name, i)  # first of duplicate names, as model.getFrameId
        return ids

    @functools.cached_property
    def _joint_slots(self) -> dict[str, JointSlot]:
        model = self.model
        lower, upper = np.asarray(model.lowerPositionLimit), np.asarray(model.upperPositionLimit)
        slots = {}
        for jid in range(2, model.njoints):  # 0 = universe, 1 = free-flyer root
            joint = model.joints[jid]
            slots[model.names[jid]] = JointSlot(
                jid,
                joint.idx_q,
                joint.nq,
                joint.nv,
                float(lower[joint.idx_q]),
                float(upper[joint.idx_q]),
            )
        return slots

    def frame_id(self, name: str, field: str = "frame") -> int:
        """Index of frame ``name``; :class:`UnknownFrameError` naming the valid ones if absent."""
        fid = self._frame_ids.get(name) if isinstance(name, str) else None
        if fid is None:
            raise UnknownFrameError(
                field, name, set(self.frame_names), listing=self.listing_command
            )
        return fid

    def joint_id(self, name: str, field: str = "joint") -> int:
        """Index of a non-root joint; :class:`UnknownJointError` if absent."""
        return self.joint_slot(name, field).id

    def joint_slot(self, name: str, field: str = "joint") -> JointSlot:
        """Configuration slot and position limits of a non-root joint.

        Raises :class:`UnknownJointError` when the model has no such joint.
        """
        slot = self._joint_slots.get(name) if isinstance(name, str) else None
        if slot is None:
            raise UnknownJointError(field, name, self.joint_names, listing=self.listing_command)
        return slot

    def joint_assignment(
        self, joints: Mapping[str, float], field: str = "joints"
    ) -> tuple[np.ndarray, np.ndarray]:
        """Configuration indices and values (``q[idx] = values``) that set joints by name.

        A 1-dof joint takes its value (rad or m), checked against its finite position limits
        (1e-9 slack); a continuous joint takes (cos, sin) of its angle. Errors are
        :class:`ScenarioError` on ``field.NAME``, for the first bad joint in order. The
        indices and limits of a set of names are cached per model, with the last values
        accepted (a stance is rebuilt from the same names many times, often with the same
        values): do not modify the returned read-only arrays.
        """
        plan = self._assignment_plans.get(tuple(joints))
        if plan is not None:  # 1-dof joints only: the values as given, checked at once
            given, last = tuple(joints.values()), plan.last  # one read: other threads swap it
            if given == last[0]:  # the same values again (a scenario analysed again)
                return plan.indices, last[1]
            try:
                values = np.array(given, dtype=float)
            except (TypeError, ValueError):
                values = None  # not numbers: the loop below says which
            if (
                values is not None
                and values.shape == plan.low.shape
                and bool(((plan.low <= values) & (values <= plan.high)).all())
            ):
                values.setflags(write=False)
                plan.last = (given, values)
                return plan.indices, values
        return self._joint_assignment(joints, field)

    def _joint_assignment(
        self, joints: Mapping[str, float], field: str
    ) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`joint_assignment` joint by joint (raising on the first bad one).

        Caches the names' plan when every joint is 1-dof: indices, and the lowest and highest
        value each accepts (-inf and inf where the limits are not checked).
        """
        indices, values = [], []
        low, high = [], []
        for name, value in joints.items():
            slot = self.joint_slot(name, field=f"{field}.{name}")
            if slot.nq == 1:
                lo, hi = slot.lower, slot.upper
                checked = math.isfinite(lo) and math.isfinite(hi) and lo < hi
                if checked and not (lo - 1e-9 <= value <= hi + 1e-9):
                    raise ScenarioError(
                        f"{field}.{name}",
                        value,
                        f"outside the joint limits [{lo:.4g}, {hi:.4g}] rad",
                    )
                indices.append(slot.idx_q)
                values.append(value)
                low.append(lo - 1e-9 if checked else -math.inf)
                high.append(hi + 1e-9 if checked else math.inf)
            elif slot.nq == 2 and slot.nv == 1:  # continuous joint: (cos, sin)
                indices += [slot.idx_q, slot.idx_q + 1]
                values += [math.cos(value), math.sin(value)]
            else:
                raise ScenarioError(
                    f"{field}.{name}", value, "only 1-dof joints can be set by a single value"
                )
        result = np.asarray(indices, dtype=int), np.asarray(values, dtype=float)
        for array in result:
            array.setflags(write=False)
        plans = self._assignment_plans
        if len(low) == len(joints):  # every joint 1-dof: the plan answers next time
            if len(plans) >= 64:  # bounded: interactive use creates many
                plans.clear()
            plans[tuple(joints)] = _JointPlan(result[0], np.array(low), np.array(high))
        return result

    @functools.cached_property
    def _assignment_plans(self) -> dict[tuple[str, ...], _JointPlan]:
        return {}

    def joint_values(self, q: np.ndarray) -> dict[str, float]:
        """Values of the 1-dof joints at configuration ``q`` (rad or m).

        Continuous joints are given by their angle.
        """
        model = self.model
        out = {}
        for jid in range(2, model.njoints):
            joint = model.joints[jid]
            if joint.nq == 1:
                out[model.names[jid]] = float(q[joint.idx_q])
            elif joint.nq == 2 and joint.nv == 1:
                out[model.names[jid]] = math.atan2(float(q[joint.idx_q + 1]), float(q[joint.idx_q]))
        return out

    def configuration(self, name: str | None = None, field: str = "configuration") -> np.ndarray:
        """A copy of the named reference configuration (default: the standing one)."""
        key = self.standing if name is None else name
        if key not in self.reference_configurations:
            raise UnknownConfigurationError(field, key, self.reference_configurations)
        answer: _FloatArray = self.reference_configurations[key].copy()
        return answer

    def actuated_effort_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Velocity indices of the torque-limited actuated joints and their effort limits (N m).

        A joint whose URDF effort limit is 0, missing or infinite is unlimited and left out.
        """
        idx, lim = self.effort_limits
        return idx.copy(), lim.copy()

    def actuated_velocity_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """Velocity indices of the velocity-limited actuated joints and their limits (rad/s)."""
        idx, lim = self._velocity_limits
        return idx.copy(), lim.copy()

    @functools.cached_property
    def effort_limits(self) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`actuated_effort_limits`, computed once (read-only arrays: never copied)."""
        return self._limited(self.model.effortLimit)

    @functools.cached_property
    def _velocity_limits(self) -> tuple[np.ndarray, np.ndarray]:
        return self._limited(self.model.velocityLimit)

    def _limited(self, limits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        limits = np.asarray(limits, dtype=float)
        offset = self.model.nv - limits.size  # some versions store nu entries, not nv
        indices, values = [], []
        for joint in list(self.model.joints)[2:]:
            for k in range(joint.idx_v, joint.idx_v + joint.nv):
                value = limits[k - offset] if 0 <= k - offset < limits.size else 0.0
                if math.isfinite(value) and value > 0.0:
                    indices.append(k)
                    values.append(value)
        idx, val = np.asarray(indices, dtype=int), np.asarray(values, dtype=float)
        idx.setflags(write=False)
        val.setflags(write=False)
        return idx, val

    @functools.cached_property
    def _thread_data(self) -> ThreadData:
        return ThreadData(self.model)

    def thread_data(self) -> ThreadData:
        """This thread's scratch pinocchio Data for the model (see :class:`ThreadData`)."""
        return self._thread_data


def _is_file(path: Path) -> bool:
    try:
        return path.is_file()
    except (OSError, ValueError):  # a name too long for the file system, a NUL character
        return False


_FD_LOCK = threading.Lock()


@contextlib.contextmanager
def _native_stderr(lines: list[str]) -> Iterator[None]:
    """Collect what C++ code writes to file descriptor 2 into ``lines``.

    urdfdom writes its "Error: ..." lines there; they are kept out of the terminal so that a failure
    is reported once, as one line naming the file.

    Redirecting a descriptor is process-wide, so loads are serialised; another thread's
    writes to stderr during a load (a few ms) are collected too, and dropped.
    """
    with _FD_LOCK, tempfile.TemporaryFile(mode="w+b") as sink:
        sys.stderr.flush()
        saved = os.dup(2)
        try:
            os.dup2(sink.fileno(), 2)
            yield
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            sink.seek(0)
            text = sink.read(20_000).decode("utf-8", "replace")
            lines += [ln.strip() for ln in text.splitlines() if ln.strip()]


def _native_reason(lines: list[str], fallback: str) -> str:
    """The first urdfdom "Error:" line (the cause), else ``fallback``."""
    for line in lines:
        if line.startswith("Error:"):
            return f"{fallback} ({line.removeprefix('Error:').strip()})"
    return fallback


def _build_model(urdf: Path, native: list[str], data: bytes | None = None) -> pin.Model:
    """The pinocchio model of the URDF, from the bytes that :func:`check_urdf` accepted.

    What urdfdom refuses while pinocchio still builds a model (an ``<inertial>`` it skips, so
    the link loads massless) is an error, as is a total mass other than the file's.
    """
    source = str(urdf)
    if data is None:
        data = read_robot_file(urdf)
    text, masses = check_urdf(data, source)
    try:
        with _native_stderr(native):
            model = pin.buildModelFromXML(text, pin.JointModelFreeFlyer())
    except (RuntimeError, ValueError, OSError) as exc:
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else "invalid URDF"
        if source in first:  # pinocchio repeats the path
            first = "not a valid URDF model"
        raise RobotLoadError(source, _native_reason(native, first)) from None
    refused = [ln.removeprefix("Error:").strip() for ln in native if ln.startswith("Error:")]
    if refused:
        raise RobotLoadError(source, "urdfdom refused part of it: " + "; ".join(refused[:3]))
    declared, built = sum(masses.values()), float(sum(i.mass for i in model.inertias))
    if not math.isclose(declared, built, rel_tol=1e-9, abs_tol=1e-12):
        raise RobotLoadError(
            source, f"the links' masses add up to {declared:.6g} kg, the model to {built:.6g} kg"
        )
    return model


def _check_srdf_values(model: pin.Model, srdf: Path, configurations: Mapping[str, Any]) -> None:
    for name, q in configurations.items():
        if not np.all(np.isfinite(q)):
            raise RobotLoadError(str(srdf), f"group_state {name!r}: a joint value is not finite")
    armature = np.asarray(model.armature, dtype=float)
    if armature.size and not (np.all(np.isfinite(armature)) and np.all(armature >= 0.0)):
        raise RobotLoadError(str(srdf), "rotor_params: an armature is negative or not finite")


def _load(
    urdf: Path,
    srdf: Path | None,
    name: str,
    standing: str | None,
    urdf_data: bytes | None = None,
    srdf_data: bytes | None = None,
) -> Robot:
    """The robot of a URDF (+ SRDF), parsed from the bytes given (read here when None)."""
    package_dirs = [str(urdf.parent.parent.parent), str(urdf.parent.parent)]
    native: list[str] = []
    model = _build_model(urdf, native, urdf_data)
    configurations = {"neutral": pin.neutral(model)}
    armature_source = None
    if srdf is not None:
        data = srdf_data if srdf_data is not None else read_robot_file(srdf)
        srdf_text = check_srdf(data, str(srdf))
        try:
            with _native_stderr(native):
                pin.loadReferenceConfigurationsFromXML(model, srdf_text, False)
        except (RuntimeError, ValueError, OSError) as exc:
            raise RobotLoadError(
                str(srdf), _native_reason(native, str(exc).strip() or "invalid SRDF")
            ) from None
        for entry in model.referenceConfigurations:
            configurations[entry.key()] = np.array(entry.data(), dtype=float)
        if "rotor_params" in srdf_text:
            armature_source = _load_rotor_parameters(model, srdf, srdf_text, native)
        _check_srdf_values(model, srdf, configurations)
    if standing is None:
        standing = "half_sitting" if "half_sitting" in configurations else "neutral"
    if standing not in configurations:
        raise UnknownConfigurationError("robot.standing", standing, configurations)
    return Robot(name, model, configurations, standing, urdf, srdf, package_dirs, armature_source)


def _load_rotor_parameters(model: pin.Model, srdf: Path, text: str, native: list[str]) -> str:
    """Read the SRDF's ``rotor_params`` into ``model.armature``.

    Each joint's rotor inertia and gear ratio give ``model.armature`` = gear ratio^2 x rotor
    inertia, the rotor inertia reflected at the joint (called when the SRDF declares
    ``rotor_params``). Returns where it came from.
    """
    # pinocchio reads rotor parameters from a path only: give it a private copy of the text
    # that was checked, never the user's file again (which may have changed since).
    try:
        with tempfile.TemporaryDirectory() as folder, _native_stderr(native):
            copy = Path(folder) / srdf.name
            copy.write_text(text, encoding="utf-8")
            pin.loadRotorParameters(model, str(copy), False)
    except (RuntimeError, ValueError, OSError) as exc:
        raise RobotLoadError(
            str(srdf), _native_reason(native, str(exc).strip() or "invalid rotor_params")
        ) from None
    # pinocchio >= 3.? sets the armature itself; older versions only fill the rotor fields.
    model.armature = np.asarray(model.rotorGearRatio) ** 2 * np.asarray(model.rotorInertia)
    return f"{srdf.name} rotor_params (armature = gear ratio^2 x rotor inertia)"


def _bundled_urdf(name: str) -> Path:
    return example_robot_data_root() / BUNDLED_ROBOTS[name].urdf


@functools.lru_cache(maxsize=16)
def _load_bundled(name: str) -> Robot:
    spec = BUNDLED_ROBOTS[name]
    root = example_robot_data_root()
    return _load(root / spec.urdf, root / spec.srdf if spec.srdf else None, name, spec.standing)


@functools.lru_cache(maxsize=16)
def _load_example(name: str) -> Robot:
    spec = EXAMPLE_ROBOTS[name]
    root = example_robot_data_root()
    return _load(root / spec.urdf, root / spec.srdf if spec.srdf else None, name, spec.standing)


def load_robot(
    robot: str | None = None,
    urdf: str | Path | None = None,
    srdf: str | Path | None = None,
    standing: str | None = None,
    *,
    read_file: RobotFileReader | None = None,
) -> Robot:
    """Load a bundled robot by name, or any URDF (+ optional SRDF) that pinocchio reads.

    Models are cached (bundled ones by name, files by path, modification time and size):
    the returned :class:`Robot` is shared, do not mutate its model (copy it:
    ``dataclasses.replace(robot, model=pinocchio.Model(robot.model))``).
    """
    if urdf is None:
        name = robot or "talos"
        if name in EXAMPLE_ROBOTS and name not in BUNDLED_ROBOTS:
            return _load_example(name)
        if name not in BUNDLED_ROBOTS:
            raise UnknownRobotError("robot", name, robot_names())
        return _load_bundled(name)
    urdf = Path(urdf)
    if read_file is None and not _is_file(urdf):
        read_robot_file(urdf)  # names what it is: missing, not a regular file, unreadable
    srdf_path = Path(srdf) if srdf else None
    # Each file is read once, and the model is parsed from those bytes and cached by their
    # digest: an edited file is reloaded, and a file rewritten while it loads can never leave
    # one content's model under another content's key.
    read = read_file or read_robot_file
    urdf_data = read(urdf)
    srdf_data = read(srdf_path) if srdf_path else None
    key = (
        str(urdf.resolve()),
        hashlib.sha256(urdf_data).hexdigest(),
        hashlib.sha256(srdf_data).hexdigest() if srdf_data is not None else None,
        robot or urdf.stem,
        standing,
    )
    cached = _FILE_ROBOTS.get(key)
    if cached is None:
        cached = _load(urdf, srdf_path, robot or urdf.stem, standing, urdf_data, srdf_data)
        if len(_FILE_ROBOTS) >= 16:  # bounded
            _FILE_ROBOTS.pop(next(iter(_FILE_ROBOTS)))
        _FILE_ROBOTS[key] = cached
    return cached


#: Robots loaded from files, by the digests of the URDF and SRDF bytes they were parsed from.
_FILE_ROBOTS: dict[tuple[Any, ...], Robot] = {}
