"""An impact trial: the impacting end-effector reaches the surface at a commanded approach speed.

``rigid`` joints: gravity off, the sustained contacts off (the robot floats), the whole robot
starts ``gap`` away from the surface (along the impact normal) with a pure translation
velocity ``-v_n n``, so the impact point approaches at ``v_n``. This is exactly the paper's
impact of one rigid body.

``servo`` joints: gravity on, the robot stands on its contacts. It first settles for
``settle`` seconds with the impacting limb retracted by ``gap``; then the limb's servo
targets move the impact point along ``-n`` at ``v_n`` (joint velocities from the limb's
Jacobian pseudo-inverse at the stance, the least-norm ones that keep the retracted start pose
within the joint limits when it would leave them, :func:`approach_joint_velocity`; positions
integrated from the retracted pose). They
go on past the stance if the servos lag, and stop where they are once the impact force
appears (a kinematic controller stops at contact). Every other joint holds the stance. The
limb is the chain of joints that leads to the impact frame and carries nothing else (Talos'
right arm for a palm push, the left leg for a kick).

The recorded time series (:class:`TrialRecord`) is what :mod:`.measure` reads and what the
log and the figures show.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import SimulationError
from impact_balance.impact.model import ImpactSpec
from impact_balance.ranges import MAX_APPROACH_SPEED, check_approach_speed
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.rigid_impact import RigidImpactHold

__all__ = [
    "MAX_APPROACH_SPEED",
    "TrialOptions",
    "TrialRecord",
    "approach_joint_velocity",
    "impact_limb",
    "run_trial",
]

_FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class TrialOptions:
    """How an impact trial runs.

    Attributes:
        approach_speed: Commanded approach speed v_n of the impact point along -n, m/s.
        after: Simulated time kept after the impact begins, s.
        gap: Initial distance of the impact point from the surface, m (default: the larger
            of 2 cm and 0.1 s of travel, so the servos reach the commanded speed).
        settle: ``servo`` only: time standing still before the approach, s.
        rigid_impact: ``servo`` only: hold every joint's velocity from the contact to the end of the
            compression (:mod:`.rigid_impact`), the paper's rigid robot at the impact.
    """

    approach_speed: float
    after: float = 0.15
    gap: float | None = None
    settle: float = 0.2
    rigid_impact: bool = False

    def resolved_gap(self) -> float:
        """The start gap (m): ``gap``, else 0.1 s of travel at the approach speed, at least 2 cm."""
        return self.gap if self.gap is not None else max(0.02, 0.1 * self.approach_speed)


@dataclass
class TrialRecord:
    """Time series of a trial, one row per integration step (world axes, SI units).

    Attributes:
        time: s, from the start of the trial (settling included).
        qpos, qvel: MuJoCo state (free joint: position, quaternion wxyz, world linear and
            base-frame angular velocity).
        com, com_velocity: CoM position and velocity, m and m/s.
        forces: Force on the robot per name (each contact's frame, and ``impact``), N, (T, 3).
        impact_velocity: Velocity of the impact point, m/s, (T, 3).
        approach_start: Time the approach begins (end of settling), s.
        hold: The rigid-impact hold (:meth:`.rigid_impact.RigidImpactHold.to_dict`), or None.
        contact_positions: Centre of each sustained-contact box, world, m, (T, k, 3).
        actuator_force: Servo torques (N m), (T, nu), aligned with ``SimModel.joint_names``.
        wall_time: Wall-clock time of the simulation loop (recording included), s.
    """

    time: np.ndarray
    qpos: np.ndarray
    qvel: np.ndarray
    com: np.ndarray
    com_velocity: np.ndarray
    forces: dict[str, np.ndarray]
    impact_velocity: np.ndarray
    approach_start: float
    wall_time: float
    contact_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 3)))
    actuator_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 0)))
    hold: dict[str, Any] | None = None

    @property
    def simulated_time(self) -> float:
        """Simulated time (s) from the first sample to the last."""
        return float(self.time[-1] - self.time[0]) if self.time.size else 0.0


def impact_limb(sim: SimModel) -> list[str]:
    """Joints of the impacting limb: on the chain to the impact frame, carrying nothing else.

    A joint belongs to the limb when every joint it carries (its subtree) is on the chain to
    the impact frame's joint or beyond it.
    """
    spec = sim.scenario.impact
    if spec is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    model = sim.stance.model
    joint = model.frames[sim.robot.frame_id(spec.frame, "impact.frame")].parentJoint
    chain = []
    j = joint
    while j > 1:
        chain.append(j)
        j = model.parents[j]
    beyond = set(model.subtrees[joint])
    limb = [j for j in chain if set(model.subtrees[j]) <= beyond | set(chain)]
    names = [model.names[j] for j in reversed(limb)]
    return [n for n in names if n in sim.joint_names]


def approach_joint_velocity(
    sim: SimModel, limb: list[str], normal: np.ndarray, gap: float
) -> np.ndarray:
    """Joint velocity of the ``limb`` that moves the impact point at unit speed along ``-normal``.

    Joint velocity (pinocchio ``nv``) of the ``limb`` that moves the impact point at unit speed
    along ``-normal`` at the stance, such that the retracted start pose ``q - gap dq`` is within the
    joints' limits.

    The smallest such ``dq``: the Jacobian's pseudo-inverse solution when its start pose is within
    the limits (MuJoCo's joint ranges), else the least-norm solution with the start pose bounded by
    them (a QP).
    A start pose beyond a limit is not a pose the servos can hold: MuJoCo's limit constraint
    snaps the joint back while the robot settles, and the limb may hit the surface before the
    approach begins (iCub's right shoulder pitch, at 0.085 rad from its limit in
    ``icub_two_feet``).

    Raises:
        SimulationError: No such ``dq`` exists: the approach cannot be commanded along a straight
            joint path from this stance.
    """
    import qpsolvers

    if sim.scenario.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    spec = sim.scenario.impact.spec()
    model = sim.stance.model
    _, J6 = sim.stance.point(spec.frame, spec.offset)
    slots = [sim.robot.joint_slot(j) for j in limb]
    v_cols = np.array([model.joints[s.id].idx_v for s in slots])
    J = J6[:3, v_cols]
    dq = np.linalg.pinv(J) @ (-normal)
    mj_joints = [sim.model.joint(j).id for j in limb]
    limited = sim.model.jnt_limited[mj_joints].astype(bool)
    low, high = sim.model.jnt_range[mj_joints].T
    q = sim.stance.q[[model.joints[s.id].idx_q for s in slots]]
    start = q - gap * dq
    # A start pose within the limits (or a joint already beyond its limit at the stance, kept
    # as it is).
    outside = limited & (((start < low) & (dq > 0)) | ((start > high) & (dq < 0)))
    if outside.any():
        big = 1e6  # rad/m: no bound
        lower = np.where(limited, np.minimum((q - high) / gap, 0.0), -big)  # q - gap dq <= high
        upper = np.where(limited, np.maximum((q - low) / gap, 0.0), big)  # q - gap dq >= low
        solution = qpsolvers.solve_qp(
            np.eye(len(limb)),
            np.zeros(len(limb)),
            A=J,
            b=-normal,
            lb=lower,
            ub=upper,
            solver="daqp",
        )
        if solution is None or not np.allclose(J @ solution, -normal, atol=1e-6):
            names = ", ".join(
                f"{j} ({q_j:+.3f} rad, range [{lo:+.3f}, {hi:+.3f}])"
                for j, q_j, lo, hi, bad in zip(limb, q, low, high, outside, strict=False)
                if bad
            )
            raise SimulationError(
                "impact",
                spec.frame,
                f"the limb cannot start {gap:.3f} m back from the surface within its joint "
                "limits: a straight joint path that moves the impact point along the normal "
                f"would take {names} beyond its limit",
            )
        dq = solution
    out = np.zeros(model.nv)
    out[v_cols] = dq
    return out


def run_trial(sim: SimModel, options: TrialOptions) -> TrialRecord:
    """Run one impact trial on ``sim`` (reset to the stance first); see the module docstring.

    Args:
        sim: The scenario's model (``rigid`` or ``servo`` joints).
        options: Approach speed, gap, settling and after times.

    Returns:
        The trial's time series.

    Raises:
        SimulationError: The scenario has no impact, the approach speed is out of range, or no
            joint path brings the impact point to the surface.
    """
    if sim.scenario.impact is None or sim.impact_geom is None:
        raise SimulationError("impact", None, "the scenario has no impact to simulate")
    v_n = options.approach_speed
    check_approach_speed(v_n)
    m, d = sim.model, sim.data
    spec = sim.scenario.impact.spec()
    n = np.asarray(spec.normal, dtype=float) / np.linalg.norm(spec.normal)
    gap = options.resolved_gap()
    travel = gap / v_n
    gravity = m.opt.gravity.copy()
    start = _start(sim, options, spec, n, gap)
    total = start.settle + 1.5 * travel + options.after
    steps = round(total / m.opt.timestep)
    frames = [c.spec.frame for c in sim.stance.contacts]
    # Log names: the contact's frame, made unique with its index when two contacts share a frame.
    names = [f if frames.count(f) == 1 else f"{f}_{i}" for i, f in enumerate(frames)] + ["impact"]
    rec = _Samples.empty(sim, steps)
    # mj_step computes the kinematics, contacts and forces of the state it starts from, then
    # integrates: sample k is the state before step k, with what mj_step computed from it
    # (its contact forces act from sample k to sample k + 1).
    d.time = 0.0
    wall0 = time.perf_counter()
    hold = None
    if options.rigid_impact and sim.joints == "servo":
        hold = RigidImpactHold(sim)
    surface = float(n @ np.asarray(sim.stance.point(spec.frame, spec.offset)[0].translation))
    try:
        _simulate(sim, rec, start, n, v_n, surface, hold)
    finally:
        wall = time.perf_counter() - wall0
        m.opt.gravity[:] = gravity
        sim.enable_supports(True)
        if hold is not None:
            hold.release(d.time)
    return TrialRecord(
        time=rec.time,
        qpos=rec.qpos,
        qvel=rec.qvel,
        com=rec.com,
        com_velocity=rec.com_velocity,
        forces={name: rec.forces[:, i] for i, name in enumerate(names)},
        impact_velocity=rec.point_velocity,
        approach_start=start.settle,
        wall_time=wall,
        contact_positions=rec.contact_positions,
        actuator_force=rec.torques[:, sim.actuator_ids] if m.nu else rec.torques,
        hold=None if hold is None else hold.to_dict(),
    )


@dataclass(frozen=True)
class _Start:
    """How a trial starts: settling time, the limb's joint velocity and the start configuration.

    Settling time in s; the joint velocity is per unit approach speed (None with rigid joints: the
    whole robot flies at the surface).
    """

    settle: float
    limb_dq: _FloatArray | None
    q_start: _FloatArray


def _start(
    sim: SimModel, options: TrialOptions, spec: ImpactSpec, n: _FloatArray, gap: float
) -> _Start:
    """Set ``sim`` to the trial's start.

    With ``rigid`` joints the robot ``gap`` back from the surface, flying at it without gravity nor
    supports; with ``servo`` joints the limb backed off.
    """
    v_n = options.approach_speed
    if sim.joints == "rigid":
        q0 = sim.stance.q.copy()
        sim.model.opt.gravity[:] = 0.0
        sim.enable_supports(False)
        q0[:3] += gap * n
        R = pin.Quaternion(q0[6], q0[3], q0[4], q0[5]).toRotationMatrix()
        v0 = np.zeros(sim.stance.model.nv)
        v0[:3] = R.T @ (-v_n * n)
        sim.set_state(q0, v0)
        return _Start(0.0, None, q0)
    sim.enable_supports(True)
    limb = impact_limb(sim)
    if not limb:
        raise SimulationError(
            "impact.frame",
            spec.frame,
            "no joint moves the impact point without moving a contact",
        )
    limb_dq = approach_joint_velocity(sim, limb, n, gap)  # joint velocity per unit approach speed
    q_start = pin.integrate(sim.stance.model, sim.stance.q, -gap * limb_dq)
    sim.set_state(q_start)
    sim.set_servo_targets(q_start)
    return _Start(options.settle, limb_dq, q_start)


@dataclass(frozen=True)
class _Samples:
    """The trial's samples, one row per integration step (see :class:`TrialRecord`)."""

    time: _FloatArray
    qpos: _FloatArray
    qvel: _FloatArray
    com: _FloatArray
    com_velocity: _FloatArray
    forces: _FloatArray
    point_velocity: _FloatArray
    contact_positions: _FloatArray
    torques: _FloatArray

    @classmethod
    def empty(cls, sim: SimModel, steps: int) -> _Samples:
        m, k = sim.model, len(sim.contact_geoms)
        return cls(
            time=np.empty(steps),
            qpos=np.empty((steps, m.nq)),
            qvel=np.empty((steps, m.nv)),
            com=np.empty((steps, 3)),
            com_velocity=np.empty((steps, 3)),
            forces=np.empty((steps, k + 1, 3)),
            point_velocity=np.empty((steps, 3)),
            contact_positions=np.empty((steps, k, 3)),
            torques=np.empty((steps, m.nu)),
        )


def _simulate(
    sim: SimModel,
    rec: _Samples,
    start: _Start,
    n: _FloatArray,
    v_n: float,
    surface: float,
    hold: RigidImpactHold | None,
) -> None:
    """Step MuJoCo, driving the limb at ``v_n`` (m/s) until the contact, and fill ``rec``."""
    m, d = sim.model, sim.data
    dt = m.opt.timestep
    assert sim.impact_geom is not None
    geoms = [*sim.contact_geoms, sim.impact_geom]
    radius = float(m.geom_size[sim.impact_geom][0])
    limb_dq, q_start, settle = start.limb_dq, start.q_start, start.settle
    frozen = None  # servo targets once the impact begins
    for k in range(len(rec.time)):
        if hold is not None and hold.start is None:
            # Hold from the step in which the point will touch: its gap closes within one step.
            approach = float(-n @ sim.impact_point_velocity(n))
            gap = float(n @ (d.geom_xpos[sim.impact_geom] - radius * n)) - surface
            if gap - max(0.0, approach) * dt <= 0.0:
                hold.begin(d.time)
        if limb_dq is not None:
            s = d.time - settle  # time into the approach
            if frozen is None and s > 0.0 and k > 0 and rec.forces[k - 1, -1].any():
                # A kinematic controller stops the limb at contact: hold the targets there.
                frozen = pin.integrate(sim.stance.model, q_start, s * v_n * limb_dq)
            if frozen is not None:
                sim.set_servo_targets(frozen)
            elif s > 0.0:
                # Past the stance if need be: the servos lag, the surface is where the stance
                # touches it.
                sim.set_servo_targets(
                    pin.integrate(sim.stance.model, q_start, s * v_n * limb_dq), v_n * limb_dq
                )
        rec.time[k] = d.time
        rec.qpos[k], rec.qvel[k] = d.qpos, d.qvel
        mujoco.mj_step(m, d)
        mujoco.mj_subtreeVel(m, d)
        rec.com[k] = d.subtree_com[sim.root_body]
        rec.com_velocity[k] = d.subtree_linvel[sim.root_body]
        rec.forces[k] = sim.contact_forces(geoms)
        rec.point_velocity[k] = sim.impact_point_velocity(n)
        rec.contact_positions[k] = d.geom_xpos[list(sim.contact_geoms)]
        rec.torques[k] = d.actuator_force
        if hold is not None:
            hold.update(d.time, float(-n @ rec.point_velocity[k]))
