"""The MuJoCo model of a scenario: :func:`build_model` -> :class:`SimModel`.

API in one paragraph: ``build_model(scenario, joints="servo" | "rigid", options=SimOptions())``
loads the scenario's robot through the same URDF as pinocchio (:mod:`.urdf`), adds one
collision box per contact rectangle, a sphere at the impact point and the environment
(:mod:`.environment`), applies the joint model (:mod:`.joints`), compiles, and returns a
:class:`SimModel` already set to the stance (at rest). ``SimModel`` holds ``model``/``data``
(``mujoco.MjModel``/``MjData``), the ``stance`` (pinocchio), the simulated actuated
joints ``joint_names`` (pinocchio names; all 1-dof joints for ``servo``, none for ``rigid``)
with their MuJoCo ``qpos_adr``, ``dof_adr`` and ``actuator_ids`` and pinocchio ``q_index``,
``v_index``; the geom ids ``contact_geoms`` (one per scenario contact, in order),
``support_geoms``, ``ground_geom``, ``impact_geom`` and ``surface_geom`` (None without an
impact); the servo gains ``kp``, ``kd``, the holding torques ``tau_hold``, and the joints' rotor
inertia ``armature`` (kg m^2) with where it came from, ``armature_source``. Its helpers
convert state both ways: ``set_state(q, v)`` takes a pinocchio configuration and velocity
(free-flyer ``[x, y, z, qx, qy, qz, qw]``, base velocity in the base frame) and runs
``mj_forward``; ``configuration()`` and ``velocity()`` read them back; ``com()`` and
``com_velocity()`` (m, m/s, world); ``contact_force(geom)`` (N, world, on the robot);
``set_servo_targets(q_ref, v_ref)`` writes the servo commands (the holding torques
included). ``inertia_repair`` says which inertials were changed for MuJoCo (see
:mod:`.inertia`; a :class:`~impact_balance.exceptions.ModelRepairWarning` names them once). MuJoCo's
free joint stores the base orientation as (w, x, y, z) and its angular
velocity in the base frame, but its linear velocity in world axes: the helpers convert.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field
from pathlib import Path

import mujoco
import numpy as np
import numpy.typing as npt

from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ModelRepairWarning, SimulationError
from impact_balance.robot.robot import JointSlot, Robot
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.model.environment import ContactParameters, add_geometry
from impact_balance.sim.model.inertia import InertiaRepair, repair_message
from impact_balance.sim.model.joints import (
    JointModel,
    ServoOptions,
    check_joint_model,
    holding_torques,
    servo_gains,
    weld_joints,
)
from impact_balance.sim.model.urdf import ROOT_JOINT, robot_spec

__all__ = ["SimModel", "SimOptions", "build_model"]

_FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class SimOptions:
    """Options of the simulated model.

    Attributes:
        timestep: Integration step, s.
        contact: Geometry and contact parameters (:class:`.environment.ContactParameters`).
        servo: Servo parameters (:class:`.joints.ServoOptions`), used by ``joints="servo"``.
        meshes: Load the robot's meshes (visual only; needed for video).
        elliptic_cone: Elliptic friction cones (exact Coulomb); MuJoCo's default pyramid has
            4 edges, inscribed, and would under-estimate friction between its edges.
        impratio: MuJoCo's ratio of frictional to normal constraint impedance. MuJoCo's soft
            friction lets a loaded contact creep; 10 (MuJoCo's default: 1) stiffens friction so
            that a foot on the 30 degree ramp stays put.
    """

    timestep: float = 0.001
    contact: ContactParameters = field(default_factory=ContactParameters)
    servo: ServoOptions = field(default_factory=ServoOptions)
    meshes: bool = True
    elliptic_cone: bool = True
    impratio: float = 10.0


@dataclass
class SimModel:
    """A scenario's MuJoCo model and the maps between it and pinocchio (see the module docstring).

    Index arrays are aligned with ``joint_names``.
    """

    scenario: Scenario
    stance: Stance
    joints: JointModel
    options: SimOptions
    model: mujoco.MjModel
    data: mujoco.MjData
    joint_names: tuple[str, ...]
    qpos_adr: np.ndarray
    dof_adr: np.ndarray
    actuator_ids: np.ndarray
    q_index: np.ndarray
    v_index: np.ndarray
    root_body: int
    contact_geoms: tuple[int, ...]
    support_geoms: tuple[int, ...]
    ground_geom: int
    impact_geom: int | None
    surface_geom: int | None
    kp: np.ndarray
    kd: np.ndarray
    tau_hold: np.ndarray
    armature: np.ndarray = field(default_factory=lambda: np.zeros(0))
    armature_source: str = "none (rigid joints)"
    inertia_repair: InertiaRepair | None = None

    @property
    def robot(self) -> Robot:
        """The scenario's robot (pinocchio)."""
        return self.stance.robot

    @property
    def mass(self) -> float:
        """Total robot mass in the MuJoCo model, kg."""
        return float(self.model.body_subtreemass[self.root_body])

    # -- state --------------------------------------------------------------------------
    def set_state(self, q: np.ndarray, v: np.ndarray | None = None) -> None:
        """Set MuJoCo's state from a pinocchio configuration and velocity, then forward.

        ``q`` and ``v`` are pinocchio's; ``v`` is zero when None.

        With ``rigid`` joints, only the free-flyer part of ``q`` and ``v`` is used (the
        joints stay at the stance).
        """
        m, d = self.model, self.data
        q = np.asarray(q, dtype=float)
        d.qpos[0:3] = q[0:3]
        d.qpos[3:7] = (q[6], q[3], q[4], q[5])
        d.qpos[self.qpos_adr] = q[self.q_index]
        d.qvel[:] = 0.0
        if v is not None:
            v = np.asarray(v, dtype=float)
            rotation = np.empty(9)
            mujoco.mju_quat2Mat(rotation, d.qpos[3:7])
            d.qvel[0:3] = rotation.reshape(3, 3) @ v[0:3]
            d.qvel[3:6] = v[3:6]
            d.qvel[self.dof_adr] = v[self.v_index]
        mujoco.mj_forward(m, d)

    def configuration(self) -> np.ndarray:
        """The pinocchio configuration of the current MuJoCo state (welded joints at the stance)."""
        d = self.data
        q: _FloatArray = self.stance.q.copy()
        q[0:3] = d.qpos[0:3]
        w, x, y, z = d.qpos[3:7]
        q[3:7] = (x, y, z, w)
        q[self.q_index] = d.qpos[self.qpos_adr]
        return q

    def velocity(self) -> np.ndarray:
        """The pinocchio velocity of the current state (base velocities in the base frame)."""
        d = self.data
        v = np.zeros(self.stance.model.nv)
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, d.qpos[3:7])
        v[0:3] = rotation.reshape(3, 3).T @ d.qvel[0:3]
        v[3:6] = d.qvel[3:6]
        v[self.v_index] = d.qvel[self.dof_adr]
        return v

    def base_velocity_world(self) -> tuple[np.ndarray, np.ndarray]:
        """Linear velocity of the base origin and angular velocity of the base (world axes)."""
        d = self.data
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, d.qpos[3:7])
        return d.qvel[0:3].copy(), rotation.reshape(3, 3) @ d.qvel[3:6]

    def com(self) -> np.ndarray:
        """Centre of mass, world, m (valid after a forward or a step)."""
        answer: _FloatArray = self.data.subtree_com[self.root_body].copy()
        return answer

    def com_velocity(self) -> np.ndarray:
        """CoM velocity, world, m/s (computes MuJoCo's subtree velocities)."""
        mujoco.mj_subtreeVel(self.model, self.data)
        answer: _FloatArray = self.data.subtree_linvel[self.root_body].copy()
        return answer

    def impact_point_velocity(self, normal: np.ndarray) -> np.ndarray:
        """World velocity of the impact point (m/s).

        The impact point is the impact sphere's surface point along ``-normal``.

        Args:
            normal: Unit surface normal (world), from the surface into the robot.

        Returns:
            The point's linear velocity (3,), world axes.

        Raises:
            SimulationError: The model has no impact sphere.
        """
        if self.impact_geom is None:
            raise SimulationError("impact", None, "the model has no impact point")
        out = np.zeros(6)
        mujoco.mj_objectVelocity(
            self.model, self.data, mujoco.mjtObj.mjOBJ_GEOM, self.impact_geom, out, 0
        )
        r = -self.model.geom_size[self.impact_geom][0] * normal
        (wx, wy, wz), (rx, ry, rz) = out[:3].tolist(), r.tolist()
        answer: _FloatArray = out[3:] + np.array(
            (wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx)
        )
        return answer

    def contact_force(self, geom: int) -> np.ndarray:
        """Total contact force on the robot at ``geom`` (a collision geom of it), N, world axes."""
        m, d = self.model, self.data
        total = np.zeros(3)
        local = np.zeros(6)
        for i in range(d.ncon):
            contact = d.contact[i]
            if contact.geom1 != geom and contact.geom2 != geom:
                continue
            mujoco.mj_contactForce(m, d, i, local)
            # The force acts on geom2, along the contact frame whose first row (normal) points from
            # geom1 to geom2.
            world = contact.frame.reshape(3, 3).T @ local[:3]
            total += world if contact.geom2 == geom else -world
        return total

    def contact_forces(self, geoms: tuple[int, ...] | list[int]) -> np.ndarray:
        """:meth:`contact_force` of several geoms at once, (len(geoms), 3), N, world, on the robot.

        Vectorised over the contacts: with elliptic cones (the default) a contact's force in
        its frame is its rows of ``efc_force`` (normal, then the two tangents), which is what
        ``mj_contactForce`` returns; with pyramidal cones it falls back to that function.
        """
        m, d = self.model, self.data
        out = np.zeros((len(geoms), 3))
        if d.ncon == 0:
            return out
        if m.opt.cone != mujoco.mjtCone.mjCONE_ELLIPTIC:
            for k, g in enumerate(geoms):
                out[k] = self.contact_force(g)
            return out
        contacts = d.contact
        address = contacts.efc_address
        active = (address >= 0) & (contacts.dim >= 3)
        if not active.any():
            return out
        address = address[active]
        local = d.efc_force[address[:, None] + np.arange(3)]  # (k, 3) in each contact frame
        world = np.einsum("kji,kj->ki", contacts.frame[active].reshape(-1, 3, 3), local)
        wanted = np.asarray(geoms)[:, None]
        sign = (contacts.geom2[active][None, :] == wanted).astype(float)
        sign -= contacts.geom1[active][None, :] == wanted
        answer: _FloatArray = sign @ world
        return answer

    def enable_supports(self, enabled: bool = True) -> None:
        """Let the sustained contacts touch their supports (default), or not (a floating robot).

        Disabling sets the pairs' margin to -1 m (contact only past 1 m of penetration).
        """
        surface = {self.surface_geom}
        for i in range(self.model.npair):
            if int(self.model.pair_geom1[i]) not in surface:
                self.model.pair_margin[i] = 0.0 if enabled else -1.0

    def enable_impact_surface(self, enabled: bool = True) -> None:
        """Let the impact point touch the impacted surface (default), or not.

        A push trial has no impacted surface, so that a falling robot cannot lean on it. Disabling
        sets the pair's margin to -1 m.
        """
        if self.surface_geom is None:
            return
        for i in range(self.model.npair):
            if int(self.model.pair_geom1[i]) == self.surface_geom:
                self.model.pair_margin[i] = 0.0 if enabled else -1.0

    def set_servo_targets(self, q_ref: np.ndarray, v_ref: np.ndarray | None = None) -> None:
        """Servo commands from target joint positions and velocities (pinocchio order).

        The holding torques (:attr:`tau_hold`) are added as a feed-forward.
        """
        if self.actuator_ids.size == 0:
            return
        target = np.asarray(q_ref, dtype=float)[self.q_index]
        ctrl = target + self.tau_hold / self.kp
        if v_ref is not None:
            ctrl += self.kd / self.kp * np.asarray(v_ref, dtype=float)[self.v_index]
        self.data.ctrl[self.actuator_ids] = ctrl


