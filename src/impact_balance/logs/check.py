"""Check a recorded motion against the balance criteria: per sample, and a summary of violations.

For every sample of a log (:mod:`.schema`), from a simulation or a real robot:

- the configuration and velocity in pinocchio's convention, from the base pose, the base velocity
  (world axes, turned into the base frame) and the joint columns;
- the CoM and the CoM velocity (pinocchio, ``centerOfMass(q, v)``);
- the areas of the stance (the scenario's contacts at the logged configuration), recomputed when
  the stance changes: a contact is released or made (its normal force, when logged, crosses
  ``force_threshold``), a contact frame moves by more than ``move_tolerance`` (m) or turns by
  more than ``turn_tolerance`` (rad), or the CoM moves horizontally by more than
  ``com_tolerance`` (m) from where the areas were computed (the LIPM constraint depends on it);
- the CoM criterion: the CoM velocity inside the CoM velocity area ``omega (Z - c_xy)``, with
  ``Z`` the ZMP support area, ``omega = sqrt(g / (c_z - h))`` at the sample's CoM. Equivalently
  the DCM ``c_xy + c_d / omega`` inside ``Z``; the margin is ``omega`` times the DCM's distance to
  the boundary (m/s, positive inside);
- the ZMP criterion, when the log has ``zmp_x, zmp_y``: the ZMP inside ``Z`` and its margin (m).

Violations are the maximal runs of consecutive samples outside an area, with their start, end and
worst margin.

A log in which no contact is ever loaded (every logged contact force below ``force_threshold``:
a floating robot, such as ``simulate --joints rigid``, which also turns gravity off) has no area
to check against. The result says so (``loaded_samples`` = 0, a ``note``), tells whether the CoM
falls as under gravity (``com_vertical_acceleration``, fitted on the samples), and gives what such
a log can be checked for: the CoM velocity change over the log (``com_velocity_change``, to be
compared with the impact model's prediction, as ``simulate`` does).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
import pandas as pd
import pinocchio as pin

from impact_balance.balance.areas import balance_areas
from impact_balance.constants import MAX_POSITION
from impact_balance.contacts.stance import ContactSpec, Stance
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.polygon import Polygon
from impact_balance.governor.governor import JOINT_LIMIT_TOLERANCE
from impact_balance.json_values import json_number
from impact_balance.logs.io import check_log_columns
from impact_balance.logs.schema import (
    LogColumns,
    force_columns,
    joint_position_column,
    joint_velocity_column,
)
from impact_balance.robot.robot import Robot
from impact_balance.scenario import Scenario, load_scenario

__all__ = [
    "LogCheck",
    "StanceSegment",
    "Violation",
    "ViolationKind",
    "check_log",
    "json_records",
    "log_state",
]

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int_]

#: Largest |norm - 1| of a logged base quaternion: a quaternion further from unit is refused,
#: not normalised (its scale says the column is not a rotation; float32 logs are within 1e-6).
QUATERNION_TOLERANCE = 1e-3
#: Prefixes of the optional columns whose values must not be infinite (an empty cell, NaN, is a
#: sample where the value was not measured).
_OPTIONAL = ("zmp_", "force_", "com_", "comd_")

#: What a violation left: the CoM velocity area (margin in m/s) or the ZMP support area (m).
ViolationKind = Literal["com_velocity", "zmp"]


@dataclass(frozen=True)
class StanceSegment:
    """Areas in force from ``start`` (s).

    Which contacts are loaded, the ZMP support area (m, world) and the CoM (m, world) where the
    areas were computed.
    """

    start: float
    contacts: tuple[str, ...]
    zmp_area: Polygon
    com: FloatArray
    can_balance: bool


@dataclass(frozen=True)
class Violation:
    """A run of samples outside an area.

    ``kind`` is ``com_velocity`` or ``zmp``; times in s; margins in m/s or m.
    """

    kind: ViolationKind
    start: float
    end: float
    worst_margin: float
    worst_time: float
    samples: int

    def to_dict(self) -> dict[str, Any]:
        """The violation as JSON values (a -inf margin, from a stance without area, is null)."""
        return {
            "kind": self.kind,
            "start": self.start,
            "end": self.end,
            "worst_margin": json_number(self.worst_margin),
            "worst_time": self.worst_time,
            "samples": self.samples,
        }


@dataclass
class LogCheck:
    """Result of :func:`check_log`: ``samples`` has one row per log sample (see there)."""

    scenario: str | None
    samples: pd.DataFrame
    segments: list[StanceSegment]
    violations: list[Violation]
    has_zmp: bool
    settings: dict[str, float] = field(default_factory=dict)
    loaded_samples: int = 0
    com_vertical_acceleration: float = float("nan")
    com_velocity_change: FloatArray = field(default_factory=lambda: np.zeros(3))
    gravity: float = 9.81

    @property
    def floating(self) -> bool:
        """No contact is loaded in any sample: no balance area applies."""
        return self.loaded_samples == 0

    @property
    def gravity_seen(self) -> bool:
        """The floating CoM falls at about g (within 20 %); meaningless when a contact is loaded."""
        return bool(
            np.isfinite(self.com_vertical_acceleration)
            and abs(self.com_vertical_acceleration + self.gravity) < 0.2 * self.gravity
        )

    @property
    def note(self) -> str | None:
        """What the check could not do, and what the log shows instead (None: all was checked)."""
        if not self.floating:
            return None
        text = (
            "no contact is loaded in any sample (every logged contact force is below "
            f"{self.settings.get('force_threshold', 5.0):g} N): the robot floats, "
            "so no balance area applies"
        )
        if not self.gravity_seen:
            text += (
                "; its CoM does not fall (vertical acceleration "
                f"{self.com_vertical_acceleration:.2f} m/s^2, "
                f"not -{self.gravity:g}): gravity is off, as in `simulate --joints rigid`"
            )
        dv = self.com_velocity_change
        text += (
            ". What it shows: the CoM velocity changed by "
            f"({dv[0]:+.4f}, {dv[1]:+.4f}, {dv[2]:+.4f}) m/s; "
            "compare it with the impact model's jump "
            "(`impact-balance simulate SCENARIO --joints rigid --json`, "
            "`predicted`)"
        )
        return text

    @property
    def ok(self) -> bool:
        """No sample is outside an area."""
        return not self.violations

    def to_dict(self, samples: bool = False) -> dict[str, Any]:
        """The result as JSON values (NaN and infinities as null).

        Args:
            samples: Add the per-sample table (``per_sample``).

        Returns:
            The summary, the violations, the stances and the settings.
        """
        num = json_number
        s = self.samples
        out = {
            "scenario": self.scenario,
            "samples": len(s),
            "duration": num(float(s["time"].iloc[-1] - s["time"].iloc[0])) if len(s) else 0.0,
            "ok": self.ok,
            "has_zmp": self.has_zmp,
            "min_com_velocity_margin": num(float(s["com_velocity_margin"].min()))
            if len(s)
            else None,
            "min_zmp_margin": num(float(s["zmp_margin"].min()))
            if self.has_zmp and len(s)
            else None,
            "violations": [v.to_dict() for v in self.violations],
            "loaded_samples": self.loaded_samples,
            "floating": self.floating,
            "com_vertical_acceleration": num(self.com_vertical_acceleration),
            "gravity_seen": self.gravity_seen if self.floating else None,
            "com_velocity_change": [num(x) for x in self.com_velocity_change],
            "note": self.note,
            "stances": [
                {
                    "start": g.start,
                    "contacts": list(g.contacts),
                    "com": g.com.tolist(),
                    "can_balance": g.can_balance,
                    "zmp_area": g.zmp_area.vertices.tolist(),
                }
                for g in self.segments
            ],
            "settings": self.settings,
        }
        if samples:
            out["per_sample"] = json_records(s)
        return out


def json_records(frame: pd.DataFrame) -> list[dict[str, Any]]:
    """Rows as dicts with NaN/inf turned into None (strict JSON)."""
    clean = frame.astype(object).where(np.isfinite(frame.astype(float)), None)
    records: list[dict[str, Any]] = clean.to_dict(orient="records")
    return records


def _joint_columns(frame: pd.DataFrame, robot: Robot, source: str) -> None:
    """Refuse a log whose joint columns do not match the robot's joints, naming the difference."""
    names = list(robot.joint_names)
    missing = [
        c
        for n in names
        for c in (joint_position_column(n), joint_velocity_column(n))
        if c not in frame.columns
    ]
    known = {joint_position_column(n) for n in names} | {joint_velocity_column(n) for n in names}
    unknown = [c for c in frame.columns if c.startswith(("q_", "v_")) and c not in known]
    if unknown:
        raise ScenarioError(
            "LOG",
            source,
            f"joint columns not in robot {robot.name!r}: {', '.join(unknown[:8])}"
            + (" ..." if len(unknown) > 8 else ""),
        )
    if missing:
        raise ScenarioError(
            "LOG",
            source,
            f"missing joint columns for robot {robot.name!r}: {', '.join(missing[:8])}"
            + (f" ... ({len(missing)} in all)" if len(missing) > 8 else ""),
        )


