"""Check a recorded motion against the balance criteria: per sample, and a summary of violations.

For every sample of a log (:mod:`.schema`), from a simulation or a real robot:

- the configuration and velocity in pinocchio's convention, from the base pose, the base velocity
  (world axes, turned into the base frame) and the joint columns;
- the CoM and the CoM velocity (pinocchio, ``centerOfMass(q, v)``);
- the areas of the stance (the scenario's contacts at the logged configuration), recomputed when
  the stance changes: a contact is released or made (its normal force, when logged, crosses
  ``force_threshold``), a contact frame moves by more than ``move_tolerance`` (m) or turns by more than
  ``turn_tolerance`` (rad), or the CoM moves horizontally by more than ``com_tolerance`` (m) from where
  the areas were computed (the LIPM constraint depends on it);
- the CoM criterion: the CoM velocity inside the CoM velocity area ``omega (Z - c_xy)``, with ``Z`` the
  ZMP support area, ``omega = sqrt(g / (c_z - h))`` at the sample's CoM. Equivalently the DCM
  ``c_xy + c_d / omega`` inside ``Z``; the margin is ``omega`` times the DCM's distance to the
  boundary (m/s, positive inside);
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

import numpy as np
import pandas as pd
import pinocchio as pin

from impact_balance.balance.areas import balance_areas
from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.polygon import Polygon
from impact_balance.json_values import json_number
from impact_balance.logs.io import check_log_columns
from impact_balance.logs.schema import (
    LogColumns,
    force_columns,
    joint_position_column,
    joint_velocity_column,
)
from impact_balance.scenario import Scenario, load_scenario

__all__ = ["LogCheck", "StanceSegment", "Violation", "check_log", "log_state"]


@dataclass(frozen=True)
class StanceSegment:
    """Areas in force from ``start`` (s): which contacts, the ZMP support area, where they were computed."""

    start: float
    contacts: tuple[str, ...]
    zmp_area: Polygon
    com: np.ndarray
    can_balance: bool


@dataclass(frozen=True)
class Violation:
    """A run of samples outside an area: ``kind`` is ``com_velocity`` or ``zmp``; margins in m/s or m."""

    kind: str
    start: float
    end: float
    worst_margin: float
    worst_time: float
    samples: int

    def to_dict(self) -> dict:
        # -inf margin: the stance had no area at all (it cannot balance); JSON null.
        worst = self.worst_margin if np.isfinite(self.worst_margin) else None
        return {
            "kind": self.kind,
            "start": self.start,
            "end": self.end,
            "worst_margin": worst,
            "worst_time": self.worst_time,
            "samples": self.samples,
        }


@dataclass
class LogCheck:
    """Result of :func:`check_log`. ``samples`` is one row per log sample (see :func:`check_log`)."""

    scenario: str | None
    samples: pd.DataFrame
    segments: list[StanceSegment]
    violations: list[Violation]
    has_zmp: bool
    settings: dict = field(default_factory=dict)
    loaded_samples: int = 0
    com_vertical_acceleration: float = float("nan")
    com_velocity_change: np.ndarray = field(default_factory=lambda: np.zeros(3))
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
        """What the check could not do, and what the log can show instead (None when all was checked)."""
        if not self.floating:
            return None
        text = (
            "no contact is loaded in any sample (every logged contact force is below "
            f"{self.settings.get('force_threshold', 5.0):g} N): the robot floats, so no balance area applies"
        )
        if not self.gravity_seen:
            text += (
                f"; its CoM does not fall (vertical acceleration {self.com_vertical_acceleration:.2f} m/s^2, "
                f"not -{self.gravity:g}): gravity is off, as in `simulate --joints rigid`"
            )
        dv = self.com_velocity_change
        text += (
            f". What it shows: the CoM velocity changed by ({dv[0]:+.4f}, {dv[1]:+.4f}, {dv[2]:+.4f}) m/s; "
            "compare it with the impact model's jump (`impact-balance simulate SCENARIO --joints rigid --json`, "
            "`predicted`)"
        )
        return text

    @property
    def ok(self) -> bool:
        return not self.violations

    def to_dict(self, samples: bool = False) -> dict:
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


def json_records(frame: pd.DataFrame) -> list[dict]:
    """Rows as dicts with NaN/inf turned into None (strict JSON)."""
    clean = frame.astype(object).where(np.isfinite(frame.astype(float)), None)
    return clean.to_dict(orient="records")


def _joint_columns(frame: pd.DataFrame, robot, source: str) -> None:
    """Refuse a log whose joint columns do not match the robot's joints, naming the difference."""
    names = list(robot.joint_names)
    missing = [
        c
        for n in names
        for c in (joint_position_column(n), joint_velocity_column(n))
        if c not in frame.columns
    ]
    known = {joint_position_column(n) for n in names} | {joint_velocity_column(n) for n in names}
    unknown = [
        c for c in frame.columns if (c.startswith("q_") or c.startswith("v_")) and c not in known
    ]
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


