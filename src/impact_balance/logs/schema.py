"""Columns of a log (version 1). SI units, world frame (z up) unless said otherwise.

Required:
- ``time``: s, increasing.
- Base (free-flyer) pose: ``base_x, base_y, base_z`` (m, world),
  ``base_qx, base_qy, base_qz, base_qw`` (unit quaternion of the base orientation in the world,
  pinocchio's order).
- Base velocity: ``base_vx, base_vy, base_vz`` (m/s, linear velocity of the base origin, world
  axes) and ``base_wx, base_wy, base_wz`` (rad/s, angular velocity, world axes).
- One ``q_<joint>`` (rad, or m for a prismatic joint) and one ``v_<joint>`` (rad/s) per actuated
  joint of the robot, named as in its URDF.

Optional:
- ``zmp_x, zmp_y``: measured ZMP on the scenario's plane (m, world).
- ``force_<name>_x, _y, _z``: force on the robot at contact ``<name>`` (its frame name, or
  ``impact``), N, world.
- ``com_x, com_y, com_z, comd_x, comd_y, comd_z``: a reference CoM and CoM velocity (e.g. the
  simulator's own), for cross-checks.
"""

from __future__ import annotations

from dataclasses import dataclass

__all__ = [
    "LOG_VERSION",
    "LogColumns",
    "force_columns",
    "joint_position_column",
    "joint_velocity_column",
]

#: Version of the column schema, stored in the Parquet metadata as ``impact_balance_log_version``.
LOG_VERSION = 1


@dataclass(frozen=True)
class LogColumns:
    """Names of the fixed columns."""

    time: str = "time"
    base_position: tuple[str, ...] = ("base_x", "base_y", "base_z")
    base_quaternion: tuple[str, ...] = ("base_qx", "base_qy", "base_qz", "base_qw")
    base_linear_velocity: tuple[str, ...] = ("base_vx", "base_vy", "base_vz")
    base_angular_velocity: tuple[str, ...] = ("base_wx", "base_wy", "base_wz")
    zmp: tuple[str, ...] = ("zmp_x", "zmp_y")
    com: tuple[str, ...] = ("com_x", "com_y", "com_z")
    com_velocity: tuple[str, ...] = ("comd_x", "comd_y", "comd_z")

    @property
    def required(self) -> tuple[str, ...]:
        """The columns every log has: time, base pose and base velocity."""
        return (
            self.time,
            *self.base_position,
            *self.base_quaternion,
            *self.base_linear_velocity,
            *self.base_angular_velocity,
        )


def joint_position_column(joint: str) -> str:
    """Column of a joint's position."""
    return f"q_{joint}"


def joint_velocity_column(joint: str) -> str:
    """Column of a joint's velocity."""
    return f"v_{joint}"


def force_columns(name: str) -> tuple[str, str, str]:
    """Columns of the force (N, world) on the robot at contact ``name`` (a frame, or ``impact``)."""
    return (f"force_{name}_x", f"force_{name}_y", f"force_{name}_z")
