"""Torque-controlled balance: DCM feedback + a whole-body inverse-dynamics QP, for MuJoCo motors.

The alternative to :mod:`~impact_balance.sim.control.kinematic` (pink IK and position servos): the
``id`` member of the :class:`~impact_balance.sim.control.controller.Controller` family. Where the
kinematic controller moves the ZMP only through a slow CoM admittance, this one chooses the
contact wrenches themselves, so the ZMP can reach the edge of the ZMP support area within one
control step: the zero-step capture that the CoM criterion assumes.

At every control step (500 Hz by default), from the measured ``(q, v)`` (pinocchio order, the
free-flyer velocity in the base frame):

1. pinocchio computes the mass matrix ``M`` (plus, with ``implicit_damping_inertia``, the
   simulated plant's ``h_s D`` on the actuated joints: below), the nonlinear effects ``h``, the
   centroidal momentum matrix ``A_g`` and its drift ``A_g_dot v``, the contact Jacobians ``J_i``
   (world-aligned axes, at the contact point) and their drifts ``J_i_dot v``.
2. :class:`~.zmp.DcmFeedback` (the same as the kinematic controller's) picks the desired ZMP
   ``p = xi + (k/omega)(xi - xi_ref)`` clamped to the ZMP support area of the contact model
   the QP enforces (:func:`clamp_areas`): the scenario's stance, torque limits, plane and ZMP
   margin, every contact's friction times ``friction_scale`` and its rectangle shrunk by
   ``cop_margin``, computed once by the library's pipeline
   (:func:`~impact_balance.analysis.analyze.contact_model_areas`). A ZMP of the full-friction
   area outside this one needs wrenches the QP's cones refuse.
3. One dense QP (daqp, called directly: the step must stay well under a millisecond) in
   ``x = [a (nv); w_1 .. w_nc (6 each)]``, the joint accelerations and the contact wrenches
   ``[f; tau]`` (world axes, at each contact point):

   - equalities: the 6 unactuated rows of ``M a + h = S^T tau + sum J_i^T w_i`` (the floating
     base), and ``J_i a + J_i_dot v = -K_c J_i v`` for each contact (the contacts stay); a point
     contact (size ``[0, 0]``) keeps its linear rows only and its torque is zero instead (a
     point foot rolls);
   - inequalities: each ``w_i`` in its contact wrench cone
     (:func:`impact_balance.contacts.cwc.cwc_faces_world`) (friction and rectangle shrunk by
     margins, see :class:`InverseDynamicsGains`) with a minimum normal force, the joint position
     limits (as acceleration bounds), and ``|tau + c| <= effort`` with ``tau`` the actuated rows
     of ``M a + h - sum J_i^T w_i`` and ``c`` what the motors add to it (step 4): the motor, not
     the QP's share of it, is what saturates; with a governed approach (a task whose
     ``speed_bound()`` is finite, :class:`~impact_balance.sim.studies.wall.GovernedApproach`),
     the impact point's approach speed one control period ahead,
     ``-n . (J_p (v + a dt) + J_p_dot v dt)``, at most the governor's cap: the paper's "track
     the maximum contact velocity with a whole-body QP" as a hard bound, so that the torque
     controller's tracking lag cannot carry the point past a falling cap;
   - cost (weighted least squares): the CoM acceleration of the LIPM,
     ``c_dd_xy = omega^2 (c_xy - p)``, with a PD on the CoM height; angular momentum damping
     ``L_dot = -K_L L``; the impact point's acceleration (the :class:`~.approach.ImpactTask`
     reference's acceleration, plus a PD to its position and velocity); a posture
     PD to the start configuration (joints) and one on the base orientation; a small regularisation.

   With ``touch_contact`` (:class:`InverseDynamicsGains`) and an impact task, ``x`` also holds
   the touching point's force ``f_h`` (3, world axes, on the robot at the impact point): from
   the first control step whose measured normal force at the impact point is positive until
   the task starts its withdrawal (its ``contact_time``), the point is a contact of the QP,

   - ``J_h a + J_h_dot v = -K_c J_h v`` (the point stays, as the stance's contacts; ``J_h`` the
     linear rows of the impact point's Jacobian) and ``J_h^T f_h`` in the floating base's rows
     and in ``tau``;
   - ``|t_k . f_h| <= mu_h n . f_h`` (k = 1, 2; ``n`` the surface normal into the robot, ``t_k``
     two tangents; ``mu_h`` the impact's friction times ``friction_scale``);
   - ``n . f_h >= f_press``, the task's ``force_threshold`` (N): the force at which the task
     withdraws, so that the withdrawal starts as without the option (0 for a task without a
     finite one);

   otherwise ``f_h = 0``. The task's reference still enters the cost; while the point is a
   contact its linear rows cannot move it.

   If the torque limits make the QP infeasible, it is solved without them and the torques are
   clipped (MuJoCo clips them too); then, if need be, without the joint limits, then without
   the approach speed's bound.
4. The torques ``tau`` go to MuJoCo's motors, plus ``c``, the compensation of the joints' viscous
   damping and dry friction (:func:`motor_compensation`: MuJoCo's ``damping`` and
   ``frictionloss``, the URDF's ``<dynamics damping friction>``), which the QP's model leaves out.
   On a joint whose effort limit is a few N m (a wrist: Talos' 3 to 6.6 N m against its 1 N m of
   friction) an uncompensated friction is a large share of what the QP plans.

**The plant's inertia.** MuJoCo's implicit(-fast) integrator integrates the joint damping ``D``
implicitly: a step of ``h_s`` seconds solves ``(M + h_s D) a = ...``
(:func:`~impact_balance.sim.model.integrator.implicit_damping_inertia`). The motors cancel
``D qdot``; the ``h_s D`` of inertia stays. With ``implicit_damping_inertia``
(:class:`InverseDynamicsGains`, the default) the QP's ``M`` is ``M + diag(h_s D)`` on the
actuated joints (built by :meth:`InverseDynamicsController.for_trial` from the trial's model: its
timestep, integrator and ``dof_damping``; zero on the floating base, so its six rows are
unchanged), in the torques' rows and so in every torque the QP plans. On a light damped joint
(iCub's wrists: ``M_ii`` 4.8e-4 kg m^2 against ``h_s D`` = 1e-3) it is most of the inertia.

The measured ZMP is not needed (the wrenches are chosen, not admitted); the argument is kept so
that both controllers share :meth:`step`'s signature.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import daqp
import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.analysis.analyze import Analysis, contact_model_areas
from impact_balance.balance.areas import BalanceAreas
from impact_balance.balance.lipm import lipm_omega
from impact_balance.contacts.contact_model import inset_half_size
from impact_balance.contacts.cwc import cwc_faces_world
from impact_balance.exceptions import SimulationError
from impact_balance.geometry.spatial import skew
from impact_balance.sim.control.actuation import use_torque_motors
from impact_balance.sim.control.approach import ImpactReference
from impact_balance.sim.control.controller import Controller
from impact_balance.sim.control.gains import InverseDynamicsGains, TrialGains, trial_gains
from impact_balance.sim.control.zmp import DcmFeedback
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.model.integrator import implicit_damping_inertia

__all__ = [
    "InverseDynamicsController",
    "TorqueOutput",
    "clamp_areas",
    "motor_compensation",
    "touch_faces",
]

_FloatArray = npt.NDArray[np.float64]

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class TorqueOutput:
    """One control step's command and what the controller saw.

    Attributes:
        tau: Joint torques of the actuated joints (nv - 6, pinocchio velocity order) [N m].
        a: Joint accelerations of the QP (nv) [m/s^2, rad/s^2].
        wrenches: Contact wrenches of the QP (nc x 6, ``[f; tau]`` at each contact point, world
            axes).
        zmp: Clamped desired ZMP (m, world).
        dcm: Measured DCM (m, world).
        clamped: Whether the desired ZMP was clamped to the area.
        com: Measured CoM (m, world).
        com_velocity: Measured CoM velocity (m/s, world).
        torque_limited: Whether the torque limits had to be dropped (infeasible) and the torques
            clipped.
        touch_force: The touching point's planned contact force (N, world, on the robot; zero
            while it is no contact of the QP); None without ``touch_contact``.
    """

    tau: np.ndarray
    a: np.ndarray
    wrenches: np.ndarray
    zmp: np.ndarray
    dcm: np.ndarray
    clamped: bool
    com: np.ndarray
    com_velocity: np.ndarray
    torque_limited: bool = False
    touch_force: np.ndarray | None = None


@dataclass(frozen=True)
class _Dynamics:
    """What one control step computes at the measured state (pinocchio; world frame)."""

    M: _FloatArray  # mass matrix (nv x nv), both triangles, plus the plant's h_s D (actuated)
    h: _FloatArray  # nonlinear effects (nv)
    Ag: _FloatArray  # centroidal momentum matrix (6 x nv)
    drift_hg: _FloatArray  # centroidal momentum drift A_g_dot v (6)
    hg: _FloatArray  # centroidal momentum (6)
    com: _FloatArray  # CoM (3), m
    com_velocity: _FloatArray  # CoM velocity (3), m/s


class _Tasks:
    """The weighted least-squares tasks ``A a = b`` (weight per row) of one control step."""

    def __init__(self) -> None:
        self.rows: list[_FloatArray] = []
        self.targets: list[_FloatArray] = []
        self.weights: list[_FloatArray] = []

    def add(self, A: _FloatArray, b: _FloatArray, weight: float) -> None:
        """One task: ``A a = b`` with ``weight`` on every row."""
        self.rows.append(A)
        self.targets.append(b)
        self.weights.append(np.full(len(b), weight))

    def stacked(self) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
        """``A``, ``b`` and the row weights of all the tasks."""
        return np.vstack(self.rows), np.concatenate(self.targets), np.concatenate(self.weights)


@dataclass(frozen=True)
class _Rows:
    """Where the optional constraint blocks start: approach speed, joint limits, torque limits."""

    ms: int
    m0: int
    m1: int


def motor_compensation(
    damping: _FloatArray, friction: _FloatArray, qdot: _FloatArray, friction_velocity: float
) -> _FloatArray:
    """The torque the motors add to the QP's to cancel the joints' damping and dry friction.

    ``D qdot + F clip(qdot / v_f, -1, 1)`` (N m), elementwise: MuJoCo's viscous joint damping
    ``D`` (N m s/rad) and dry friction ``F`` (``frictionloss``, N m) at the joint velocities
    ``qdot`` (rad/s); the friction's sign is linear below ``v_f = friction_velocity`` (rad/s), so
    that a joint at rest gets no full-size switching torque.
    """
    answer: _FloatArray = damping * qdot + friction * np.clip(qdot / friction_velocity, -1.0, 1.0)
    return answer


def clamp_areas(analysis: Analysis, gains: InverseDynamicsGains) -> BalanceAreas:
    """The balance areas of the contact model the ``id`` controller's QP enforces.

    :func:`~impact_balance.analysis.analyze.contact_model_areas` of the analysis's scenario and
    stance with every contact's friction times ``gains.friction_scale`` and its rectangle shrunk
    by ``gains.cop_margin`` (m; never below half its size, as the QP's). The analysis's own
    areas when both leave the contacts as they are (scale 1, margin 0, and the analysis at the
    scenario's frictions).

    Args:
        analysis: The scenario's analysis (its stance's contacts are the scenario's).
        gains: The controller's gains.

    Returns:
        The ZMP support area and CoM velocity area (world frame) the desired ZMP is clamped to.
    """
    if (
        gains.friction_scale == 1.0
        and gains.cop_margin == 0.0
        and analysis.scenario.friction_scale == 1.0
    ):
        return analysis.areas
    return contact_model_areas(
        analysis.scenario, analysis.stance, gains.friction_scale, gains.cop_margin
    )


def touch_faces(normal: npt.ArrayLike, friction: float) -> _FloatArray:
    """The friction pyramid of a point contact: ``F f <= 0`` (4 x 3, world axes).

    Rows ``(+-t_k - mu n)`` for two unit tangents ``t_1``, ``t_2`` orthogonal to the unit
    ``normal`` ``n``: ``|t_k . f| <= mu n . f``, the pyramid of
    :func:`~impact_balance.contacts.cwc.cwc_faces_world` at a point.

    Args:
        normal: The surface normal, into the robot (world; normalised here).
        friction: The friction coefficient ``mu`` (>= 0).

    Raises:
        ValueError: A zero or non-finite normal, or a negative or non-finite friction.
    """
    n = np.asarray(normal, dtype=float)
    norm = float(np.linalg.norm(n))
    if not (np.isfinite(norm) and norm > 0):
        raise ValueError(f"normal must be a non-zero finite vector, not {n.tolist()!r}")
    if not (np.isfinite(friction) and friction >= 0):
        raise ValueError(f"friction must be finite and >= 0, not {friction!r}")
    n = n / norm
    helper = np.eye(3)[int(np.argmin(np.abs(n)))]
    t1 = np.cross(n, helper)
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    mu = float(friction)
    faces: _FloatArray = np.array([t1 - mu * n, -t1 - mu * n, t2 - mu * n, -t2 - mu * n])
    return faces


def _impact_friction(analysis: Analysis, gains: InverseDynamicsGains) -> float:
    """The touching point's friction in the QP: the impact's times ``gains.friction_scale``."""
    if analysis.impact is None:
        raise SimulationError("touch_contact", True, "the scenario has no impact: nothing touches")
    return float(gains.friction_scale * analysis.impact.model.spec.friction)


def _point_jacobian(
    model: pin.Model, data: pin.Data, fid: int, offset: pin.SE3
) -> tuple[pin.SE3, np.ndarray, np.ndarray]:
    """Pose, Jacobian and acceleration drift of the point ``frame * offset``.

    Pose, 6 x nv Jacobian (world axes, linear first) and acceleration drift ``J_dot v`` of ``frame *
    offset``.

    Needs ``data`` from a forward kinematics with zero acceleration (so the frame acceleration is
    the drift).
    The drift is the classical one: the linear acceleration of the point itself.
    """
    frame_pose = data.oMf[fid]
    J = pin.getFrameJacobian(model, data, fid, _LWA)
    drift = pin.getFrameClassicalAcceleration(model, data, fid, _LWA).vector.copy()
    if offset.isIdentity():
        return pin.SE3(frame_pose), J, drift
    placement = frame_pose * offset
    r = placement.translation - frame_pose.translation
    velocity = pin.getFrameVelocity(model, data, fid, _LWA)
    w = velocity.angular
    # Rigid point at r from the frame origin:
    # v_p = v_o + w x r, a_p = a_o + w_dot x r + w x (w x r).
    J[:3] -= skew(r) @ J[3:]
    drift[:3] += np.cross(drift[3:], r) + np.cross(w, np.cross(w, r))
    return placement, J, drift


class InverseDynamicsController(Controller["TorqueOutput"]):
    """DCM-feedback balance through a whole-body inverse-dynamics QP (see the module docstring).

    Args:
        analysis: The scenario's analysis (stance, areas; the impact if any).
        q0: Start configuration (nq), the posture target; default the stance's.
        gains: Gains, weights and rate (default :class:`InverseDynamicsGains`).
        impact: The impact task, if any.
        effort_limits: Bound the joint torques by the URDF effort limits.

    Attributes:
        joint_damping: MuJoCo's viscous joint damping (N m s/rad, by simulated joint) that
            :meth:`actuate` compensates; none unless built by :meth:`for_trial`.
        joint_friction: MuJoCo's dry joint friction (``frictionloss``, N m, by simulated joint)
            that :meth:`actuate` compensates; none unless built by :meth:`for_trial`.
        implicit_inertia: The inertia added to the QP's ``M`` on each actuated velocity row
            (nv - 6, pinocchio order; kg m^2): ``h_s D`` of the simulated joint
            (:func:`~impact_balance.sim.model.integrator.implicit_damping_inertia`) when built by
            :meth:`for_trial` with ``implicit_damping_inertia``, else zeros.
    """

    name = "dcm-zmp-clamp + inverse-dynamics QP -> joint torques"

    def __init__(
        self,
        analysis: Analysis,
        q0: np.ndarray | None = None,
        gains: InverseDynamicsGains | None = None,
        impact: ImpactReference | None = None,
        effort_limits: bool = True,
    ):
        gains = gains or InverseDynamicsGains()
        self.analysis = analysis
        self.gains = gains
        self.impact = impact
        stance = analysis.stance
        self.model = model = stance.robot.model
        self.data = model.createData()
        self.q0 = stance.q.copy() if q0 is None else np.asarray(q0, dtype=float).copy()
        self.rate = gains.rate
        self.dt = 1.0 / gains.rate
        self.joint_damping: _FloatArray = np.zeros(0)
        self.joint_friction: _FloatArray = np.zeros(0)
        self.nv = nv = model.nv
        # The damping (N m s/rad) and dry friction (N m) the motors compensate, by actuated
        # velocity row (see for_trial and compensation()).
        self._damping_rows: _FloatArray = np.zeros(nv - 6)
        self._friction_rows: _FloatArray = np.zeros(nv - 6)
        self.implicit_inertia: _FloatArray = np.zeros(nv - 6)
        self._actuated_diagonal = (np.arange(6, nv), np.arange(6, nv))
        self.nc = len(stance.contacts)
        self._init_touch(analysis, gains, impact)
        self.n = nv + 6 * self.nc + self._touch_vars
        self.mass = float(sum(inertia.mass for inertia in model.inertias))
        self.gravity = analysis.areas.gravity
        self.plane_height = analysis.areas.plane_height
        com0 = np.array(pin.centerOfMass(model, self.data, self.q0), dtype=float)
        self.com_height = float(com0[2])
        self.omega = lipm_omega(self.com_height, self.plane_height, self.gravity)
        #: The areas of the QP's contact model (:func:`clamp_areas`): the desired ZMP's clamp.
        self.clamp_areas = clamp_areas(analysis, gains)
        self.feedback = DcmFeedback(
            self.clamp_areas.zmp_area, self.omega, com0[:2].copy(), gains.dcm_gain, gains.zmp_margin
        )
        pin.framesForwardKinematics(model, self.data, self.q0)
        self.contact_frames = [model.getFrameId(c.spec.frame) for c in stance.contacts]
        self.contact_offsets = [c.spec.offset for c in stance.contacts]
        self.contact_specs = [c.spec for c in stance.contacts]
        self.contact_half_sizes = [
            (
                inset_half_size(c.half_length, gains.cop_margin),
                inset_half_size(c.half_width, gains.cop_margin),
            )
            for c in stance.contacts
        ]
        # Torque limits on the actuated rows (velocity index >= 6); 0 or missing effort: unbounded.
        effort = np.full(nv - 6, np.inf)
        idx, values = stance.robot.effort_limits
        for i, e in zip(idx, values, strict=False):
            if i >= 6 and e > 0:
                effort[i - 6] = e
        self.effort = effort
        self.effort_limits = effort_limits
        self._limited = (
            np.flatnonzero(np.isfinite(effort)) if effort_limits else np.zeros(0, dtype=int)
        )
        self._impact_frame = None
        if impact is not None:
            self._impact_frame = model.getFrameId(impact.frame)
            pose = self.data.oMf[self._impact_frame] * impact.offset
            self._impact_rotation = pose.rotation.copy()
        self._zero = np.zeros(nv)
        # Posture weights per velocity row: none on the base translation (the CoM task owns it).
        self._posture_w = np.full(nv, gains.posture_weight)
        self._posture_w[:3] = 0.0
        self._posture_w[3:6] = 0.0  # the base orientation has its own task (world axes)
        self.last: TorqueOutput | None = None
        self._base_rotation = pin.XYZQUATToSE3(self.q0[:7]).rotation
        self._lower_triangle = np.tril_indices(nv, -1)
        n, nc = self.n, self.nc
        P_diag = np.zeros((n, n))
        P_diag[np.arange(nv), np.arange(nv)] = self._posture_w + gains.acceleration_regularization
        P_diag[np.arange(nv, n), np.arange(nv, n)] = np.concatenate(
            [
                np.tile([gains.wrench_regularization] * 3 + [gains.torque_regularization] * 3, nc),
                np.full(self._touch_vars, gains.wrench_regularization),
            ]
        )
        self._P_diag, self._P = P_diag, np.zeros((n, n))
        # Position limits of the 1-dof joints (a continuous joint has nq = 2 and no limit).
        one_dof = [j for j in model.joints[2:] if j.nq == 1 and j.nv == 1]
        self._limit_q = np.array([j.idx_q for j in one_dof], dtype=int)
        self._limit_v = np.array([j.idx_v for j in one_dof], dtype=int)
        self._q_lower = model.lowerPositionLimit[self._limit_q].copy()
        self._q_upper = model.upperPositionLimit[self._limit_q].copy()
        # One row bounds the impact point's approach speed when the task is governed (see step()).
        bound = getattr(impact, "speed_bound", None)
        self._speed_bound: Callable[[], float] | None = bound if callable(bound) else None
        self._speed_rows = int(impact is not None and self._speed_bound is not None)
        self._init_rows()

    def _init_touch(
        self, analysis: Analysis, gains: InverseDynamicsGains, impact: ImpactReference | None
    ) -> None:
        """The touching point's force (3 variables, 8 rows) with ``touch_contact`` and a task."""
        touch = bool(gains.touch_contact and impact is not None)
        self._touch_vars, self._touch_rows = (3, 8) if touch else (0, 0)
        #: When the impact point first touched (s; the first positive measured normal force).
        self.touch_time: float | None = None
        #: The touching point's pressing force while it is a contact (N).
        self.touch_force = 0.0
        if impact is None or not touch:
            return
        self._touch_normal = np.asarray(impact.normal, dtype=float)
        self._touch_faces = touch_faces(self._touch_normal, _impact_friction(analysis, gains))
        threshold = float(getattr(impact, "force_threshold", 0.0))
        self.touch_force = threshold if np.isfinite(threshold) and threshold > 0 else 0.0
        self._touch_point: tuple[_FloatArray, _FloatArray] | None = None
        self._touch_jacobian = np.zeros((3, self.nv))

    def _init_rows(self) -> None:
        """The QP's constraint buffers (see :meth:`_constraints` for their order)."""
        n, nc, nv = self.n, self.nc, self.nv
        m = (
            6
            + 6 * nc
            + 17 * nc
            + self._touch_rows
            + self._speed_rows
            + self._limit_q.size
            + self._limited.size
        )
        self._C = np.zeros((m, n))
        self._upper = np.zeros(m)
        self._lower = np.full(m, -1e30)
        self._sense = np.zeros(m, dtype=np.intc)
        self._sense[: 6 + 6 * nc] = 5  # daqp: active and immutable = equality
        touch_equalities = 6 + 23 * nc  # after the cones and the minimum normal forces
        self._sense[touch_equalities : touch_equalities + min(self._touch_rows, 3)] = 5
        self._Jw = np.zeros((6 * nc, nv))  # contact Jacobians at the contact points (world axes)
        self._x: np.ndarray | None = None

    # -- measurement -----------------------------------------------------------------
    def measure(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured CoM and CoM velocity (m, m/s, world) from pinocchio's ``(q, v)``."""
        pin.centerOfMass(self.model, self.data, q, v, False)
        return self.data.com[0].copy(), self.data.vcom[0].copy()

    # -- the family's hooks ---------------------------------------------------------------
    @classmethod
    def prepare_model(cls, sim: SimModel, analysis: Analysis) -> None:
        """Torque motors instead of servos (see :meth:`Controller.prepare_model`)."""
        use_torque_motors(sim)

    @classmethod
    def zmp_margin(cls, options: TrialGains) -> float:
        """The margin of ``options.id_gains`` (m; see :meth:`Controller.zmp_margin`)."""
        return options.id_gains.zmp_margin

    @classmethod
    def for_trial(
        cls,
        analysis: Analysis,
        q_start: _FloatArray,
        options: TrialGains,
        task: ImpactReference | None,
        sim: SimModel,
        support_v_index: npt.NDArray[np.int_],
    ) -> InverseDynamicsController:
        """The controller of one trial, with ``options.id_gains`` (derived from the robot).

        See :meth:`Controller.for_trial` and :func:`~impact_balance.sim.control.gains.trial_gains`.

        The torques are bounded when ``sim``'s motors are force-limited; MuJoCo's viscous joint
        damping and dry friction (the URDF's) are compensated: the motors add
        :func:`motor_compensation`, and the QP bounds the sum by the effort limits. With
        ``implicit_damping_inertia`` the QP's inertia is the plant's, ``M + h_s D``
        (:attr:`implicit_inertia`, from ``sim``'s model).
        """
        controller = cls(
            analysis,
            q_start,
            trial_gains(options, sim)[1],
            task,
            effort_limits=bool(sim.model.actuator_forcelimited[sim.actuator_ids].any()),
        )
        controller.joint_damping = sim.model.dof_damping[sim.dof_adr].copy()
        controller._damping_rows[sim.v_index - 6] = controller.joint_damping
        controller.joint_friction = sim.model.dof_frictionloss[sim.dof_adr].copy()
        controller._friction_rows[sim.v_index - 6] = controller.joint_friction
        if controller.gains.implicit_damping_inertia:
            added = implicit_damping_inertia(sim.model)[sim.dof_adr]
            controller.implicit_inertia[sim.v_index - 6] = added
        return controller

    def compensation(self, v: _FloatArray) -> _FloatArray:
        """What :meth:`actuate` adds to the QP's torques at ``v`` (N m, actuated rows).

        :func:`motor_compensation` of the joints' damping and dry friction (zero unless built
        by :meth:`for_trial`) at the actuated rows of ``v`` (pinocchio order).
        """
        return motor_compensation(
            self._damping_rows, self._friction_rows, v[6:], self.gains.friction_velocity
        )

    def hold(self, sim: SimModel, q_start: _FloatArray) -> None:
        """The motors apply the holding torques (see :meth:`Controller.hold`)."""
        sim.data.ctrl[sim.actuator_ids] = sim.tau_hold

    def actuate(self, sim: SimModel, out: TorqueOutput) -> None:
        """The motors apply ``out.tau`` plus the compensation of the joint damping and friction.

        Args:
            sim: The trial's MuJoCo model.
            out: What :meth:`step` returned.
        """
        d = sim.data
        d.ctrl[sim.actuator_ids] = out.tau[sim.v_index - 6] + motor_compensation(
            self.joint_damping,
            self.joint_friction,
            d.qvel[sim.dof_adr],
            self.gains.friction_velocity,
        )

    @classmethod
    def trial_description(
        cls, options: TrialGains, sim: SimModel, effort_limits: bool
    ) -> dict[str, Any]:
        """Name, gains, rates and actuators (see :meth:`Controller.trial_description`)."""
        gains = trial_gains(options, sim)[1]
        return {
            "name": cls.name,
            "gains": gains.to_dict(),
            "control_rate_hz": gains.rate,
            "sim_timestep": float(sim.model.opt.timestep),
            "actuators": (
                "torque motors (MuJoCo), viscous joint damping and dry friction compensated"
            ),
            "effort_limits": effort_limits,
            "impact_task": {"force_threshold": 15.0, "retract": 0.05},
        }

    # -- control ------------------------------------------------------------------------
    def step(
        self,
        t: float,
        q: _FloatArray,
        v: _FloatArray,
        zmp_measured: _FloatArray | None = None,
        impact_force: float = 0.0,
    ) -> TorqueOutput:
        """One control step from the measured state; returns the joint torques.

        Args:
            t: Time (s).
            q: Measured configuration (nq, pinocchio order).
            v: Measured velocity (nv, free-flyer velocity in the base frame).
            zmp_measured: Unused (the wrenches are chosen, not admitted).
            impact_force: Measured normal force at the impact point (N).

        Returns:
            The torques and the QP's accelerations and wrenches (see :class:`TorqueOutput`).
        """
        state = self._dynamics(q, v)
        if self._touch_rows and self.touch_time is None and impact_force > 0.0:
            self.touch_time = float(t)
        zmp, xi, clamped = self.feedback.desired_zmp(state.com[:2], state.com_velocity[:2])
        tasks, speed_row = self._tasks(t, v, impact_force, state, zmp)
        P, c = self._cost(tasks, q, v)
        compensation = self.compensation(v)
        T, t0, rows = self._constraints(q, v, state, speed_row, compensation)
        x, torque_limited = self._solve(P, c, rows)
        nv, nc = self.nv, self.nc
        a, w = x[:nv], x[nv : nv + 6 * nc]
        tau = T @ x + t0
        if self.effort_limits:
            tau = np.clip(tau, -self.effort - compensation, self.effort - compensation)
        out = TorqueOutput(
            tau,
            a,
            w.reshape(nc, 6),
            zmp,
            xi,
            clamped,
            state.com,
            state.com_velocity,
            torque_limited,
            x[nv + 6 * nc :].copy() if self._touch_vars else None,
        )
        self.last = out
        return out

    def _dynamics(self, q: _FloatArray, v: _FloatArray) -> _Dynamics:
        """Dynamics and kinematics at ``(q, v)`` and zero acceleration (so drifts)."""
        model, data = self.model, self.data
        pin.crba(model, data, q)
        M = data.M.copy()
        M[self._lower_triangle] = M.T[self._lower_triangle]  # crba fills the upper triangle only
        M[self._actuated_diagonal] += self.implicit_inertia  # the plant's h_s D (for_trial)
        h = pin.nonLinearEffects(model, data, q, v)
        pin.forwardKinematics(model, data, q, v, self._zero)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        Ag = pin.computeCentroidalMap(model, data, q)
        # With a = 0, dhg is the centroidal momentum drift A_g_dot v (also sets data.com, data.hg).
        pin.computeCentroidalMomentumTimeVariation(model, data, q, v, self._zero)
        drift_hg = data.dhg.vector.copy()
        hg = data.hg.vector.copy()
        com = data.com[0].copy()
        return _Dynamics(M, h, Ag, drift_hg, hg, com, hg[:3] / self.mass)

    def _tasks(
        self,
        t: float,
        v: _FloatArray,
        impact_force: float,
        state: _Dynamics,
        zmp: _FloatArray,
    ) -> tuple[_Tasks, tuple[_FloatArray, float] | None]:
        """The weighted least-squares tasks on the accelerations, and the approach speed's row.

        Returns:
            The tasks, and ``(row, bound)`` of the governed approach speed (None when unbounded).
        """
        g, model, data = self.gains, self.model, self.data
        com, com_velocity, hg, drift_hg = state.com, state.com_velocity, state.hg, state.drift_hg
        tasks = _Tasks()
        # CoM: m c_dd = A_g[:3] a + drift; LIPM horizontally, PD on the height.
        com_dd = np.empty(3)
        com_dd[:2] = self.omega**2 * (com[:2] - zmp)
        com_dd[2] = (
            g.com_height_stiffness * (self.com_height - com[2])
            - g.com_height_damping * com_velocity[2]
        )
        tasks.add(state.Ag[:3] / self.mass, com_dd - drift_hg[:3] / self.mass, g.com_weight)
        # Angular momentum about the CoM (per unit mass): L_dot = -K_L L.
        tasks.add(
            state.Ag[3:] / self.mass,
            (-g.angular_momentum_damping * hg[3:] - drift_hg[3:]) / self.mass,
            g.angular_momentum_weight,
        )
        # Base orientation (world axes): angular acceleration of the base frame.
        J_base = pin.getJointJacobian(model, data, 1, _LWA)
        base_drift = pin.getClassicalAcceleration(model, data, 1, _LWA).angular
        R = data.oMi[1].rotation
        rot_error = R @ pin.log3(R.T @ self._base_rotation)
        tasks.add(
            J_base[3:],
            g.base_orientation_stiffness * rot_error
            - g.base_orientation_damping * (J_base[3:] @ v)
            - base_drift,
            g.base_orientation_weight,
        )
        speed_row = None
        if self.impact is not None:
            speed_row = self._impact_tasks(tasks, self.impact, t, v, impact_force)
        return tasks, speed_row

    def _impact_tasks(
        self, tasks: _Tasks, impact: ImpactReference, t: float, v: _FloatArray, impact_force: float
    ) -> tuple[_FloatArray, float] | None:
        """Impact point tasks: PD to the task's target and velocity; the approach speed's row."""
        g = self.gains
        assert self._impact_frame is not None
        placement, Ji, drift = _point_jacobian(
            self.model, self.data, self._impact_frame, impact.offset
        )
        target, target_velocity, target_acceleration = impact.reference(t, impact_force)
        vel = Ji @ v
        lin = (
            target_acceleration
            + g.impact_stiffness * (target - placement.translation)
            + g.impact_damping * (target_velocity - vel[:3])
        )
        ang = (
            g.impact_stiffness
            * (placement.rotation @ pin.log3(placement.rotation.T @ self._impact_rotation))
            - g.impact_damping * vel[3:]
        )
        tasks.add(Ji[:3], lin - drift[:3], g.impact_weight)
        tasks.add(Ji[3:], ang - drift[3:], g.impact_orientation_weight)
        if self._touch_rows:
            self._touch_point = (Ji[:3].copy(), drift[:3].copy())
        if not self._speed_rows:
            return None
        # Approach speed one control period ahead (torques are held for dt):
        # -n . (vel + (Ji a + drift) dt) <= cap. Linear in a; inactive when unbounded.
        assert self._speed_bound is not None
        cap = float(self._speed_bound())
        n_dir = np.asarray(impact.normal, dtype=float)
        if not np.isfinite(cap):
            return None
        return (
            -self.dt * (n_dir @ Ji[:3]),
            cap + n_dir @ vel[:3] + self.dt * (n_dir @ drift[:3]),
        )

    def _cost(
        self, tasks: _Tasks, q: _FloatArray, v: _FloatArray
    ) -> tuple[_FloatArray, _FloatArray]:
        """The QP's cost ``x^T P x / 2 + c^T x``: the tasks, the posture PD, the regularisation."""
        g, nv = self.gains, self.nv
        A_t, b_t, w_t = tasks.stacked()
        P = self._P
        P[:] = self._P_diag
        Aw = A_t.T * w_t
        P[:nv, :nv] += Aw @ A_t
        c = np.zeros(self.n)
        c[:nv] = -(Aw @ b_t)
        # Posture: PD to the start configuration on the joints.
        posture = (
            g.posture_stiffness * pin.difference(self.model, q, self.q0) - g.posture_damping * v
        )
        c[:nv] -= self._posture_w * posture
        return P, c

    def _constraints(
        self,
        q: _FloatArray,
        v: _FloatArray,
        state: _Dynamics,
        speed_row: tuple[_FloatArray, float] | None,
        compensation: _FloatArray,
    ) -> tuple[_FloatArray, _FloatArray, _Rows]:
        """Fill the QP's constraints; return the torques' map and where each block starts.

        The torques are ``tau = T x + t0``; ``compensation`` is what the motors add to them
        (:meth:`compensation` at ``v``, N m, actuated rows): the effort limits bound the sum.

        Stacked for daqp: [floating base (6); contacts (6 nc)] equalities, the contact wrench cones
        (16 nc), the minimum normal forces (nc), the governed approach speed (0 or 1), the joint
        position limits, then the torque limits (double-sided rows).
        """
        g, model, data, nv, nc = self.gains, self.model, self.data, self.nv, self.nc
        M, h = state.M, state.h
        C, upper, lower = self._C, self._upper, self._lower
        ne = 6 + 6 * nc
        C[:6, :nv] = M[:6]
        upper[:6] = -h[:6]
        for i, (fid, offset, spec) in enumerate(
            zip(self.contact_frames, self.contact_offsets, self.contact_specs, strict=True)
        ):
            placement, J, drift = _point_jacobian(model, data, fid, offset)
            r = 6 + 6 * i
            C[:6, nv + 6 * i : nv + 6 * i + 6] = -J[:, :6].T
            C[r : r + 6, :nv] = J
            upper[r : r + 6] = -drift - g.contact_damping * (J @ v)
            if spec.is_point:  # a point foot may roll: no torque instead of no rotation
                C[r + 3 : r + 6, :nv] = 0.0
                C[r + 3 : r + 6, nv + 6 * i + 3 : nv + 6 * i + 6] = np.eye(3)
                upper[r + 3 : r + 6] = 0.0
            self._Jw[6 * i : 6 * i + 6] = J
            k = ne + 16 * i
            C[k : k + 16, nv + 6 * i : nv + 6 * i + 6] = cwc_faces_world(
                g.friction_scale * spec.friction, *self.contact_half_sizes[i], placement.rotation
            )
        lower[:ne] = upper[:ne]
        # Minimum normal force (rows after the cones): n_i . f_i >= f_min, n_i the contact's normal
        # (the frame's axes turned by the contact's offset, as in the cones).
        k = ne + 16 * nc
        for i, (fid, offset) in enumerate(
            zip(self.contact_frames, self.contact_offsets, strict=True)
        ):
            C[k + i, nv + 6 * i : nv + 6 * i + 3] = data.oMf[fid].rotation @ offset.rotation[:, 2]
        lower[k : k + nc] = g.min_normal_force
        upper[k : k + nc] = 1e30
        # The touching point (rows after the minimum normal forces), then the approach speed.
        if self._touch_rows:
            self._touch_constraints(ne + 17 * nc, v)
        ms = ne + 17 * nc + self._touch_rows
        if self._speed_rows:
            C[ms, :] = 0.0
            if speed_row is None:
                upper[ms] = 1e30
            else:
                C[ms, :nv], upper[ms] = speed_row
        # tau = M[6:] a + h[6:] - Jw[:, 6:]^T w - J_h[:, 6:]^T f_h (actuated rows)
        T = np.hstack([M[6:], -self._Jw[:, 6:].T])
        if self._touch_rows:
            T = np.hstack([T, -self._touch_jacobian[:, 6:].T])
        t0 = h[6:]
        limited = self._limited
        m0 = ms + self._speed_rows
        # Joint position limits (rows after the approach speed), then the torque limits.
        T2 = g.joint_limit_horizon
        qj, vj = q[self._limit_q], v[self._limit_v]
        m1 = m0 + self._limit_q.size
        C[np.arange(m0, m1), self._limit_v] = 1.0
        upper[m0:m1] = 2.0 * (self._q_upper - qj - vj * T2) / T2**2
        lower[m0:m1] = np.minimum(2.0 * (self._q_lower - qj - vj * T2) / T2**2, upper[m0:m1])
        if limited.size:
            # The motors add the compensation to tau (actuate): the effort bounds the sum.
            bias = t0[limited] + compensation[limited]
            C[m1:, :] = T[limited]
            upper[m1:] = self.effort[limited] - bias
            lower[m1:] = -self.effort[limited] - bias
        return T, t0, _Rows(ms, m0, m1)

    @property
    def touching(self) -> bool:
        """Whether the impact point is a contact of the QP now (``touch_contact``).

        From its first touch (:attr:`touch_time`) until the impact task's withdrawal starts
        (its ``contact_time``).
        """
        return (
            self._touch_rows > 0
            and self.touch_time is not None
            and self.impact is not None
            and self.impact.contact_time is None
        )

    def _touch_constraints(self, k: int, v: _FloatArray) -> None:
        """Fill the touching point's 8 rows from ``k`` and its columns (see the module docstring).

        Touching: ``J_h a = -J_h_dot v - K_c J_h v`` (3 equalities), the 4 friction faces
        ``F f_h <= 0`` (:func:`touch_faces`) and ``n . f_h >= f_press``; otherwise ``f_h = 0``
        and the inequalities inactive. ``J_h^T f_h`` enters the floating base's rows here, the
        torques' map in :meth:`_constraints`.
        """
        nv, g = self.nv, self.gains
        C, upper, lower = self._C, self._upper, self._lower
        f = slice(nv + 6 * self.nc, self.n)
        assert self._touch_point is not None
        J, drift = self._touch_point
        self._touch_jacobian = J
        C[k : k + 8, :] = 0.0
        C[:6, f] = -J[:, :6].T
        if self.touching:
            C[k : k + 3, :nv] = J
            upper[k : k + 3] = -drift - g.contact_damping * (J @ v)
            C[k + 3 : k + 7, f] = self._touch_faces
            upper[k + 3 : k + 7] = 0.0
            C[k + 7, f] = self._touch_normal
            lower[k + 7] = self.touch_force
            upper[k + 7] = 1e30
        else:
            C[k : k + 3, f] = np.eye(3)
            upper[k : k + 3] = 0.0
            upper[k + 3 : k + 8] = 1e30
        lower[k : k + 3] = upper[k : k + 3]
        lower[k + 3 : k + 7] = -1e30
        if not self.touching:
            lower[k + 7] = -1e30

    def _solve(self, P: _FloatArray, c: _FloatArray, rows: _Rows) -> tuple[_FloatArray, bool]:
        """Solve the QP (daqp), dropping constraints while it is infeasible.

        Solve the QP (daqp); infeasible: drop the torque limits, then the joint limits, then the
        approach speed's bound; still infeasible: hold the last solution.

        Returns:
            The solution ``x`` and whether a constraint had to be dropped.
        """
        C, upper, lower = self._C, self._upper, self._lower
        x, _, exitflag, _ = daqp.solve(P, c, C, upper, lower, self._sense)
        torque_limited = False
        # Infeasible: drop the torque limits (the torques are clipped after), then the joint limits.
        for last in (
            ((rows.m1,) if self._limited.size else ())
            + (rows.m0,)
            + ((rows.ms,) if self._speed_rows else ())
        ):
            if exitflag >= 1:
                break
            torque_limited = True
            x, _, exitflag, _ = daqp.solve(
                P, c, C[:last], upper[:last], lower[:last], self._sense[:last]
            )
        if exitflag < 1:
            # Not even the cones and the contacts together: hold the last command.
            torque_limited = True
            x = np.zeros(self.n) if self._x is None else self._x
        self._x = x
        return x, torque_limited

    def describe(self) -> dict[str, Any]:
        """Name and gains (the ``controller`` object of ``validate --json``)."""
        return {
            "name": self.name,
            "gains": self.gains.to_dict(),
            "omega": self.omega,
            "effort_limits": self.effort_limits,
        }
