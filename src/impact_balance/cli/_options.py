"""Options shared by the simulation commands (``simulate``, ``validate``, ``push-test``)."""

from __future__ import annotations

import argparse

__all__ = ["add_controller_option", "add_output_options", "add_zmp_margin_option", "with_zmp_margin"]


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


def add_zmp_margin_option(parser: argparse.ArgumentParser, default_help: str) -> None:
    """``--zmp-margin M``: the ZMP support area shrunk by M metres (``default_help``: what it defaults to)."""
    parser.add_argument("--zmp-margin", type=float, default=None, metavar="M",
                        help=f"shrink the ZMP support area by M metres, and the CoM velocity area with it "
                             f"({default_help}; 0 is the paper's criterion)")


def with_zmp_margin(scenario, margin: float | None):
    """``scenario`` with its ``zmp_margin`` replaced by ``margin`` (m) when given, checked like the key."""
    if margin is None:
        return scenario
    from ..constants import MAX_SIZE
    from ..exceptions import ScenarioError

    if not (margin == margin and 0.0 <= margin <= MAX_SIZE):  # NaN fails the first test
        raise ScenarioError("--zmp-margin", margin, f"must be in [0, {MAX_SIZE:g}] m")
    return scenario.model_copy(update={"zmp_margin": float(margin)})