def log_state(frame: pd.DataFrame, robot) -> tuple[np.ndarray, np.ndarray]:
    """Configurations (T x nq) and velocities (T x nv) in pinocchio's convention from a log's columns.

    The base velocity columns are world-axis linear velocity of the base origin and world-axis angular
    velocity; pinocchio's free-flyer velocity is in the base frame, so both are rotated by ``R^T``.
    """
    cols = LogColumns()
    model = robot.model
    T = len(frame)
    Q = np.tile(robot.configuration(), (T, 1)) if T else np.zeros((0, model.nq))
    V = np.zeros((T, model.nv))
    Q[:, 0:3] = frame[list(cols.base_position)].to_numpy(float)
    quat = frame[list(cols.base_quaternion)].to_numpy(float)
    norms = np.linalg.norm(quat, axis=1, keepdims=True)
    if np.any(~np.isfinite(norms)) or np.any(norms < 1e-9):
        raise ScenarioError(
            "LOG", "base_qx..base_qw", "the base quaternion must be finite and non-zero"
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
    times: np.ndarray, outside: np.ndarray, margins: np.ndarray, kind: str
) -> list[Violation]:
    out = []
    k, T = 0, len(outside)
    while k < T:
        if not outside[k]:
            k += 1
            continue
        j = k
        while j + 1 < T and outside[j + 1]:
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


