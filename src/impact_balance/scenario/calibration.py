"""A calibration file: the ZMP margin calibrated on training trials, and how to apply it.

``impact-balance calibrate ... --out FILE`` writes one (YAML, :class:`CalibrationFile`); the
commands' ``--calibration FILE`` and ``Governor(..., calibration=FILE)`` read it with
:func:`read_calibration` and apply its ``zmp_margin`` (m) as the scenario's ZMP margin
(:func:`apply_calibration`): the ZMP support area is shrunk by it, and the CoM velocity area
with it. A calibration belongs to one robot: applying it to a scenario of another robot is
refused.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Annotated, Any, Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from impact_balance.constants import MAX_SIZE
from impact_balance.exceptions import ScenarioError
from impact_balance.files import read_bounded
from impact_balance.scenario.errors import scenario_error

if TYPE_CHECKING:
    from impact_balance.scenario.schema import Scenario

__all__ = [
    "CALIBRATION_VERSION",
    "MAX_CALIBRATION_BYTES",
    "CalibrationFile",
    "CalibrationRate",
    "RemovalAxis",
    "TrainingFile",
    "apply_calibration",
    "calibration_in_use",
    "read_calibration",
    "write_calibration",
]

#: Version of the calibration file format written and read.
CALIBRATION_VERSION: Literal[1] = 1
#: Largest calibration file read (bytes).
MAX_CALIBRATION_BYTES = 4 * 1024 * 1024

Fraction = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, strict=True, allow_inf_nan=False)


class CalibrationRate(_Strict):
    """A proportion with its counts and 95 % Wilson interval (``count`` of ``of``)."""

    rate: Fraction | None
    ci95: Annotated[list[Fraction], Field(min_length=2, max_length=2)] | None
    count: Annotated[int, Field(ge=0)]
    of: Annotated[int, Field(ge=0)]


class RemovalAxis(_Strict):
    """The controller's realised angular momentum removal on one axis (``calibrate``).

    ``share``: the part of the immediate removal's capture cost spent, pooled; ``damping_time``
    (s): the exponential removal's time constant that costs the same; both None without pushes
    (``damping_time`` also when nothing was removed).
    """

    pushes: Annotated[int, Field(ge=0)]
    share: Annotated[float, Field(allow_inf_nan=False)] | None
    damping_time: Annotated[float, Field(ge=0.0, allow_inf_nan=False)] | None


class TrainingFile(_Strict):
    """One training file: its path as given, SHA-256 of its bytes, and what it holds."""

    file: str
    sha256: Annotated[str, Field(pattern=r"^[0-9a-f]{64}$")]
    scenario: str | None
    body: str | None
    pushes: Annotated[int, Field(ge=0)]


class CalibrationFile(_Strict):
    """The calibration file (YAML), version :data:`CALIBRATION_VERSION`.

    Attributes:
        version: The format's version.
        robot: The robot of every training trial (its model name, e.g. ``talos``).
        controller: The balance controller of the trials (``push-test``'s ``controller``).
        criterion: Settings of the trials that change the predictions, passed through verbatim.
        outcome_criteria: The outcome thresholds of the trials (``strict_fail``'s bounds).
        outcome: The outcome scored: ``strict`` (fell or broke a contact beyond the bounds)
            or ``lenient`` (fell).
        target: The false-safe rate P(failed | predicted safe) aimed at.
        zmp_margin: The calibrated ZMP margin, m (never below ``margin_floor``).
        fell_given_safe: P(failed | predicted safe) at ``zmp_margin`` over the training pushes.
        safe_given_stood: The share of the standing pushes called safe at ``zmp_margin``.
        upper_target: Target of the upper Wilson bound of the false-safe rate.
        upper_margin: The smallest margin whose upper bound reaches ``upper_target`` (m), or
            None when none up to the grid's end does.
        training: The training files.
        margin_floor: The smallest margin the calibration could answer, m: the trials'
            controller's own ZMP margin by default (0 in files written before the floor).
        unfloored_margin: The smallest margin meeting the target without the floor, m, or
            None (none does, or the file predates the floor).
        angular_momentum_removal: The trials' controller's realised removal of the angular
            momentum pushes left, per axis (``x`` roll, ``y`` pitch), None in older files;
            informative: no command reads it as the criterion's tau.
        created: When the file was written (ISO 8601, UTC).
        impact_balance_version: The package's version that wrote it.
    """

    version: Literal[1]
    robot: str
    controller: dict[str, Any]
    criterion: dict[str, Any]
    outcome_criteria: dict[str, Any]
    outcome: Literal["strict", "lenient"]
    target: Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)]
    zmp_margin: Annotated[float, Field(ge=0.0, le=MAX_SIZE, allow_inf_nan=False)]
    fell_given_safe: CalibrationRate
    safe_given_stood: CalibrationRate
    upper_target: Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False)]
    upper_margin: Annotated[float, Field(ge=0.0, le=MAX_SIZE, allow_inf_nan=False)] | None
    training: Annotated[list[TrainingFile], Field(min_length=1)]
    margin_floor: Annotated[float, Field(ge=0.0, le=MAX_SIZE, allow_inf_nan=False)] = 0.0
    unfloored_margin: Annotated[float, Field(ge=0.0, le=MAX_SIZE, allow_inf_nan=False)] | None = (
        None
    )
    angular_momentum_removal: dict[Literal["x", "y"], RemovalAxis] | None = None
    created: str
    impact_balance_version: str


def read_calibration(path: str | os.PathLike[str], what: str = "--calibration") -> CalibrationFile:
    """Read and check a calibration file (the package's file-reading rule, YAML, strict model).

    Args:
        path: The file.
        what: The option or key named in errors.

    Returns:
        The calibration.

    Raises:
        ScenarioError: Unreadable, not YAML, not a mapping, or a bad field (named, with the file).
    """
    shown = os.fspath(path)
    data = read_bounded(path, limit=MAX_CALIBRATION_BYTES, what=what)
    try:
        raw = yaml.safe_load(data)
    except yaml.YAMLError as exc:
        reason = " ".join(str(exc).split())
        raise ScenarioError(what, shown, f"not valid YAML: {reason}") from None
    if not isinstance(raw, dict):
        raise ScenarioError(what, shown, "not a calibration file (a YAML mapping)")
    if raw.get("version") != CALIBRATION_VERSION:
        raise ScenarioError(
            "version",
            raw.get("version"),
            f"this package reads calibration files of version {CALIBRATION_VERSION}",
            shown,
        )
    try:
        return CalibrationFile.model_validate(raw)
    except ValidationError as exc:
        raise scenario_error(exc, raw, CalibrationFile, shown) from None


def write_calibration(calibration: CalibrationFile, path: str | os.PathLike[str]) -> None:
    """Write ``calibration`` as YAML to ``path`` (read back by :func:`read_calibration`)."""
    text = yaml.safe_dump(calibration.model_dump(mode="json"), sort_keys=False)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def calibration_in_use(
    calibration: CalibrationFile, file: str, applied: bool, zmp_margin: float
) -> dict[str, Any]:
    """What a command's JSON says of the calibration it read.

    Args:
        calibration: The calibration read.
        file: Its path, as given.
        applied: Whether its margin is the one in use (False: ``--zmp-margin`` won).
        zmp_margin: The ZMP margin in use, m.

    Returns:
        ``{file, robot, zmp_margin (calibrated), target, outcome, applied, zmp_margin_in_use}``.
    """
    return {
        "file": file,
        "robot": calibration.robot,
        "zmp_margin": calibration.zmp_margin,
        "target": calibration.target,
        "outcome": calibration.outcome,
        "applied": applied,
        "zmp_margin_in_use": zmp_margin,
    }


def apply_calibration(
    scenario: Scenario, calibration: CalibrationFile, file: str, what: str = "--calibration"
) -> Scenario:
    """``scenario`` with the calibrated ZMP margin, after checking its robot.

    Args:
        scenario: A :class:`~impact_balance.scenario.Scenario`.
        calibration: The calibration read.
        file: Its path, named in errors.
        what: The option or keyword named in errors.

    Returns:
        The scenario with ``zmp_margin`` set to ``calibration.zmp_margin`` (m).

    Raises:
        ScenarioError: The scenario's robot is not the calibration's (field ``what``).
    """
    robot = scenario.load_robot().name
    if robot != calibration.robot:
        raise ScenarioError(
            what,
            file,
            f"calibrated for robot {calibration.robot!r}; the scenario's robot is {robot!r}",
        )
    return scenario.replace(zmp_margin=calibration.zmp_margin)
