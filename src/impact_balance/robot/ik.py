"""Whole-body inverse kinematics for building stances, on top of pink.

This module is a thin, deterministic wrapper around pink's differential IK
(:class:`pink.Configuration`, :class:`pink.tasks.FrameTask`, :class:`pink.tasks.ComTask`,
:class:`pink.tasks.PostureTask`, :func:`pink.solve_ik` with the ``daqp`` QP solver). It is
used offline to compute the joint values and base poses of the bundled scenarios
(``examples/build_stances.py``); the analysis pipeline itself never runs IK.

Frames and units: every target is expressed in the world frame (z up), positions in metres,
orientations as rotation matrices (pinocchio ``SE3``), configurations in pinocchio's
convention for a free-flyer model: ``q = [base position (m), base quaternion (x, y, z, w),
joint angles (rad)]``. Residuals are reported in metres (positions, CoM) and radians
(orientation: angle of ``R_target^T R``).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pink
import pinocchio as pin
from numpy.typing import ArrayLike
from pink.exceptions import PinkError
from pink.limits import ConfigurationLimit
from pink.tasks import ComTask, FrameTask, PostureTask

from impact_balance.exceptions import ImpactBalanceError
from impact_balance.robot.robot import Robot

__all__ = [
    "IKError",
    "IKOptions",
    "chain_dofs",
    "solve_stance",
    "stance_residuals",
    "within_limits",
]

_FloatArray = npt.NDArray[np.float64]

#: Residual (m or rad) below which the regularisation is scaled down by ``_FINISH_SCALE``.
_FINISH_THRESHOLD = 1e-3
_FINISH_SCALE = 1e-3


class IKError(ImpactBalanceError):
    """Inverse kinematics did not reach its targets.

    Attributes:
        residuals: Remaining errors by target: ``"<frame>.position"`` (m),
            ``"<frame>.orientation"`` (rad) and ``"com_xy"`` (m).
        iterations: Number of IK steps taken.
        q: The last configuration (full model, nq).
        reason: Why the iterations stopped.
    """

    def __init__(self, reason: str, residuals: Mapping[str, float], iterations: int, q: ArrayLike):
        self.reason = reason
        self.residuals = dict(residuals)
        self.iterations = iterations
        self.q = np.asarray(q, dtype=float).copy()
        worst = sorted(self.residuals.items(), key=lambda kv: -kv[1])[:3]
        detail = ", ".join(f"{k} = {v:.3g}" for k, v in worst)
        super().__init__(
            f"inverse kinematics failed after {iterations} iterations ({reason}); "
            f"largest residuals: {detail}"
        )


def _reduced(
    robot: Robot, locked_joints: Iterable[str], q0: _FloatArray
) -> tuple[pin.Model, list[tuple[int, int, int]]]:
    """A private copy of the model with ``locked_joints`` fixed at ``q0``, and the index map.

    The map lists ``(full idx_q, reduced idx_q, nq)`` for every joint kept, root included.
    """
    model = robot.model
    locked = [robot.joint_id(name, field="locked_joints") for name in locked_joints]
    reduced = pin.buildReducedModel(model, sorted(set(locked)), q0) if locked else pin.Model(model)
    index = []
    for jid in range(1, reduced.njoints):
        joint = reduced.joints[jid]
        full = model.joints[model.getJointId(reduced.names[jid])]
        index.append((full.idx_q, joint.idx_q, joint.nq))
    return reduced, index


def chain_dofs(robot: Robot, frame: str) -> int:
    """Degrees of freedom of the joints between the floating base and ``frame`` (base excluded).

    Args:
        robot: The robot.
        frame: A frame of its model.

    Returns:
        The summed velocity dimension of the joints on the chain from the base to ``frame``.
    """
    model = robot.model
    joint = model.frames[robot.frame_id(frame)].parentJoint
    count = 0
    while joint > 1:
        count += model.joints[joint].nv
        joint = model.parents[joint]
    return count


def stance_residuals(
    robot: Robot,
    q: ArrayLike,
    frame_targets: Mapping[str, pin.SE3],
    com_target_xy: ArrayLike | None = None,
    position_only: Iterable[str] = (),
) -> dict[str, float]:
    """Errors of configuration ``q`` with respect to world-frame targets.

    Returns ``"<frame>.position"`` (m, Euclidean), ``"<frame>.orientation"`` (rad, rotation
    angle between target and actual; omitted for ``position_only`` frames) and ``"com_xy"``
    (m, horizontal CoM error) when ``com_target_xy`` is given.
    """
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    free = set(position_only)
    out: dict[str, float] = {}
    for name, target in frame_targets.items():
        actual = data.oMf[robot.frame_id(name, field="frame_targets")]
        out[f"{name}.position"] = float(np.linalg.norm(actual.translation - target.translation))
        if name not in free:
            out[f"{name}.orientation"] = float(
                np.linalg.norm(pin.log3(target.rotation.T @ actual.rotation))
            )
    if com_target_xy is not None:
        com = pin.centerOfMass(model, data, q, False)
        out["com_xy"] = float(np.linalg.norm(com[:2] - np.asarray(com_target_xy, dtype=float)))
    return out


@dataclass(frozen=True)
class IKOptions:
    """How :func:`solve_stance` iterates: regularisation costs, stopping rule and QP solver.

    Attributes:
        posture_cost: Posture-task cost, [cost]/rad. The smaller, the more exactly targets
            are met, the larger, the closer the result stays to the preferred posture.
        joint_costs: Posture-task cost of individual joints, by name, overriding
            ``posture_cost`` (e.g. a stiffer torso).
        base_orientation_cost: Cost, [cost]/rad, pulling the floating base's orientation
            towards the preferred one (keeps the pelvis upright).
        max_iterations: Maximum number of IK steps.
        tolerance: Convergence threshold on every residual, m and rad.
        damping: Tikhonov regularisation of each step's QP.
        solver: QP solver name for qpsolvers.
    """

    posture_cost: float = 1e-3
    joint_costs: Mapping[str, float] | None = None
    base_orientation_cost: float = 1e-2
    max_iterations: int = 500
    tolerance: float = 1e-6
    damping: float = 1e-9
    solver: str = "daqp"


class _ReducedModel:
    """The model with some joints locked at ``q0``; maps between its and the full configurations."""

    def __init__(self, robot: Robot, locked_joints: Iterable[str], q0: _FloatArray):
        self.model, self._index = _reduced(robot, locked_joints, q0)
        self._q0 = q0

    def to_reduced(self, q_full: _FloatArray) -> _FloatArray:
        """The reduced configuration of a full one."""
        q = np.empty(self.model.nq)
        for i_full, i_red, n in self._index:
            q[i_red : i_red + n] = q_full[i_full : i_full + n]
        return q

    def to_full(self, q_red: _FloatArray) -> _FloatArray:
        """The full configuration of a reduced one (locked joints at ``q0``)."""
        q: _FloatArray = self._q0.copy()
        for i_full, i_red, n in self._index:
            q[i_full : i_full + n] = q_red[i_red : i_red + n]
        return q


def within_limits(robot: Robot, q: ArrayLike) -> _FloatArray:
    """A float copy of ``q`` (nq) with its bounded 1-dof joints clamped into their limits.

    pink refuses to start from a configuration outside the limits; a stance written to a file
    with rounded joint values can sit a few 1e-6 rad outside one.

    Raises:
        ValueError: ``q`` does not have the model's nq coordinates.
    """
    out: _FloatArray = np.asarray(q, dtype=float).copy()
    nq = robot.model.nq
    if out.shape != (nq,):
        raise ValueError(f"q0 must have {nq} coordinates, got shape {out.shape}")
    for slot in (robot.joint_slot(name) for name in robot.joint_names):
        if (
            slot.nq == 1
            and np.isfinite(slot.lower)
            and np.isfinite(slot.upper)
            and slot.lower < slot.upper
        ):
            out[slot.idx_q] = min(max(out[slot.idx_q], slot.lower), slot.upper)
    return out


def _frame_targets(
    robot: Robot,
    q0: _FloatArray,
    frame_targets: Mapping[str, pin.SE3] | None,
    fixed_frames: Iterable[str],
) -> dict[str, pin.SE3]:
    """World pose targets by frame: the fixed frames at their pose in ``q0``, then the targets."""
    model = robot.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q0)
    targets: dict[str, pin.SE3] = {}
    for name in fixed_frames:
        targets[name] = pin.SE3(data.oMf[robot.frame_id(name, field="fixed_frames")])
    for name, target in (frame_targets or {}).items():
        robot.frame_id(name, field="frame_targets")
        targets[name] = pin.SE3(target)
    return targets


def _target_tasks(
    targets: Mapping[str, pin.SE3], free: set[str], com_target_xy: ArrayLike | None
) -> list[Any]:
    """Unit-cost frame tasks (position only for ``free`` frames) and the horizontal CoM task."""
    tasks: list[Any] = []
    for name, target in targets.items():
        task = FrameTask(name, position_cost=1.0, orientation_cost=0.0 if name in free else 1.0)
        task.set_target(target)
        tasks.append(task)
    if com_target_xy is not None:
        com_task = ComTask(cost=np.array([1.0, 1.0, 0.0]))
        com_task.set_target(np.array([*np.asarray(com_target_xy, dtype=float)[:2], 0.0]))
        tasks.append(com_task)
    return tasks


def _posture_costs(robot: Robot, model: pin.Model, options: IKOptions) -> _FloatArray:
    """Posture-task cost of every actuated velocity of the (reduced) ``model``."""
    costs = np.full(model.nv - 6, float(options.posture_cost))
    for name, cost in (options.joint_costs or {}).items():
        robot.joint_id(name, field="joint_costs")
        if model.existJointName(name):
            joint = model.joints[model.getJointId(name)]
            costs[joint.idx_v - 6 : joint.idx_v - 6 + joint.nv] = float(cost)
    return costs


def _regularisation_phases(
    robot: Robot, reduced: _ReducedModel, preferred: _FloatArray, options: IKOptions
) -> tuple[list[Any], list[Any]]:
    """The posture and base-orientation tasks, at full cost and scaled down by ``_FINISH_SCALE``."""
    model = reduced.model
    costs = _posture_costs(robot, model, options)
    base_frame = model.names[1]  # the free-flyer's joint frame
    base_target = pin.SE3(pin.Quaternion(preferred[3:7]).normalized().matrix(), np.zeros(3))

    def regularisation(scale: float) -> list[Any]:
        posture = PostureTask(cost=scale * costs)
        posture.set_target(preferred)
        base = FrameTask(
            base_frame,
            position_cost=0.0,
            orientation_cost=scale * float(options.base_orientation_cost),
        )
        base.set_target(base_target)
        return [posture, base]

    return regularisation(1.0), regularisation(_FINISH_SCALE)


def solve_stance(
    robot: Robot,
    q0: ArrayLike,
    frame_targets: Mapping[str, pin.SE3] | None = None,
    com_target_xy: ArrayLike | None = None,
    *,
    fixed_frames: Iterable[str] = (),
    position_only: Iterable[str] = (),
    locked_joints: Iterable[str] = (),
    posture_target: ArrayLike | None = None,
    options: IKOptions | None = None,
) -> _FloatArray:
    """Configuration that places frames and the CoM at world targets, within joint limits.

    Iterates pink's differential IK (one QP per step, dead-beat gains, ``dt`` = 1) from
    ``q0`` until every target is met within ``options.tolerance``. The floating base is free:
    the solver moves it together with the joints. Targets are soft tasks of unit cost (per
    metre and per radian); a posture task of cost ``options.posture_cost`` (per radian) pulls
    the actuated joints towards ``posture_target`` (default ``q0``), and a base task of cost
    ``options.base_orientation_cost`` the base orientation towards that of ``posture_target``:
    they select one solution among the many of a redundant robot. Once every residual is below
    1e-3 (m, rad) these two are scaled down by 1e-3, so that they no longer bias the targets.
    Joint limits are hard constraints of every step (pink's
    :class:`~pink.limits.ConfigurationLimit`), so the result is always within limits; a ``q0``
    outside them (some SRDF configurations are) is first clamped into them.
    A frame on a chain of fewer than 6 joints from the base (a quadruped's 3-joint leg)
    cannot hold an orientation: its target is a position only (as in ``position_only``).
    The result only depends on the inputs (no randomness).

    Args:
        robot: Robot with a free-flyer root (e.g. ``load_robot("talos")``).
        q0: Initial configuration (nq), within the joint limits.
        frame_targets: World poses to reach, by frame name (m, rotation matrices).
        com_target_xy: World horizontal CoM position to reach (m); the CoM height is free.
        fixed_frames: Frames kept at their pose in ``q0`` (e.g. feet on the ground).
        position_only: Frames of ``frame_targets`` whose orientation is left free.
        locked_joints: Joints kept at their ``q0`` value (e.g. grippers, head).
        posture_target: Preferred configuration (nq); only its joint part is used.
        options: Costs, stopping rule and solver (default :class:`IKOptions`).

    Returns:
        The configuration (nq) of the full model.

    Raises:
        IKError: if the targets are not met within ``options.tolerance`` after
            ``options.max_iterations`` steps (unreachable targets, joint limits), or a step's QP
            fails. The error carries the residuals, the iteration count and the last configuration.
        UnknownFrameError: for a frame name that is not in the model.
        UnknownJointError: for a joint name that is not in the model.
        ValueError: if ``q0`` does not have nq coordinates.
    """
    options = options or IKOptions()
    q0 = within_limits(robot, q0)
    targets = _frame_targets(robot, q0, frame_targets, fixed_frames)
    free = set(position_only) | {name for name in targets if chain_dofs(robot, name) < 6}
    reduced = _ReducedModel(robot, locked_joints, q0)
    tasks = _target_tasks(targets, free, com_target_xy)
    preferred = reduced.to_reduced(
        q0 if posture_target is None else np.asarray(posture_target, dtype=float)
    )
    # Two phases: the regularisation (posture, base orientation) selects the solution while
    # far from the targets, then is scaled down so that it no longer biases them.
    far, near = _regularisation_phases(robot, reduced, preferred, options)
    phases = [tasks + far, tasks + near]
    limits = [ConfigurationLimit(reduced.model)]

    def residuals(q_full: _FloatArray) -> dict[str, float]:
        return stance_residuals(robot, q_full, targets, com_target_xy, free)

    configuration = pink.Configuration(
        reduced.model, reduced.model.createData(), reduced.to_reduced(q0)
    )
    res = residuals(q0)
    for iteration in range(1, options.max_iterations + 1):
        worst = max(res.values(), default=0.0)
        step_tasks = phases[1] if worst <= _FINISH_THRESHOLD else phases[0]
        try:
            velocity = pink.solve_ik(
                configuration,
                step_tasks,
                dt=1.0,
                solver=options.solver,
                damping=options.damping,
                limits=limits,
            )
        except PinkError as exc:
            last = reduced.to_full(configuration.q)
            raise IKError(f"{exc.__class__.__name__}: {exc}", res, iteration - 1, last) from None
        configuration.integrate_inplace(velocity, 1.0)
        q = reduced.to_full(configuration.q)
        res = residuals(q)
        if max(res.values(), default=0.0) <= options.tolerance:
            return q
    raise IKError("not converged", res, options.max_iterations, reduced.to_full(configuration.q))
