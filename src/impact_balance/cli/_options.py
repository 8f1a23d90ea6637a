"""Options shared by the simulation commands (``simulate``, ``validate``, ``push-test``)."""

from __future__ import annotations

import argparse

__all__ = ["add_controller_option", "add_output_options"]


def add_controller_option(parser: argparse.ArgumentParser, default: str, why: str) -> None:
    """``--controller ik|id``: the balance controller of the trials (``why``: the default's reason)."""
    parser.add_argument("--controller", default=default, choices=("ik", "id"),
                        help=f"ik: pink IK -> position servos; id: inverse-dynamics QP -> torque motors "
                             f"(default: {default}, {why})")


def add_output_options(parser: argparse.ArgumentParser, log_help: str) -> None:
    """``--json``, ``--plots DIR`` and ``--log FILE`` (what the log holds: ``log_help``)."""
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plots", metavar="DIR", help="write the figures to DIR")
    parser.add_argument("--log", metavar="FILE", help=f"write the time series (.parquet or .csv) {log_help}")