def log_state(frame: pd.DataFrame, robot: Robot) -> tuple[FloatArray, FloatArray]:
    """Configurations (T x nq) and velocities (T x nv) in pinocchio's convention from a log.

    The base velocity columns are world-axis linear velocity of the base origin and world-axis
    angular velocity; pinocchio's free-flyer velocity is in the base frame, so both are rotated
    by ``R^T``.

    Args:
        frame: The log (columns of :mod:`impact_balance.logs.schema`).
        robot: The robot whose joints the log's columns name.

    Returns:
        The configurations and the velocities, one row per sample.

    Raises:
        ScenarioError: A base quaternion that is not unit (within :data:`QUATERNION_TOLERANCE`;
            it is then normalised exactly), or a joint has several dofs.
    """
    cols = LogColumns()
    model = robot.model
    T = len(frame)
    Q = np.tile(robot.configuration(), (T, 1)) if T else np.zeros((0, model.nq))
    V = np.zeros((T, model.nv))
    Q[:, 0:3] = frame[list(cols.base_position)].to_numpy(float)
    quat = frame[list(cols.base_quaternion)].to_numpy(float)
    with np.errstate(over="ignore", invalid="ignore"):
        norms = np.sqrt(np.sum((quat / 2.0) ** 2, axis=1, keepdims=True)) * 2.0  # no overflow
    off = ~(np.abs(norms[:, 0] - 1.0) <= QUATERNION_TOLERANCE)
    if off.any():
        k = int(np.flatnonzero(off)[0])
        raise ScenarioError(
            "LOG",
            "base_qx..base_qw",
            f"row {k + 1}: the base quaternion has norm {float(norms[k, 0]):.6g}; it must be "
            f"unit within {QUATERNION_TOLERANCE:g} (x, y, z, w)",
        )
    Q[:, 3:7] = quat / norms
    lin = frame[list(cols.base_linear_velocity)].to_numpy(float)
    ang = frame[list(cols.base_angular_velocity)].to_numpy(float)
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        if slot.nq != 1:
            raise ScenarioError("LOG", name, "only 1-dof joints can be read from a log")
        Q[:, slot.idx_q] = frame[joint_position_column(name)].to_numpy(float)
        V[:, model.joints[slot.id].idx_v] = frame[joint_velocity_column(name)].to_numpy(float)
    for k in range(T):
        R = pin.Quaternion(Q[k, 6], Q[k, 3], Q[k, 4], Q[k, 5]).matrix()  # (w, x, y, z) constructor
        V[k, 0:3] = R.T @ lin[k]
        V[k, 3:6] = R.T @ ang[k]
    return Q, V


