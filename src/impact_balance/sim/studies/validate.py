"""Empirical fall threshold of an impact (paper Exp. 1), in measured approach speed.

:func:`validate` runs balance trials (:func:`~.balance_trial.run_balance_trial`) at increasing
commanded approach speeds until the robot falls, then bisects the commanded speed until the
bracket ``[stood, fell]`` is within a relative tolerance (5 %). The bracket is reported in the
**measured** approach speed at first contact (the commanded one beside it): ``survived`` is the
fastest measured speed that did not fall below the slowest that fell. Only ``fell`` counts as a
fall (the lenient outcome). Two more thresholds are then bisected to the same tolerance, from the
trials already run: the **strict** failure (fell, or a contact broke beyond the strict bounds of
:mod:`~impact_balance.sim.trials.outcomes`; ``strict_failed``) and the **first contact break**
(any contact event, fell or not). Aborted trials (the impact point never reached the surface, or
something went wrong before the contact) close a search on their side and are left out.

Beside the brackets: the maximum contact velocity by the CoM criterion and by the ZMP criterion,
each with both inertia models (``composite`` and ``joint_space``), without margin and with the
scoring ZMP margin; the project's default (``default``: the CoM criterion with the scenario's
inertia model, the scoring ZMP margin and the scenario's velocity margin, the maximum the governor
caps at); and per trial the CoM criterion's call at the measured speed (safe when the measured
speed is at most the maximum: a prediction made before the trial, evaluated at the speed the
trial reached) and in the trial (the measured post-impact CoM velocity in the area). Every trial
starts at rest, so every prediction is made from a CoM at rest (the scenario's ``com_velocity``
is replaced by zero).

The **verdict** (:func:`fall_verdict`) compares the fall bracket in measured speed,
``(survived, fell]``, with the prediction ``default``: ``fall_over_predicted`` is
``[survived / default, fell / default]`` (the low end 0 when no trial stood below the fall, the
high end None when none fell), and the verdict is ``within`` when the prediction lies in the
bracket (``survived <= default <= fell``), ``optimistic`` by ``1 - fell / default`` when the robot
fell below the prediction, ``conservative`` by ``survived / default - 1`` when it stood above it,
and ``inconclusive`` when no trial fell (the bracket is open above; the fastest measured speed is
named) or there is no prediction.

With the CoM's reach (``validate(..., com_reach=True)``, ``validate --com-reach``), the reach of
the scenario's stance is computed once before the trials
(:func:`~impact_balance.analysis.reach.reach_answer`, the analysis of ``default``: the scoring ZMP
margin, a CoM at rest), and the prediction the verdict compares with is the default's maximum
contact velocity within reach (``predicted.com_reach.max_contact_velocity``); each trial's
``com_reach_safe`` calls its measured speed against it. The search is unchanged (it starts at the
CoM criterion's prediction without margin).

With the held-stance impact model (``validate(..., impact_model="held-stance")``,
``validate --impact-model held-stance``), its maximum contact velocity
(:func:`~impact_balance.analysis.held_stance.held_stance_max_contact_velocity`: the composite
model, the scoring ZMP margin, a CoM at rest; the paper's answer where its fixed point is not
reached) is computed once before the trials and kept in ``predicted.held_stance``; each trial's
``held_stance_safe`` calls its measured speed against it. The search and the verdict are
unchanged.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from impact_balance.analysis.analyze import analyze
from impact_balance.analysis.held_stance import HeldStanceLimit, held_stance_max_contact_velocity
from impact_balance.analysis.reach import ReachAnswer, reach_answer
from impact_balance.analysis.result import Analysis
from impact_balance.balance.reach import ReachOptions
from impact_balance.exceptions import SimulationError
from impact_balance.impact import IMPACT_MODELS
from impact_balance.impact.model import INERTIA_MODELS
from impact_balance.json_values import json_number
from impact_balance.ranges import check_tolerance
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.control.registry import controller_class
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    controller_margin,
    run_balance_trial,
)
from impact_balance.sim.trials.outcomes import OutcomeName
from impact_balance.sim.trials.result import TrialEntry, trajectory

__all__ = [
    "IMPACT_MODELS",
    "INERTIA_MODELS",
    "TrialTest",
    "ValidationProgress",
    "ValidationResult",
    "ValidationTrial",
    "default_prediction",
    "fall_verdict",
    "held_stance_prediction",
    "predictions",
    "validate",
]


def predictions(scenario: Scenario, zmp_margin: float = 0.0) -> dict[str, dict[str, float | None]]:
    """Maximum contact velocity by each criterion and inertia model.

    Maximum contact velocity (m/s; None if unbounded) by each criterion and inertia model, with the
    ZMP support area shrunk by ``zmp_margin`` (m).
    """
    out: dict[str, dict[str, float | None]] = {"com_criterion": {}, "zmp_criterion": {}}
    impact = scenario.impact
    if impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact")
    for inertia in INERTIA_MODELS:
        variant = scenario.model_copy(
            update={
                "impact": impact.model_copy(update={"inertia": inertia}),
                "zmp_margin": float(zmp_margin),
                "com_velocity": (0.0, 0.0),  # the trials start at rest
            }
        )
        answer = analyze(variant).impact
        if answer is None:
            raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact")
        out["com_criterion"][inertia] = json_number(answer.max_contact_velocity)
        out["zmp_criterion"][inertia] = json_number(answer.zmp_max_contact_velocity)
    return out


def default_prediction(scenario: Scenario, zmp_margin: float) -> float | None:
    """The project's default maximum contact velocity (m/s; None if unbounded): the governor's cap.

    The CoM criterion with the scenario's inertia model, velocity margin and angular momentum
    damping time (:attr:`~impact_balance.analysis.result.ImpactAnswer.default`), the ZMP support
    area shrunk by ``zmp_margin`` (m), from a CoM at rest (the trials start at rest).
    """
    answer = _default_analysis(scenario, zmp_margin).impact
    assert answer is not None  # _default_analysis refuses a scenario without an impact
    return json_number(answer.default.max_contact_velocity)  # with the angular momentum when set


def _default_analysis(scenario: Scenario, zmp_margin: float) -> Analysis:
    """What :func:`default_prediction` answers from: ZMP margin ``zmp_margin`` (m), CoM at rest."""
    if scenario.impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact")
    variant = scenario.model_copy(
        update={"zmp_margin": float(zmp_margin), "com_velocity": (0.0, 0.0)}
    )
    analysis = analyze(variant)
    if analysis.impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact")
    return analysis


def held_stance_prediction(scenario: Scenario, zmp_margin: float) -> HeldStanceLimit:
    """The held-stance model's maximum contact velocity (m/s) before the trials.

    :func:`~impact_balance.analysis.held_stance.held_stance_max_contact_velocity` of the
    scenario with the composite inertia model, the ZMP support area shrunk by ``zmp_margin``
    (m), the scenario's velocity margin and a CoM at rest (the trials start at rest). Its
    fallback is then the CoM criterion's composite answer with that margin.
    """
    impact = scenario.impact
    if impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact")
    variant = scenario.model_copy(
        update={"impact": impact.model_copy(update={"inertia": "composite"})}
    )
    return held_stance_max_contact_velocity(_default_analysis(variant, zmp_margin))


@dataclass(kw_only=True)
class ValidationTrial(TrialEntry):
    """One trial of the search: commanded speed, summary and CoM velocity trajectory."""

    speed: float

    @property
    def measured(self) -> float | None:
        """The approach speed measured at the contact (m/s), None without one."""
        measured: float | None = self.summary.get("approach_speed_measured")
        return measured


def _measured(trial: ValidationTrial) -> float:
    """The measured approach speed (m/s) of a scored trial (scored trials have one)."""
    measured = trial.measured
    assert measured is not None
    return measured


#: Whether a trial failed, for a threshold search (fell, failed strictly, broke a contact).
TrialTest = Callable[[ValidationTrial], bool]


def _fell(trial: ValidationTrial) -> bool:
    return trial.fell


def _strict(trial: ValidationTrial) -> bool:
    return trial.strict_fail


def _broke(trial: ValidationTrial) -> bool:
    return bool(trial.summary["events"])


def _threshold(trials: list[ValidationTrial], failed: TrialTest) -> dict[str, Any]:
    """The slowest measured speed that ``failed`` and the fastest below it that did not (m/s).

    Both None when not found; the commanded speeds beside them.
    """
    bad = [t for t in trials if failed(t)]
    lowest = min(bad, key=_measured) if bad else None
    good = [t for t in trials if not failed(t)]
    below = [t for t in good if lowest is None or _measured(t) < _measured(lowest)]
    highest = max(below, key=_measured) if below else None
    return {
        "failed": None if lowest is None else lowest.measured,
        "stood": None if highest is None else highest.measured,
        "failed_commanded": None if lowest is None else lowest.speed,
        "stood_commanded": None if highest is None else highest.speed,
    }


def fall_verdict(
    survived: float | None,
    fell: float | None,
    predicted: float | None,
    fastest: float | None = None,
) -> dict[str, Any]:
    """The fall bracket over the prediction, and the verdict (see the module docstring).

    Args:
        survived: Fastest measured approach speed that stood below the slowest fall, m/s (None:
            none stood).
        fell: Slowest measured approach speed that fell, m/s (None: none fell).
        predicted: The predicted maximum contact velocity, m/s (None: unbounded or unknown).
        fastest: Fastest measured approach speed of any scored trial, m/s (named when no trial
            fell).

    Returns:
        ``predicted``; ``fall_over_predicted`` (``low``, ``high``: the bracket's ends over the
        prediction, None where undefined); ``verdict`` (``within``, ``optimistic``,
        ``conservative`` or ``inconclusive``); ``by`` (the relative error, a fraction, for
        optimistic and conservative, else None); ``text`` (one line).
    """
    out: dict[str, Any] = {
        "predicted": predicted,
        "fall_over_predicted": {"low": None, "high": None},
        "verdict": "inconclusive",
        "by": None,
    }
    if predicted is None or not predicted > 0.0:
        return {**out, "text": "inconclusive: no finite prediction to compare with"}
    low = 0.0 if survived is None else survived / predicted
    high = None if fell is None else fell / predicted
    out["fall_over_predicted"] = {"low": low, "high": high}
    if high is None:
        up_to = "-" if fastest is None else f"{fastest:.3f} m/s ({fastest / predicted:.2f} x)"
        return {**out, "text": f"inconclusive: no fall up to {up_to}"}
    if high < 1.0:
        by = 1.0 - high
        text = f"optimistic by {100 * by:.0f} %: fell at {high:.2f} x the prediction"
        return {**out, "verdict": "optimistic", "by": by, "text": text}
    if low > 1.0:
        by = low - 1.0
        text = f"conservative by {100 * by:.0f} %: stood at {low:.2f} x the prediction"
        return {**out, "verdict": "conservative", "by": by, "text": text}
    return {**out, "verdict": "within", "text": "prediction within the bracket"}


@dataclass
class ValidationResult:
    """Predictions beside the empirical bracket; ``to_dict()`` is ``validate --json``."""

    scenario: str | None
    joints: str
    rigid_impact: bool
    predicted: dict[str, Any]
    predicted_with_margin: dict[str, Any]
    zmp_margin: float
    omega: float
    trials: list[ValidationTrial]
    controller: dict[str, Any]
    outcome_criteria: dict[str, Any]
    tolerance: float
    max_speed: float
    wall_time: float = 0.0
    journal: str | None = None
    reused: int = 0
    extra: dict[str, Any] = field(default_factory=dict)
    default: float | None = None
    reach: ReachAnswer | None = None
    held_stance: HeldStanceLimit | None = None

    @property
    def scored_against(self) -> float | None:
        """The prediction the verdict compares with (m/s; None if unbounded).

        ``default``, or with the CoM's reach its maximum contact velocity within reach.
        """
        if self.reach is None:
            return self.default
        return json_number(self.reach.max_contact_velocity)

    @property
    def scored(self) -> list[ValidationTrial]:
        """The trials that count in the bracket (not aborted, approach speed measured)."""
        return [t for t in self.trials if t.scored and t.measured is not None]

    def bracket(self) -> dict[str, Any]:
        """The bracket in measured and commanded approach speed (see the module docstring)."""
        scored = self.scored
        fell = [t for t in scored if t.fell]
        stood = [t for t in scored if not t.fell]
        lowest_fall = min(fell, key=_measured) if fell else None
        below = [t for t in stood if lowest_fall is None or _measured(t) < _measured(lowest_fall)]
        survived = max(below, key=_measured) if below else None
        monotonic = not (
            lowest_fall is not None
            and stood
            and max(_measured(t) for t in stood) > _measured(lowest_fall)
        )
        fell_c = min((t.speed for t in fell), default=None)
        stood_c = max((t.speed for t in stood if fell_c is None or t.speed < fell_c), default=None)
        strict = _threshold(scored, _strict)
        return {
            "survived": None if survived is None else survived.measured,
            "fell": None if lowest_fall is None else lowest_fall.measured,
            "survived_commanded": stood_c,
            "fell_commanded": fell_c,
            "monotonic": monotonic,
            "fastest_measured": max((_measured(t) for t in scored), default=None),
            "strict_failed": strict["failed"],
            "strict_stood": strict["stood"],
            "strict_failed_commanded": strict["failed_commanded"],
            "strict_stood_commanded": strict["stood_commanded"],
            "first_contact_break": self.first_contact_break(),
        }

    def first_contact_break(self) -> dict[str, Any] | None:
        """The contact-break threshold, bisected (see the module docstring); None: no break.

        ``measured``: the slowest measured speed with a contact event; ``no_break_below``: the
        fastest measured speed below it without one (None if none was found); the commanded
        speeds, the trial's outcome and its first event (``contact``, ``kind``, ``time``,
        ``value``) beside them.
        """
        scored = self.scored
        found = _threshold(scored, _broke)
        if found["failed"] is None:
            return None
        first = min((t for t in scored if _broke(t)), key=_measured)
        event = min(first.summary["events"], key=lambda e: e["time"])
        return {
            "measured": found["failed"],
            "no_break_below": found["stood"],
            "commanded": found["failed_commanded"],
            "no_break_below_commanded": found["stood_commanded"],
            "outcome": first.outcome,
            **event,
        }

    def contact_break(self) -> dict[str, Any] | None:
        """The slowest trial that broke a contact (fell or not) and its first event.

        The slowest trial (measured speed) that broke a contact (fell or not) and its first event.
        """
        broken = [t for t in self.scored if t.summary["events"]]
        if not broken:
            return None
        first = min(broken, key=_measured)
        event = min(first.summary["events"], key=lambda e: e["time"])
        return {
            "measured": first.measured,
            "commanded": first.speed,
            "outcome": first.outcome,
            **event,
        }

    def post_impact(self, trial: ValidationTrial) -> dict[str, Any] | None:
        """The measured post-impact CoM velocity against the predicted set.

        The predicted set is the composite model's, over the scenario's friction and restitution
        range, at the measured speed from the measured pre-impact CoM velocity. Returns the set's
        vertices and the distance from the measurement to it (m/s, 0 inside).
        """
        impact = trial.summary.get("impact")
        setup = self.extra.get("setup")
        if (
            impact is None
            or setup is None
            or None in (trial.measured, impact["com_velocity_before"], impact["com_velocity_after"])
        ):
            return None
        from impact_balance.sim.trials.measure import distance_to_hull

        vertices = setup.analysis.impact.model.post_impact_com_velocities(
            impact["com_velocity_before"], trial.measured
        )
        after = np.asarray(impact["com_velocity_after"], dtype=float)
        return {"vertices": vertices.tolist(), "distance": float(distance_to_hull(after, vertices))}

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: ``validate --json``."""
        com_max = self.predicted_with_margin["com_criterion"]["composite"]
        trials = []
        for t in self.trials:
            s = t.summary
            margin_end = s.get("com_velocity_margin_at_end")
            trials.append(
                {
                    "speed": t.speed,
                    "approach_speed_measured": t.measured,
                    "outcome": t.outcome,
                    "fell": t.fell,
                    "strict_fail": t.strict_fail,
                    "reason": s["reason"],
                    "strict_reason": s["strict_reason"],
                    "detail": s["detail"],
                    "events": s["events"],
                    "com_criterion_safe": None
                    if t.measured is None or com_max is None
                    else bool(t.measured <= com_max),
                    "com_criterion_safe_in_trial": None
                    if margin_end is None
                    else bool(margin_end >= self.omega * self.zmp_margin),
                    "predicted_post_impact": self.post_impact(t),
                    "trial": s,
                }
            )
            if self.reach is not None:  # the measured speed against the maximum within reach
                within = self.scored_against
                trials[-1]["com_reach_safe"] = (
                    None if t.measured is None or within is None else bool(t.measured <= within)
                )
            if self.held_stance is not None:  # the measured speed against the held stance's
                held = self.held_stance.max_contact_velocity
                trials[-1]["held_stance_safe"] = (
                    None if t.measured is None else bool(t.measured <= held)
                )
        empirical = {**self.bracket(), "tolerance": self.tolerance, "max_speed": self.max_speed}
        verdict = fall_verdict(
            empirical["survived"],
            empirical["fell"],
            self.scored_against,
            empirical["fastest_measured"],
        )
        predicted = {**self.predicted, "default": self.default}
        if self.reach is not None:
            predicted["com_reach"] = self.reach.to_dict()
        if self.held_stance is not None:
            predicted["held_stance"] = self.held_stance.to_dict()
        return {
            "scenario": self.scenario,
            "joints": self.joints,
            "rigid_impact": self.rigid_impact,
            "zmp_margin": self.zmp_margin,
            "predicted": predicted,
            "predicted_with_margin": self.predicted_with_margin,
            "empirical": empirical,
            "verdict": verdict,
            "contact_break": self.contact_break(),
            "trials": trials,
            "controller": self.controller,
            "outcome_criteria": self.outcome_criteria,
            "journal": self.journal,
            "reused_trials": self.reused,
            "wall_time": self.wall_time,
        }


