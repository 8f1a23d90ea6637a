"""One balance trial in MuJoCo: the controller holds the stance through an impact or a push.

:class:`~.trial_setup.BalanceSetup` prepares a scenario once (analysis, MuJoCo model, the start
configurations with the impacting point backed off); :func:`run_balance_trial` resets the model and
runs one trial:

- ``impact_speed``: the impact task drives the impact point into the surface at that commanded
  speed (m/s), reached before the surface with a bounded acceleration, then withdraws on contact
  (:class:`~.approach.ImpactTask`); with ``rigid_impact`` the joints keep their velocities through
  the impact (:class:`~.rigid_impact.RigidImpactHold`);
- ``push``: a force on a body (the torso) for a short time (see :class:`Push`).

At every control step (500 Hz) the loop reads MuJoCo's state as pinocchio's ``(q, v)``, runs
:class:`~.balance.BalanceController` and writes the servo targets (``controller="ik"``), or runs
:class:`~.inverse_dynamics.InverseDynamicsController` and writes the motor torques
(``controller="id"``, the actuators then being torque motors), and feeds the
:class:`~.outcomes.OutcomeMonitor`. It records the measured ZMP (from the sustained contacts' forces,
on the plane ``z = h``), the CoM, the CoM velocity and the DCM, and their margins in the scenario's
ZMP support area and CoM velocity area (without margin: scores apply theirs), and optionally a log
(:mod:`impact_balance.logs`). The impact itself is measured at every step (1 ms) by an
:class:`~.impact_tracker.ImpactTracker`: the approach speed just before the contact (the measured
speed), the impulses at the impact point and at the sustained contacts, and the CoM velocity across.
"""

from __future__ import annotations

import math
import time

import mujoco
import numpy as np
import pinocchio as pin

from impact_balance.analysis.analyze import Analysis
from impact_balance.balance.lipm import lipm_omega
from impact_balance.exceptions import SimulationError
from impact_balance.json_values import json_number
from impact_balance.logs import write_log
from impact_balance.sim.control.approach import ImpactTask
from impact_balance.sim.control.approach import standoff as approach_standoff
from impact_balance.sim.control.kinematic import BalanceController
from impact_balance.sim.control.torque import InverseDynamicsController
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.impact_tracker import ImpactTracker
from impact_balance.sim.trials.log import LOG_START, LogRecorder
from impact_balance.sim.trials.outcomes import OutcomeMonitor
from impact_balance.sim.trials.result import BalanceTrialResult
from impact_balance.sim.trials.rigid_impact import RigidImpactHold
from impact_balance.sim.trials.setup import (
    CONTROLLERS,
    STIFF_SERVOS,
    BalanceSetup,
    BalanceTrialOptions,
    Push,
    controller_margin,
    push_body,
)

#: Version of the trials' physics and measurements: journals of another version are not reused.
TRIAL_VERSION = 3

__all__ = [
    "CONTROLLERS",
    "STIFF_SERVOS",
    "TRIAL_VERSION",
    "BalanceSetup",
    "BalanceTrialOptions",
    "BalanceTrialResult",
    "Push",
    "controller_margin",
    "measured_zmp",
    "run_balance_trial",
    "write_trial_log",
]


def measured_zmp(
    sim: SimModel, com: np.ndarray, plane_height: float
) -> tuple[np.ndarray, np.ndarray]:
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


def _base_rotation(q: np.ndarray) -> np.ndarray:
    return pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()


def _omega_now(com_height: float, plane_height: float, gravity: float) -> float:
    """The LIPM's omega (1/s) at the measured CoM height (m), NaN once the CoM is at or below the plane.

    A falling robot's CoM may reach the plane: its CoM velocity margin is then undefined (NaN), not an
    error.
    """
    if com_height <= plane_height:
        return math.nan
    return lipm_omega(com_height, plane_height, gravity)


