"""Joint models of the simulated robot: ``rigid`` and ``servo``.

``rigid``
    Every joint is welded at the stance: the robot is one rigid body, exactly the paper's
    model of a kinematically controlled robot during an impact (its ``composite`` inertia).
    Built by giving each body its pose relative to its parent at the stance and deleting
    the joints (only the root's free joint remains); MuJoCo then fuses the bodies.

``servo``
    Each actuated joint is held by a position servo (a MuJoCo ``general`` actuator with
    force ``kp (u - q) - kd qdot``, the command ``u`` carrying the target position, the
    velocity feed-forward ``kd qdot_ref / kp`` and the torque feed-forward ``tau_ff / kp``).
    Gains follow one rule, critical damping of the joint's reflected inertia at a chosen
    bandwidth ``omega``:

        I_j = M_jj(q_stance) + armature,   kp = I_j omega^2,   kd = 2 zeta I_j omega

    with ``M`` the joint-space mass matrix at the stance (the inertia the joint moves when
    all the others are locked) and ``zeta = 1``. The torque is clamped to the URDF effort
    limit (the actuator's force range; MuJoCo also keeps it as the joint's actuator force
    range), and the URDF damping and friction loss stay. ``armature`` (rotor inertia
    reflected through the gearbox, kg m^2) is added to every joint: by default what the robot
    files declare (the SRDF's ``rotor_params``, see
    :attr:`impact_balance.robot.robot.Robot.armature_source`; 0 where they declare none), or one
    value for every joint. The torque feed-forward holds the stance against gravity: the joint
    torques of the smallest contact wrenches (least squares) that balance gravity within the contact
    wrench cones, solved once at the stance.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import mujoco
import numpy as np
import numpy.typing as npt
import qpsolvers

from impact_balance.constants import GRAVITY
from impact_balance.contacts.cwc import cwc_faces_world
from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import SimulationError

__all__ = [
    "JOINT_MODELS",
    "JointModel",
    "ServoOptions",
    "check_joint_model",
    "holding_torques",
    "servo_gains",
    "weld_joints",
]

_FloatArray = npt.NDArray[np.float64]

#: A joint model: ``rigid`` (welded joints) or ``servo`` (position servos).
JointModel = Literal["rigid", "servo"]

#: Joint models, in the order of ``--help``.
JOINT_MODELS: tuple[JointModel, ...] = ("rigid", "servo")


def check_joint_model(name: str) -> JointModel:
    """``name`` as a joint model.

    Args:
        name: ``rigid`` or ``servo``.

    Returns:
        The joint model.

    Raises:
        SimulationError: ``name`` is not a joint model's.
    """
    for model in JOINT_MODELS:
        if model == name:
            return model
    raise SimulationError(
        "--joints", name, f"unknown joint model; valid: {', '.join(JOINT_MODELS)}"
    )


@dataclass(frozen=True)
class ServoOptions:
    """Parameters of the ``servo`` joint model.

    Attributes:
        bandwidth: Closed-loop natural frequency omega of every joint servo, rad/s.
        damping_ratio: zeta (1 = critically damped).
        armature: Rotor inertia of every actuated joint, kg m^2; None: the robot files' own
            (declared per joint, 0 where they declare none).
        effort_limits: Clamp each servo's torque to the joint's URDF effort limit.
    """

    bandwidth: float = 2.0 * math.pi * 15.0
    damping_ratio: float = 1.0
    armature: float | None = None
    effort_limits: bool = True


def servo_gains(
    reflected_inertia: np.ndarray, options: ServoOptions
) -> tuple[np.ndarray, np.ndarray]:
    """``(kp, kd)`` of each joint from its reflected inertia.

    Gains in N m/rad and N m s/rad, inertias in kg m^2 (armature included).
    """
    inertia = np.asarray(reflected_inertia, dtype=float)
    w = options.bandwidth
    return inertia * w * w, 2.0 * options.damping_ratio * inertia * w


def holding_torques(stance: Stance, gravity: float = GRAVITY) -> np.ndarray:
    """Actuated joint torques (nv - 6) that hold the stance still under gravity.

    The contact wrenches ``w`` are the smallest (least squares) that balance the floating
    base, ``J_base^T w = g_base(q)``, inside every contact wrench cone; the torques are then
    ``g(q) - J^T w`` on the actuated rows. When no wrench in the cones balances the robot,
    the unconstrained least-squares wrenches are used (the stance cannot hold; the servos
    do their best).
    """
    g: _FloatArray = stance.gravity_torques * (gravity / GRAVITY)
    if not stance.contacts:
        return np.array(g[6:])
    J = np.vstack([c.jacobian for c in stance.contacts])  # (6k, nv)
    A = J[:, :6].T
    b = g[:6]
    k = len(stance.contacts)
    blocks = [
        cwc_faces_world(c.spec.friction, c.half_length, c.half_width, c.rotation)
        for c in stance.contacts
    ]
    G = np.zeros((sum(f.shape[0] for f in blocks), 6 * k))
    row = 0
    for i, faces in enumerate(blocks):
        G[row : row + faces.shape[0], 6 * i : 6 * i + 6] = faces
        row += faces.shape[0]
    # Scale forces and torques alike: weigh wrenches so that 1 N and 1 N m cost the same.
    w = qpsolvers.solve_qp(
        np.eye(6 * k), np.zeros(6 * k), G, np.zeros(G.shape[0]), A, b, solver="daqp"
    )
    if w is None:
        w = np.linalg.lstsq(A, b, rcond=None)[0]
    torques: _FloatArray = (g - J.T @ w)[6:]
    return torques


def weld_joints(spec: mujoco.MjSpec, model: mujoco.MjModel, qpos: np.ndarray) -> None:
    """Weld every non-free joint of ``spec`` at ``qpos``.

    ``qpos`` is a configuration of ``model``, compiled from ``spec`` without fusing static bodies,
    so that every body of ``spec`` is in ``model``.

    Each body takes its pose relative to its parent at ``qpos``, then its joints are deleted.
    """
    data = mujoco.MjData(model)
    data.qpos[:] = qpos
    mujoco.mj_kinematics(model, data)
    for joint in list(spec.joints):
        if joint.type == mujoco.mjtJoint.mjJNT_FREE:
            continue
        body = joint.parent
        child = model.body(body.name).id
        parent = model.body(body.parent.name).id
        rotation_parent = data.xmat[parent].reshape(3, 3)
        body.pos = rotation_parent.T @ (data.xpos[child] - data.xpos[parent])
        inverse = np.empty(4)
        mujoco.mju_negQuat(inverse, data.xquat[parent])
        relative = np.empty(4)
        mujoco.mju_mulQuat(relative, inverse, data.xquat[child])
        body.quat = relative
        spec.delete(joint)
