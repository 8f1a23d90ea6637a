"""Synthetic ``push-test --json`` documents for the calibration tests (no trial is run)."""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

__all__ = ["calibration_mapping", "push_test_document", "write_document"]


def push_test_document(
    rows: Sequence[tuple[float, bool, bool]],
    *,
    robot: str = "talos",
    omega: float = 3.3,
    zmp_margin: float = 0.01,
    scenario: str = "synthetic",
    body: str = "torso_2_link",
    controller: str = "id",
    raw_key: bool = True,
    **extra: Any,
) -> dict[str, Any]:
    """A push-test JSON document whose pushes have raw CoM velocity margins and outcomes.

    Args:
        rows: Per push ``(raw margin m/s, fell, strict_fail)``; a fall is a strict failure too.
        robot, omega, zmp_margin, scenario, body, controller: The document's keys.
        raw_key: Write ``predicted_com_velocity_margin`` (False: only the scored
            ``com_velocity_margin``, as older files).
        **extra: Further top-level keys (criterion settings).

    Returns:
        The document, as ``json.loads`` of a push-test output gives it.
    """
    pushes = []
    for raw, fell, strict in rows:
        push: dict[str, Any] = {
            "outcome": "fell" if fell else "balanced",
            "fell": bool(fell),
            "strict_fail": bool(fell or strict),
            "com_velocity_margin": raw - omega * zmp_margin,
        }
        if raw_key:
            push["predicted_com_velocity_margin"] = raw
        pushes.append(push)
    return {
        "scenario": scenario,
        "robot": robot,
        "body": body,
        "zmp_margin": zmp_margin,
        "omega": omega,
        "pushes": pushes,
        "start_com_velocity": [0.0, 0.0],
        "controller": {"name": controller, "gains": {"zmp_margin": 0.01}},
        "outcome_criteria": {"strict_max_slip": 0.03},
        **extra,
    }


def write_document(path: Path, document: dict[str, Any]) -> Path:
    """Write ``document`` as strict JSON to ``path`` and return the path."""
    path.write_text(json.dumps(document, allow_nan=False))
    return path


def calibration_mapping(robot: str = "talos", zmp_margin: float = 0.017) -> dict[str, Any]:
    """The mapping of a valid calibration file (as ``calibrate --out`` writes it)."""
    rate = {"rate": 0.04, "ci95": [0.01, 0.13], "count": 2, "of": 50}
    return {
        "version": 1,
        "robot": robot,
        "controller": {"name": "id"},
        "criterion": {"start_com_velocity": [0.0, 0.0]},
        "outcome_criteria": {"strict_max_slip": 0.03},
        "outcome": "strict",
        "target": 0.05,
        "zmp_margin": zmp_margin,
        "fell_given_safe": rate,
        "safe_given_stood": {"rate": 0.6, "ci95": [0.45, 0.73], "count": 30, "of": 50},
        "upper_target": 0.12,
        "upper_margin": None,
        "training": [
            {"file": "a.json", "sha256": "0" * 64, "scenario": "s", "body": "b", "pushes": 100}
        ],
        "created": "2026-11-27T05:00:00+00:00",
        "impact_balance_version": "0.1.0",
    }