def _runs(
    times: FloatArray, outside: npt.NDArray[np.bool_], margins: FloatArray, kind: ViolationKind
) -> list[Violation]:
    """The maximal runs of consecutive ``outside`` samples, each with its worst margin.

    Args:
        times: Sample times (s).
        outside: Whether each sample is outside the area.
        margins: Each sample's margin (m/s or m; NaN where unknown, -inf without an area).
        kind: What was checked.

    Returns:
        One :class:`Violation` per run, in time order.
    """
    out = []
    k, count = 0, len(outside)
    while k < count:
        if not outside[k]:
            k += 1
            continue
        j = k
        while j + 1 < count and outside[j + 1]:
            j += 1
        seg = margins[k : j + 1]
        w = (
            k + int(np.nanargmin(np.where(np.isfinite(seg), seg, -np.inf)))
            if np.any(~np.isnan(seg))
            else k
        )
        out.append(
            Violation(
                kind,
                float(times[k]),
                float(times[j]),
                float(margins[w]),
                float(times[w]),
                j - k + 1,
            )
        )
        k = j + 1
    return out


@dataclass(frozen=True)
class _Tolerances:
    """When the areas are recomputed (see :func:`check_log`)."""

    force_threshold: float
    move_tolerance: float
    turn_tolerance: float
    com_tolerance: float

    def as_dict(self) -> dict[str, float]:
        """The settings as written in the result."""
        return {
            "force_threshold": self.force_threshold,
            "move_tolerance": self.move_tolerance,
            "turn_tolerance": self.turn_tolerance,
            "com_tolerance": self.com_tolerance,
        }