def run_balance_trial(
    setup: BalanceSetup,
    impact_speed: float | None = None,
    push: Push | None = None,
    options: BalanceTrialOptions | None = None,
    *,
    impact_task=None,
    surface_point=None,
    standoff: float | None = None,
    before_control=None,
    max_approach_time: float | None = None,
) -> BalanceTrialResult:
    """Run one trial (an impact at the commanded ``impact_speed``, or a ``push``) from rest; see the module docstring.

    An impact may instead follow ``impact_task`` (an object with ``reference(t, normal_force)``,
    ``target``, ``start_time``, ``contact_time``, like :class:`~.approach.ImpactTask`), from a start
    posture backed off ``standoff`` (m), towards a surface moved to ``surface_point`` (m, world; the
    scenario's impact point by default), for at most ``max_approach_time`` (s) after ``start_time``
    (:mod:`.wall` uses this). ``before_control(t, q, v)`` is called before every control step
    with the measured state (pinocchio order).
    """
    options = options or BalanceTrialOptions()
    sim, analysis = setup.sim, setup.analysis
    impact = impact_speed is not None or impact_task is not None
    if impact and analysis.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    if impact_speed is not None and not (np.isfinite(impact_speed) and 0 < impact_speed <= 20):
        raise SimulationError("speed", impact_speed, "must be in (0, 20] m/s")
    hold = RigidImpactHold(sim) if (options.rigid_impact and impact) else None
    moved = surface_point is not None and sim.surface_geom is not None
    if moved:
        home = sim.model.geom_pos[sim.surface_geom].copy()
        sim.model.geom_pos[sim.surface_geom] = home + (
            np.asarray(surface_point, dtype=float) - analysis.impact.model.point
        )
    try:
        return _run(
            setup,
            impact_speed,
            push,
            options,
            hold,
            impact_task,
            surface_point,
            standoff,
            before_control,
            max_approach_time,
        )
    finally:
        if (
            hold is not None
        ):  # the setup's model is reused: never leave a joint held, nor the wall moved
            hold.release(sim.data.time)
        if moved:
            sim.model.geom_pos[sim.surface_geom] = home


