"""Push recovery (paper Exp. 2): impulsive pushes in every direction.

Both criteria predict each push's outcome before the trial; the trials then score them.

For every push both criteria predict the outcome **before the trial**, from the scenario alone:

- the CoM criterion: the post-push CoM velocity ``c0 + J u / m`` (pre-push velocity plus impulse
  over mass) lies in the CoM velocity area;
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
margin), so that a grid straddles the boundary in every direction.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from impact_balance.exceptions import SimulationError
from impact_balance.geometry.polygon import Polygon
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.control.registry import controller_class
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.studies.scores import MARGIN_GRID, confusion
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
    "PushOutcome",
    "PushPrediction",
    "PushTestResult",
    "boundary_impulse",
    "check_push_arguments",
    "push_test",
]

#: Default impulses (N s): for a 90 kg robot, CoM velocity changes of about 0.06 to 0.33 m/s.
DEFAULT_MAGNITUDES = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)
#: The predictions scored: each criterion before the trial, and read in the trial.
CRITERIA = ("com", "com_in_trial", "zmp", "zmp_in_trial")
#: Target share of all pushes predicted safe that fell (the margin study reports the smallest margin
#: reaching it).
SAFE_FELL_TARGET = 0.05


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
    """

    com_velocity: np.ndarray
    com_velocity_margin: float
    zmp: np.ndarray
    zmp_margin: float


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
        if criterion == "com":
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
            "reason": s["reason"],
            "detail": s["detail"],
            "events": s["events"],
            "outcome_time": s["outcome_time"],
            "com_criterion_safe": self.safe("com", margin, omega),
            "com_criterion_safe_in_trial": self.safe("com_in_trial", margin, omega),
            "zmp_criterion_safe": self.safe("zmp", margin, omega),
            "zmp_criterion_safe_in_trial": self.safe("zmp_in_trial", margin, omega),
            # Before the trial, in the area the score uses (with the margin): m/s, >= 0 inside.
            "com_velocity_margin": float(self.prediction.com_velocity_margin - omega * margin),
            "predicted_com_velocity": self.prediction.com_velocity.tolist(),
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

    @property
    def scored(self) -> list[PushOutcome]:
        """The pushes that count in the scores (their trial was not aborted)."""
        return [o for o in self.outcomes if o.scored]

    def scores(self, margin: float | None = None) -> dict[str, Any]:
        """Confusion of every criterion (:data:`CRITERIA`) at ZMP margin ``margin``.

        ``margin`` defaults to the result's.
        """
        margin = self.zmp_margin if margin is None else margin
        scored = self.scored
        fell = [o.fell for o in scored]
        return {
            c: confusion([o.safe(c, margin, self.omega) for o in scored], fell) for c in CRITERIA
        }

    def margin_study(self) -> dict[str, Any]:
        """Scores at several margins, and the smallest margin that makes each criterion safe.

        Scores at 0, the controller's margin and twice it, and the smallest margin (of
        :data:`MARGIN_GRID`) that brings each criterion's "predicted safe, fell" to
        :data:`SAFE_FELL_TARGET` or less.
        """
        own = self.controller_margin
        margins = sorted({0.0, own, 2 * own})
        smallest: dict[str, float | None] = {}
        out = {
            "margins": margins,
            "scores": {f"{m:g}": self.scores(m) for m in margins},
            "smallest_margin": smallest,
        }
        for c in CRITERIA:
            found = None
            for m in MARGIN_GRID:
                rate = self.scores(m)[c]["safe_fell_rate"]
                if rate is not None and rate <= SAFE_FELL_TARGET:
                    found = m
                    break
            smallest[c] = found
        return out

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
                    "first": {},
                },
            )
            row["pushes"] += 1
            row["fell"] += o.fell
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
        return {"outcomes": outcomes, "reasons": reasons}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``push-test --json``."""
        return {
            "scenario": self.scenario,
            "zmp_margin": self.zmp_margin,
            "controller_margin": self.controller_margin,
            "omega": self.omega,
            "pushes": [o.to_dict(self.zmp_margin, self.omega) for o in self.outcomes],
            "counts": self.counts(),
            "scores": self.scores(),
            "margin_study": self.margin_study(),
            "contact_breaks": self.contact_breaks(),
            "controller": self.controller,
            "outcome_criteria": self.criteria,
            "journal": self.journal,
            "reused_trials": self.reused,
            "wall_time": self.wall_time,
        }


def _body_height(setup: BalanceSetup, body: int) -> float:
    """Height of the pushed body's centre of mass at the start (m)."""
    sim = setup.sim
    sim.set_state(setup.start_configuration())
    mujoco.mj_forward(sim.model, sim.data)
    return float(sim.data.xipos[body][2])


def predict_push(setup: BalanceSetup, push: Push, body_height: float) -> PushPrediction:
    """The push's before-trial predictions (see the module docstring)."""
    a = setup.analysis
    areas, mass, g = a.areas, a.stance.mass, a.areas.gravity
    u = np.array([np.cos(push.direction), np.sin(push.direction)])
    c0 = np.asarray(a.scenario.com_velocity, dtype=float)
    velocity = c0 + push.magnitude * u / mass
    force = push.magnitude / push.duration * u
    zmp = a.stance.com[:2] + (body_height - areas.plane_height) * force / (mass * g)
    return PushPrediction(
        velocity,
        float(areas.com_velocity_area.margins(velocity)[0]),
        zmp,
        float(areas.zmp_area.margins(zmp)[0]),
    )


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
) -> PushTestResult:
    """Push the robot in evenly spaced directions and score both criteria.

    Pushes in ``directions`` directions at every magnitude (N s, or fractions ``relative`` of each
    direction's boundary impulse) for ``duration`` s; both criteria are scored at ``zmp_margin`` (m;
    default: the controller's own margin). Finished trials go to ``journal`` as they end, and trials
    it already holds are not run again.
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
    height = _body_height(setup, body_id)
    a = setup.analysis
    omega = float(a.areas.omega)
    own = controller_margin(options)
    journal = journal or TrialJournal(None, "")
    outcomes, reused = [], 0
    levels = list(relative if relative is not None else magnitudes or ())
    for level in levels:
        for k in range(directions):
            angle = 2 * np.pi * k / directions
            if relative is not None:
                J = float(level) * boundary_impulse(
                    a.areas.com_velocity_area, a.stance.mass, angle, a.scenario.com_velocity
                )
                if not (np.isfinite(J) and 0 < J <= 1000):
                    raise SimulationError(
                        "--relative",
                        level,
                        f"gives {J:g} N s at {np.rad2deg(angle):g} deg: "
                        "not in (0, 1000] N s (unbounded or empty area that way)",
                    )
            else:
                J = float(level)
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
                prediction=predict_push(setup, push, height),
                summary=entry["summary"],
                trajectory=entry["trajectory"],
            )
            outcomes.append(outcome)
            if progress:
                progress(outcome)
    controller = controller_class(setup.controller).trial_summary(
        options, setup.sim, setup.joints == "servo"
    )
    controller["armature"] = setup.sim.armature_source
    repair = setup.sim.inertia_repair
    controller["inertia_repair"] = None if repair is None else repair.to_dict()
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
    )