class _TrialRunner:
    """Runs the search's trials (or reads them from the journal) and keeps them in order."""

    def __init__(self, setup: BalanceSetup, options: BalanceTrialOptions, journal: TrialJournal):
        self.setup, self.options, self.journal = setup, options, journal
        self.trials: list[ValidationTrial] = []
        self.reused = 0

    def __call__(self, speed: float) -> OutcomeName:
        """The outcome of the trial at the commanded ``speed`` (m/s).

        A speed already run in this search is not run (nor kept) again.
        """
        for done in self.trials:
            if round(done.speed, 9) == round(speed, 9):
                return done.outcome
        key = {"speed": round(speed, 9)}
        entry = self.journal.get(key)
        if entry is None:
            result = run_balance_trial(self.setup, impact_speed=speed, options=self.options)
            start = (
                result.disturbance_time
                if result.disturbance_time is not None
                else self.options.settle
            )
            entry = {
                "summary": result.summary(),
                "trajectory": trajectory(result, start - 0.05, start + 1.5),
            }
            self.journal.add(key, entry)
        else:
            self.reused += 1
        self.trials.append(
            ValidationTrial(speed=speed, summary=entry["summary"], trajectory=entry["trajectory"])
        )
        return self.trials[-1].outcome


ValidationProgress = Callable[[ValidationTrial, float | None, float | None], None]


