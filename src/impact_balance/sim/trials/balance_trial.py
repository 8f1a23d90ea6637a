"""One balance trial in MuJoCo: the controller holds the stance through an impact or a push.

:class:`~impact_balance.sim.trials.setup.BalanceSetup` prepares a scenario once (analysis, MuJoCo
model, the start configurations with the impacting point backed off); :func:`run_balance_trial`
resets the model and runs one trial:

- ``impact_speed``: the impact task drives the impact point into the surface at that commanded
  speed (m/s), reached before the surface with a bounded acceleration, then withdraws on contact
  (:class:`~impact_balance.sim.control.approach.ImpactTask`); with ``rigid_impact`` the joints keep
  their velocities through the impact (:class:`~.rigid_impact.RigidImpactHold`);
- ``push``: a force on a body (the torso) for a short time (see :class:`Push`).

At every control step (500 Hz) the loop reads MuJoCo's state as pinocchio's ``(q, v)``, runs the
setup's :class:`~impact_balance.sim.control.controller.Controller` (``ik``: servo targets; ``id``:
motor torques) and feeds the :class:`~.outcomes.OutcomeMonitor`. It records the measured ZMP (from
the sustained contacts' forces, on the plane ``z = h``), the CoM, the CoM velocity and the DCM, and
their margins in the scenario's ZMP support area and CoM velocity area (without margin: scores apply
theirs), and optionally a log (:mod:`impact_balance.logs`). The impact itself is measured at every
step (1 ms) by an :class:`~.impact_tracker.ImpactTracker`: the approach speed just before the
contact (the measured speed), the impulses at the impact point and at the sustained contacts, and
the CoM velocity across.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import ArrayLike

from impact_balance.analysis.analyze import Analysis
from impact_balance.balance.lipm import lipm_omega
from impact_balance.exceptions import SimulationError
from impact_balance.impact.model import ImpactModel
from impact_balance.json_values import json_number
from impact_balance.logs import write_log
from impact_balance.robot.ik import IKError
from impact_balance.sim.control.approach import ImpactReference, ImpactTask
from impact_balance.sim.control.approach import standoff as approach_standoff
from impact_balance.sim.control.controller import ControllerName, ControlStep
from impact_balance.sim.control.gains import InverseDynamicsGains
from impact_balance.sim.control.registry import controller_class
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.angular_momentum_removal import AngularMomentumRemoval
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

_FloatArray = npt.NDArray[np.float64]
#: ``before_control(t, q, v)``: called before every control step with the measured state.
BeforeControl = Callable[[float, _FloatArray, _FloatArray], None]

#: Version of the trials' physics and measurements: journals of another version are not reused.
TRIAL_VERSION = 5

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
    answer: _FloatArray = pin.Quaternion(q[6], q[3], q[4], q[5]).toRotationMatrix()
    return answer


def _omega_now(com_height: float, plane_height: float, gravity: float) -> float:
    """The LIPM's omega (1/s) at the measured CoM height (m).

    NaN once the CoM is at or below the plane.

    A falling robot's CoM may reach the plane: its CoM velocity margin is then undefined (NaN), not
    an error.
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
    impact_task: ImpactReference | None = None,
    surface_point: ArrayLike | None = None,
    standoff: float | None = None,
    before_control: BeforeControl | None = None,
    max_approach_time: float | None = None,
) -> BalanceTrialResult:
    """Run one trial (an impact or a push) from rest; see the module docstring.

    An impact at the commanded ``impact_speed``, or a ``push``.

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
    if impact:
        _impact_model(analysis)  # refuses a scenario without an impact
    if impact_speed is not None and not (np.isfinite(impact_speed) and 0 < impact_speed <= 20):
        raise SimulationError("speed", impact_speed, "must be in (0, 20] m/s")
    hold = RigidImpactHold(sim) if (options.rigid_impact and impact) else None
    moved = surface_point is not None and sim.surface_geom is not None
    if moved:
        home = sim.model.geom_pos[sim.surface_geom].copy()
        sim.model.geom_pos[sim.surface_geom] = home + (
            np.asarray(surface_point, dtype=float) - _impact_model(analysis).point
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


_SERIES = (
    "time",
    "zmp",
    "zmp_desired",
    "com",
    "com_velocity",
    "dcm",
    "zmp_margin",
    "com_velocity_margin",
)


def _run(
    setup: BalanceSetup,
    impact_speed: float | None,
    push: Push | None,
    options: BalanceTrialOptions,
    hold: RigidImpactHold | None,
    task: ImpactReference | None,
    surface_point: ArrayLike | None,
    standoff: float | None,
    before_control: BeforeControl | None,
    max_approach_time: float | None,
) -> BalanceTrialResult:
    if impact_speed is not None and task is None:
        task, standoff = _commanded_task(setup.analysis, impact_speed, options.settle)
    try:
        trial = _TrialRun(setup, impact_speed, push, options, hold, task, surface_point, standoff)
    except IKError as exc:  # the approach's start is out of the robot's reach: nothing to test
        return BalanceTrialResult(
            "aborted",
            "no_start",
            None,
            f"the approach cannot start: its start, {standoff or 0.0:.3f} m off the surface, "
            f"is out of the robot's reach ({exc})",
            (),
            None,
            None,
            approach_speed=impact_speed,
        )
    trial.set_end_time(max_approach_time)
    trial.loop(before_control)
    return trial.result()


def _commanded_task(
    analysis: Analysis, impact_speed: float, settle: float
) -> tuple[ImpactTask, float]:
    """The impact task at the commanded ``impact_speed`` (m/s), and its standoff (m).

    The task starts after ``settle`` (s).
    """
    im = _impact_model(analysis)
    task = ImpactTask(
        im.spec.frame,
        im.spec.offset,
        im.point,
        im.normal,
        impact_speed,
        start_time=settle,
    )
    return task, approach_standoff(impact_speed)


def _impact_model(analysis: Analysis) -> ImpactModel:
    if analysis.impact is None:
        raise SimulationError("impact", None, "the scenario has no impact")
    return analysis.impact.model


class _TrialRun:
    """One trial's state between its steps: the model, the controller, the monitors, the series."""

    def __init__(
        self,
        setup: BalanceSetup,
        impact_speed: float | None,
        push: Push | None,
        options: BalanceTrialOptions,
        hold: RigidImpactHold | None,
        task: ImpactReference | None,
        surface_point: ArrayLike | None,
        standoff: float | None,
    ):
        self.setup, self.impact_speed, self.push, self.options = setup, impact_speed, push, options
        self.hold, self.task = hold, task
        sim, analysis = setup.sim, setup.analysis
        self.sim, self.analysis = sim, analysis
        m, d = sim.model, sim.data
        stance = analysis.stance
        self.model = model = stance.robot.model
        self.pdata = model.createData()
        self.dt = dt = float(m.opt.timestep)
        self.tracker: ImpactTracker | None = None
        self.n = np.zeros(3)
        if task is not None:
            im = _impact_model(analysis)
            self.n = np.asarray(im.normal, dtype=float)
            self.tracker = ImpactTracker(self.n, dt)
            if surface_point is None:
                surface_point = im.point
        q_start = setup.start_configuration(standoff or 0.0)
        # A push trial has no impacted surface: a robot falling forward must not lean on the wall of
        # the impact.
        sim.enable_impact_surface(task is not None)
        mujoco.mj_resetData(m, d)
        sim.set_state(q_start)
        cls = controller_class(setup.controller)
        self.controller = cls.for_trial(
            analysis, q_start, options, task, sim, setup.support_v_index
        )
        self.controller.hold(sim, q_start)
        self.contact_names = [c.spec.frame for c in stance.contacts]
        self.contact_frames = [model.getFrameId(name) for name in self.contact_names]
        pin.framesForwardKinematics(model, self.pdata, q_start)
        self.monitor = OutcomeMonitor(
            self.contact_names,
            np.array([self.pdata.oMf[f].translation for f in self.contact_frames]),
            np.array([self.pdata.oMf[f].rotation for f in self.contact_frames]),
            float(q_start[2]),
            _base_rotation(q_start),
            options.criteria.for_robot(stance.mass * analysis.areas.gravity, len(stance.contacts)),
            points=[c.is_point for c in stance.contacts],
        )
        self.normals = np.array([c.normal for c in stance.contacts])
        self.recorder = (
            LogRecorder(sim, self.contact_names, task is not None) if options.record else None
        )
        self.body = None if push is None else push_body(sim, push.body)
        self.steps_per_control = max(1, round(1.0 / (self.controller.rate * dt)))
        self.series: dict[str, list[Any]] = {k: [] for k in _SERIES}
        self.surface = (
            0.0 if surface_point is None else float(self.n @ np.asarray(surface_point, dtype=float))
        )
        self.radius = 0.0 if task is None else float(m.geom_size[sim.impact_geom][0])
        self.impact_force = np.zeros(3)
        self.fn = 0.0
        self.angular_momentum: _FloatArray | None = None
        self.removal: AngularMomentumRemoval | None = None
        self.disturbance: float | None = None
        self.disturbance_end: float | None = None
        self.end_time = 0.0
        self.wall = 0.0

    def set_end_time(self, max_approach_time: float | None) -> None:
        """The disturbance's times when known (a push) and when the trial ends (s)."""
        push, task, options = self.push, self.task, self.options
        if push is not None:
            self.disturbance, self.disturbance_end = push.start, push.start + push.duration
            self.end_time = self.disturbance_end + options.after
        elif task is None:
            self.end_time = options.settle + options.after
        elif max_approach_time is not None:
            self.end_time = task.start_time + max_approach_time + options.after
        elif isinstance(task, ImpactTask):
            self.end_time = task.arrival_time + options.max_approach_time + options.after
        else:
            raise SimulationError(
                "max_approach_time", None, "an impact task other than ImpactTask needs one"
            )

    def loop(self, before_control: BeforeControl | None) -> None:
        """Step MuJoCo until the trial ends (a fall, or the end time, extended once if moving)."""
        sim, push, criteria = self.sim, self.push, self.options.criteria
        m, d = sim.model, sim.data
        wall0 = time.perf_counter()
        step = 0
        extended = False
        while True:
            if d.time >= self.end_time:
                # Still moving at the end: the robot gets extra_time more to come to rest (a slow
                # recovery is no fall).
                velocities = self.series["com_velocity"]
                moving = len(velocities) and np.linalg.norm(velocities[-1]) > criteria.rest_speed
                if extended or self.disturbance is None or not moving:
                    break
                extended = True
                self.end_time += criteria.extra_time
            t = float(d.time)
            if self.task is not None:
                self._track_impact(t)
            if step % self.steps_per_control == 0 and self._control(t, before_control):
                break
            if self.body is not None and push is not None:
                d.xfrc_applied[self.body, :3] = (
                    push.force if push.start <= t < push.start + push.duration else 0.0
                )
            mujoco.mj_step(m, d)
            step += 1
        self.wall = time.perf_counter() - wall0

    def _track_impact(self, t: float) -> None:
        """Every MuJoCo step: the impact's measurements, hold and disturbance times.

        Every step (1 ms): the forces of the last step, the impact point's velocity, the CoM
        velocity; the rigid-impact hold; the disturbance's start and end.
        """
        sim, n, hold, tracker = self.sim, self.n, self.hold, self.tracker
        assert tracker is not None and sim.impact_geom is not None
        self.impact_force = sim.contact_force(sim.impact_geom)
        self.fn = float(self.impact_force @ n)
        point_v = sim.impact_point_velocity(n)
        com_v = sim.com_velocity()
        tracker.update(t, self.impact_force, sim.contact_forces(sim.contact_geoms), point_v, com_v)
        if hold is not None:
            hold.update(t, float(-point_v @ n))
            # Hold from the step in which the point will touch: its gap closes within one step.
            gap = float(n @ (sim.data.geom_xpos[sim.impact_geom] - self.radius * n)) - self.surface
            if hold.start is None and gap - max(0.0, float(-point_v @ n)) * self.dt <= 0.0:
                hold.begin(t)
        if self.disturbance is None and tracker.start is not None:
            self.disturbance = tracker.start
            self.monitor.start_disturbance(tracker.start)
            self.end_time = tracker.start + self.options.after
        if self.disturbance_end is None and tracker.done:
            self.disturbance_end = tracker.end

    def _control(self, t: float, before_control: BeforeControl | None) -> bool:
        """One control step: command, record, monitor. Returns whether the robot fell."""
        sim, controller = self.sim, self.controller
        q, v = sim.configuration(), sim.velocity()
        if before_control is not None:
            before_control(t, q, v)
        com_now, _ = controller.measure(q, v)
        areas = self.analysis.areas
        zmp, forces = measured_zmp(sim, com_now, areas.plane_height)
        out = controller.step(t, q, v, zmp, self.fn)
        controller.actuate(sim, out)
        dcm_margin = self._record(t, zmp, out)
        pin.framesForwardKinematics(self.model, self.pdata, q)
        self._angular_momentum(t, q, v)
        push = self.push
        if push is not None and t >= push.start:
            self.monitor.start_disturbance(push.start)
        pushing = push is not None and push.start <= t < push.start + push.duration
        disturbed = self.disturbance is not None and t >= self.disturbance
        self.monitor.update(
            t,
            np.array([self.pdata.oMf[f].translation for f in self.contact_frames]),
            np.array([self.pdata.oMf[f].rotation for f in self.contact_frames]),
            np.einsum("ij,ij->i", forces, self.normals),
            float(q[2]),
            _base_rotation(q),
            dcm_margin if disturbed else None,
            impulsive=pushing,
        )
        if self.recorder is not None and t >= LOG_START:
            impact_force = self.impact_force if self.task is not None else None
            self.recorder.add(t, q, v, sim, zmp, forces, impact_force)
        if self.monitor.fell:
            if self.monitor.disturbance is None:
                self.monitor.abort(
                    "fell_before_disturbance", t, "the robot fell before the disturbance"
                )
            return True
        return False

    def _angular_momentum(self, t: float, q: _FloatArray, v: _FloatArray) -> None:
        """The angular momentum about the CoM the disturbance left, and its removal.

        What the LIPM leaves out: L at the disturbance's end, then how the controller removes
        it (every control step until a fall).
        """
        if self.disturbance_end is None or t < self.disturbance_end or self.monitor.fell:
            return
        now = np.array(pin.computeCentroidalMomentum(self.model, self.pdata, q, v).angular)
        if self.angular_momentum is None:
            self.angular_momentum = now
            self.removal = AngularMomentumRemoval(
                self.analysis.areas.omega, self.disturbance_end, now
            )
        elif self.removal is not None:
            self.removal.add(t, now)

    def _record(self, t: float, zmp: _FloatArray, out: ControlStep) -> float:
        """Append one control step to the series; return the DCM's margin in the ZMP area (m)."""
        areas = self.analysis.areas
        zmp_area = areas.zmp_area
        com, com_velocity = out.com, out.com_velocity
        omega = _omega_now(float(com[2]), areas.plane_height, areas.gravity)
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
            self.series[key].append(value)
        return dcm_margin

    def result(self) -> BalanceTrialResult:
        """The trial's outcome, measurements and series."""
        sim, monitor, tracker = self.sim, self.monitor, self.tracker
        arrays = {k: np.array(v) for k, v in self.series.items()}
        t = float(sim.data.time)
        if self.task is not None and self.disturbance is None:
            monitor.abort("no_contact", t, "the impact point never reached the surface")
        velocities = arrays["com_velocity"]
        outcome = monitor.finish(t, velocities[-1] if len(velocities) else np.zeros(3))
        result = BalanceTrialResult(
            outcome=outcome.outcome,
            reason=outcome.reason,
            outcome_time=outcome.time,
            detail=outcome.detail,
            events=outcome.events,
            disturbance_time=self.disturbance,
            disturbance_end=self.disturbance_end,
            approach_speed=self.impact_speed,
            max_tilt=monitor.max_tilt,
            max_slip=monitor.max_slip,
            max_trunk_tilt=monitor.max_trunk_tilt,
            max_drop=monitor.max_drop,
            sim_time=t,
            wall_time=self.wall,
            contact_names=tuple(self.contact_names),
            series=arrays,
            log=self.recorder.frame() if self.recorder is not None else None,
            angular_momentum_at_end=self.angular_momentum,
            angular_momentum_removed=None
            if self.removal is None or self.removal.samples == 0
            else self.removal.removed,
            strict_fail=outcome.strict_fail,
            strict_reason=outcome.strict_reason,
            stance_changed_time=None
            if outcome.stance_changed is None
            else outcome.stance_changed[0],
            max_unloaded=outcome.max_unloaded,
        )
        if tracker is not None and tracker.touched:
            hold = None if self.hold is None else self.hold.to_dict()
            result.impact = tracker.measurement(t, sim.com_velocity(), hold)
        _margins(result, self.analysis, arrays)
        return result


