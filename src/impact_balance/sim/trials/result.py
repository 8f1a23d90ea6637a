"""What one balance trial measured (:class:`BalanceTrialResult`) and its JSON summary.

Every number of the summary is finite or ``null``; a ``null`` comes with its reason in the
summary's ``nulls`` (``{field: reason}``), so that one undefined quantity (a ZMP while the
contacts carry no vertical force, say) never ends a run.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from numpy.typing import ArrayLike

from impact_balance.sim.trials.outcomes import ContactEvent, OutcomeName

__all__ = [
    "BalanceTrialResult",
    "ImpactMeasurement",
    "TrialEntry",
    "finite_or_null",
    "trajectory",
]

_FloatArray = npt.NDArray[np.float64]


def finite_or_null(
    nulls: dict[str, str], name: str, value: ArrayLike | None, reason: str
) -> float | list[Any] | None:
    """``value`` as a float (or a list of floats) when finite, else None (reason in ``nulls``)."""
    if value is None:
        nulls[name] = reason
        return None
    array = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(array)):
        nulls[name] = reason
        return None
    return array.tolist() if array.ndim else float(array)


@dataclass
class ImpactMeasurement:
    """The impact as the simulation made it (SI units, world frame).

    Attributes:
        contact_time: First contact of the impact point with the surface (s).
        approach_speed: Normal approach speed of the impact point just before it (m/s): the measured
            speed.
        window: (start, end) of the impact (s): from the step before the contact to the separation,
            or ``max_duration`` later if the point stays.
        impulse: Impulse on the robot at the impact point over the window (N s, 3).
        sustained_impulses: Impulse on the robot at each sustained contact over the window, its
            force before the contact subtracted (N s, k x 3): what the paper neglects.
        com_velocity_before, com_velocity_after: Planar CoM velocity at the window's ends (m/s).
        hold: The rigid-impact hold (:meth:`RigidImpactHold.to_dict`), or None.
    """

    contact_time: float
    approach_speed: float
    window: tuple[float, float]
    impulse: np.ndarray
    sustained_impulses: np.ndarray
    com_velocity_before: np.ndarray
    com_velocity_after: np.ndarray
    hold: dict[str, Any] | None = None

    @property
    def com_velocity_jump(self) -> _FloatArray:
        """Planar CoM velocity change across the window (m/s)."""
        jump: _FloatArray = self.com_velocity_after - self.com_velocity_before
        return jump

    def to_dict(self, contact_names: list[str]) -> dict[str, Any]:
        """JSON-ready (strict: null for what is not finite, ``nulls`` giving why)."""
        nulls: dict[str, str] = {}
        out = {
            "contact_time": self.contact_time,
            "approach_speed_measured": finite_or_null(
                nulls, "approach_speed_measured", self.approach_speed, "not measured"
            ),
            "window": [float(x) for x in self.window],
            "impulse": finite_or_null(nulls, "impulse", self.impulse, "not finite"),
            "sustained_impulses": {
                name: finite_or_null(nulls, f"sustained_impulses.{name}", imp, "not finite")
                for name, imp in zip(contact_names, self.sustained_impulses, strict=False)
            },
            "com_velocity_before": finite_or_null(
                nulls, "com_velocity_before", self.com_velocity_before, "not finite"
            ),
            "com_velocity_after": finite_or_null(
                nulls, "com_velocity_after", self.com_velocity_after, "not finite"
            ),
            "com_velocity_jump": finite_or_null(
                nulls, "com_velocity_jump", self.com_velocity_jump, "not finite"
            ),
            "rigid_hold": self.hold,
        }
        if nulls:
            out["nulls"] = nulls
        return out


@dataclass
class BalanceTrialResult:
    """Outcome and measurements of one trial (SI units, world frame).

    ``series`` holds the per-control-step arrays: ``time``, ``zmp`` (measured, k x 2; NaN while the
    contacts carry no vertical force), ``zmp_desired``, ``com`` (k x 3), ``com_velocity`` (k x 3),
    ``dcm`` (k x 2), ``zmp_margin`` (m, >= 0 inside the ZMP support area without margin),
    ``com_velocity_margin`` (m/s, >= 0 inside the CoM velocity area without margin).

    Attributes:
        outcome, reason, outcome_time, detail, events: see :mod:`.outcomes`.
        disturbance_time, disturbance_end: When the impact began (first contact) or the push began
            and ended (s).
        approach_speed: Commanded approach speed (m/s), impacts only.
        impact: What the impact measured (:class:`ImpactMeasurement`), impacts that touched only.
        com_velocity_at_end: Planar CoM velocity when the disturbance ended (m/s): after the impact
            window, or at the end of the push.
        com_velocity_margin_at_end: Its margin in the CoM velocity area without margin (m/s, >= 0
            inside).
        min_com_velocity_margin: The worst margin of the CoM velocity after the disturbance (m/s).
        min_zmp_margin_during: The worst margin of the measured ZMP during the push (m), None if
            undefined.
        max_tilt, max_slip, max_trunk_tilt, max_drop: Largest contact tilt (rad) and slip (m), base
            tilt (rad) and drop (m) seen.
        angular_momentum_at_end: Angular momentum about the CoM when the disturbance ended (N m s,
            world): what the LIPM leaves out (a push above the CoM leaves some).
        angular_momentum_removed: Its decrements after the disturbance until the trial ended or
            fell, each weighted by ``exp(-omega (t - end))`` (N m s, world; see
            :mod:`.angular_momentum_removal`): over ``angular_momentum_at_end`` per axis, the
            share of the immediate removal's capture cost the controller spent. None before
            the disturbance ended.
        strict_fail, strict_reason: Whether the trial failed strictly (fell, or a contact broke
            beyond the strict bounds of :mod:`.outcomes`) and why.
        stance_changed_time: When the contacts first went beyond the strict bounds (s), None if
            never: the ``dcm_escaped`` check stops there.
        max_unloaded: The longest time a loaded contact carried (almost) nothing after the
            disturbance (s).
        sim_time, wall_time: Simulated and wall-clock time (s).
    """

    outcome: str
    reason: str | None
    outcome_time: float | None
    detail: str
    events: tuple[ContactEvent, ...]
    disturbance_time: float | None
    disturbance_end: float | None
    approach_speed: float | None = None
    impact: ImpactMeasurement | None = None
    com_velocity_at_end: np.ndarray | None = None
    com_velocity_margin_at_end: float | None = None
    min_com_velocity_margin: float | None = None
    min_zmp_margin_during: float | None = None
    max_tilt: float = 0.0
    max_slip: float = 0.0
    max_trunk_tilt: float = 0.0
    max_drop: float = 0.0
    sim_time: float = 0.0
    wall_time: float = 0.0
    angular_momentum_at_end: np.ndarray | None = None
    angular_momentum_removed: np.ndarray | None = None
    strict_fail: bool = False
    strict_reason: str | None = None
    stance_changed_time: float | None = None
    max_unloaded: float = 0.0
    contact_names: tuple[str, ...] = ()
    series: dict[str, np.ndarray] = field(default_factory=dict)
    log: pd.DataFrame | None = None

    @property
    def fell(self) -> bool:
        """Whether the outcome is ``fell``."""
        return self.outcome == "fell"

    @property
    def aborted(self) -> bool:
        """Whether the outcome is ``aborted``."""
        return self.outcome == "aborted"

    @property
    def approach_speed_measured(self) -> float | None:
        """The impact point's approach speed just before the contact (m/s), None without one."""
        return None if self.impact is None else self.impact.approach_speed

    def summary(self) -> dict[str, Any]:
        """JSON-ready summary (no series, no log): finite numbers or null, ``nulls`` giving why."""
        nulls: dict[str, str] = {}
        out = {
            "outcome": self.outcome,
            "fell": self.fell,
            "strict_fail": bool(self.strict_fail),
            "reason": self.reason,
            "strict_reason": self.strict_reason,
            "outcome_time": finite_or_null(nulls, "outcome_time", self.outcome_time, "no event"),
            "detail": self.detail,
            "events": [e.to_dict() for e in self.events],
            "disturbance_time": finite_or_null(
                nulls, "disturbance_time", self.disturbance_time, "no disturbance"
            ),
            "approach_speed": None if self.approach_speed is None else float(self.approach_speed),
            "approach_speed_measured": finite_or_null(
                nulls,
                "approach_speed_measured",
                self.approach_speed_measured,
                "no impact" if self.approach_speed is None else "no contact",
            ),
            "com_velocity_at_end": finite_or_null(
                nulls,
                "com_velocity_at_end",
                self.com_velocity_at_end,
                "the disturbance did not end",
            ),
            "com_velocity_margin_at_end": finite_or_null(
                nulls,
                "com_velocity_margin_at_end",
                self.com_velocity_margin_at_end,
                "the disturbance did not end",
            ),
            "worst_com_velocity_margin": finite_or_null(
                nulls,
                "worst_com_velocity_margin",
                self.min_com_velocity_margin,
                "no sample after the disturbance",
            ),
            "min_zmp_margin_during": finite_or_null(
                nulls,
                "min_zmp_margin_during",
                self.min_zmp_margin_during,
                "the contacts carried no vertical force (ZMP undefined)",
            ),
            "angular_momentum_at_end": finite_or_null(
                nulls,
                "angular_momentum_at_end",
                self.angular_momentum_at_end,
                "the disturbance did not end",
            ),
            "angular_momentum_removed": finite_or_null(
                nulls,
                "angular_momentum_removed",
                self.angular_momentum_removed,
                "the disturbance did not end before the trial did",
            ),
            "max_tilt_deg": float(np.rad2deg(self.max_tilt)),
            "max_slip": float(self.max_slip),
            "max_trunk_tilt_deg": float(np.rad2deg(self.max_trunk_tilt)),
            "max_drop": float(self.max_drop),
            "max_unloaded": float(self.max_unloaded),
            "stance_changed_time": finite_or_null(
                nulls,
                "stance_changed_time",
                self.stance_changed_time,
                "the contacts stayed within the strict bounds (the DCM was checked throughout)",
            ),
            "sim_time": float(self.sim_time),
            "wall_time": float(self.wall_time),
        }
        if self.impact is not None:
            out["impact"] = self.impact.to_dict(list(self.contact_names))
        if nulls:
            out["nulls"] = nulls
        return out