def _checked_times(
    frame: pd.DataFrame, scenario: Scenario, source: str
) -> tuple[Robot, FloatArray]:
    """The scenario's robot and the log's times, after the log's columns and times are checked."""
    cols = LogColumns()
    missing = [c for c in cols.required if c not in frame.columns]
    if missing:
        raise ScenarioError("LOG", source, f"missing required columns: {', '.join(missing)}")
    if len(frame) == 0:
        raise ScenarioError("LOG", source, "no samples")
    check_log_columns(frame, source)  # a NaN is named by its column, not by what it spoils later
    robot = scenario.load_robot()
    _joint_columns(frame, robot, source)
    times = frame[cols.time].to_numpy(float)
    if np.any(~np.isfinite(times)):
        raise ScenarioError("LOG", source, "time must be finite")
    steps = np.flatnonzero(~(np.diff(times) > 0.0))
    if steps.size:
        k = int(steps[0]) + 1
        raise ScenarioError(
            "LOG",
            source,
            f"column {cols.time}, row {k + 1}: {times[k]:.9g} s after {times[k - 1]:.9g} s; "
            "time must strictly increase",
        )
    _infinite_optional(frame, source)
    _bounded_positions(frame, robot, source)
    return robot, times


def _infinite_optional(frame: pd.DataFrame, source: str) -> None:
    """Refuse an infinite value in an optional column (a force, the ZMP, a reference CoM)."""
    for name in frame.columns:
        if not str(name).startswith(_OPTIONAL):
            continue
        values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(np.isinf(values))
        if bad.size:
            raise ScenarioError(
                "LOG",
                source,
                f"column {name}, row {int(bad[0]) + 1}: {values[bad[0]]:g}, not a finite number "
                "(leave the cell empty where it was not measured)",
            )


def _bounded_positions(frame: pd.DataFrame, robot: Robot, source: str) -> None:
    """Refuse a base position or a joint beyond what a scenario accepts.

    The base within :data:`~impact_balance.constants.MAX_POSITION` m of the origin per
    coordinate; a 1-dof joint with finite limits within them plus
    :data:`~impact_balance.governor.governor.JOINT_LIMIT_TOLERANCE` (the governor's rule).
    """
    columns = [(c, -MAX_POSITION, MAX_POSITION, "m") for c in LogColumns().base_position]
    for name in robot.joint_names:
        slot = robot.joint_slot(name)
        lo, hi = slot.lower, slot.upper
        if slot.nq == 1 and np.isfinite(lo) and np.isfinite(hi) and lo < hi:
            column = joint_position_column(name)
            columns.append((column, lo - JOINT_LIMIT_TOLERANCE, hi + JOINT_LIMIT_TOLERANCE, ""))
    for column, lo, hi, unit in columns:
        values = frame[column].to_numpy(dtype=float)
        bad = np.flatnonzero((values < lo) | (values > hi))
        if bad.size:
            k = int(bad[0])
            if unit:
                bound = f"must be in [{lo:g}, {hi:g}] {unit}"
            else:
                bound = (
                    f"outside the joint limits [{lo + JOINT_LIMIT_TOLERANCE:.4g}, "
                    f"{hi - JOINT_LIMIT_TOLERANCE:.4g}] (tolerance {JOINT_LIMIT_TOLERANCE:g})"
                )
            raise ScenarioError(
                "LOG", source, f"column {column}, row {k + 1}: {values[k]:.6g} {bound}"
            )


