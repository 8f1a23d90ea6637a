"""Compute the joint values and base poses of the bundled non-trivial stances.

Run from the repository root:

    PYTHONPATH=src python examples/build_stances.py            # every stance
    PYTHONPATH=src python examples/build_stances.py palm_push_ramp

For each stance it solves whole-body inverse kinematics with :mod:`impact_balance.robot.ik`
(pink, daqp) and prints a YAML snippet (``base`` and the ``joints`` that differ from the
scenario's reference configuration) to paste into ``src/impact_balance/scenarios/<name>.yaml``.
The output is deterministic: same library versions, same numbers. Values are rounded to
1e-6 rad / 1e-6 m; the residuals printed in the snippet's comment are those of the rounded
values, checked by rebuilding the configuration exactly as the scenario loader does.

World frame: z up, ground at z = 0, the robot facing +x. All positions in m, angles in rad.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from impact_balance.robot.ik import IKOptions, solve_stance, stance_residuals
from impact_balance.robot.robot import Robot, load_robot
from impact_balance.scenario import scenario_from_dict

DIGITS = 6
TALOS_LOCKED = ("gripper_left_joint", "gripper_right_joint", "head_1_joint", "head_2_joint")
TALOS_FEET = ("left_sole_link", "right_sole_link")
# Flat sole poses of Talos' half_sitting (its soles carry a 0.002 rad roll: we level them).
TALOS_LEFT_SOLE = (-0.009, 0.085, 0.0)
TALOS_RIGHT_SOLE = (-0.009, -0.085, 0.0)
# Right gripper in front of the chest for the frontal palm push. With the identity
# orientation the fingers point down and the gripper's flat +x face (x = +0.051 m in
# gripper_right_base_link) faces the wall.
TALOS_PUSH_GRIPPER = pin.SE3(np.eye(3), np.array([0.40, -0.25, 1.00]))
# The torso moves less than the arms.
TALOS_JOINT_COSTS = {"torso_1_joint": 1e-2, "torso_2_joint": 1e-2}


def se3(position, rpy=(0.0, 0.0, 0.0)) -> pin.SE3:
    return pin.SE3(pin.rpy.rpyToMatrix(*map(float, rpy)), np.asarray(position, dtype=float))


@dataclass
class StanceProblem:
    """One IK problem: frame targets (world), CoM xy target, and solver options."""

    name: str
    robot: str
    configuration: str
    frame_targets: dict[str, pin.SE3]
    com_target_xy: tuple[float, float]
    notes: str
    setup: Callable[[Robot, np.ndarray], np.ndarray] | None = None  # initial guess from reference q
    options: dict = field(default_factory=dict)


def _set(robot: Robot, q: np.ndarray, values: dict[str, float]) -> np.ndarray:
    q = q.copy()
    for name, value in values.items():
        q[robot.model.joints[robot.joint_id(name)].idx_q] = value
    return q


def _talos_arm_forward(robot: Robot, q: np.ndarray) -> np.ndarray:
    # Initial guess: right shoulder yawed and raised forward, elbow bent.
    return _set(
        robot, q, {"arm_right_1_joint": 1.2, "arm_right_2_joint": -1.0, "arm_right_4_joint": -0.8}
    )


def _talos_both_arms(robot: Robot, q: np.ndarray) -> np.ndarray:
    q = _talos_arm_forward(robot, q)
    # Left arm raised sideways towards the wall.
    return _set(robot, q, {"arm_left_2_joint": 0.8, "arm_left_4_joint": -1.0})


def _mid(a, b) -> tuple[float, float]:
    return (0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]))


# -- the stances ------------------------------------------------------------------------
RAMP_ANGLE = math.radians(30.0)
RAMP_SOLE = (0.10, -0.085, 0.10)  # right sole centre on the ramp
WALL_Y = 0.60  # wall plane on Talos' left (world y), for the three-contact stance
HAND_CONTACT_OFFSET = se3(
    (-0.057, 0.0, -0.045), (0.0, math.pi / 2, 0.0)
)  # gripper -x face, z_c = +x_g
HAND_CONTACT_TARGET = se3(
    (0.05, WALL_Y, 1.00), (math.pi / 2, 0.0, 0.0)
)  # contact z axis = world -y
TALOS_STAGGER_LEFT = (0.08, 0.10, 0.0)
TALOS_STAGGER_RIGHT = (-0.08, -0.10, 0.0)
SIDE_SLOPE_ANGLE = math.radians(15.0)
SIDE_SLOPE_SOLE = (-0.009, -0.12, 0.04)
G1_SOLE_OFFSET = (0.035, 0.0, -0.035)  # sole centre in *_ankle_roll_link (collision spheres)
G1_LEFT_SOLE = (0.0, 0.119, 0.0)
G1_RIGHT_SOLE = (0.0, -0.119, 0.0)
# G1 right hand in front of the chest, fingers up, palm (+y of right_rubber_hand) facing +x.
G1_HAND = pin.SE3(
    np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]), np.array([0.25, -0.15, 0.95])
)


def _g1_ankle(sole) -> pin.SE3:
    return se3(np.asarray(sole) - np.asarray(G1_SOLE_OFFSET))


def _g1_knees(robot: Robot, q: np.ndarray) -> np.ndarray:
    bent = {}
    for side in ("left", "right"):
        bent |= {
            f"{side}_hip_pitch_joint": -0.15,
            f"{side}_knee_joint": 0.35,
            f"{side}_ankle_pitch_joint": -0.2,
        }
    return _set(robot, q, bent)


PROBLEMS = [
    StanceProblem(
        "palm_push_two_feet",
        "talos",
        "half_sitting",
        {
            "left_sole_link": se3(TALOS_LEFT_SOLE),
            "right_sole_link": se3(TALOS_RIGHT_SOLE),
            "gripper_right_base_link": TALOS_PUSH_GRIPPER,
        },
        _mid(TALOS_LEFT_SOLE, TALOS_RIGHT_SOLE),
        "feet flat; right gripper at (0.40, -0.25, 1.00), fingers down, +x face forward; CoM "
        "between the soles",
        _talos_arm_forward,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "palm_push_ramp",
        "talos",
        "half_sitting",
        {
            "left_sole_link": se3(TALOS_LEFT_SOLE),
            # Toe up: rotation about world y by -30 degrees (sole normal tilted backwards).
            "right_sole_link": se3(RAMP_SOLE, (0.0, -RAMP_ANGLE, 0.0)),
            "gripper_right_base_link": TALOS_PUSH_GRIPPER,
        },
        _mid(TALOS_LEFT_SOLE, RAMP_SOLE),
        "left sole flat; right sole pitched 30 deg toe up, centre at (0.10, -0.085, 0.10); "
        "CoM at the midpoint of the sole centres",
        _talos_arm_forward,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "kick_one_foot",
        "talos",
        "half_sitting",
        {
            "right_sole_link": se3(TALOS_RIGHT_SOLE),
            "left_sole_link": se3((0.20, 0.085, 0.12)),
        },
        TALOS_RIGHT_SOLE[:2],
        "right sole flat; left sole lifted 0.12 m and 0.21 m forward; CoM over the right sole "
        "centre",
        None,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "talos_three_contacts",
        "talos",
        "half_sitting",
        {
            "left_sole_link": se3(TALOS_LEFT_SOLE),
            "right_sole_link": se3(TALOS_RIGHT_SOLE),
            "gripper_left_base_link": HAND_CONTACT_TARGET * HAND_CONTACT_OFFSET.inverse(),
            "gripper_right_base_link": TALOS_PUSH_GRIPPER,
        },
        _mid(TALOS_LEFT_SOLE, TALOS_RIGHT_SOLE),
        f"feet flat; left gripper's -x face on a wall at y = {WALL_Y} (contact centre (0.05, "
        f"{WALL_Y}, 1.00)); right gripper as in palm_push_two_feet; CoM between the soles",
        _talos_both_arms,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "talos_tuning_stagger",
        "talos",
        "half_sitting",
        {
            "left_sole_link": se3(TALOS_STAGGER_LEFT),
            "right_sole_link": se3(TALOS_STAGGER_RIGHT),
            "gripper_right_base_link": TALOS_PUSH_GRIPPER,
        },
        _mid(TALOS_STAGGER_LEFT, TALOS_STAGGER_RIGHT),
        "feet flat, staggered: left sole 8 cm forward, right 8 cm back, 20 cm apart; right "
        "gripper as in palm_push_two_feet; CoM between the soles. The balance controllers' gains "
        "are tuned here only.",
        _talos_arm_forward,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "talos_side_slope",
        "talos",
        "half_sitting",
        {
            "left_sole_link": se3(TALOS_LEFT_SOLE),
            # Rolled 15 degrees about world x: the sole normal tilts inwards (+y), the slope rises
            # outwards.
            "right_sole_link": se3(SIDE_SLOPE_SOLE, (-SIDE_SLOPE_ANGLE, 0.0, 0.0)),
            "gripper_right_base_link": TALOS_PUSH_GRIPPER,
        },
        _mid(TALOS_LEFT_SOLE, SIDE_SLOPE_SOLE),
        "left sole flat; right sole on a 15 deg side slope (rolled, normal tilted inwards), "
        "centre at (-0.009, -0.12, 0.04); right gripper as in palm_push_two_feet; CoM at the "
        "midpoint of the sole centres. Written for the held-out scores: nothing is tuned on it.",
        _talos_arm_forward,
        {"joint_costs": TALOS_JOINT_COSTS},
    ),
    StanceProblem(
        "g1_two_feet",
        "g1",
        "neutral",
        {
            "left_ankle_roll_link": _g1_ankle(G1_LEFT_SOLE),
            "right_ankle_roll_link": _g1_ankle(G1_RIGHT_SOLE),
            "right_rubber_hand": G1_HAND,
        },
        _mid(G1_LEFT_SOLE, G1_RIGHT_SOLE),
        "soles flat at y = +-0.119; knees bent; right hand at (0.25, -0.15, 0.95), palm forward; "
        "CoM between the soles",
        _g1_knees,
        {
            "joint_costs": {
                "waist_yaw_joint": 1e-2,
                "waist_roll_joint": 1e-2,
                "waist_pitch_joint": 1e-2,
            }
        },
    ),
]
LOCKED = {"talos": TALOS_LOCKED, "g1": ()}


def _fmt(x: float) -> str:
    value = round(float(x), DIGITS)
    return repr(0.0 if value == 0 else value)


def _snippet(problem: StanceProblem, robot: Robot, q: np.ndarray) -> tuple[str, dict]:
    reference = robot.configuration(problem.configuration)
    rpy = pin.rpy.matrixToRpy(pin.Quaternion(q[3:7]).normalized().matrix())
    joints = {}
    for name in robot.joint_names:
        joint = robot.model.joints[robot.joint_id(name)]
        if joint.nq != 1:
            continue
        if round(q[joint.idx_q], DIGITS) != round(reference[joint.idx_q], DIGITS):
            joints[name] = round(float(q[joint.idx_q]), DIGITS)
    base = {
        "position": [round(float(v), DIGITS) for v in q[:3]],
        "rpy": [round(float(v), DIGITS) for v in rpy],
    }
    lines = [
        "base:",
        f"  position: [{', '.join(_fmt(v) for v in q[:3])}]",
        f"  rpy: [{', '.join(_fmt(v) for v in rpy)}]",
        "joints:",
        *(f"  {name}: {_fmt(value)}" for name, value in joints.items()),
    ]
    return "\n".join(lines), {"base": base, "joints": joints}


def build(problem: StanceProblem) -> str:
    robot = load_robot(problem.robot)
    reference = robot.configuration(problem.configuration)
    q0 = problem.setup(robot, reference) if problem.setup else reference
    q = solve_stance(
        robot,
        q0,
        problem.frame_targets,
        problem.com_target_xy,
        locked_joints=LOCKED[problem.robot],
        posture_target=q0,
        options=IKOptions(max_iterations=2000, tolerance=1e-7, **problem.options),
    )
    text, data = _snippet(problem, robot, q)
    # Check the rounded values, loaded the way a scenario file is.
    scenario = scenario_from_dict(
        {
            "robot": problem.robot,
            "configuration": problem.configuration,
            **data,
            "contacts": [
                {"frame": next(iter(problem.frame_targets)), "friction": 1.0, "size": [0.1, 0.1]}
            ],
        }
    )
    q_rounded = scenario.configuration_vector(robot)
    residuals = stance_residuals(robot, q_rounded, problem.frame_targets, problem.com_target_xy)
    worst = max(residuals.values())
    com = pin.centerOfMass(robot.model, robot.model.createData(), q_rounded)
    header = (
        f"# --- {problem.name} ({problem.robot}, from {problem.configuration}) ---\n# "
        f"{problem.notes}\n# CoM = [{', '.join(f'{v:.4f}' for v in com)}] m; largest residual "
        f"after rounding = {worst:.1e} (m / rad)"
    )
    return f"{header}\n{text}\n"


def main(argv: list[str]) -> int:
    names = argv or [p.name for p in PROBLEMS]
    known = {p.name: p for p in PROBLEMS}
    unknown = [n for n in names if n not in known]
    if unknown:
        print(
            f"unknown stance(s): {', '.join(unknown)}; known: {', '.join(known)}", file=sys.stderr
        )
        return 2
    for name in names:
        print(build(known[name]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