def _joint_bodies(spec: mujoco.MjSpec, stance: Stance) -> dict[int, mujoco.MjsBody]:
    """MuJoCo body of each pinocchio joint id (1 = the root's free flyer)."""
    model = stance.model
    bodies = {1: spec.joint(ROOT_JOINT).parent}
    for jid in range(2, model.njoints):
        joint = spec.joint(model.names[jid])
        if joint is None:
            raise SimulationError(
                "robot", model.names[jid], "joint missing from MuJoCo's reading of the URDF"
            )
        bodies[jid] = joint.parent
    return bodies


def _armature(robot: Robot, override: float | None, v_index: list[int]) -> tuple[np.ndarray, str]:
    """Rotor inertia of each simulated joint (kg m^2) and its source.

    The source is ``override`` for every joint, or what the robot files declare (pinocchio's
    ``model.armature``, read from the SRDF's rotor_params).
    """
    if override is not None:
        return np.full(
            len(v_index), float(override)
        ), f"--armature {override:g} kg m^2 (every joint)"
    declared = np.asarray(robot.model.armature, dtype=float)[v_index] if v_index else np.zeros(0)
    if robot.armature_source is None:
        return declared, "none declared by the robot files (0)"
    return declared, robot.armature_source


def build_model(
    scenario: Scenario | str | Path, joints: str = "servo", options: SimOptions | None = None
) -> SimModel:
    """The scenario's MuJoCo model with ``rigid`` or ``servo`` joints, set to the stance at rest.

    Args:
        scenario: The scenario, or its name or file.
        joints: Joint model, ``rigid`` (welded at the stance) or ``servo`` (position servos).
        options: The model's options (default :class:`SimOptions`).

    Returns:
        The model, at the stance, at rest, the servos holding it.

    Raises:
        SimulationError: An unknown joint model, or a robot MuJoCo reads differently.
    """
    joint_model = check_joint_model(joints)
    options = options or SimOptions()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    stance = scenario.build_stance()
    robot = stance.robot
    impact = scenario.impact.spec() if scenario.impact is not None else None

    spec, repair = _robot_spec(robot, scenario.gravity, options)
    names = add_geometry(spec, stance, _joint_bodies(spec, stance), impact, options.contact)

    # Joints simulated as joints (1-dof ones; pinocchio's continuous joints have nq = 2).
    slots = {name: robot.joint_slot(name) for name in robot.joint_names}
    sim_joints = [name for name, s in slots.items() if s.nq == 1 and s.nv == 1]
    # A first model at the stance (for the servo gains and the weld), from a copy: compiling
    # fuses static bodies in the spec itself. Unfused, so that every spec body is in it.
    unfused = spec.copy()
    unfused.compiler.fusestatic = False
    first = unfused.compile()
    stance_qpos = _stance_qpos(first, stance, slots)

    v_of = {name: robot.model.joints[slots[name].id].idx_v for name in sim_joints}
    armature, armature_source = _armature(
        robot, options.servo.armature, [v_of[n] for n in sim_joints]
    )
    if joint_model == "rigid":
        weld_joints(spec, first, stance_qpos)
        sim_joints = []
        armature, armature_source = np.zeros(0), "none (rigid joints)"
    else:
        _add_servos(spec, first, stance_qpos, sim_joints, armature, robot, options.servo)
    model = spec.compile()
    data = mujoco.MjData(model)

    def geom_id(name: str) -> int:
        return int(model.geom(name).id)

    def optional_geom_id(name: str | None) -> int | None:
        return None if name is None else geom_id(name)

    qpos_adr = np.array([model.joint(n).qposadr[0] for n in sim_joints], dtype=int)
    dof_adr = np.array([model.joint(n).dofadr[0] for n in sim_joints], dtype=int)
    actuator_ids = np.array([model.actuator(n).id for n in sim_joints], dtype=int)
    q_index = np.array([slots[n].idx_q for n in sim_joints], dtype=int)
    v_index = np.array([robot.model.joints[slots[n].id].idx_v for n in sim_joints], dtype=int)
    if joint_model == "servo":
        kp = model.actuator_gainprm[actuator_ids, 0].copy()
        kd = -model.actuator_biasprm[actuator_ids, 2].copy()
        tau_hold = holding_torques(stance, scenario.gravity)[v_index - 6]
    else:
        kp = kd = tau_hold = np.zeros(0)
    sim = SimModel(
        scenario=scenario,
        stance=stance,
        joints=joint_model,
        options=options,
        model=model,
        data=data,
        joint_names=tuple(sim_joints),
        qpos_adr=qpos_adr,
        dof_adr=dof_adr,
        actuator_ids=actuator_ids,
        q_index=q_index,
        v_index=v_index,
        root_body=model.joint(ROOT_JOINT).bodyid[0],
        contact_geoms=tuple(geom_id(n) for n in names.contacts),
        support_geoms=tuple(geom_id(n) for n in names.supports),
        ground_geom=geom_id(names.ground),
        impact_geom=optional_geom_id(names.impact),
        surface_geom=optional_geom_id(names.surface),
        kp=kp,
        kd=kd,
        tau_hold=tau_hold,
        armature=armature,
        armature_source=armature_source,
        inertia_repair=repair,
    )
    sim.set_state(stance.q)
    sim.set_servo_targets(stance.q)
    return sim


