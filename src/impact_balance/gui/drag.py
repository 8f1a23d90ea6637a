"""Gizmo drags: move one contact or the impact point, inverse kinematics moves the robot.

The dragged frame goes to the gizmo's pose while every other contact frame stays where it is
(whole-body IK of :func:`impact_balance.robot.ik.solve_stance`, pink). The answer is a set of
scenario changes (an explicit ``base`` pose and every joint value), so the dragged stance can
be saved and analysed like any other.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ScenarioError
from impact_balance.gui.limbs import joint_values
from impact_balance.gui.state import FieldPath, GuiState
from impact_balance.robot.ik import IKError, IKOptions, solve_stance

__all__ = ["FIXED_TOLERANCE", "DragResult", "DragTarget", "drag_changes", "handle_pose"]

#: Largest drift (m, rad) of a contact frame that must stay put for an IK answer to be kept.
FIXED_TOLERANCE = 1e-3
#: IK convergence threshold of a drag step, m and rad.
DRAG_TOLERANCE = 1e-5
#: IK steps per drag update: drags move little between updates, a few steps suffice.
DRAG_ITERATIONS = 60


@dataclass(frozen=True)
class DragTarget:
    """What is dragged: ``("contact", index)`` or ``("impact", None)``."""

    kind: Literal["contact", "impact"]
    index: int | None = None

    @property
    def key(self) -> str:
        """The gizmo key: ``"impact"`` or ``"contact<index>"``."""
        return "impact" if self.kind == "impact" else f"contact{self.index}"


@dataclass(frozen=True)
class DragResult:
    """Changes to apply, and whether the target was reached exactly.

    Attributes:
        changes: Scenario changes (``base`` and ``joints``).
        reached: False when the target is out of reach: the robot went as close as it could.
        residual: Remaining error of the dragged frame, m (position).
    """

    changes: dict[FieldPath, Any]
    reached: bool
    residual: float


def _offset(state: GuiState, path: FieldPath) -> pin.SE3:
    """The offset (in its frame) of the contact or impact at ``path``, identity if none."""
    from impact_balance.geometry.spatial import pose

    offset = state.get((*path, "offset")) or {}
    return pose(offset.get("position", (0.0, 0.0, 0.0)), offset.get("rpy", (0.0, 0.0, 0.0)))


def handle_pose(state: GuiState, stance: Stance, target: DragTarget) -> pin.SE3:
    """World pose of a gizmo: the contact centre (or impact point) with its frame's axes.

    Args:
        state: The current state (the target's frame and offset).
        stance: Its stance (the frame's world pose).
        target: The contact or the impact point.

    Returns:
        The pose, world, m.

    Raises:
        ScenarioError: The target does not exist (no such contact, or no impact).
    """
    frame, path = _frame_and_path(state, target)
    return stance.frame_pose(frame) * _offset(state, path)


def _frame_and_path(state: GuiState, target: DragTarget) -> tuple[str, FieldPath]:
    if target.kind == "impact":
        frame = state.get(("impact", "frame"))
        if frame is None:
            raise ScenarioError("impact", None, "this scenario has no impact to drag")
        return frame, ("impact",)
    n = len(state.get(("contacts",), []))
    if target.index is None or not 0 <= target.index < n:
        raise ScenarioError("contacts", target.index, f"no such contact (there are {n})")
    return state.get(("contacts", target.index, "frame")), ("contacts", target.index)


def drag_changes(state: GuiState, stance: Stance, target: DragTarget, pose: pin.SE3) -> DragResult:
    """Scenario changes that put ``target`` at world ``pose``, other contacts fixed.

    Args:
        state: The current state.
        stance: Its stance (configuration and robot).
        target: The dragged contact or impact point.
        pose: Wanted world pose of the gizmo (contact centre or impact point, m).

    Raises:
        ScenarioError: the target does not exist, or the dragged frame is also a frame that
            must stay put.
        IKError: the other contacts could not be kept in place, even an eighth of the way.
    """
    frame, path = _frame_and_path(state, target)
    fixed = [
        c.spec.frame
        for i, c in enumerate(stance.contacts)
        if not (target.kind == "contact" and i == target.index)
    ]
    if frame in fixed:
        raise ScenarioError(
            ".".join(map(str, path)) + ".frame", frame, "is also a contact that must stay put"
        )
    offset_inv = _offset(state, path).inverse()
    start = stance.frame_pose(frame)
    goal = pin.SE3(pose) * offset_inv
    fixed_frames = sorted(set(fixed))
    failure: IKError | None = None
    # Out of reach: go part of the way (1/2, 1/4, 1/8) rather than refuse the whole drag.
    for fraction in (1.0, 0.5, 0.25, 0.125):
        frame_target = _interpolate(start, goal, fraction)
        try:
            q = _solve(stance, frame, frame_target, fixed_frames)
        except IKError as exc:
            failure = failure or exc
            continue
        residual = float(np.linalg.norm(frame_target.translation - goal.translation))
        return _changes(stance, q, fraction == 1.0, residual)
    assert failure is not None
    raise failure


def _interpolate(a: pin.SE3, b: pin.SE3, t: float) -> pin.SE3:
    """Pose a fraction ``t`` of the way from ``a`` to ``b`` (straight line, geodesic rotation)."""
    rotation = a.rotation @ pin.exp3(t * pin.log3(a.rotation.T @ b.rotation))
    return pin.SE3(rotation, a.translation + t * (b.translation - a.translation))


def _solve(
    stance: Stance, frame: str, target: pin.SE3, fixed_frames: list[str]
) -> npt.NDArray[np.float64]:
    """IK for one target, other frames fixed; a non-converged answer is kept if they stayed put."""
    try:
        return solve_stance(
            stance.robot,
            stance.q,
            {frame: target},
            fixed_frames=fixed_frames,
            options=IKOptions(max_iterations=DRAG_ITERATIONS, tolerance=DRAG_TOLERANCE),
        )
    except IKError as exc:
        drift = max(
            (v for k, v in exc.residuals.items() if k.split(".")[0] in fixed_frames), default=0.0
        )
        miss = max((v for k, v in exc.residuals.items() if k.split(".")[0] == frame), default=0.0)
        if drift > FIXED_TOLERANCE or miss > FIXED_TOLERANCE:
            raise
        q: npt.NDArray[np.float64] = exc.q
        return q  # slow convergence, but within a millimetre: good enough for a drag


def _changes(
    stance: Stance, q: npt.NDArray[np.float64], reached: bool, residual: float
) -> DragResult:
    """The scenario changes of configuration ``q``: the base pose and every joint value."""
    rpy = pin.rpy.matrixToRpy(pin.Quaternion(np.asarray(q[3:7])).normalized().matrix())
    changes: dict[FieldPath, Any] = {
        ("base",): {"position": [float(x) for x in q[:3]], "rpy": [float(x) for x in rpy]},
        ("joints",): joint_values(stance.robot, q),
    }
    return DragResult(changes, reached, float(residual))