def _run(
    setup: BalanceSetup,
    impact_speed: float | None,
    push: Push | None,
    options: BalanceTrialOptions,
    hold: RigidImpactHold | None,
    task,
    surface_point,
    standoff,
    before_control,
    max_approach_time,
) -> BalanceTrialResult:
    sim, analysis = setup.sim, setup.analysis
    m, d = sim.model, sim.data
    stance = analysis.stance
    model = stance.robot.model
    pdata = model.createData()
    dt = float(m.opt.timestep)

    tracker = None
    n = None
    if impact_speed is not None and task is None:
        im = analysis.impact.model
        standoff = approach_standoff(impact_speed)
        task = ImpactTask(
            im.spec.frame,
            im.spec.offset,
            im.point,
            im.normal,
            impact_speed,
            start_time=options.settle,
        )
    if task is not None:
        n = np.asarray(analysis.impact.model.normal, dtype=float)
        tracker = ImpactTracker(n, dt)
        if surface_point is None:
            surface_point = analysis.impact.model.point
    q_start = setup.start_configuration(standoff or 0.0)
    # A push trial has no impacted surface: a robot falling forward must not lean on the wall of the impact.
    sim.enable_impact_surface(task is not None)
    mujoco.mj_resetData(m, d)
    sim.set_state(q_start)
    if setup.controller == "id":
        d.ctrl[sim.actuator_ids] = (
            sim.tau_hold
        )  # motors: the holding torques until the first control step
    else:
        sim.set_servo_targets(q_start)

    torque = setup.controller == "id"
    if torque:
        controller = InverseDynamicsController(
            analysis,
            q_start,
            options.id_gains,
            task,
            effort_limits=bool(sim.model.actuator_forcelimited[sim.actuator_ids].any()),
        )
        # MuJoCo's viscous joint damping (the URDF's) is compensated: the motors add damping * qdot.
        joint_damping = m.dof_damping[sim.dof_adr].copy()
        rate = options.id_gains.rate
    else:
        controller = BalanceController(analysis, q_start, options.gains, task)
        rate = options.gains.rate
    contact_names = [c.spec.frame for c in stance.contacts]
    contact_frames = [model.getFrameId(name) for name in contact_names]
    pin.framesForwardKinematics(model, pdata, q_start)
    monitor = OutcomeMonitor(
        contact_names,
        np.array([pdata.oMf[f].translation for f in contact_frames]),
        np.array([pdata.oMf[f].rotation for f in contact_frames]),
        float(q_start[2]),
        _base_rotation(q_start),
        options.criteria,
    )
    normals = np.array([c.normal for c in stance.contacts])
    zmp_area = analysis.areas.zmp_area
    h, g = analysis.areas.plane_height, analysis.areas.gravity
    recorder = LogRecorder(sim, contact_names, task is not None) if options.record else None

    body = None
    if push is not None:
        body = push_body(sim, push.body)
        disturbance, disturbance_end = push.start, push.start + push.duration
        end_time = disturbance_end + options.after
    else:
        disturbance = disturbance_end = None
        if task is None:
            end_time = options.settle + options.after
        elif max_approach_time is not None:
            end_time = task.start_time + max_approach_time + options.after
        else:
            end_time = task.arrival_time + options.max_approach_time + options.after
    steps_per_control = max(1, int(round(1.0 / (rate * dt))))
    series: dict[str, list] = {
        k: []
        for k in (
            "time",
            "zmp",
            "zmp_desired",
            "com",
            "com_velocity",
            "dcm",
            "zmp_margin",
            "com_velocity_margin",
        )
    }
    surface = None if task is None else float(n @ np.asarray(surface_point, dtype=float))
    radius = 0.0 if task is None else float(m.geom_size[sim.impact_geom][0])
    wall0 = time.perf_counter()
    step = 0
    impact_force = np.zeros(3)
    fn = 0.0
    extended = False
    angular_momentum = None
    while True:
        if d.time >= end_time:
            # Still moving at the end: the robot gets extra_time more to come to rest (a slow recovery is no fall).
            moving = (
                len(series["com_velocity"])
                and np.linalg.norm(series["com_velocity"][-1]) > options.criteria.rest_speed
            )
            if extended or disturbance is None or not moving:
                break
            extended = True
            end_time += options.criteria.extra_time
        t = float(d.time)
        if task is not None:
            # Every step (1 ms): the forces of the last step, the impact point's velocity, the CoM velocity.
            impact_force = sim.contact_force(sim.impact_geom)
            fn = float(impact_force @ n)
            point_v = sim.impact_point_velocity(n)
            com_v = sim.com_velocity()
            tracker.update(t, impact_force, sim.contact_forces(sim.contact_geoms), point_v, com_v)
            if hold is not None:
                hold.update(t, float(-point_v @ n))
                # Hold from the step in which the point will touch: its gap closes within one step.
                gap = float(n @ (sim.data.geom_xpos[sim.impact_geom] - radius * n)) - surface
                if hold.start is None and gap - max(0.0, float(-point_v @ n)) * dt <= 0.0:
                    hold.begin(t)
            if disturbance is None and tracker.touched:
                disturbance = tracker.start
                monitor.start_disturbance(disturbance)
                end_time = disturbance + options.after
            if disturbance_end is None and tracker.done:
                disturbance_end = tracker.end
        if step % steps_per_control == 0:
            q, v = sim.configuration(), sim.velocity()
            if before_control is not None:
                before_control(t, q, v)
            com_now, _ = controller.measure(q, v)
            zmp, forces = measured_zmp(sim, com_now, h)
            out = controller.step(t, q, v, zmp, fn)
            if torque:
                d.ctrl[sim.actuator_ids] = (
                    out.tau[sim.v_index - 6] + joint_damping * d.qvel[sim.dof_adr]
                )
            else:
                # Velocity feed-forward (kd v_ref) for the free limbs only: on the stiffened support limbs
                # it would turn the dead-beat IK's velocity noise into large torques.
                v_ff = out.v.copy()
                v_ff[setup.support_v_index] = 0.0
                sim.set_servo_targets(out.q, v_ff)
            com, com_velocity = out.com, out.com_velocity
            omega = _omega_now(float(com[2]), h, g)
            zmp_margin = float(zmp_area.margins(zmp)[0]) if np.all(np.isfinite(zmp)) else -np.inf
            dcm_margin = float(zmp_area.margins(out.dcm)[0])
            for key, value in (
                ("time", t),
                ("zmp", zmp),
                ("zmp_desired", out.zmp),
                ("com", com),
                ("com_velocity", com_velocity),
                ("dcm", out.dcm),
                ("zmp_margin", zmp_margin),
                ("com_velocity_margin", omega * dcm_margin),
            ):
                series[key].append(value)
            pin.framesForwardKinematics(model, pdata, q)
            if angular_momentum is None and disturbance_end is not None and t >= disturbance_end:
                # What the LIPM leaves out: the angular momentum about the CoM the disturbance left.
                angular_momentum = np.array(
                    pin.computeCentroidalMomentum(model, pdata, q, v).angular
                )
            if push is not None and t >= push.start:
                monitor.start_disturbance(push.start)
            pushing = push is not None and push.start <= t < push.start + push.duration
            monitor.update(
                t,
                np.array([pdata.oMf[f].translation for f in contact_frames]),
                np.array([pdata.oMf[f].rotation for f in contact_frames]),
                np.einsum("ij,ij->i", forces, normals),
                float(q[2]),
                _base_rotation(q),
                dcm_margin if disturbance is not None and t >= disturbance else None,
                impulsive=pushing,
            )
            if recorder is not None and t >= LOG_START:
                recorder.add(t, q, v, sim, zmp, forces, impact_force if task is not None else None)
            if monitor.fell:
                if monitor.disturbance is None:
                    monitor.abort(
                        "fell_before_disturbance", t, "the robot fell before the disturbance"
                    )
                break
        if body is not None:
            d.xfrc_applied[body, :3] = (
                push.force if push.start <= t < push.start + push.duration else 0.0
            )
        mujoco.mj_step(m, d)
        step += 1
    wall = time.perf_counter() - wall0
    arrays = {k: np.array(v) for k, v in series.items()}
    t = float(d.time)
    if task is not None and disturbance is None:
        monitor.abort("no_contact", t, "the impact point never reached the surface")
    outcome = monitor.finish(
        t, arrays["com_velocity"][-1] if len(arrays["com_velocity"]) else np.zeros(3)
    )
    result = BalanceTrialResult(
        outcome=outcome.outcome,
        reason=outcome.reason,
        outcome_time=outcome.time,
        detail=outcome.detail,
        events=outcome.events,
        disturbance_time=disturbance,
        disturbance_end=disturbance_end,
        approach_speed=impact_speed,
        max_tilt=monitor.max_tilt,
        max_slip=monitor.max_slip,
        max_trunk_tilt=monitor.max_trunk_tilt,
        max_drop=monitor.max_drop,
        sim_time=t,
        wall_time=wall,
        contact_names=tuple(contact_names),
        series=arrays,
        log=recorder.frame() if recorder is not None else None,
        angular_momentum_at_end=angular_momentum,
    )
    if tracker is not None and tracker.touched:
        result.impact = tracker.measurement(
            t, sim.com_velocity(), None if hold is None else hold.to_dict()
        )
    _margins(result, analysis, arrays)
    return result


