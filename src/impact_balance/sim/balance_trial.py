"""One balance trial in MuJoCo: the controller holds the stance through an impact or a push.

:class:`BalanceSetup` prepares a scenario once (analysis, MuJoCo model, the start configuration
with the hand backed off); :func:`run_balance_trial` resets the model and runs one trial:

- ``impact_speed``: the impact task drives the impact point into the surface at that speed
  (m/s), then pulls back (see :class:`~.balance.ImpactTask`);
- ``push``: a force on a body (the torso) for a short time (see :class:`Push`).

At every control step (500 Hz) the loop reads MuJoCo's state as pinocchio's ``(q, v)``,
runs :class:`~.balance.BalanceController` and writes the servo targets (``controller="ik"``), or
runs :class:`~.inverse_dynamics.InverseDynamicsController` and writes the motor torques
(``controller="id"``, the actuators then being torque motors), and feeds the
:class:`~.falls.FallDetector`. It records the measured ZMP (from the sustained contacts' forces,
on the plane ``z = h``), the CoM, the CoM velocity and the DCM, and their margins in the
scenario's ZMP support area and CoM velocity area, and optionally a log (:mod:`impact_balance.logs`).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import mujoco
import numpy as np
import pandas as pd
import pinocchio as pin

from ..analysis import Analysis, analyze
from ..exceptions import SimulationError
from ..scenario import Scenario, load_scenario
from .balance import BalanceController, BalanceGains, ImpactTask, retracted_stance
from .falls import FallCriteria, FallDetector
from ..logs import write_log
from .actuation import STIFF_SERVOS, stiffen_support_limbs, support_joints, use_torque_motors
from .inverse_dynamics import InverseDynamicsController, InverseDynamicsGains
from .joints import JOINT_MODELS, ServoOptions
from .log import LOG_START, LogRecorder
from .model import SimModel, SimOptions, build_model

#: Iterations of MuJoCo's no-slip solver in balance trials.
NOSLIP_ITERATIONS = 10

#: Balance controllers: ``ik`` (pink IK -> position servos, :mod:`.balance`) and ``id`` (inverse-dynamics QP ->
#: torque motors, :mod:`.inverse_dynamics`).
CONTROLLERS = ("ik", "id")

__all__ = ["CONTROLLERS", "STIFF_SERVOS", "Push", "BalanceTrialOptions", "BalanceSetup", "BalanceTrialResult", "run_balance_trial", "write_trial_log", "measured_zmp"]


@dataclass(frozen=True)
class Push:
    """A horizontal force on a body for a short time (MuJoCo ``xfrc_applied``, at the body's CoM).

    Attributes:
        direction: Direction of the force in the horizontal plane (rad, from world x).
        magnitude: Impulse (N s); the force is ``magnitude / duration``.
        duration: How long the force acts (s), 10-50 ms for an impulsive push.
        start: When it starts (s).
        body: MuJoCo body name (None: the deepest body named like "torso", else the root).
    """

    direction: float
    magnitude: float
    duration: float = 0.02
    start: float = 0.3
    body: str | None = None

    @property
    def force(self) -> np.ndarray:
        f = self.magnitude / self.duration
        return np.array([f * np.cos(self.direction), f * np.sin(self.direction), 0.0])


@dataclass(frozen=True)
class BalanceTrialOptions:
    """Options of a trial.

    Attributes:
        after: Simulated time after the disturbance (contact or end of push) (s).
        settle: Time standing still before the disturbance (s).
        standoff: Distance of the impact point from the surface at the start (m).
        max_approach_time: Longest approach before the trial gives up waiting for the contact (s).
        gains: Gains of the ``ik`` controller.
        criteria: Fall thresholds.
        record: Keep a log (:mod:`impact_balance.logs` columns) in the result.
        controller: ``ik`` (pink IK, position servos) or ``id`` (inverse-dynamics QP, torque motors); it
            decides the actuators, so it is read when the :class:`BalanceSetup` is created.
        id_gains: Gains of the ``id`` controller.
    """

    after: float = 2.5
    settle: float = 0.3
    standoff: float = 0.05
    max_approach_time: float = 2.0
    gains: BalanceGains = field(default_factory=BalanceGains)
    criteria: FallCriteria = field(default_factory=FallCriteria)
    record: bool = False
    controller: str = "ik"
    id_gains: InverseDynamicsGains = field(default_factory=InverseDynamicsGains)


@dataclass
class BalanceSetup:
    """A scenario prepared for trials: analysis, MuJoCo model, start configuration."""

    scenario: Scenario
    joints: str
    analysis: Analysis
    sim: SimModel
    q_start: np.ndarray
    standoff: float
    support_v_index: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    controller: str = "ik"

    @classmethod
    def create(cls, scenario: Scenario | str, joints: str = "servo", options: BalanceTrialOptions | None = None,
               sim_options: SimOptions | None = None) -> BalanceSetup:
        options = options or BalanceTrialOptions()
        if not isinstance(scenario, Scenario):
            scenario = load_scenario(scenario)
        if joints not in JOINT_MODELS:
            raise SimulationError("--joints", joints, f"unknown joint model; valid: {', '.join(JOINT_MODELS)}")
        if options.controller not in CONTROLLERS:
            raise SimulationError("--controller", options.controller, f"unknown controller; valid: {', '.join(CONTROLLERS)}")
        analysis = analyze(scenario)
        if sim_options is None:
            # 1 ms steps: the stiffest contact (impact, time constant 4 ms) still spans 4 steps.
            servo = ServoOptions() if joints == "servo" else STIFF_SERVOS
            sim_options = SimOptions(timestep=0.001, meshes=False, servo=servo)
        # Welded joints admit no controller: "rigid" balance trials use stiff servos without effort limits.
        sim = build_model(scenario, "servo", sim_options)
        # MuJoCo's soft friction lets a loaded contact creep (a sole on the 30 degree ramp slides about
        # 3 mm/s within its friction cone); the no-slip pass removes that drift, which would otherwise
        # count as a slip after a few seconds.
        sim.model.opt.noslip_iterations = NOSLIP_ITERATIONS
        if options.controller == "id":
            use_torque_motors(sim)
        else:
            stiffen_support_limbs(sim, analysis)
        standoff = options.standoff if analysis.impact is not None else 0.0
        q_start = retracted_stance(analysis, standoff)
        support = [analysis.stance.robot.joint_slot(n) for n in support_joints(sim, analysis)]
        support_v = np.array([analysis.stance.model.joints[j.id].idx_v for j in support], dtype=int)
        return cls(scenario, joints, analysis, sim, q_start, standoff, support_v, options.controller)


@dataclass
class BalanceTrialResult:
    """Outcome and measurements of one trial (SI units, world frame).

    ``series`` holds the per-control-step arrays: ``time``, ``zmp`` (measured, k x 2),
    ``zmp_desired``, ``com`` (k x 3), ``com_velocity`` (k x 3), ``dcm`` (k x 2),
    ``zmp_margin`` (m, >= 0 inside the ZMP support area), ``com_velocity_margin``
    (m/s, >= 0 inside the CoM velocity area).
    """

    fell: bool
    reason: str | None
    detail: str
    fall_time: float | None
    disturbance_time: float | None
    disturbance_end: float | None
    approach_speed: float | None = None
    approach_speed_measured: float | None = None
    max_zmp_excursion: float = 0.0
    max_com_velocity_excursion: float = 0.0
    min_com_velocity_margin: float = float("inf")
    com_velocity_margin_at_end: float | None = None  # m/s, at the end of the disturbance (push)
    com_criterion_safe: bool | None = None
    zmp_criterion_safe: bool | None = None
    max_tilt: float = 0.0
    max_slip: float = 0.0
    sim_time: float = 0.0
    wall_time: float = 0.0
    series: dict[str, np.ndarray] = field(default_factory=dict)
    log: pd.DataFrame | None = None

    def summary(self) -> dict:
        """JSON-ready summary (no series, no log)."""
        def num(x):
            return None if x is None or not np.isfinite(x) else float(x)
        return {
            "fell": self.fell, "reason": self.reason, "detail": self.detail, "fall_time": num(self.fall_time),
            "approach_speed": num(self.approach_speed), "approach_speed_measured": num(self.approach_speed_measured),
            "max_zmp_excursion": num(self.max_zmp_excursion),
            "max_com_velocity_excursion": num(self.max_com_velocity_excursion),
            "min_com_velocity_margin": num(self.min_com_velocity_margin),
            "com_criterion_safe": self.com_criterion_safe, "zmp_criterion_safe": self.zmp_criterion_safe,
            "max_tilt_deg": float(np.rad2deg(self.max_tilt)), "max_slip": float(self.max_slip),
            "sim_time": self.sim_time, "wall_time": self.wall_time,
        }


def measured_zmp(sim: SimModel, com: np.ndarray, plane_height: float) -> tuple[np.ndarray, np.ndarray]:
    """ZMP of the sustained contacts' resultant force, in the LIPM sense, and each contact's force.

    The ZMP support area is defined through the resultant contact force ``f``:
    ``p = c_xy + (h - c_z) f_xy / f_z`` (the point of the plane ``z = h`` on the line of action of
    ``f`` through the CoM ``c``, as in the LIPM where the moment about the CoM is zero). Internal
    forces between non-coplanar contacts cancel in the sum, so this is the ZMP the CoM motion
    controls: ``f = m (c_dd + g)``. Returns ``(zmp (2,), forces (k, 3))``, forces on the robot, N,
    world; the ZMP is NaN when the contacts carry no vertical force.
    """
    forces = sim.contact_forces(sim.contact_geoms)
    total = forces.sum(axis=0)
    if total[2] <= 1e-6:
        return np.full(2, np.nan), forces
    return com[:2] + (plane_height - com[2]) * total[:2] / total[2], forces


def _push_body(sim: SimModel, name: str | None) -> int:
    m = sim.model
    if name is not None:
        try:
            return m.body(name).id
        except KeyError:
            valid = ", ".join(m.body(i).name for i in range(1, m.nbody))
            raise SimulationError("--body", name, f"no such body; valid: {valid}") from None
    torso = [i for i in range(m.nbody) if "torso" in m.body(i).name and m.body_mass[i] > 0]
    return max(torso) if torso else sim.root_body


def run_balance_trial(setup: BalanceSetup, impact_speed: float | None = None, push: Push | None = None,
              options: BalanceTrialOptions | None = None) -> BalanceTrialResult:
    """Run one trial (an impact at ``impact_speed``, or a ``push``) from rest; see the module docstring."""
    options = options or BalanceTrialOptions()
    sim, analysis = setup.sim, setup.analysis
    m, d = sim.model, sim.data
    if impact_speed is not None and analysis.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    if impact_speed is not None and not (np.isfinite(impact_speed) and 0 < impact_speed <= 20):
        raise SimulationError("speed", impact_speed, "must be in (0, 20] m/s")
    mujoco.mj_resetData(m, d)
    sim.set_state(setup.q_start)
    if setup.controller == "id":
        d.ctrl[sim.actuator_ids] = sim.tau_hold  # motors: the holding torques until the first control step
    else:
        sim.set_servo_targets(setup.q_start)
    stance = analysis.stance
    model = stance.robot.model
    pdata = model.createData()

    task = None
    n = None
    if impact_speed is not None:
        im = analysis.impact.model
        n = im.normal
        task = ImpactTask(im.spec.frame, im.spec.offset, im.point, n, impact_speed, start_time=options.settle,
                          standoff=setup.standoff)
    torque = setup.controller == "id"
    if torque:
        controller = InverseDynamicsController(analysis, setup.q_start, options.id_gains, task,
                                               effort_limits=bool(sim.model.actuator_forcelimited[sim.actuator_ids].any()))
        # MuJoCo's viscous joint damping (the URDF's) is compensated: the motors add damping * qdot.
        joint_damping = m.dof_damping[sim.dof_adr].copy()
        rate = options.id_gains.rate
    else:
        controller = BalanceController(analysis, setup.q_start, options.gains, task)
        rate = options.gains.rate
    contact_frames = [model.getFrameId(c.spec.frame) for c in stance.contacts]
    pin.framesForwardKinematics(model, pdata, setup.q_start)
    detector = FallDetector(
        [c.spec.frame for c in stance.contacts],
        np.array([pdata.oMf[f].translation for f in contact_frames]),
        np.array([pdata.oMf[f].rotation for f in contact_frames]),
        float(setup.q_start[2]), options.criteria,
    )
    normals = np.array([c.normal for c in stance.contacts])
    zmp_area = analysis.areas.zmp_area
    h, g = analysis.areas.plane_height, analysis.areas.gravity
    recorder = LogRecorder(sim, [c.spec.frame for c in stance.contacts], task is not None) if options.record else None

    body = None
    if push is not None:
        body = _push_body(sim, push.body)
        disturbance, disturbance_end = push.start, push.start + push.duration
        end_time = disturbance_end + options.after
    else:
        disturbance = disturbance_end = None
        end_time = options.settle + (setup.standoff / impact_speed + options.max_approach_time
                                     if impact_speed else 0.0) + options.after
    steps_per_control = max(1, int(round(1.0 / (rate * m.opt.timestep))))
    series: dict[str, list] = {k: [] for k in ("time", "zmp", "zmp_desired", "com", "com_velocity", "dcm",
                                               "zmp_margin", "com_velocity_margin")}
    approach_measured = None
    impact_velocity = np.zeros(6)
    wall0 = time.perf_counter()
    step = 0
    t = 0.0
    while t < end_time:
        t = d.time
        if step % steps_per_control == 0:
            q, v = sim.configuration(), sim.velocity()
            impact_force = None
            fn = 0.0
            if task is not None:
                impact_force = sim.contact_force(sim.impact_geom)
                fn = float(impact_force @ n)
                if disturbance is None and fn > 0.0:
                    # First touch: the disturbance starts; the approach speed is the one just before.
                    disturbance = disturbance_end = t
                    end_time = t + options.after
                if disturbance is None:
                    mujoco.mj_objectVelocity(m, d, mujoco.mjtObj.mjOBJ_GEOM, sim.impact_geom, impact_velocity, 0)
                    approach_measured = float(-impact_velocity[3:] @ n)
            com_now, _ = controller.measure(q, v)
            zmp, forces = measured_zmp(sim, com_now, h)
            out = controller.step(t, q, v, zmp, fn)
            if torque:
                d.ctrl[sim.actuator_ids] = out.tau[sim.v_index - 6] + joint_damping * d.qvel[sim.dof_adr]
            else:
                # Velocity feed-forward (kd v_ref) for the free limbs only: on the stiffened support limbs
                # it would turn the dead-beat IK's velocity noise into large torques.
                v_ff = out.v.copy()
                v_ff[setup.support_v_index] = 0.0
                sim.set_servo_targets(out.q, v_ff)
            com, com_velocity = out.com, out.com_velocity
            omega = np.sqrt(g / (com[2] - h))
            zmp_margin = float(zmp_area.margins(zmp)[0]) if np.all(np.isfinite(zmp)) else -np.inf
            vel_margin = float(omega * zmp_area.margins(out.dcm)[0]) if not zmp_area.is_empty else -np.inf
            for key, value in (("time", t), ("zmp", zmp), ("zmp_desired", out.zmp), ("com", com),
                               ("com_velocity", com_velocity), ("dcm", out.dcm), ("zmp_margin", zmp_margin),
                               ("com_velocity_margin", vel_margin)):
                series[key].append(value)
            pin.framesForwardKinematics(model, pdata, q)
            detector.update(t, np.array([pdata.oMf[f].translation for f in contact_frames]),
                            np.array([pdata.oMf[f].rotation for f in contact_frames]),
                            np.einsum("ij,ij->i", forces, normals), float(q[2]),
                            impulsive=push is not None and push.start <= t < disturbance_end)
            if recorder is not None and t >= LOG_START:
                recorder.add(t, q, v, sim, zmp, forces, impact_force)
            if detector.fell:
                break
        if body is not None:
            d.xfrc_applied[body, :3] = push.force if push.start <= t < disturbance_end else 0.0
        mujoco.mj_step(m, d)
        step += 1
    wall = time.perf_counter() - wall0
    arrays = {k: np.array(v) for k, v in series.items()}
    if not detector.fell:
        if disturbance is None and task is not None:
            detector._fail("no_contact", t, "the impact point never reached the surface")
        else:
            detector.finish(t, arrays["com_velocity"][-1])
    verdict = detector.verdict
    result = BalanceTrialResult(
        fell=verdict.fell, reason=verdict.reason, detail=verdict.detail, fall_time=verdict.time,
        disturbance_time=disturbance, disturbance_end=disturbance_end, approach_speed=impact_speed,
        approach_speed_measured=approach_measured, max_tilt=detector.max_tilt, max_slip=detector.max_slip,
        sim_time=float(d.time), wall_time=wall, series=arrays,
        log=recorder.frame() if recorder is not None else None,
    )
    if disturbance is not None:
        tt = arrays["time"]
        after = tt >= disturbance
        zm, vm = arrays["zmp_margin"], arrays["com_velocity_margin"]
        result.max_zmp_excursion = float(max(0.0, -np.min(zm[after]))) if after.any() else 0.0
        result.max_com_velocity_excursion = float(max(0.0, -np.min(vm[after]))) if after.any() else 0.0
        result.min_com_velocity_margin = float(np.min(vm[after])) if after.any() else float("inf")
        # Criteria judged at the end of the disturbance (CoM) and throughout it (ZMP).
        end_idx = int(np.searchsorted(tt, disturbance_end + 1e-9))
        end_idx = min(end_idx, len(tt) - 1)
        during = (tt >= disturbance) & (tt <= disturbance_end + 1e-9)
        result.com_velocity_margin_at_end = float(vm[end_idx])
        result.com_criterion_safe = bool(vm[end_idx] >= 0.0)
        result.zmp_criterion_safe = bool(np.all(zm[during] >= 0.0)) if during.any() else bool(zm[end_idx] >= 0)
    return result


def write_trial_log(setup: BalanceSetup, path, controller: str, metadata: dict, impact_speed: float | None = None,
                    push: Push | None = None):
    """Run one trial again with recording on and write its log (searches run their trials unrecorded).

    Returns the path written; ``metadata`` goes into the Parquet metadata with the scenario's name.
    """
    trial = run_balance_trial(setup, impact_speed=impact_speed, push=push,
                              options=BalanceTrialOptions(record=True, controller=controller))
    return write_log(trial.log, path, {"scenario": setup.scenario.name, **metadata})