class _StanceTracker:
    """The stance segments of a log, extended sample by sample (see :func:`check_log`)."""

    def __init__(
        self,
        scenario: Scenario,
        robot: Robot,
        specs: list[ContactSpec],
        forces: dict[str, FloatArray],
        tolerances: _Tolerances,
    ) -> None:
        self.scenario = scenario
        self.robot = robot
        self.specs = specs
        self.forces = forces
        self.tolerances = tolerances
        self.segments: list[StanceSegment] = []
        self.loaded = 0
        self._key_poses: list[pin.SE3] = []
        self._active: tuple[str, ...] | None = None

    def _loaded_contacts(self, k: int, poses: list[pin.SE3]) -> tuple[str, ...]:
        """The contacts loaded at sample ``k``: all but those whose logged force is too small."""
        active = []
        for spec, pose in zip(self.specs, poses, strict=True):
            if spec.frame in self.forces:
                f = self.forces[spec.frame][k]
                if not (
                    np.all(np.isfinite(f))
                    and f @ pose.rotation[:, 2] > self.tolerances.force_threshold
                ):
                    continue
            active.append(spec.frame)
        return tuple(active)

    def _changed(self, active: tuple[str, ...], poses: list[pin.SE3], com: FloatArray) -> bool:
        """Whether the areas must be recomputed (see :func:`check_log`)."""
        if not self.segments or active != self._active:
            return True
        tol = self.tolerances
        moved = any(
            np.linalg.norm(p.translation - p0.translation) > tol.move_tolerance
            or np.linalg.norm(pin.log3(p0.rotation.T @ p.rotation)) > tol.turn_tolerance
            for p, p0 in zip(poses, self._key_poses, strict=True)
        )
        return bool(
            moved or np.linalg.norm(com[:2] - self.segments[-1].com[:2]) > tol.com_tolerance
        )

    def update(
        self, k: int, time: float, q: FloatArray, com: FloatArray, poses: list[pin.SE3]
    ) -> StanceSegment:
        """The segment in force at sample ``k``, a new one when the stance changed.

        Args:
            k: The sample's index.
            time: The sample's time (s).
            q: The configuration (pinocchio's convention).
            com: The CoM (m, world).
            poses: Each contact's pose (world), in the order of ``specs``.

        Returns:
            The segment in force.
        """
        active = self._loaded_contacts(k, poses)
        self.loaded += bool(active)
        if self._changed(active, poses, com):
            scenario, h = self.scenario, self.scenario.plane_height
            chosen = [s for s in self.specs if s.frame in active]
            if chosen and com[2] > h:
                stance = Stance(self.robot, q, chosen)
                zmp_area = balance_areas(
                    stance, h, scenario.torque_limits, scenario.gravity, scenario.zmp_margin
                ).zmp_area
            else:
                zmp_area = Polygon.empty()
            self.segments.append(
                StanceSegment(time, active, zmp_area, com.copy(), not zmp_area.is_empty)
            )
            self._key_poses = [pin.SE3(p) for p in poses]
            self._active = active
        return self.segments[-1]


def _sample_row(
    seg: StanceSegment,
    com: FloatArray,
    comd: FloatArray,
    zmp: FloatArray | None,
    h: float,
    g: float,
) -> list[float]:
    """One row of the samples: CoM, CoM velocity, DCM, the two margins, omega and a spare 0.

    Args:
        seg: The segment in force.
        com: The CoM (m, world).
        comd: The CoM velocity (m/s, world).
        zmp: The logged ZMP (m, world), None without a ZMP column.
        h: The contact plane's height (m).
        g: Gravity (m/s^2).

    Returns:
        Twelve numbers (see :func:`_samples_frame`).
    """
    omega = np.sqrt(g / (com[2] - h)) if com[2] > h else np.nan
    dcm = com[:2] + comd[:2] / omega if np.isfinite(omega) else np.full(2, np.nan)
    vel_margin = (
        omega * float(seg.zmp_area.margins(dcm)[0])
        if seg.can_balance and np.isfinite(omega)
        else -np.inf
    )
    zmp_margin = np.nan
    if zmp is not None and np.all(np.isfinite(zmp)):
        zmp_margin = float(seg.zmp_area.margins(zmp)[0]) if seg.can_balance else -np.inf
    return [*com, *comd, *dcm, vel_margin, zmp_margin, omega, 0.0]


def _samples_frame(times: FloatArray, rows: FloatArray, stance_index: IntArray) -> pd.DataFrame:
    """The per-sample table of :class:`LogCheck` from the rows of :func:`_sample_row`."""
    return pd.DataFrame(
        {
            "time": times,
            "com_x": rows[:, 0],
            "com_y": rows[:, 1],
            "com_z": rows[:, 2],
            "comd_x": rows[:, 3],
            "comd_y": rows[:, 4],
            "comd_z": rows[:, 5],
            "dcm_x": rows[:, 6],
            "dcm_y": rows[:, 7],
            "com_velocity_margin": rows[:, 8],
            "com_velocity_inside": rows[:, 8] >= 0.0,
            "zmp_margin": rows[:, 9],
            "zmp_inside": np.where(np.isnan(rows[:, 9]), np.nan, rows[:, 9] >= 0.0),
            "omega": rows[:, 10],
            "stance": stance_index,
        }
    )