def _robot_spec(
    robot: Robot, gravity: float, options: SimOptions
) -> tuple[mujoco.MjSpec, InertiaRepair | None]:
    """The robot's MuJoCo spec with the simulation options (a repaired inertial is warned of)."""
    spec, repair = robot_spec(robot, meshes=options.meshes)
    if repair is not None:
        # Once per robot and process: the default filter shows a message once per place it is
        # issued from.
        warnings.warn(
            ModelRepairWarning(robot.name, repair.bodies, repair_message(robot.name, repair)),
            stacklevel=1,
        )
    spec.option.timestep = options.timestep
    spec.option.gravity = [0.0, 0.0, -gravity]
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    if options.elliptic_cone:
        spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = options.impratio
    return spec, repair


def _stance_qpos(first: mujoco.MjModel, stance: Stance, slots: dict[str, JointSlot]) -> _FloatArray:
    """MuJoCo's ``qpos`` of the stance in the model ``first`` (free joint quaternion w first)."""
    stance_qpos = np.zeros(first.nq)
    stance_qpos[0:3] = stance.q[0:3]
    stance_qpos[3:7] = (stance.q[6], *stance.q[3:6])
    for name, slot in slots.items():
        value = (
            stance.q[slot.idx_q]
            if slot.nq == 1
            else np.arctan2(stance.q[slot.idx_q + 1], stance.q[slot.idx_q])
        )
        stance_qpos[first.joint(name).qposadr[0]] = value
    return stance_qpos


