"""The paper's QP in joint velocities (eq. qp:velocity, Algorithm 1), through qpsolvers.

    min_{qd, lambda}  ||J qd - v_ref||^2 (+ eps ||qd||^2, J has a null space)
    s.t.  lambda >= 0
          (1 + c_hi) (-n^T J qd) = n^T W K_i lambda_{2i}        (planes of restitution)
          (1 + c_lo) (-n^T J qd) = n^T W K_i lambda_{2i+1}
          G (cd0 + (K_i lambda_j)_xy / m) <= h                 (post-impact CoM velocity)
    optional (paper's Remark):
          qd_lo <= qd + J^+ W K_i lambda_j <= qd_hi            (post-impact joint velocities)
          -tau_max <= tau0 + (a / dt) (J^T K_i lambda_j)_act <= tau_max   (impulsive torques)

J is the impact point's 3 x nv translational Jacobian, so the approach speed is -n^T J qd.
Without the optional bounds, its solution equals
:func:`~impact_balance.criteria.com.max_contact_velocity` with
:func:`~impact_balance.criteria.cap.capped_velocity` (tested). The QP also forces
-n^T J qd >= 0 (lambda >= 0).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance.contacts.stance import Stance
from impact_balance.contacts.wrench_polytope import WrenchPolytope
from impact_balance.exceptions import SolverError
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel
from impact_balance.robot.robot import Robot

__all__ = ["QPOptions", "QPResult", "solve_contact_velocity_qp", "static_torques"]


@dataclass(frozen=True)
class QPOptions:
    """Options of the QP.

    Attributes:
        joint_velocity_limits: Bound the post-impact joint velocities by the URDF limits.
        impulsive_torque_limits: Bound pre-impact + impulsive joint torques by the URDF efforts.
        peak_factor: a, ratio of peak impulsive force to mean force iota / dt.
        duration: dt, s.
        solver: qpsolvers backend name.
        regularization: eps on ||qd||^2 (J has a null space), relative to ||J||^2.
    """

    joint_velocity_limits: bool = False
    impulsive_torque_limits: bool = False
    peak_factor: float = 1.0
    duration: float = 0.005
    solver: str = "daqp"
    regularization: float = 1e-10


@dataclass(frozen=True)
class QPResult:
    """Solution of the QP.

    Attributes:
        status: "optimal" or "infeasible".
        joint_velocities: qd* (nv), rad/s (floating base first), or None.
        contact_velocity: J qd*, m/s, world, or None.
        approach_speed: -n^T J qd*, m/s (nan if infeasible).
        lambdas: (2N,) impulse magnitudes, N s, or None.
    """

    status: str
    joint_velocities: np.ndarray | None
    contact_velocity: np.ndarray | None
    approach_speed: float
    lambdas: np.ndarray | None


def solve_contact_velocity_qp(
    impact: ImpactModel,
    area: Polygon,
    com_velocity: npt.ArrayLike,
    reference_velocity: npt.ArrayLike,
    robot: Robot | None = None,
    pre_impact_torques: np.ndarray | None = None,
    options: QPOptions = QPOptions(),
) -> QPResult:
    """Solve the paper's QP for the contact velocity (m/s, world).

    ``robot`` is needed for the optional bounds (URDF limits); ``pre_impact_torques`` (nv)
    is tau0 for the impulsive-torque bound (zeros if not given).
    """
    J = impact.jacobian
    nv = J.shape[1]
    K = impact.cone
    N = K.shape[1]
    n = impact.normal
    lo, hi = impact.spec.restitution
    v_ref = np.asarray(reference_velocity, dtype=float)
    nx = nv + 2 * N
    scale = float(np.linalg.norm(J, 2)) ** 2
    P = np.zeros((nx, nx))
    P[:nv, :nv] = 2.0 * (J.T @ J + options.regularization * scale * np.eye(nv))
    P[nv:, nv:] = 2.0 * options.regularization * np.eye(2 * N)
    q = np.zeros(nx)
    q[:nv] = -2.0 * J.T @ v_ref
    # Planes of restitution.
    response = n @ impact.W @ K  # (N,)
    Aeq = np.zeros((2 * N, nx))
    for i in range(N):
        for j, c in ((2 * i, hi), (2 * i + 1, lo)):
            Aeq[j, :nv] = (1.0 + c) * (-(n @ J))
            Aeq[j, nv + j] = -response[i]
    beq = np.zeros(2 * N)
    # Post-impact CoM velocity in the area, for every vertex.
    G, h = area.halfplanes
    c0 = np.asarray(com_velocity, dtype=float)[:2]
    gen = np.repeat(K.T, 2, axis=0)  # (2N, 3): generator of lambda_j
    rows, rhs = [], []
    for j in range(2 * N):
        block = np.zeros((G.shape[0], nx))
        block[:, nv + j] = G @ gen[j, :2] / impact.mass
        rows.append(block)
        rhs.append(h - G @ c0)
    if options.joint_velocity_limits or options.impulsive_torque_limits:
        if robot is None:
            raise ValueError("robot is needed for the joint velocity / torque bounds")
    if options.joint_velocity_limits and robot is not None:
        idx, vmax = robot.actuated_velocity_limits()
        pinv = J.T @ np.linalg.inv(J @ J.T)  # J^+ = J^T (J J^T)^-1
        for j in range(2 * N):
            block = np.zeros((idx.size, nx))
            block[np.arange(idx.size), idx] = 1.0
            block[:, nv + j] = (pinv @ impact.W @ gen[j])[idx]
            rows += [block, -block]
            rhs += [vmax, vmax]
    if options.impulsive_torque_limits and robot is not None:
        idx, tmax = robot.actuated_effort_limits()
        tau0 = (
            np.zeros(nv)
            if pre_impact_torques is None
            else np.asarray(pre_impact_torques, dtype=float)
        )
        gain = options.peak_factor / options.duration
        for j in range(2 * N):
            block = np.zeros((idx.size, nx))
            block[:, nv + j] = gain * (J.T @ gen[j])[idx]
            rows += [block, -block]
            rhs += [tmax - tau0[idx], tmax + tau0[idx]]
    Gin, hin = np.vstack(rows), np.concatenate(rhs)
    lb = np.full(nx, -np.inf)
    lb[nv:] = 0.0
    ub = np.full(nx, np.inf)
    tolerances: dict[str, Any] = (
        {"eps_abs": 1e-10, "eps_rel": 0.0} if options.solver == "proxqp" else {}
    )
    import qpsolvers  # here: its import takes ~0.4 s, and a plain analysis does not solve this QP

    try:
        x = qpsolvers.solve_qp(
            P, q, Gin, hin, Aeq, beq, lb, ub, solver=options.solver, **tolerances
        )
    except (qpsolvers.SolverNotFound, qpsolvers.SolverError, ValueError) as exc:
        raise SolverError(options.solver, type(exc).__name__, str(exc)) from exc
    if x is None or not np.all(np.isfinite(x)):
        return QPResult("infeasible", None, None, float("nan"), None)
    qd = x[:nv]
    v = J @ qd
    return QPResult("optimal", qd, v, float(-(n @ v)), x[nv:].copy())


def static_torques(stance: Stance, polytope: WrenchPolytope) -> npt.NDArray[np.float64]:
    """Pre-impact joint torques tau0 (nv) of a static stance, for the impulsive-torque bound.

    The contact wrenches are the least-norm ones that hold the robot at rest (resultant = the
    weight through the CoM) within the contact wrench cones; tau0 = g(q) - J^T w. When the
    stance cannot hold the robot at rest, tau0 = g(q).
    """
    n = polytope.dim
    tau0: npt.NDArray[np.float64] = stance.gravity_torques.copy()
    if n == 0:
        return tau0
    weight = polytope.weight
    target = np.concatenate([[0.0, 0.0, weight], np.cross(stance.com, [0.0, 0.0, weight])])
    cwc = slice(0, polytope.n_cwc_rows)
    import qpsolvers

    try:
        w = qpsolvers.solve_qp(
            np.eye(n),
            np.zeros(n),
            polytope.A[cwc],
            polytope.b[cwc],
            polytope.grasp,
            target,
            solver="daqp",
        )
    except (qpsolvers.SolverError, ValueError):
        w = None
    if w is None:
        return tau0
    JT = np.hstack([c.jacobian.T for c in stance.contacts])
    tau0 = stance.gravity_torques - JT @ w
    return tau0
