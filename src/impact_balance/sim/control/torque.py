"""Torque-controlled balance: DCM feedback + a whole-body inverse-dynamics QP, for MuJoCo motors.

The alternative to :mod:`.balance` (pink IK and position servos) that issue 10 allows. Where the
kinematic controller moves the ZMP only through a slow CoM admittance, this one chooses the
contact wrenches themselves, so the ZMP can reach the edge of the ZMP support area within one
control step: the zero-step capture that the CoM criterion assumes.

At every control step (500 Hz by default), from the measured ``(q, v)`` (pinocchio order, the
free-flyer velocity in the base frame):

1. pinocchio computes the mass matrix ``M``, the nonlinear effects ``h``, the centroidal
   momentum matrix ``A_g`` and its drift ``A_g_dot v``, the contact Jacobians ``J_i`` (world-aligned
   axes, at the contact point) and their drifts ``J_i_dot v``.
2. :class:`~.zmp.DcmFeedback` (the same as the kinematic controller's) picks the desired ZMP
   ``p = xi + (k/omega)(xi - xi_ref)`` clamped to the scenario's ZMP support area.
3. One dense QP (daqp, called directly: the step must stay well under a millisecond) in
   ``x = [a (nv); w_1 .. w_nc (6 each)]``, the joint accelerations and the contact wrenches
   ``[f; tau]`` (world axes, at each contact point):

   - equalities: the 6 unactuated rows of ``M a + h = S^T tau + sum J_i^T w_i`` (the floating
     base), and ``J_i a + J_i_dot v = -K_c J_i v`` for each contact (the contacts stay);
   - inequalities: each ``w_i`` in its contact wrench cone (:func:`impact_balance.contacts.cwc.cwc_faces_world`)
     (friction and rectangle shrunk by margins, see :class:`InverseDynamicsGains`) with a
     minimum normal force, the joint position limits (as acceleration bounds), and
     ``|tau| <= effort`` with ``tau`` the actuated rows of ``M a + h - sum J_i^T w_i``;
     with a governed approach (a task whose ``speed_bound()`` is finite, :class:`~.wall.GovernedApproach`),
     the impact point's approach speed one control period ahead, ``-n . (J_p (v + a dt) + J_p_dot v dt)``,
     at most the governor's cap: the paper's "track the maximum contact velocity with a whole-body QP"
     as a hard bound, so that the torque controller's tracking lag cannot carry the point past a
     falling cap;
   - cost (weighted least squares): the CoM acceleration of the LIPM, ``c_dd_xy = omega^2 (c_xy - p)``,
     with a PD on the CoM height; angular momentum damping ``L_dot = -K_L L``; the impact point's
     acceleration (the :class:`~.approach.ImpactTask` reference's acceleration, plus a PD to its
     position and velocity); a posture
     PD to the start configuration (joints) and one on the base orientation; a small regularisation.

   If the torque limits make the QP infeasible, it is solved without them and the torques are
   clipped (MuJoCo clips them too); then, if need be, without the joint limits, then without
   the approach speed's bound.
4. The torques ``tau`` go to MuJoCo's motors.

The measured ZMP is not needed (the wrenches are chosen, not admitted); the argument is kept so
that both controllers share :meth:`step`'s signature.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import daqp
import numpy as np
import pinocchio as pin

from impact_balance.analysis.analyze import Analysis
from impact_balance.balance.lipm import lipm_omega
from impact_balance.contacts.cwc import cwc_faces_world
from impact_balance.geometry.spatial import skew
from impact_balance.sim.control.approach import ImpactTask
from impact_balance.sim.control.zmp import DcmFeedback

__all__ = ["InverseDynamicsController", "InverseDynamicsGains", "TorqueOutput", "describe"]

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


@dataclass(frozen=True)
class InverseDynamicsGains:
    """Gains, weights and rate of :class:`InverseDynamicsController` (units in brackets).

    Task weights multiply squared accelerations (m/s^2, rad/s^2; the angular momentum rate per
    unit mass, m^2/s^2); the wrench regularisation multiplies squared newtons and newton-metres.

    Attributes:
        rate: Control rate [Hz].
        dcm_gain: DCM error decay rate k [1/s].
        zmp_margin: Desired ZMP kept this far inside the ZMP support area [m].
        com_height_stiffness, com_height_damping: PD on the CoM height [1/s^2], [1/s].
        angular_momentum_damping: K_L in L_dot = -K_L L [1/s].
        contact_damping: K_c in the contact acceleration J a + J_dot v = -K_c J v [1/s].
        posture_stiffness, posture_damping: PD to the start configuration [1/s^2], [1/s].
        base_orientation_stiffness, base_orientation_damping: PD on the base orientation [1/s^2], [1/s].
        impact_stiffness, impact_damping: PD of the impact point to its target [1/s^2], [1/s].
        com_weight, angular_momentum_weight, posture_weight, base_orientation_weight, impact_weight,
        impact_orientation_weight: task weights.
        acceleration_regularization, wrench_regularization: regularisation weights (the latter on the
            contact forces).
        torque_regularization: regularisation weight of the contact torques (N m): keeps the centres
            of pressure central and the yaw torques small.
        friction_scale: The QP's friction coefficient is this fraction of the contact's: a margin
            against slipping, as MuJoCo's contact, like a real one, is not exactly the ideal cone.
        cop_margin: The QP's contact rectangles are shrunk by this much on every side [m].
        min_normal_force: Every contact carries at least this normal force [N]. The ZMP support area
            includes ZMPs reached only by unloading a contact (its cone contains zero); the fall
            detector counts an unloaded contact as lost, so the QP keeps each one loaded.
        joint_limit_horizon: T [s] of the joint position limits on the accelerations: braking at
            ``a`` from ``(q, v)`` stays within the limits for T, ``q + v T + a T^2 / 2`` in
            ``[lower, upper]``. MuJoCo enforces the limits with forces the QP would not know.
    """

    rate: float = 500.0
    dcm_gain: float = 2.0
    zmp_margin: float = 0.01
    com_height_stiffness: float = 100.0
    com_height_damping: float = 20.0
    angular_momentum_damping: float = 10.0
    contact_damping: float = 20.0
    posture_stiffness: float = 100.0
    posture_damping: float = 20.0
    base_orientation_stiffness: float = 100.0
    base_orientation_damping: float = 20.0
    impact_stiffness: float = 400.0
    impact_damping: float = 40.0
    com_weight: float = 1000.0
    angular_momentum_weight: float = 0.1
    posture_weight: float = 1e-2
    base_orientation_weight: float = 0.1
    impact_weight: float = 10.0
    impact_orientation_weight: float = 1.0
    acceleration_regularization: float = 1e-6
    wrench_regularization: float = 1e-7
    torque_regularization: float = 1e-5
    friction_scale: float = 0.65
    cop_margin: float = 0.0
    min_normal_force: float = 20.0
    joint_limit_horizon: float = 0.1

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass(frozen=True)
class TorqueOutput:
    """One control step's command and what the controller saw.

    Attributes:
        tau: Joint torques of the actuated joints (nv - 6, pinocchio velocity order) [N m].
        a: Joint accelerations of the QP (nv) [m/s^2, rad/s^2].
        wrenches: Contact wrenches of the QP (nc x 6, ``[f; tau]`` at each contact point, world axes).
        zmp: Clamped desired ZMP (m, world).
        dcm: Measured DCM (m, world).
        clamped: Whether the desired ZMP was clamped to the area.
        com: Measured CoM (m, world).
        com_velocity: Measured CoM velocity (m/s, world).
        torque_limited: Whether the torque limits had to be dropped (infeasible) and the torques clipped.
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


