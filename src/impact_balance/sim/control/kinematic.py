"""Whole-body balance controller: DCM feedback + pink IK, for MuJoCo position servos.

Choice (documented in ``docs/validation.md``): a *kinematic* controller, as the paper assumes
("the robot is kinematically controlled"). At every control step (500 Hz by default):

1. The measured CoM ``c`` and CoM velocity ``c_d`` (pinocchio, from the measured base pose and
   velocity and the joints) give the DCM ``xi = c + c_d / omega``.
2. :class:`~.zmp.DcmFeedback` picks the desired ZMP ``p = xi + (k / omega)(xi - xi_ref)`` and
   clamps it to the scenario's own ZMP support area (shrunk by a margin).
3. ZMP feedback through the CoM (the admittance of position-controlled humanoids, Kajita et al.
   2010): the commanded CoM moves at ``c_cmd_d = K_zmp (p_measured - p)``. If the measured ZMP is
   ahead of the desired one, the CoM is accelerated forward, which moves the ZMP back. With ideal
   tracking the closed loop ``s^2 + (omega + k + omega^2/K_zmp) s + omega k`` is stable for any
   positive gains. The measured ZMP comes from the contact forces (force sensors); without it
   (no vertical force) the CoM command holds. The measured ZMP is filtered, the command's speed
   bounded, and the commanded CoM kept over the ZMP support area.
4. pink's differential IK moves a reference configuration so that its CoM follows ``c_cmd``,
   every contact frame stays at its initial pose, the impacting point follows the impact task,
   and a posture task holds the rest. The reference joint angles go to the joint position servos
   (the trial adds the reference velocities as feed-forward on the free limbs).

The impact task (:class:`~.approach.ImpactTask`): hold; then the impact point's target accelerates
towards the surface along ``-n`` (bounded acceleration) to the commanded approach speed, which it
reaches before the surface; once the measured normal force exceeds a threshold (15 N, as the
paper's experiment) the target stops pushing and withdraws along ``n``.

Everything here is pinocchio and pink; MuJoCo is only seen through the measured ``(q, v)`` and
the impact force passed to :meth:`BalanceController.step`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pink
import pinocchio as pin
from pink.tasks import ComTask, FrameTask, PostureTask

from impact_balance.analysis.analyze import Analysis
from impact_balance.balance.lipm import lipm_omega
from impact_balance.robot.ik import IKOptions, solve_stance
from impact_balance.sim.control.actuation import stiffen_support_limbs
from impact_balance.sim.control.approach import ImpactReference
from impact_balance.sim.control.controller import Controller
from impact_balance.sim.control.gains import BalanceGains, TrialGains, trial_gains
from impact_balance.sim.control.zmp import DcmFeedback, clamp_to_polygon
from impact_balance.sim.model.build import SimModel

__all__ = ["BalanceController", "ControlOutput", "retracted_stance"]

_FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ControlOutput:
    """One control step's command and what the controller saw.

    Attributes:
        q: Reference configuration (nq, pinocchio order); joint part goes to the servos.
        v: Reference velocity (nv).
        zmp: Clamped desired ZMP (m, world).
        dcm: Measured DCM (m, world).
        clamped: Whether the desired ZMP was clamped to the area.
        com: Measured CoM (m, world).
        com_velocity: Measured CoM velocity (m/s, world).
    """

    q: np.ndarray
    v: np.ndarray
    zmp: np.ndarray
    dcm: np.ndarray
    clamped: bool
    com: np.ndarray
    com_velocity: np.ndarray


def retracted_stance(analysis: Analysis, standoff: float) -> np.ndarray:
    """The stance's configuration with the impact point backed off along the normal.

    The point backs off by ``standoff`` (m).

    Whole-body IK (pink, :func:`impact_balance.robot.ik.solve_stance`): contacts fixed, CoM xy
    fixed.
    """
    stance, impact = analysis.stance, analysis.impact
    if impact is None or standoff <= 0:
        answer: _FloatArray = stance.q.copy()
        return answer
    spec = impact.model.spec
    frame_pose = stance.frame_pose(spec.frame)
    target = pin.SE3(frame_pose.rotation, frame_pose.translation + standoff * impact.model.normal)
    return solve_stance(
        stance.robot,
        stance.q,
        {spec.frame: target},
        stance.com[:2],
        fixed_frames=[c.spec.frame for c in stance.contacts],
        options=IKOptions(tolerance=1e-5, max_iterations=300),
    )


class BalanceController(Controller["ControlOutput"]):
    """DCM-feedback balance with whole-body IK (see the module docstring).

    Args:
        analysis: The scenario's analysis (stance, areas; the impact if any).
        q0: Initial reference configuration (nq); default the stance's.
        gains: Gains and rates (default :class:`BalanceGains`).
        impact: The impact task, if any.

    Attributes:
        support_v_index: Velocity indices (pinocchio) of the support limbs' joints, which get no
            velocity feed-forward (:meth:`actuate`); none unless built by :meth:`for_trial`.
    """

    name = "dcm-zmp-clamp + pink IK -> joint position servos"

    def __init__(
        self,
        analysis: Analysis,
        q0: np.ndarray | None = None,
        gains: BalanceGains | None = None,
        impact: ImpactReference | None = None,
    ):
        gains = gains or BalanceGains()
        self.analysis = analysis
        self.gains = gains
        self.impact = impact
        stance = analysis.stance
        self.model = stance.robot.model
        self.data = self.model.createData()  # measured state
        q0 = stance.q.copy() if q0 is None else np.asarray(q0, dtype=float).copy()
        self.configuration = pink.Configuration(self.model, self.model.createData(), q0)
        self.rate = gains.rate
        self.dt = 1.0 / gains.rate
        self.support_v_index: npt.NDArray[np.int_] = np.zeros(0, dtype=int)
        areas = analysis.areas
        self.plane_height = areas.plane_height
        self.gravity = areas.gravity
        com0 = np.array(pin.centerOfMass(self.model, self.configuration.data, q0), dtype=float)
        self.com_height = float(com0[2])
        self.omega = lipm_omega(self.com_height, self.plane_height, self.gravity)
        self.feedback = DcmFeedback(
            areas.zmp_area, self.omega, com0[:2].copy(), gains.dcm_gain, gains.zmp_margin
        )
        self.com_command = com0[:2].copy()
        self._zmp_filtered: np.ndarray | None = None
        self.contact_tasks = []
        for c in stance.contacts:
            # A point foot rolls: its frame's orientation is free.
            turn = 0.0 if c.is_point else gains.contact_cost
            task = FrameTask(c.spec.frame, gains.contact_cost, turn)
            task.set_target(self.configuration.get_transform_frame_to_world(c.spec.frame))
            self.contact_tasks.append(task)
        self.com_task = ComTask(cost=gains.com_cost)
        self.com_task.set_target(com0)
        self.posture_task = PostureTask(cost=gains.posture_cost)
        self.posture_task.set_target(q0)
        self.impact_task: FrameTask | None = None
        if impact is not None:
            self.impact_task = FrameTask(impact.frame, gains.impact_cost, 0.1 * gains.impact_cost)
            self._impact_rotation = self.configuration.get_transform_frame_to_world(
                impact.frame
            ).rotation.copy()
        self.v_ref = np.zeros(self.model.nv)
        self._lower = self.model.lowerPositionLimit[7:].copy()
        self._upper = self.model.upperPositionLimit[7:].copy()

    @classmethod
    def prepare_model(cls, sim: SimModel, analysis: Analysis) -> None:
        """Position servos, the support limbs' stiffened (see :meth:`Controller.prepare_model`)."""
        stiffen_support_limbs(sim, analysis)

    @classmethod
    def zmp_margin(cls, options: TrialGains) -> float:
        """The margin of ``options.gains`` (m; see :meth:`Controller.zmp_margin`)."""
        return options.gains.zmp_margin

    @classmethod
    def for_trial(
        cls,
        analysis: Analysis,
        q_start: _FloatArray,
        options: TrialGains,
        task: ImpactReference | None,
        sim: SimModel,
        support_v_index: npt.NDArray[np.int_],
    ) -> BalanceController:
        """The controller of one trial, with ``options.gains`` (derived from the robot).

        See :meth:`Controller.for_trial` and :func:`~impact_balance.sim.control.gains.trial_gains`.
        """
        controller = cls(analysis, q_start, trial_gains(options, sim)[0], task)
        controller.support_v_index = support_v_index
        return controller

    def hold(self, sim: SimModel, q_start: _FloatArray) -> None:
        """The servos hold ``q_start`` (see :meth:`Controller.hold`)."""
        sim.set_servo_targets(q_start)

    def actuate(self, sim: SimModel, out: ControlOutput) -> None:
        """Servo targets ``out.q``, with velocity feed-forward on the free limbs only.

        On the stiffened support limbs the feed-forward would turn the dead-beat IK's velocity
        noise into large torques.

        Args:
            sim: The trial's MuJoCo model.
            out: What :meth:`step` returned.
        """
        v_ff = out.v.copy()
        v_ff[self.support_v_index] = 0.0
        sim.set_servo_targets(out.q, v_ff)

    @classmethod
    def trial_description(
        cls, options: TrialGains, sim: SimModel, effort_limits: bool
    ) -> dict[str, Any]:
        """Name, gains, rates and servo gains (see :meth:`Controller.trial_description`)."""
        gains = trial_gains(options, sim)[0]
        return {
            "name": cls.name,
            "gains": gains.to_dict(),
            "control_rate_hz": gains.rate,
            "sim_timestep": float(sim.model.opt.timestep),
            "servo": {
                "kp": sim.kp.tolist(),
                "kd": sim.kd.tolist(),
                "joints": list(sim.joint_names),
            },
        }

    @classmethod
    def trial_summary(
        cls, options: TrialGains, sim: SimModel, effort_limits: bool
    ) -> dict[str, Any]:
        """Name and gains only (see :meth:`Controller.trial_summary`)."""
        return {"name": cls.name, "gains": trial_gains(options, sim)[0].to_dict()}

    @property
    def q_ref(self) -> _FloatArray:
        """The reference configuration (nq, pinocchio order)."""
        answer: _FloatArray = self.configuration.q
        return answer

    def measure(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured CoM and CoM velocity (m, m/s, world) from pinocchio's ``(q, v)``."""
        pin.centerOfMass(self.model, self.data, q, v, False)
        return self.data.com[0].copy(), self.data.vcom[0].copy()

    def step(
        self,
        t: float,
        q: np.ndarray,
        v: np.ndarray,
        zmp_measured: np.ndarray | None = None,
        impact_force: float = 0.0,
    ) -> ControlOutput:
        """One control step from the measured state.

        ``q`` and ``v`` are pinocchio's, the free-flyer velocity in the base frame.

        ``zmp_measured`` is the ZMP of the measured contact forces on the plane (m, world; None or
        NaN when unknown); ``impact_force`` the measured normal force at the impact point (N).
        """
        g, dt = self.gains, self.dt
        com, com_velocity = self.measure(q, v)
        zmp, xi, clamped = self.feedback.desired_zmp(com[:2], com_velocity[:2])
        if zmp_measured is not None and np.all(np.isfinite(zmp_measured)):
            zmp_measured = np.asarray(zmp_measured, dtype=float)[:2]
            if self._zmp_filtered is None:
                self._zmp_filtered = zmp_measured.copy()
            self._zmp_filtered += min(1.0, dt / g.zmp_filter) * (zmp_measured - self._zmp_filtered)
            speed = g.zmp_admittance * (self._zmp_filtered - zmp)
            norm = float(np.linalg.norm(speed))
            if norm > g.max_com_speed:
                speed *= g.max_com_speed / norm
            # The commanded CoM stays over the ZMP support area: a reference that could stand still.
            self.com_command = clamp_to_polygon(
                self.feedback.zmp_area, self.com_command + dt * speed, g.zmp_margin
            )
        self.com_task.set_target(np.array([*self.com_command, self.com_height]))
        tasks = [self.com_task, *self.contact_tasks, self.posture_task]
        if self.impact is not None and self.impact_task is not None:
            point = self.impact.target(t, impact_force)
            frame_origin = point - self._impact_rotation @ self.impact.offset.translation
            self.impact_task.set_target(pin.SE3(self._impact_rotation, frame_origin))
            tasks.append(self.impact_task)
        velocity = pink.solve_ik(
            self.configuration, tasks, dt, solver=g.solver, damping=g.damping, safety_break=False
        )
        q_next = pin.integrate(self.model, self.configuration.q, velocity * dt)
        # pink's limits keep the step within bounds up to round-off; clip that round-off away.
        q_next[7:] = np.clip(q_next[7:], self._lower, self._upper)
        self.configuration.update(q_next)
        self.v_ref = velocity
        return ControlOutput(
            self.configuration.q.copy(), velocity, zmp, xi, clamped, com, com_velocity
        )

    def describe(self) -> dict[str, Any]:
        """Name and gains (the ``controller`` object of ``validate --json``)."""
        return {"name": self.name, "gains": self.gains.to_dict(), "omega": self.omega}