def _add_servos(
    spec: mujoco.MjSpec,
    first: mujoco.MjModel,
    stance_qpos: _FloatArray,
    sim_joints: list[str],
    armature: _FloatArray,
    robot: Robot,
    servo: ServoOptions,
) -> None:
    """One position servo per simulated joint, its gains from the joint's inertia at the stance."""
    data = mujoco.MjData(first)
    data.qpos[:] = stance_qpos
    mujoco.mj_forward(first, data)
    full = np.zeros((first.nv, first.nv))
    mujoco.mj_fullM(first, data, full)
    inertia = (
        np.array([full[first.joint(n).dofadr[0], first.joint(n).dofadr[0]] for n in sim_joints])
        + armature
    )
    kp, kd = servo_gains(inertia, servo)
    # velocity index -> N m
    efforts = dict(zip(*(a.tolist() for a in robot.effort_limits), strict=False))
    for name, p, d, a in zip(sim_joints, kp, kd, armature, strict=False):
        joint = spec.joint(name)
        joint.armature = float(a)
        effort = efforts.get(robot.model.joints[robot.joint_slot(name).id].idx_v, 0.0)
        limited = servo.effort_limits and effort > 0.0
        spec.add_actuator(
            name=name,
            target=name,
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
            gaintype=mujoco.mjtGain.mjGAIN_FIXED,
            gainprm=[p] + [0.0] * 9,
            biastype=mujoco.mjtBias.mjBIAS_AFFINE,
            biasprm=[0.0, -p, -d] + [0.0] * 7,
            forcelimited=bool(limited),
            forcerange=[-effort, effort] if limited else [0.0, 0.0],
        )
        if not servo.effort_limits:
            joint.actfrclimited = mujoco.mjtLimited.mjLIMITED_FALSE