def _margins(result: BalanceTrialResult, analysis: Analysis, arrays: dict[str, np.ndarray]) -> None:
    """The CoM velocity margins of a trial after its disturbance.

    The CoM velocity when the disturbance ended, its margin, the worst margin after it, and the
    worst ZMP margin during a push (all in the areas without margin).
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
    path: str | Path,
    controller: ControllerName,
    metadata: dict[str, object],
    impact_speed: float | None = None,
    push: Push | None = None,
    rigid_impact: bool = False,
    id_gains: InverseDynamicsGains | None = None,
) -> Path:
    """Run one trial again with recording on and write its log.

    Searches run their trials unrecorded: this reruns one to log it.

    Args:
        setup: The scenario prepared for trials.
        path: The log file (Parquet or CSV).
        controller: The controller's name.
        metadata: Parquet metadata (as text), written with the scenario's name.
        impact_speed: Commanded approach speed of an impact trial (m/s).
        push: The push of a push trial.
        rigid_impact: Hold every joint's velocity through the impact.
        id_gains: The ``id`` controller's gains (default :class:`InverseDynamicsGains`).

    Returns:
        The path written.
    """
    trial = run_balance_trial(
        setup,
        impact_speed=impact_speed,
        push=push,
        options=BalanceTrialOptions(
            record=True,
            controller=controller,
            rigid_impact=rigid_impact,
            id_gains=id_gains or InverseDynamicsGains(),
        ),
    )
    assert trial.log is not None  # recorded
    values = {"scenario": setup.scenario.name, **metadata}
    return write_log(trial.log, path, {k: str(v) for k, v in values.items()})