class _Search:
    """The search of the fall threshold: bracket, then bisect (see :func:`validate`)."""

    def __init__(
        self,
        trial: _TrialRunner,
        tolerance: float,
        min_speed: float,
        max_speed: float,
        progress: ValidationProgress | None,
    ):
        self.trial, self.tolerance = trial, tolerance
        self.min_speed, self.max_speed = min_speed, max_speed
        self.progress = progress

    def _report(self, stood: float | None, fell: float | None) -> None:
        if self.progress:
            self.progress(self.trial.trials[-1], stood, fell)

    def bracket(self, speed: float) -> tuple[float | None, float | None]:
        """Double (or halve) the commanded ``speed`` (m/s) until the outcome changes.

        Returns:
            The fastest speed that stood and the slowest that fell (None: not found).
        """
        tolerance, min_speed, max_speed = self.tolerance, self.min_speed, self.max_speed
        stood: float | None = None
        fell: float | None = None
        ceiling = max_speed  # aborted trials lower it: nothing faster can be tested
        while True:
            outcome = self.trial(speed)
            if outcome == "aborted":  # nothing this fast can be tested: look below
                ceiling = speed
                if fell is not None or speed <= min_speed:
                    break
                speed = max(min_speed, speed / 2) if stood is None else 0.5 * (stood + speed)
                if stood is not None and speed - stood <= tolerance * speed:
                    break
            elif outcome == "fell":
                fell = speed
                if stood is not None or speed <= min_speed:
                    break
                speed = max(min_speed, speed / 2)
            else:
                stood = speed
                if fell is not None or speed >= ceiling * (1 - 1e-9):
                    break
                speed = min(ceiling, speed * 2)
                if speed >= ceiling * (1 - 1e-9) and ceiling < max_speed:
                    break
            self._report(stood, fell)
        return stood, fell

    def threshold(self, failed: TrialTest) -> None:
        """Bisect the commanded speed where ``failed`` starts, from the trials already run.

        Between the slowest commanded speed that failed and the fastest below it that did not (or,
        without one, halving down to the minimum speed) until ``hi - lo <= tolerance * hi``.
        """
        scored = [t for t in self.trial.trials if t.scored and t.measured is not None]
        bad = [t.speed for t in scored if failed(t)]
        if not bad:
            return
        hi = min(bad)
        good = [t.speed for t in scored if not failed(t) and t.speed < hi]
        lo = max(good) if good else None
        # Nothing at or below an aborted speed can be tested (a slower approach lasts longer).
        floor = max(
            (t.speed for t in self.trial.trials if not t.scored and t.speed < hi), default=0
        )
        while lo is None or hi - lo > self.tolerance * hi:
            speed = max(self.min_speed, hi / 2) if lo is None else 0.5 * (lo + hi)
            if speed >= hi * (1 - 1e-9) or (lo is None and speed <= floor):
                return
            if self.trial(speed) == "aborted":
                return
            last = self.trial.trials[-1]
            if last.measured is None:
                return
            if failed(last):
                hi = speed
            else:
                lo = speed
            self._report(lo, hi)

    def bisect(self, stood: float, fell: float) -> None:
        """Bisect ``[stood, fell]`` (m/s) until ``fell - stood <= tolerance * fell``."""
        while fell - stood > self.tolerance * fell:
            mid = 0.5 * (stood + fell)
            outcome = self.trial(mid)
            if outcome == "aborted":
                break
            if outcome == "fell":
                fell = mid
            else:
                stood = mid
            self._report(stood, fell)