def _point_jacobian(
    model: pin.Model, data: pin.Data, fid: int, offset: pin.SE3
) -> tuple[pin.SE3, np.ndarray, np.ndarray]:
    """Pose, 6 x nv Jacobian (world axes, linear first) and acceleration drift ``J_dot v`` of ``frame * offset``.

    Needs ``data`` from a forward kinematics with zero acceleration (so the frame acceleration is the drift).
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
    # Rigid point at r from the frame origin: v_p = v_o + w x r, a_p = a_o + w_dot x r + w x (w x r).
    J[:3] -= skew(r) @ J[3:]
    drift[:3] += np.cross(drift[3:], r) + np.cross(w, np.cross(w, r))
    return placement, J, drift


class InverseDynamicsController:
    """DCM-feedback balance through a whole-body inverse-dynamics QP (see the module docstring).

    Args:
        analysis: The scenario's analysis (stance, areas; the impact if any).
        q0: Start configuration (nq), the posture target; default the stance's.
        gains: Gains, weights and rate.
        impact: The impact task, if any.
        effort_limits: Bound the joint torques by the URDF effort limits.
    """

    name = "dcm-zmp-clamp + inverse-dynamics QP -> joint torques"

    def __init__(
        self,
        analysis: Analysis,
        q0: np.ndarray | None = None,
        gains: InverseDynamicsGains = InverseDynamicsGains(),
        impact: ImpactTask | None = None,
        effort_limits: bool = True,
    ):
        self.analysis = analysis
        self.gains = gains
        self.impact = impact
        stance = analysis.stance
        self.model = model = stance.robot.model
        self.data = model.createData()
        self.q0 = stance.q.copy() if q0 is None else np.asarray(q0, dtype=float).copy()
        self.dt = 1.0 / gains.rate
        self.nv = nv = model.nv
        self.nc = len(stance.contacts)
        self.n = nv + 6 * self.nc
        self.mass = float(sum(inertia.mass for inertia in model.inertias))
        self.gravity = analysis.areas.gravity
        self.plane_height = analysis.areas.plane_height
        com0 = np.array(pin.centerOfMass(model, self.data, self.q0), dtype=float)
        self.com_height = float(com0[2])
        self.omega = lipm_omega(self.com_height, self.plane_height, self.gravity)
        self.feedback = DcmFeedback(
            analysis.areas.zmp_area, self.omega, com0[:2].copy(), gains.dcm_gain, gains.zmp_margin
        )
        pin.framesForwardKinematics(model, self.data, self.q0)
        self.contact_frames = [model.getFrameId(c.spec.frame) for c in stance.contacts]
        self.contact_offsets = [c.spec.offset for c in stance.contacts]
        self.contact_specs = [c.spec for c in stance.contacts]
        self.contact_half_sizes = [
            (
                max(c.half_length - gains.cop_margin, 0.5 * c.half_length),
                max(c.half_width - gains.cop_margin, 0.5 * c.half_width),
            )
            for c in stance.contacts
        ]
        # Torque limits on the actuated rows (velocity index >= 6); 0 or missing effort: unbounded.
        effort = np.full(nv - 6, np.inf)
        idx, values = stance.robot.effort_limits
        for i, e in zip(idx, values):
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
        P_diag[np.arange(nv, n), np.arange(nv, n)] = np.tile(
            [gains.wrench_regularization] * 3 + [gains.torque_regularization] * 3, nc
        )
        self._P_diag, self._P = P_diag, np.zeros((n, n))
        # Position limits of the 1-dof joints (a continuous joint has nq = 2 and no limit).
        one_dof = [j for j in model.joints[2:] if j.nq == 1 and j.nv == 1]
        self._limit_q = np.array([j.idx_q for j in one_dof], dtype=int)
        self._limit_v = np.array([j.idx_v for j in one_dof], dtype=int)
        self._q_lower = model.lowerPositionLimit[self._limit_q].copy()
        self._q_upper = model.upperPositionLimit[self._limit_q].copy()
        # One row bounds the impact point's approach speed when the task is governed (see step()).
        self._speed_rows = int(
            impact is not None and callable(getattr(impact, "speed_bound", None))
        )
        m = 6 + 6 * nc + 17 * nc + self._speed_rows + self._limit_q.size + self._limited.size
        self._C = np.zeros((m, n))
        self._upper = np.zeros(m)
        self._lower = np.full(m, -1e30)
        self._sense = np.zeros(m, dtype=np.intc)
        self._sense[: 6 + 6 * nc] = 5  # daqp: active and immutable = equality
        self._Jw = np.zeros((6 * nc, nv))  # contact Jacobians at the contact points (world axes)
        self._x: np.ndarray | None = None

    # -- measurement -----------------------------------------------------------------
    def measure(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Measured CoM and CoM velocity (m, m/s, world) from pinocchio's ``(q, v)``."""
        pin.centerOfMass(self.model, self.data, q, v, False)
        return self.data.com[0].copy(), self.data.vcom[0].copy()

    # -- control ------------------------------------------------------------------------
    def step(
        self,
        t: float,
        q: np.ndarray,
        v: np.ndarray,
        zmp_measured: np.ndarray | None = None,
        impact_force: float = 0.0,
    ) -> TorqueOutput:
        """One control step from the measured state; returns the joint torques (see :class:`TorqueOutput`).

        ``impact_force`` is the measured normal force at the impact point (N); ``zmp_measured`` is unused.
        """
        g = self.gains
        model, data, nv, nc = self.model, self.data, self.nv, self.nc
        # Dynamics and kinematics at (q, v) with zero acceleration: frame accelerations are drifts.
        pin.crba(model, data, q)
        M = data.M.copy()
        M[self._lower_triangle] = M.T[self._lower_triangle]  # crba fills the upper triangle only
        h = pin.nonLinearEffects(model, data, q, v)
        pin.forwardKinematics(model, data, q, v, self._zero)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        Ag = pin.computeCentroidalMap(model, data, q)
        # With a = 0, dhg is the centroidal momentum drift A_g_dot v; it also sets data.com[0], data.hg.
        pin.computeCentroidalMomentumTimeVariation(model, data, q, v, self._zero)
        drift_hg = data.dhg.vector.copy()
        hg = data.hg.vector.copy()
        com = data.com[0].copy()
        com_velocity = hg[:3] / self.mass
        zmp, xi, clamped = self.feedback.desired_zmp(com[:2], com_velocity[:2])

        n = self.n
        rows: list[np.ndarray] = []  # (A, b, weight) of the weighted least-squares tasks on a
        targets: list[np.ndarray] = []
        weights: list[np.ndarray] = []

        def task(A: np.ndarray, b: np.ndarray, weight: float) -> None:
            rows.append(A)
            targets.append(b)
            weights.append(np.full(len(b), weight))

        # CoM: m c_dd = A_g[:3] a + drift; LIPM horizontally, PD on the height.
        com_dd = np.empty(3)
        com_dd[:2] = self.omega**2 * (com[:2] - zmp)
        com_dd[2] = (
            g.com_height_stiffness * (self.com_height - com[2])
            - g.com_height_damping * com_velocity[2]
        )
        task(Ag[:3] / self.mass, com_dd - drift_hg[:3] / self.mass, g.com_weight)
        # Angular momentum about the CoM (per unit mass): L_dot = -K_L L.
        task(
            Ag[3:] / self.mass,
            (-g.angular_momentum_damping * hg[3:] - drift_hg[3:]) / self.mass,
            g.angular_momentum_weight,
        )
        # Base orientation (world axes): angular acceleration of the base frame.
        J_base = pin.getJointJacobian(model, data, 1, _LWA)
        base_drift = pin.getClassicalAcceleration(model, data, 1, _LWA).angular
        R = data.oMi[1].rotation
        rot_error = R @ pin.log3(R.T @ self._base_rotation)
        task(
            J_base[3:],
            g.base_orientation_stiffness * rot_error
            - g.base_orientation_damping * (J_base[3:] @ v)
            - base_drift,
            g.base_orientation_weight,
        )
        # Impact point: PD to the impact task's target and its velocity.
        speed_row = None
        if self.impact is not None:
            placement, Ji, drift = _point_jacobian(
                model, data, self._impact_frame, self.impact.offset
            )
            target, target_velocity, target_acceleration = self.impact.reference(t, impact_force)
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
            task(Ji[:3], lin - drift[:3], g.impact_weight)
            task(Ji[3:], ang - drift[3:], g.impact_orientation_weight)
            if self._speed_rows:
                # Approach speed one control period ahead (torques are held for dt):
                # -n . (vel + (Ji a + drift) dt) <= cap. Linear in a; inactive when unbounded.
                cap = float(self.impact.speed_bound())
                n_dir = np.asarray(self.impact.normal, dtype=float)
                if np.isfinite(cap):
                    speed_row = (
                        -self.dt * (n_dir @ Ji[:3]),
                        cap + n_dir @ vel[:3] + self.dt * (n_dir @ drift[:3]),
                    )
        A_t, b_t, w_t = np.vstack(rows), np.concatenate(targets), np.concatenate(weights)
        P = self._P
        P[:] = self._P_diag
        Aw = A_t.T * w_t
        P[:nv, :nv] += Aw @ A_t
        c = np.zeros(n)
        c[:nv] = -(Aw @ b_t)
        # Posture: PD to the start configuration on the joints.
        posture = g.posture_stiffness * pin.difference(model, q, self.q0) - g.posture_damping * v
        c[:nv] -= self._posture_w * posture

        # Constraints, stacked for daqp: [floating base (6); contacts (6 nc)] equalities, then the
        # contact wrench cones (16 nc), then the torque limits (double-sided rows).
        C, upper, lower = self._C, self._upper, self._lower
        ne = 6 + 6 * nc
        C[:6, :nv] = M[:6]
        upper[:6] = -h[:6]
        for i, (fid, offset, spec) in enumerate(
            zip(self.contact_frames, self.contact_offsets, self.contact_specs)
        ):
            placement, J, drift = _point_jacobian(model, data, fid, offset)
            r = 6 + 6 * i
            C[:6, nv + 6 * i : nv + 6 * i + 6] = -J[:, :6].T
            C[r : r + 6, :nv] = J
            upper[r : r + 6] = -drift - g.contact_damping * (J @ v)
            self._Jw[6 * i : 6 * i + 6] = J
            k = ne + 16 * i
            C[k : k + 16, nv + 6 * i : nv + 6 * i + 6] = cwc_faces_world(
                g.friction_scale * spec.friction, *self.contact_half_sizes[i], placement.rotation
            )
        lower[:ne] = upper[:ne]
        # Minimum normal force (rows after the cones): n_i . f_i >= f_min.
        k = ne + 16 * nc
        for i, fid in enumerate(self.contact_frames):
            C[k + i, nv + 6 * i : nv + 6 * i + 3] = data.oMf[fid].rotation[:, 2]
        lower[k : k + nc] = g.min_normal_force
        upper[k : k + nc] = 1e30
        # The governed approach speed (one row, after the minimum normal forces; 1e30: inactive).
        ms = ne + 17 * nc
        if self._speed_rows:
            C[ms, :] = 0.0
            if speed_row is None:
                upper[ms] = 1e30
            else:
                C[ms, :nv], upper[ms] = speed_row
        # tau = M[6:] a + h[6:] - Jw[:, 6:]^T w (actuated rows)
        T = np.hstack([M[6:], -self._Jw[:, 6:].T])
        t0 = h[6:]
        limited = self._limited
        m0 = ms + self._speed_rows
        # Joint position limits (rows after the minimum normal forces), then the torque limits.
        T2 = g.joint_limit_horizon
        qj, vj = q[self._limit_q], v[self._limit_v]
        m1 = m0 + self._limit_q.size
        C[np.arange(m0, m1), self._limit_v] = 1.0
        upper[m0:m1] = 2.0 * (self._q_upper - qj - vj * T2) / T2**2
        lower[m0:m1] = np.minimum(2.0 * (self._q_lower - qj - vj * T2) / T2**2, upper[m0:m1])
        if limited.size:
            C[m1:, :] = T[limited]
            upper[m1:] = self.effort[limited] - t0[limited]
            lower[m1:] = -self.effort[limited] - t0[limited]
        x, _, exitflag, _ = daqp.solve(P, c, C, upper, lower, self._sense)
        torque_limited = False
        # Infeasible: drop the torque limits (the torques are clipped below), then the joint limits.
        for rows in ((m1,) if limited.size else ()) + (m0,) + ((ms,) if self._speed_rows else ()):
            if exitflag >= 1:
                break
            torque_limited = True
            x, _, exitflag, _ = daqp.solve(
                P, c, C[:rows], upper[:rows], lower[:rows], self._sense[:rows]
            )
        if exitflag < 1:
            # Not even the cones and the contacts together: hold the last command.
            torque_limited = True
            x = np.zeros(n) if self._x is None else self._x
        self._x = x
        a, w = x[:nv], x[nv:]
        tau = T @ x + t0
        if self.effort_limits:
            tau = np.clip(tau, -self.effort, self.effort)
        out = TorqueOutput(
            tau, a, w.reshape(nc, 6), zmp, xi, clamped, com, com_velocity, torque_limited
        )
        self.last = out
        return out

    def describe(self) -> dict:
        """Name and gains (the ``controller`` object of ``validate --json``)."""
        return {
            "name": self.name,
            "gains": self.gains.to_dict(),
            "omega": self.omega,
            "effort_limits": self.effort_limits,
        }


def describe(gains: InverseDynamicsGains, sim_timestep: float, effort_limits: bool) -> dict:
    """The ``controller`` object of ``validate --json`` and ``push-test --json`` for the ``id`` controller."""
    return {
        "name": InverseDynamicsController.name,
        "gains": gains.to_dict(),
        "control_rate_hz": gains.rate,
        "sim_timestep": sim_timestep,
        "actuators": "torque motors (MuJoCo), viscous joint damping compensated",
        "effort_limits": effort_limits,
        "impact_task": {"force_threshold": 15.0, "retract": 0.05},
    }
