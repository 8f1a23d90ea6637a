"""Time-series logs of a robot's motion: one schema, written by the simulation, read by the checker.

A log is a table, one row per sample, stored as Parquet (``.parquet``) or CSV (``.csv``).
See :mod:`impact_balance.logs.schema` for the columns.
"""

from impact_balance.logs.check import LogCheck, Violation, check_log
from impact_balance.logs.io import check_log_columns, check_log_path, read_log, write_log
from impact_balance.logs.schema import (
    LOG_VERSION,
    LogColumns,
    force_columns,
    joint_position_column,
    joint_velocity_column,
)

__all__ = [
    "LOG_VERSION",
    "LogCheck",
    "LogColumns",
    "Violation",
    "check_log",
    "check_log_columns",
    "check_log_path",
    "force_columns",
    "joint_position_column",
    "joint_velocity_column",
    "read_log",
    "write_log",
]