def check_log(
    frame: pd.DataFrame,
    scenario: Scenario | str,
    *,
    force_threshold: float = 5.0,
    move_tolerance: float = 0.01,
    turn_tolerance: float = np.deg2rad(3.0),
    com_tolerance: float = 0.01,
    source: str = "LOG",
) -> LogCheck:
    """Check a log (a DataFrame with the columns of :mod:`.schema`) against ``scenario``'s criteria.

    ``samples`` columns: ``time``, ``com_x/y/z`` (m), ``comd_x/y/z`` (m/s), ``dcm_x/y`` (m),
    ``com_velocity_inside``, ``com_velocity_margin`` (m/s), ``zmp_inside``, ``zmp_margin`` (m; NaN
    without a logged ZMP), ``stance`` (index into ``segments``).
    """
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
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
    if np.any(~np.isfinite(times)) or np.any(np.diff(times) < 0):
        raise ScenarioError("LOG", source, "time must be finite and increasing")
    Q, V = log_state(frame, robot)
    specs = [
        c.spec for c in scenario.build_stance(robot).contacts
    ]  # contacts given by a normal: at the stance
    names = [s.frame for s in specs]
    forces = {
        n: frame[list(force_columns(n))].to_numpy(float)
        for n in names
        if all(c in frame.columns for c in force_columns(n))
    }
    has_zmp = all(c in frame.columns for c in cols.zmp)
    zmp_logged = frame[list(cols.zmp)].to_numpy(float) if has_zmp else None
    model = robot.model
    data = model.createData()
    h, g = scenario.plane_height, scenario.gravity

    segments: list[StanceSegment] = []
    key_poses: list[pin.SE3] | None = None
    active_prev: tuple[str, ...] | None = None
    rows = np.full((len(frame), 12), np.nan)
    stance_index = np.zeros(len(frame), dtype=int)
    loaded = 0
    for k in range(len(frame)):
        q, v = Q[k], V[k]
        pin.centerOfMass(model, data, q, v, False)
        com, comd = data.com[0].copy(), data.vcom[0].copy()
        pin.framesForwardKinematics(model, data, q)
        poses = [data.oMf[robot.frame_id(s.frame)] * s.offset for s in specs]
        active = []
        for spec, pose in zip(specs, poses):
            if spec.frame in forces:
                f = forces[spec.frame][k]
                if not (np.all(np.isfinite(f)) and f @ pose.rotation[:, 2] > force_threshold):
                    continue
            active.append(spec.frame)
        active_t = tuple(active)
        loaded += bool(active_t)
        changed = not segments or active_t != active_prev
        if not changed:
            seg = segments[-1]
            moved = any(
                np.linalg.norm(p.translation - p0.translation) > move_tolerance
                or np.linalg.norm(pin.log3(p0.rotation.T @ p.rotation)) > turn_tolerance
                for p, p0 in zip(poses, key_poses)
            )
            changed = moved or np.linalg.norm(com[:2] - seg.com[:2]) > com_tolerance
        if changed:
            chosen = [s for s in specs if s.frame in active_t]
            if chosen and com[2] > h:
                stance = Stance(robot, q, chosen)
                zmp_area = balance_areas(
                    stance, h, scenario.torque_limits, g, scenario.zmp_margin
                ).zmp_area
            else:
                zmp_area = Polygon.empty()
            segments.append(
                StanceSegment(
                    float(times[k]), active_t, zmp_area, com.copy(), not zmp_area.is_empty
                )
            )
            key_poses = [pin.SE3(p) for p in poses]
            active_prev = active_t
        seg = segments[-1]
        stance_index[k] = len(segments) - 1
        omega = np.sqrt(g / (com[2] - h)) if com[2] > h else np.nan
        dcm = com[:2] + comd[:2] / omega if np.isfinite(omega) else np.full(2, np.nan)
        vel_margin = (
            omega * float(seg.zmp_area.margins(dcm)[0])
            if seg.can_balance and np.isfinite(omega)
            else -np.inf
        )
        zmp_margin = np.nan
        if has_zmp and np.all(np.isfinite(zmp_logged[k])):
            zmp_margin = (
                float(seg.zmp_area.margins(zmp_logged[k])[0]) if seg.can_balance else -np.inf
            )
        rows[k] = [*com, *comd, *dcm, vel_margin, zmp_margin, omega, 0.0]
    samples = pd.DataFrame(
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
    violations = _runs(
        times, ~samples["com_velocity_inside"].to_numpy(bool), rows[:, 8], "com_velocity"
    )
    if has_zmp:
        zm = rows[:, 9]
        violations += _runs(times, np.isfinite(zm) & (zm < 0.0) | np.isneginf(zm), zm, "zmp")
    violations.sort(key=lambda v: (v.start, v.kind))
    settings = {
        "force_threshold": force_threshold,
        "move_tolerance": move_tolerance,
        "turn_tolerance": turn_tolerance,
        "com_tolerance": com_tolerance,
    }
    # The CoM's vertical acceleration, fitted over the log: -g for a falling robot, 0 with gravity off.
    accel = (
        float(np.polyfit(times, rows[:, 5], 1)[0])
        if len(times) > 2 and np.ptp(times) > 0
        else float("nan")
    )
    change = rows[-1, 3:6] - rows[0, 3:6]
    return LogCheck(
        scenario.name, samples, segments, violations, has_zmp, settings, loaded, accel, change, g
    )