def trajectory(
    result: BalanceTrialResult, start: float, stop: float, every: int = 2
) -> dict[str, Any]:
    """The trial's CoM velocity, ZMP and DCM between ``start`` and ``stop`` (s), as plain lists.

    Every ``every``-th control step; a ZMP that is undefined is null. What the figures draw.
    """
    s = result.series
    if not len(s.get("time", ())):
        return {"time": [], "com_velocity": [], "zmp": [], "dcm": []}
    t = s["time"]
    keep = np.flatnonzero((t >= start - 1e-9) & (t <= stop + 1e-9))[::every]

    def rows(values: _FloatArray) -> list[list[float] | None]:
        return [[float(x) for x in row] if np.all(np.isfinite(row)) else None for row in values]

    return {
        "time": [float(x) for x in t[keep]],
        "com_velocity": rows(s["com_velocity"][keep][:, :2]),
        "zmp": rows(s["zmp"][keep]),
        "dcm": rows(s["dcm"][keep]),
    }


@dataclass
class TrialEntry:
    """A finished trial as the commands (and the journal) keep it.

    Its JSON ``summary`` (:meth:`BalanceTrialResult.summary`) and a short ``trajectory``
    (:func:`trajectory`) for the figures.
    """

    summary: dict[str, Any]
    trajectory: dict[str, Any] = field(default_factory=dict)

    @property
    def outcome(self) -> OutcomeName:
        """The trial's outcome."""
        outcome: OutcomeName = self.summary["outcome"]
        return outcome

    @property
    def fell(self) -> bool:
        """Whether the outcome is ``fell``."""
        return self.outcome == "fell"

    @property
    def strict_fail(self) -> bool:
        """Whether the trial fell or broke a contact beyond the strict bounds.

        A summary without ``strict_fail`` (made by hand, without the strict outcome) counts its
        falls only.
        """
        return bool(self.summary.get("strict_fail", self.fell))

    @property
    def scored(self) -> bool:
        """Aborted trials test nothing: they are left out of brackets and scores."""
        return self.outcome != "aborted"
