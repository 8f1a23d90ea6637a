"""Push recovery (paper Exp. 2): impulsive pushes in every direction.

Both criteria predict each push's outcome before the trial; the trials then score them.

For every push both criteria predict the outcome **before the trial**, from the scenario alone:

- the CoM criterion: the post-push CoM velocity ``c0 + J u / m`` (pre-push velocity, zero: the
  trial starts at rest, plus impulse over mass) lies in the CoM velocity area;
- the ZMP criterion: the quasi-static ZMP while the push force ``F = J u / duration`` acts at the
  pushed body's centre of mass (height ``z_b``), ``c_xy + (z_b - h) F / (m g)``, lies in the ZMP
  support area.

They are also read from the trial, as a second column (``*_in_trial``): the measured CoM velocity
at the end of the push in the area, and the measured ZMP in the ZMP support area throughout the
push. Each prediction is made against the areas shrunk by a ZMP margin
(:mod:`impact_balance.balance.areas`); the trials themselves do not depend on it, so one set of
trials is scored at any margin.

Magnitudes are impulses in N s, or fractions of each direction's *boundary impulse* ``m r(u)`` (the
impulse that puts the predicted CoM velocity on the boundary of the CoM velocity area without
margin), so that a grid straddles the boundary in every direction. A *band* (:func:`band_levels`)
samples the fractions where the criterion decides densely (0.75 to 1.05 of the boundary in steps
of 0.03, say) plus a few far points; the scores are then also given on the band alone.

Every trial starts at rest, so the predictions start from a CoM at rest too (``c0 = 0``), whatever
the scenario's ``com_velocity``.

With the scenario's ``friction_scale`` below 1, every prediction (``com`` and ``paper_com``) uses
the areas of the contacts at that share of their friction
(:func:`~impact_balance.analysis.analyze.contact_model_areas`); the grid's boundary impulses stay
those of the contacts' own friction, so that the pushes do not move with a criterion setting.

``com`` is the project's default prediction; ``paper_com`` is the paper's CoM criterion. With the
scenario's ``angular_momentum_damping_time`` tau set, ``com`` counts the centroidal angular momentum
the push leaves, ``L = (p - c) x J u`` (p the pushed body's centre of mass, c the CoM): the
effective post-push CoM velocity ``c0 + (J u + S(L) / (h (1 + omega tau))) / m``,
``S(L) = (L_y, -L_x)``, must lie in the area (:mod:`impact_balance.impact.angular_momentum`);
without it the two are the same call. With a reach (``push_test(..., reach=True)``, ``push-test
--com-reach``), ``com`` also asks the capture to stay within the CoM's reach at constant height
(:mod:`impact_balance.balance.reach`). With the push's duration (``push_test(...,
finite_push=True)``, the default of both ``push_test`` and ``push-test``; ``finite_push=False``,
``push-test --no-finite-push`` predict an impulse), ``com`` predicts a push of constant force
``J u / T`` for its duration ``T`` with the ZMP held under the starting CoM, not an impulse: the
velocity of the impulse, ``J u / m``, is scaled by ``kappa = (exp(omega T) - 1) / (omega T)``
(:func:`~impact_balance.balance.lipm.finite_push_factor`) in every velocity the default tests
(the paper's and the effective one, in the area and against the reach), so that the area test
``c0 + kappa J u / m`` in the CoM velocity area is exactly the LIPM's DCM at the push's end,
``xi(T) = kappa J / (m omega) u`` from the starting CoM, in the ZMP support area (the CoM's
displacement during the push included). ``paper_com`` stays impulsive. Each criterion is
scored against the lenient outcome (fell) and the strict one (:mod:`.scores`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from impact_balance.balance.lipm import finite_push_factor
from impact_balance.balance.reach import ComReach, com_reach, reach_speed_limit
from impact_balance.exceptions import SimulationError
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.angular_momentum import angular_momentum_gain
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.control.registry import controller_class
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.studies.scores import FALSE_SAFE_TARGET, MARGIN_GRID, confusion
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    Push,
    controller_margin,
    run_balance_trial,
)
from impact_balance.sim.trials.result import TrialEntry, trajectory
from impact_balance.sim.trials.setup import push_body

__all__ = [
    "CRITERIA",
    "DEFAULT_MAGNITUDES",
    "START_COM_VELOCITY",
    "PushOutcome",
    "PushPrediction",
    "PushTestResult",
    "band_levels",
    "boundary_impulse",
    "check_band_arguments",
    "check_push_arguments",
    "push_test",
]

#: Default impulses (N s): for a 90 kg robot, CoM velocity changes of about 0.06 to 0.33 m/s.
DEFAULT_MAGNITUDES = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)
#: The predictions scored: each criterion before the trial, and read in the trial. ``com`` is the
#: project's default prediction, ``paper_com`` the paper's CoM criterion.
CRITERIA = ("com", "paper_com", "com_in_trial", "zmp", "zmp_in_trial")
#: The planar CoM velocity every push trial starts from (m/s): at rest; the predictions use it.
START_COM_VELOCITY = (0.0, 0.0)


def check_push_arguments(
    directions: int,
    magnitudes: Sequence[float] | None,
    duration: float,
    relative: Sequence[float] | None = None,
) -> None:
    """Refuse bad push-test arguments with one clear error naming the option."""
    if not (isinstance(directions, int) and 1 <= directions <= 360):
        raise SimulationError("--directions", directions, "must be an integer in [1, 360]")
    if magnitudes is not None and relative is not None:
        raise SimulationError(
            "--relative",
            list(relative),
            "give impulses (--magnitudes) or fractions of the boundary "
            "impulse (--relative), not both",
        )
    if magnitudes is not None and (
        not magnitudes or any(not (np.isfinite(m) and 0 < m <= 1000) for m in magnitudes)
    ):
        raise SimulationError("--magnitudes", list(magnitudes), "each must be in (0, 1000] N s")
    if relative is not None and (
        not relative or any(not (np.isfinite(f) and 0 < f <= 10) for f in relative)
    ):
        raise SimulationError(
            "--relative",
            list(relative),
            "each must be in (0, 10] (fractions of the boundary impulse)",
        )
    if not (np.isfinite(duration) and 0.001 <= duration <= 0.2):
        raise SimulationError(
            "--duration", duration, "must be in [0.001, 0.2] s (an impulsive push: 10-50 ms)"
        )


def check_band_arguments(
    band: Sequence[float] | None, step: float, far: Sequence[float] | None
) -> None:
    """Refuse a bad ``--band LO HI``, ``--band-step`` or ``--far`` with a clear error."""
    if band is None:
        if far is not None:
            raise SimulationError("--far", list(far), "needs --band (far points beside the band)")
        return
    lo, hi = (float(x) for x in band)
    if not (np.isfinite(lo) and np.isfinite(hi) and 0 < lo < hi <= 10):
        raise SimulationError("--band", [lo, hi], "must be 0 < LO < HI <= 10 (boundary fractions)")
    if not (np.isfinite(step) and 0 < step <= hi - lo + 1e-9):
        raise SimulationError("--band-step", step, f"must be in (0, {hi - lo:g}] (HI - LO)")
    if far is not None and any(not (np.isfinite(f) and 0 < f <= 10) for f in far):
        raise SimulationError("--far", list(far), "each must be in (0, 10] (boundary fractions)")


def band_levels(
    band: Sequence[float], step: float = 0.03, far: Sequence[float] = ()
) -> list[float]:
    """The boundary fractions of a band: ``LO, LO + step, ...`` up to ``HI``, then ``far``.

    Fractions are rounded to 1e-6 and kept once, in increasing order.

    Raises:
        SimulationError: A bad band, step or far point (naming the option).
    """
    check_band_arguments(band, step, list(far) or None)
    lo, hi = float(band[0]), float(band[1])
    count = int(np.floor((hi - lo) / step + 1e-9))
    levels = [lo + k * step for k in range(count + 1)]
    if hi - levels[-1] > 1e-9:
        levels.append(hi)
    return sorted({round(x, 6) for x in [*levels, *far]})


def boundary_impulse(
    area: Polygon, mass: float, direction: float, com_velocity: ArrayLike = (0.0, 0.0)
) -> float:
    """The impulse (N s) along ``direction`` that brings the CoM velocity to the area's boundary.

    The impulse puts ``com_velocity + J u / m`` (m/s) on the boundary of ``area``; it is 0 when
    ``com_velocity`` is outside, inf when the area is unbounded that way. ``direction`` is in rad.
    """
    G, h = area.halfplanes
    u = np.array([np.cos(direction), np.sin(direction)])
    slack = h - G @ np.asarray(com_velocity, dtype=float)
    if np.any(slack < 0):
        return 0.0
    rate = G @ u
    ahead = rate > 1e-12
    return float(mass * np.min(slack[ahead] / rate[ahead])) if ahead.any() else float("inf")


@dataclass(frozen=True)
class PushPrediction:
    """A push's before-trial predictions, as margins in the areas without margin.

    The push is safe at a ZMP margin ``M`` when ``com_velocity_margin >= omega M``, resp.
    ``zmp_margin >= M``.

    Attributes:
        com_velocity: Predicted post-push planar CoM velocity (m/s, world).
        com_velocity_margin: Its margin in the CoM velocity area (m/s, >= 0 inside).
        zmp: Predicted quasi-static ZMP while the push acts (m, world).
        zmp_margin: Its margin in the ZMP support area (m, >= 0 inside).
        angular_momentum: Predicted centroidal angular momentum the push leaves,
            ``(p - c) x J u`` (N m s, world axes, about the CoM).
        effective_com_velocity: The effective post-push CoM velocity that counts it (m/s,
            world xy; None when the scenario's ``angular_momentum_damping_time`` is unset).
        effective_com_velocity_margin: Its margin in the CoM velocity area (m/s; None likewise).
        reach: The CoM's reach at constant height (:mod:`impact_balance.balance.reach`), when
            the default prediction also asks the capture to stay within it; else None.
        area: The CoM velocity area without margin (m/s), for the reach check at any margin.
        finite_push_factor: kappa of the push's duration
            (:func:`~impact_balance.balance.lipm.finite_push_factor`) when the default predicts
            a push of finite duration; None for the impulsive push.
        finite_push_com_velocity: ``c0 + kappa J u / m`` (m/s, world xy; None likewise): the
            CoM velocity whose DCM from the starting CoM is the LIPM's at the push's end.
        finite_push_effective_com_velocity: The effective velocity with the impulse's part
            scaled likewise, ``c0 + (kappa J u + S(L) / (h (1 + omega tau))) / m`` (m/s; None
            without the angular momentum or the finite push).
        finite_push_margin: The default's margin with the finite push, the smaller of the two
            scaled velocities' margins in the CoM velocity area (m/s; None likewise).
    """

    com_velocity: np.ndarray
    com_velocity_margin: float
    zmp: np.ndarray
    zmp_margin: float
    angular_momentum: np.ndarray | None = None
    effective_com_velocity: np.ndarray | None = None
    effective_com_velocity_margin: float | None = None
    reach: ComReach | None = None
    area: Polygon | None = None
    finite_push_factor: float | None = None
    finite_push_com_velocity: np.ndarray | None = None
    finite_push_effective_com_velocity: np.ndarray | None = None
    finite_push_margin: float | None = None

    @property
    def default_velocities(self) -> tuple[np.ndarray | None, np.ndarray | None]:
        """The velocities the default tests (m/s): the paper's and the effective one.

        With the finite push, their kappa-scaled counterparts; the effective one is None
        without the angular momentum.
        """
        if self.finite_push_factor is not None:
            return self.finite_push_com_velocity, self.finite_push_effective_com_velocity
        return self.com_velocity, self.effective_com_velocity

    def reach_margin(self, margin: float, omega: float) -> float | None:
        """The reach-limited capture's margin at ZMP margin ``margin`` (m), m/s; None without.

        The reach speed limit (:func:`~impact_balance.balance.reach.reach_speed_limit`, in the
        area inset by ``omega margin``) minus the speed, the smaller over the default's
        velocities (:attr:`default_velocities`: the paper's and the effective post-push ones,
        kappa-scaled with the finite push): >= 0 when the capture stays within the CoM's reach.
        """
        if self.reach is None or self.area is None:
            return None
        area = self.area.inset(omega * margin) if margin > 0 else self.area
        worst = float("inf")
        for velocity in self.default_velocities:
            if velocity is None:
                continue
            speed = float(np.linalg.norm(velocity))
            if speed == 0.0:
                continue
            limit = 0.0 if area.is_empty else reach_speed_limit(area, omega, self.reach, velocity)
            worst = min(worst, limit - speed)
        return worst

    @property
    def default_com_velocity_margin(self) -> float:
        """The margin of the project's default prediction, m/s.

        With the angular momentum counted, the smaller of the paper's and the effective
        velocity's margins: the capture must hold whether the contacts remove the angular
        momentum with the damping time or never (see
        :class:`~impact_balance.criteria.com.ComCriterion`). With the finite push,
        :attr:`finite_push_margin`.
        """
        if self.finite_push_margin is not None:
            return self.finite_push_margin
        if self.effective_com_velocity_margin is None:
            return self.com_velocity_margin
        return min(self.com_velocity_margin, self.effective_com_velocity_margin)


@dataclass(kw_only=True)
class PushOutcome(TrialEntry):
    """One push: what was tried and predicted, and the trial's summary and trajectory."""

    push: Push
    relative: float | None
    prediction: PushPrediction

    def safe(self, criterion: str, margin: float, omega: float) -> bool:
        """Whether ``criterion`` calls the push safe at ZMP margin ``margin`` (m).

        Whether ``criterion`` (one of :data:`CRITERIA`) calls the push safe at ZMP margin ``margin``
        (m).
        """
        s, p = self.summary, self.prediction
        if criterion == "com":  # the project's default: with the angular momentum when set
            reach = p.reach_margin(margin, omega)
            return p.default_com_velocity_margin >= omega * margin and (
                reach is None or reach >= 0.0
            )
        if criterion == "paper_com":
            return p.com_velocity_margin >= omega * margin
        if criterion == "zmp":
            return p.zmp_margin >= margin
        if criterion == "com_in_trial":
            m = s.get("com_velocity_margin_at_end")
            return m is not None and m >= omega * margin
        m = s.get("min_zmp_margin_during")  # null: a foot carried nothing, no ZMP: not safe
        return m is not None and m >= margin

    def to_dict(self, margin: float, omega: float) -> dict[str, Any]:
        """JSON-ready, the criteria's calls at ZMP margin ``margin`` (m) with ``omega`` (1/s)."""
        s = self.summary
        return {
            "direction": float(self.push.direction),
            "direction_deg": float(np.rad2deg(self.push.direction)),
            "magnitude": float(self.push.magnitude),
            "relative": self.relative,
            "duration": float(self.push.duration),
            "outcome": s["outcome"],
            "fell": self.fell,
            "strict_fail": self.strict_fail,
            "reason": s["reason"],
            "strict_reason": s["strict_reason"],
            "detail": s["detail"],
            "events": s["events"],
            "outcome_time": s["outcome_time"],
            "com_criterion_safe": self.safe("com", margin, omega),
            "paper_com_criterion_safe": self.safe("paper_com", margin, omega),
            "com_criterion_safe_in_trial": self.safe("com_in_trial", margin, omega),
            "zmp_criterion_safe": self.safe("zmp", margin, omega),
            "zmp_criterion_safe_in_trial": self.safe("zmp_in_trial", margin, omega),
            # Before the trial, in the area the score uses (with the margin): m/s, >= 0 inside.
            "com_velocity_margin": float(self.prediction.com_velocity_margin - omega * margin),
            # The default prediction's margin without the margin (m/s; the effective one when the
            # angular momentum is counted): what a calibration compares with omega M.
            "predicted_com_velocity_margin": float(self.prediction.default_com_velocity_margin),
            "predicted_com_velocity": self.prediction.com_velocity.tolist(),
            # The reach-limited capture's margin at the score's margin (m/s; null without).
            "com_reach_margin": self.prediction.reach_margin(margin, omega),
            **_angular_momentum_keys(self.prediction, margin, omega),
            **_finite_push_keys(self.prediction, margin, omega),
            "predicted_zmp": self.prediction.zmp.tolist(),
            "trial": s,
        }


@dataclass
class PushTestResult:
    """Every push of a push test and how each criterion scores.

    The scores are at ``zmp_margin``, and against the margin.
    """

    scenario: str | None
    outcomes: list[PushOutcome]
    controller: dict[str, Any]
    criteria: dict[str, Any]
    setup: BalanceSetup
    zmp_margin: float
    controller_margin: float
    omega: float
    wall_time: float
    journal: str | None = None
    reused: int = 0
    band: tuple[float, float] | None = None
    body: str | None = None
    robot: str | None = None
    reach: ComReach | None = None
    #: The push's duration (s) and its kappa, when the default predicts a finite push.
    finite_push: tuple[float, float] | None = None

    @property
    def scored(self) -> list[PushOutcome]:
        """The pushes that count in the scores (their trial was not aborted)."""
        return [o for o in self.outcomes if o.scored]

    @property
    def in_band(self) -> list[PushOutcome]:
        """The scored pushes whose boundary fraction lies in the band (all of them without one)."""
        if self.band is None:
            return self.scored
        lo, hi = self.band
        return [
            o
            for o in self.scored
            if o.relative is not None and lo - 1e-9 <= o.relative <= hi + 1e-9
        ]

    def scores(
        self, margin: float | None = None, pushes: Sequence[PushOutcome] | None = None
    ) -> dict[str, Any]:
        """Confusion of every criterion (:data:`CRITERIA`) at ZMP margin ``margin``.

        Each criterion's :func:`~.scores.confusion` against the falls (lenient), with the one
        against the strict failures under ``strict``. ``margin`` defaults to the result's,
        ``pushes`` to every scored push.
        """
        margin = self.zmp_margin if margin is None else margin
        scored = self.scored if pushes is None else list(pushes)
        fell = [o.fell for o in scored]
        strict = [o.strict_fail for o in scored]
        out = {}
        for c in CRITERIA:
            safe = [o.safe(c, margin, self.omega) for o in scored]
            out[c] = {**confusion(safe, fell), "strict": confusion(safe, strict)}
        return out

    def margin_study(self) -> dict[str, Any]:
        """Scores at several margins, and the smallest margin that makes each criterion safe.

        Scores at 0, the controller's margin and twice it, and the smallest margin (of
        :data:`~.scores.MARGIN_GRID`) that brings each criterion's false-safe rate
        P(fell | predicted safe) to :data:`~.scores.FALSE_SAFE_TARGET` or less, for the lenient
        outcome (``smallest_margin``) and the strict one (``smallest_margin_strict``), over every
        scored push (``scope``): on a band alone, where every push may fall, a margin that calls
        nothing safe has no false-safe rate, and the far points are what it must still call safe.
        """
        own = self.controller_margin
        pushes = self.scored
        margins = sorted({0.0, own, 2 * own})
        grid = {m: self.scores(m, pushes) for m in MARGIN_GRID}
        smallest: dict[str, float | None] = {}
        strict: dict[str, float | None] = {}
        for c in CRITERIA:
            smallest[c] = _smallest(grid, c, strict=False)
            strict[c] = _smallest(grid, c, strict=True)
        return {
            "scope": "all",
            "target": FALSE_SAFE_TARGET,
            "margins": margins,
            "scores": {f"{m:g}": self.scores(m, pushes) for m in margins},
            "smallest_margin": smallest,
            "smallest_margin_strict": strict,
        }

    def contact_breaks(self) -> dict[str, Any]:
        """Pushes that broke a contact without a fall, and which contact first, by magnitude."""
        rows: dict[str, dict[str, Any]] = {}
        for o in self.scored:
            key = f"{o.push.magnitude:g}"
            row = rows.setdefault(
                key,
                {
                    "magnitude": o.push.magnitude,
                    "relative": o.relative,
                    "pushes": 0,
                    "contact_broken": 0,
                    "fell": 0,
                    "strict_fail": 0,
                    "first": {},
                },
            )
            row["pushes"] += 1
            row["fell"] += o.fell
            row["strict_fail"] += o.strict_fail
            if o.outcome == "contact_broken":
                row["contact_broken"] += 1
            events = sorted(o.summary["events"], key=lambda e: e["time"])
            if events:
                first = f"{events[0]['contact']} {events[0]['kind']}"
                row["first"][first] = row["first"].get(first, 0) + 1
        return {
            "total": sum(o.outcome == "contact_broken" for o in self.scored),
            "by_magnitude": list(rows.values()),
        }

    def counts(self) -> dict[str, Any]:
        """Outcomes counted, and the falls by reason."""
        outcomes = {
            k: sum(o.outcome == k for o in self.outcomes)
            for k in ("balanced", "contact_broken", "fell", "aborted")
        }
        reasons: dict[str, int] = {}
        for o in self.outcomes:
            if o.outcome in ("fell", "aborted"):
                key = f"{o.outcome}: {o.summary['reason']}"
                reasons[key] = reasons.get(key, 0) + 1
        strict = sum(o.strict_fail for o in self.scored)
        return {"outcomes": outcomes, "strict_fail": strict, "reasons": reasons}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``push-test --json``."""
        return {
            "scenario": self.scenario,
            "robot": self.robot,
            "body": self.body,
            "zmp_margin": self.zmp_margin,
            "controller_margin": self.controller_margin,
            "omega": self.omega,
            # The CoM's reach the default prediction keeps the capture within (null: not asked).
            "com_reach": None if self.reach is None else self.reach.to_dict(),
            # The push's duration in the default prediction: only with the option (a criterion
            # setting, the same for every stance; each push's kappa is in the push).
            **({} if self.finite_push is None else {"finite_push": True}),
            "pushes": [o.to_dict(self.zmp_margin, self.omega) for o in self.outcomes],
            "start_com_velocity": list(START_COM_VELOCITY),
            "counts": self.counts(),
            "scores_scope": "all pushes",
            "scores": self.scores(),
            "band": None if self.band is None else list(self.band),
            "band_scores": None if self.band is None else self.scores(pushes=self.in_band),
            "margin_study": self.margin_study(),
            "contact_breaks": self.contact_breaks(),
            "controller": self.controller,
            "outcome_criteria": self.criteria,
            "journal": self.journal,
            "reused_trials": self.reused,
            "wall_time": self.wall_time,
        }


def _smallest(grid: dict[float, dict[str, Any]], criterion: str, strict: bool) -> float | None:
    """The smallest margin of ``grid`` whose false-safe rate is at most the target (None: none)."""
    for m, scores in grid.items():
        k = scores[criterion]["strict"] if strict else scores[criterion]
        r = k["fell_given_safe"]["rate"]
        if r is not None and r <= FALSE_SAFE_TARGET:
            return m
    return None


def _body_position(setup: BalanceSetup, body: int) -> np.ndarray:
    """The pushed body's centre of mass at the start (m, world)."""
    sim = setup.sim
    sim.set_state(setup.start_configuration())
    mujoco.mj_forward(sim.model, sim.data)
    return np.array(sim.data.xipos[body], dtype=float)


def _impulse(setup: BalanceSetup, level: float, angle: float, relative: bool) -> float:
    """The push's impulse (N s): ``level`` itself, or that fraction of the boundary impulse."""
    if not relative:
        return level
    a = setup.analysis
    J = level * boundary_impulse(
        a.areas.com_velocity_area, a.stance.mass, angle, START_COM_VELOCITY
    )
    if not (np.isfinite(J) and 0 < J <= 1000):
        raise SimulationError(
            "--relative",
            level,
            f"gives {J:g} N s at {np.rad2deg(angle):g} deg: "
            "not in (0, 1000] N s (unbounded or empty area that way)",
        )
    return J


def predict_push(
    setup: BalanceSetup,
    push: Push,
    body_height: float,
    body_position: ArrayLike | None = None,
    reach: ComReach | None = None,
    finite_push: bool = False,
) -> PushPrediction:
    """The push's before-trial predictions (see the module docstring).

    ``body_position`` (m, world) is the pushed body's centre of mass at the start, where the push
    acts; without it, the point above the CoM at ``body_height`` (m). With ``reach``, the
    default prediction also asks the capture to stay within the CoM's reach. With
    ``finite_push``, the default predicts a push of ``push.duration`` (s): the impulse's
    velocity ``J u / m`` scaled by kappa (:func:`~impact_balance.balance.lipm.finite_push_factor`)
    in every velocity it tests.

    Raises:
        ScenarioError: With ``finite_push``, a push duration that kappa does not take.
    """
    a = setup.analysis
    # The criterion's areas, at the scenario's friction_scale (none: the analysis's).
    criterion = getattr(setup, "criterion_areas", None)
    areas = a.areas if criterion is None else criterion
    mass, g = a.stance.mass, a.areas.gravity
    u = np.array([np.cos(push.direction), np.sin(push.direction)])
    c0 = np.asarray(START_COM_VELOCITY, dtype=float)  # the trial starts at rest
    velocity = c0 + push.magnitude * u / mass
    force = push.magnitude / push.duration * u
    zmp = a.stance.com[:2] + (body_height - areas.plane_height) * force / (mass * g)
    com = np.asarray(a.stance.com, dtype=float)
    point = (
        np.array([com[0], com[1], body_height])
        if body_position is None
        else np.asarray(body_position, dtype=float)
    )
    L = np.cross(point - com, np.array([*(push.magnitude * u), 0.0]))
    tau = a.scenario.angular_momentum_damping_time
    effective = effective_margin = None
    held = np.zeros(2)
    if tau is not None:
        gain = angular_momentum_gain(float(areas.omega), g, tau)
        held = gain * np.array([L[1], -L[0]]) / mass
        effective = velocity + held
        effective_margin = float(areas.com_velocity_area.margins(effective)[0])
    finite: tuple[Any, ...] = (None, None, None, None)
    if finite_push:
        finite = _finite_push(areas.com_velocity_area, float(areas.omega), push, mass, held, tau)
    return PushPrediction(
        velocity,
        float(areas.com_velocity_area.margins(velocity)[0]),
        zmp,
        float(areas.zmp_area.margins(zmp)[0]),
        L,
        effective,
        effective_margin,
        reach,
        None if reach is None else areas.com_velocity_area,
        *finite,
    )


def _finite_push(
    area: Polygon, omega: float, push: Push, mass: float, held: np.ndarray, tau: float | None
) -> tuple[float, np.ndarray, np.ndarray | None, float]:
    """kappa, the scaled paper's and effective velocities (m/s), and the smaller margin (m/s).

    ``held`` is the angular momentum's term of the effective velocity (m/s), counted when
    ``tau`` is set.
    """
    kappa = finite_push_factor(omega, float(push.duration))
    u = np.array([np.cos(push.direction), np.sin(push.direction)])
    c0 = np.asarray(START_COM_VELOCITY, dtype=float)
    scaled = c0 + kappa * push.magnitude * u / mass
    margin = float(area.margins(scaled)[0])
    effective = None
    if tau is not None:
        effective = scaled + held
        margin = min(margin, float(area.margins(effective)[0]))
    return kappa, scaled, effective, margin


def _finite_push_keys(p: PushPrediction, margin: float, omega: float) -> dict[str, Any]:
    """The JSON keys of the finite push's prediction (none without the option)."""
    if p.finite_push_margin is None or p.finite_push_com_velocity is None:
        return {}
    return {
        "finite_push_factor": p.finite_push_factor,
        "predicted_finite_push_com_velocity": p.finite_push_com_velocity.tolist(),
        # The default's margin with the push's duration, at the score's margin (m/s).
        "finite_push_margin": float(p.finite_push_margin - omega * margin),
    }


def _angular_momentum_keys(p: PushPrediction, margin: float, omega: float) -> dict[str, Any]:
    """The JSON keys of the angular momentum a push leaves (predicted, and what it costs)."""
    out: dict[str, Any] = {
        "predicted_angular_momentum": None
        if p.angular_momentum is None
        else p.angular_momentum.tolist()
    }
    if p.effective_com_velocity is not None and p.effective_com_velocity_margin is not None:
        out["predicted_effective_com_velocity"] = p.effective_com_velocity.tolist()
        out["effective_com_velocity_margin"] = float(
            p.effective_com_velocity_margin - omega * margin
        )
    return out


def _reach_of(setup: BalanceSetup, reach: ComReach | bool) -> ComReach | None:
    """The reach the default prediction keeps the capture within: given, computed, or none."""
    if isinstance(reach, ComReach):
        return reach
    return com_reach(setup.analysis.stance) if reach else None


def _controller_summary(setup: BalanceSetup, options: BalanceTrialOptions) -> dict[str, Any]:
    """The controller's summary in ``push-test --json``: gains, armature, inertia repair."""
    controller = controller_class(setup.controller).trial_summary(
        options, setup.sim, setup.joints == "servo"
    )
    controller["armature"] = setup.sim.armature_source
    # The gains from the robot's rules (they differ between stances of one robot) or as given.
    controller["gains_from_robot"] = bool(options.robot_gains)
    repair = setup.sim.inertia_repair
    controller["inertia_repair"] = None if repair is None else repair.to_dict()
    return controller


def push_test(
    scenario: Scenario | str,
    directions: int = 16,
    magnitudes: Sequence[float] | None = None,
    duration: float = 0.05,
    body: str | None = None,
    options: BalanceTrialOptions | None = None,
    progress: Callable[[PushOutcome], None] | None = None,
    setup: BalanceSetup | None = None,
    relative: Sequence[float] | None = None,
    zmp_margin: float | None = None,
    journal: TrialJournal | None = None,
    band: Sequence[float] | None = None,
    reach: ComReach | bool = False,
    finite_push: bool = True,
) -> PushTestResult:
    """Push the robot in evenly spaced directions and score both criteria.

    Pushes in ``directions`` directions at every magnitude (N s, or fractions ``relative`` of each
    direction's boundary impulse) for ``duration`` s; both criteria are scored at ``zmp_margin`` (m;
    default: the controller's own margin). Finished trials go to ``journal`` as they end, and trials
    it already holds are not run again. ``band`` (``(LO, HI)``, fractions of the boundary impulse,
    with ``relative`` from :func:`band_levels`) adds the scores of the pushes in it. ``reach``
    (True: :func:`.com_reach` of the stance) keeps the default's capture within the CoM's reach.
    ``finite_push`` (the default) makes the default predict a push of ``duration``, not an
    impulse (kappa, :func:`~impact_balance.balance.lipm.finite_push_factor`); with
    ``finite_push=False`` the predictions are the impulsive ones.
    """
    wall0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if magnitudes is None and relative is None:
        magnitudes = DEFAULT_MAGNITUDES
    check_push_arguments(directions, magnitudes, duration, relative)
    options = options or BalanceTrialOptions()
    setup = setup or BalanceSetup.create(scenario, "servo", options)
    body_id = push_body(setup.sim, body)
    position = _body_position(setup, body_id)
    height = float(position[2])
    a = setup.analysis
    omega = float(a.areas.omega)
    own = controller_margin(options)
    limit = _reach_of(setup, reach)
    journal = journal or TrialJournal(None, "")
    outcomes, reused = [], 0
    levels = list(relative if relative is not None else magnitudes or ())
    for level in levels:
        for k in range(directions):
            angle = 2 * np.pi * k / directions
            J = _impulse(setup, float(level), angle, relative is not None)
            push = Push(angle, J, duration, options.settle, body)
            key = {
                "direction": round(angle, 9),
                "magnitude": round(J, 9),
                "duration": duration,
                "body": body,
            }
            entry = journal.get(key)
            if entry is None:
                result = run_balance_trial(setup, push=push, options=options)
                entry = {
                    "summary": result.summary(),
                    "trajectory": trajectory(
                        result, push.start - 0.02, push.start + push.duration + 0.5
                    ),
                }
                journal.add(key, entry)
            else:
                reused += 1
            outcome = PushOutcome(
                push=push,
                relative=None if relative is None else float(level),
                prediction=predict_push(setup, push, height, position, limit, finite_push),
                summary=entry["summary"],
                trajectory=entry["trajectory"],
            )
            outcomes.append(outcome)
            if progress:
                progress(outcome)
    controller = _controller_summary(setup, options)
    return PushTestResult(
        scenario.name,
        outcomes,
        controller,
        options.criteria.to_dict(),
        setup,
        own if zmp_margin is None else float(zmp_margin),
        own,
        omega,
        time.perf_counter() - wall0,
        None if journal.path is None else str(journal.path),
        reused,
        None if band is None else (float(band[0]), float(band[1])),
        mujoco.mj_id2name(setup.sim.model, mujoco.mjtObj.mjOBJ_BODY, body_id),
        a.stance.robot.name,
        limit,
        (float(duration), finite_push_factor(omega, duration)) if finite_push else None,
    )
