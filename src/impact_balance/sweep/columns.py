"""The result columns of a sweep and the statuses of its rows (names, Arrow types, meanings)."""

from __future__ import annotations

from typing import Literal, get_args

import pyarrow as pa

__all__ = [
    "EVALUATED",
    "RESULT_COLUMNS",
    "STATUSES",
    "VERDICTS",
    "EvaluatedStatus",
    "Status",
    "Verdict",
]

#: The statuses of points that were evaluated: "ok" (finite maximum), "unbounded" (no approach
#: speed makes it fall), "already_falling" (pre-impact CoM velocity outside the area: maximum
#: 0), "cannot_balance" (empty areas: maximum 0).
EvaluatedStatus = Literal["ok", "unbounded", "already_falling", "cannot_balance"]
#: Row statuses: the evaluated ones, then the points that could not be evaluated: "invalid" (a
#: value the scenario refuses), "unreachable" (the posture IK did not reach the target with
#: the contacts kept), "error" (anything else).
Status = Literal[
    "ok",
    "unbounded",
    "already_falling",
    "cannot_balance",
    "invalid",
    "unreachable",
    "error",
]
#: The pre-impact state of an evaluated point (the ``verdict`` column).
Verdict = Literal["balanced", "falling", "cannot balance"]

#: Every status, in the order above (counts and figures list them so).
STATUSES: tuple[Status, ...] = get_args(Status)
#: Statuses of points that were evaluated (the others are rows with a message).
EVALUATED: tuple[EvaluatedStatus, ...] = get_args(EvaluatedStatus)
#: Every verdict.
VERDICTS: tuple[Verdict, ...] = get_args(Verdict)

#: Result columns after the point index and the dimensions: name, Arrow type, meaning.
RESULT_COLUMNS: tuple[tuple[str, pa.DataType, str], ...] = (
    ("status", pa.string(), "see STATUSES"),
    ("message", pa.string(), "why a point is invalid/unreachable/error (null otherwise)"),
    ("verdict", pa.string(), "balanced, falling or cannot balance (null when not evaluated)"),
    (
        "max_contact_velocity",
        pa.float64(),
        "CoM criterion, approach speed, m/s (inf when unbounded)",
    ),
    ("zmp_max_contact_velocity", pa.float64(), "ZMP criterion, m/s (inf when unbounded)"),
    ("zmp_status", pa.string(), "status of the ZMP criterion"),
    ("com_velocity_area", pa.float64(), "area of the CoM velocity area, m^2/s^2"),
    ("zmp_area", pa.float64(), "area of the ZMP support area, m^2"),
    (
        "limiting_vertex",
        pa.int32(),
        "post-impact vertex (row of the impulse set) that reaches the boundary first",
    ),
    ("limiting_edge", pa.int32(), "half-plane (edge) of the CoM velocity area it reaches"),
    (
        "limiting_direction",
        pa.float64(),
        "outward normal of that edge, degrees from world +x about z: where the robot would fall",
    ),
    ("impact_x", pa.float64(), "impact point, world, m"),
    ("impact_y", pa.float64(), "impact point, world, m"),
    ("impact_z", pa.float64(), "impact point, world, m"),
    ("ik_residual", pa.float64(), "largest posture IK residual, m or rad (posture sweeps)"),
    (
        "robot_name",
        pa.string(),
        "the robot: a bundled name or its URDF file (null when the point is invalid)",
    ),
    (
        "contact_frames",
        pa.string(),
        "the contact frames, comma-separated (null when the point is invalid)",
    ),
    (
        "stance_digest",
        pa.string(),
        "digest of robot, configuration and contacts: equal digests share their areas",
    ),
    ("q", pa.list_(pa.float64()), "the configuration, pinocchio's order (free-flyer base first)"),
)