def _controller_description(
    setup: BalanceSetup, options: BalanceTrialOptions, joints: str
) -> dict[str, Any]:
    """The ``controller`` object of ``validate --json``."""
    controller = controller_class(setup.controller).trial_description(
        options, setup.sim, joints == "servo"
    )
    controller["impact_task"] = {
        "approach": "bounded acceleration, then cruise",
        "acceleration": 20.0,
        "cruise": 0.03,
        "force_threshold": 15.0,
        "retract": 0.05,
    }
    controller["armature"] = setup.sim.armature_source
    # The gains from the robot's rules (they differ between stances of one robot) or as given.
    controller["gains_from_robot"] = bool(options.robot_gains)
    repair = setup.sim.inertia_repair
    controller["inertia_repair"] = None if repair is None else repair.to_dict()
    return controller


def validate(
    scenario: Scenario | str,
    joints: str = "servo",
    *,
    tolerance: float = 0.05,
    max_speed: float = 4.0,
    min_speed: float = 0.02,
    options: BalanceTrialOptions | None = None,
    progress: ValidationProgress | None = None,
    setup: BalanceSetup | None = None,
    zmp_margin: float | None = None,
    journal: TrialJournal | None = None,
    com_reach: ReachOptions | bool = False,
    impact_model: str = "floating",
) -> ValidationResult:
    """Bracket the approach speed at which the robot starts to fall (m/s); see the module docstring.

    Starts at the CoM criterion's prediction (composite, no margin), doubles (or halves) the
    commanded speed until the outcome changes, then bisects until
    ``fell - stood <= tolerance * fell`` (commanded). If the robot stands at ``max_speed`` (or falls
    at ``min_speed``), or a trial is aborted, the bracket stays open on that side.
    ``progress(trial, stood, fell)`` is called after every trial. ``com_reach`` (True: the
    default :class:`~impact_balance.balance.reach.ReachOptions`; or the options) computes the
    CoM's reach once, before the trials, and scores the verdict against the maximum contact
    velocity within it (see the module docstring). ``impact_model`` (one of
    :data:`IMPACT_MODELS`) "held-stance" adds :func:`held_stance_prediction` before the trials.
    """
    wall0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.impact is None:
        raise SimulationError(
            "impact", None, f"scenario {scenario.name!r} has no impact to validate"
        )
    check_tolerance(tolerance)  # numeric_limits: a bracket the bisection can close
    if impact_model not in IMPACT_MODELS:
        raise SimulationError(
            "impact_model", impact_model, f"must be one of {', '.join(IMPACT_MODELS)}"
        )
    options = options or BalanceTrialOptions()
    margin = controller_margin(options) if zmp_margin is None else float(zmp_margin)
    predicted = predictions(scenario)
    with_margin = predictions(scenario, margin)
    reach = None
    if com_reach is not False:
        options_reach = None if com_reach is True else com_reach
        reach = reach_answer(_default_analysis(scenario, margin), options_reach)
    held = held_stance_prediction(scenario, margin) if impact_model == "held-stance" else None
    setup = setup or BalanceSetup.create(scenario, joints, options)
    runner = _TrialRunner(setup, options, journal or TrialJournal(None, ""))
    start = predicted["com_criterion"]["composite"] or 0.5
    search = _Search(runner, tolerance, min_speed, max_speed, progress)
    stood, fell = search.bracket(float(np.clip(start, min_speed, max_speed)))
    if progress and runner.trials:
        progress(runner.trials[-1], stood, fell)
    if stood is not None and fell is not None:
        search.bisect(stood, fell)
    search.threshold(_strict)
    search.threshold(_broke)
    trials, reused, journal = runner.trials, runner.reused, runner.journal
    controller = _controller_description(setup, options, joints)
    return ValidationResult(
        scenario.name,
        joints,
        options.rigid_impact,
        predicted,
        with_margin,
        margin,
        float(setup.analysis.areas.omega),
        trials,
        controller,
        options.criteria.to_dict(),
        tolerance,
        max_speed,
        time.perf_counter() - wall0,
        None if journal.path is None else str(journal.path),
        reused,
        {"setup": setup},
        default_prediction(scenario, margin),
        reach,
        held,
    )