def _violations(
    times: FloatArray, samples: pd.DataFrame, rows: FloatArray, has_zmp: bool
) -> list[Violation]:
    """The runs outside the CoM velocity area, then (with a logged ZMP) the ZMP area, by start."""
    violations = _runs(
        times, ~samples["com_velocity_inside"].to_numpy(bool), rows[:, 8], "com_velocity"
    )
    if has_zmp:
        zm = rows[:, 9]
        violations += _runs(times, np.isfinite(zm) & (zm < 0.0) | np.isneginf(zm), zm, "zmp")
    violations.sort(key=lambda v: (v.start, v.kind))
    return violations


def _vertical_acceleration(times: FloatArray, rows: FloatArray) -> float:
    """The CoM's vertical acceleration (m/s^2) fitted over the log.

    It is -g for a falling robot, 0 with gravity off.
    """
    if len(times) > 2 and np.ptp(times) > 0:
        return float(np.polyfit(times, rows[:, 5], 1)[0])
    return float("nan")


def check_log(
    frame: pd.DataFrame,
    scenario: Scenario | str,
    *,
    force_threshold: float = 5.0,
    move_tolerance: float = 0.01,
    turn_tolerance: float = float(np.deg2rad(3.0)),
    com_tolerance: float = 0.01,
    source: str = "LOG",
) -> LogCheck:
    """Check a log (a DataFrame with the columns of :mod:`.schema`) against ``scenario``'s criteria.

    ``samples`` columns: ``time``, ``com_x/y/z`` (m), ``comd_x/y/z`` (m/s), ``dcm_x/y`` (m),
    ``com_velocity_inside``, ``com_velocity_margin`` (m/s), ``zmp_inside``, ``zmp_margin`` (m; NaN
    without a logged ZMP), ``stance`` (index into ``segments``).

    Args:
        frame: The log.
        scenario: The scenario (or its name or file) whose contacts and limits apply.
        force_threshold: Normal force (N) above which a logged contact is loaded.
        move_tolerance: Contact frame motion (m) that recomputes the areas.
        turn_tolerance: Contact frame rotation (rad) that recomputes the areas.
        com_tolerance: Horizontal CoM motion (m) that recomputes the areas.
        source: The log's name in error messages.

    Returns:
        The samples, the stance segments and the violations.

    Raises:
        ScenarioError: The log lacks a column, has no sample, a value that is not a finite
            number (an infinite force or ZMP included), joints that are not the robot's,
            times that do not strictly increase, a base quaternion that is not unit (within
            :data:`QUATERNION_TOLERANCE`), a base position beyond
            :data:`~impact_balance.constants.MAX_POSITION` m or a joint beyond its limits
            (plus the governor's ``JOINT_LIMIT_TOLERANCE``); each names its column and row.
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    robot, times = _checked_times(frame, scenario, source)
    cols = LogColumns()
    q_all, v_all = log_state(frame, robot)
    # contacts given by a normal: at the stance
    specs = [c.spec for c in scenario.build_stance(robot).contacts]
    forces = {
        s.frame: frame[list(force_columns(s.frame))].to_numpy(float)
        for s in specs
        if all(c in frame.columns for c in force_columns(s.frame))
    }
    has_zmp = all(c in frame.columns for c in cols.zmp)
    zmp_logged = frame[list(cols.zmp)].to_numpy(float) if has_zmp else None
    model = robot.model
    data = model.createData()
    h, g = scenario.plane_height, scenario.gravity
    tolerances = _Tolerances(force_threshold, move_tolerance, turn_tolerance, com_tolerance)
    tracker = _StanceTracker(scenario, robot, specs, forces, tolerances)
    rows = np.full((len(frame), 12), np.nan)
    stance_index = np.zeros(len(frame), dtype=int)
    for k in range(len(frame)):
        q, v = q_all[k], v_all[k]
        pin.centerOfMass(model, data, q, v, False)
        com, comd = data.com[0].copy(), data.vcom[0].copy()
        pin.framesForwardKinematics(model, data, q)
        poses = [data.oMf[robot.frame_id(s.frame)] * s.offset for s in specs]
        seg = tracker.update(k, float(times[k]), q, com, poses)
        stance_index[k] = len(tracker.segments) - 1
        zmp = zmp_logged[k] if zmp_logged is not None else None
        rows[k] = _sample_row(seg, com, comd, zmp, h, g)
    samples = _samples_frame(times, rows, stance_index)
    violations = _violations(times, samples, rows, has_zmp)
    accel = _vertical_acceleration(times, rows)
    change = rows[-1, 3:6] - rows[0, 3:6]
    return LogCheck(
        scenario.name,
        samples,
        tracker.segments,
        violations,
        has_zmp,
        tolerances.as_dict(),
        tracker.loaded,
        accel,
        change,
        g,
    )