def _margins(result: BalanceTrialResult, analysis: Analysis, arrays: dict[str, np.ndarray]) -> None:
    """The CoM velocity when the disturbance ended, its margin, the worst margin after it, and the worst ZMP
    margin during a push (all in the areas without margin).
    """
    if result.disturbance_time is None or not len(arrays["time"]):
        return
    tt, vm, zm = arrays["time"], arrays["com_velocity_margin"], arrays["zmp_margin"]
    after = tt >= result.disturbance_time
    if after.any():
        result.min_com_velocity_margin = float(np.min(vm[after]))
    if result.impact is not None:
        area = analysis.areas.com_velocity_area
        result.com_velocity_at_end = result.impact.com_velocity_after
        result.com_velocity_margin_at_end = float(area.margins(result.com_velocity_at_end)[0])
    elif result.disturbance_end is not None and tt[-1] >= result.disturbance_end:
        end = min(int(np.searchsorted(tt, result.disturbance_end - 1e-9)), len(tt) - 1)
        result.com_velocity_at_end = arrays["com_velocity"][end][:2].copy()
        result.com_velocity_margin_at_end = float(vm[end])
        during = (tt >= result.disturbance_time) & (tt <= result.disturbance_end + 1e-9)
        if during.any():
            worst = float(np.min(zm[during]))
            result.min_zmp_margin_during = json_number(worst)


def write_trial_log(
    setup: BalanceSetup,
    path,
    controller: str,
    metadata: dict,
    impact_speed: float | None = None,
    push: Push | None = None,
    rigid_impact: bool = False,
):
    """Run one trial again with recording on and write its log (searches run their trials unrecorded).

    Returns the path written; ``metadata`` goes into the Parquet metadata with the scenario's name.
    """
    trial = run_balance_trial(
        setup,
        impact_speed=impact_speed,
        push=push,
        options=BalanceTrialOptions(record=True, controller=controller, rigid_impact=rigid_impact),
    )
    return write_log(trial.log, path, {"scenario": setup.scenario.name, **metadata})
