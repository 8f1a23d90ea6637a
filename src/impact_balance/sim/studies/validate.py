"""Empirical fall threshold of an impact (paper Exp. 1), in measured approach speed.

:func:`validate` runs balance trials (:func:`~.balance_trial.run_balance_trial`) at increasing
commanded approach speeds until the robot falls, then bisects the commanded speed until the
bracket ``[stood, fell]`` is within a relative tolerance (5 %). The bracket is reported in the
**measured** approach speed at first contact (the commanded one beside it): ``survived`` is the
fastest measured speed that did not fall below the slowest that fell. Only ``fell`` counts as a
fall; ``contact_broken`` trials (the robot came to rest without a step, but a contact slipped,
lifted or tilted) are reported apart, with the first speed and contact that broke. Aborted
trials (the impact point never reached the surface, or something went wrong before the contact)
close the search on their side and are left out.

Beside the bracket: the maximum contact velocity by the CoM criterion and by the ZMP criterion,
each with both inertia models (``composite`` and ``joint_space``), without margin and with the
scoring ZMP margin; and per trial the CoM criterion's call at the measured speed (safe when the
measured speed is at most the maximum: a prediction made before the trial, evaluated at the
speed the trial reached) and in the trial (the measured post-impact CoM velocity in the area).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from impact_balance.analysis.analyze import analyze
from impact_balance.exceptions import SimulationError
from impact_balance.json_values import json_number
from impact_balance.ranges import check_tolerance
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.studies.journal import TrialJournal
from impact_balance.sim.trials.balance_trial import (
    BalanceSetup,
    BalanceTrialOptions,
    controller_margin,
    run_balance_trial,
)
from impact_balance.sim.trials.result import TrialEntry, trajectory

__all__ = ["INERTIA_MODELS", "ValidationResult", "ValidationTrial", "predictions", "validate"]

INERTIA_MODELS = ("composite", "joint_space")


def predictions(scenario: Scenario, zmp_margin: float = 0.0) -> dict[str, dict[str, float | None]]:
    """Maximum contact velocity (m/s; None if unbounded) by each criterion and inertia model, with the ZMP
    support area shrunk by ``zmp_margin`` (m).
    """
    out: dict[str, dict[str, float | None]] = {"com_criterion": {}, "zmp_criterion": {}}
    for inertia in INERTIA_MODELS:
        variant = scenario.model_copy(
            update={
                "impact": scenario.impact.model_copy(update={"inertia": inertia}),
                "zmp_margin": float(zmp_margin),
            }
        )
        answer = analyze(variant).impact
        out["com_criterion"][inertia] = json_number(answer.max_contact_velocity)
        out["zmp_criterion"][inertia] = json_number(answer.zmp_max_contact_velocity)
    return out


@dataclass(kw_only=True)
class ValidationTrial(TrialEntry):
    """One trial of the search: the commanded speed, the trial's summary and its CoM velocity trajectory."""

    speed: float

    @property
    def measured(self) -> float | None:
        return self.summary.get("approach_speed_measured")


@dataclass
class ValidationResult:
    """Predictions beside the empirical bracket; ``to_dict()`` is ``validate --json``."""

    scenario: str
    joints: str
    rigid_impact: bool
    predicted: dict
    predicted_with_margin: dict
    zmp_margin: float
    omega: float
    trials: list[ValidationTrial]
    controller: dict
    outcome_criteria: dict
    tolerance: float
    max_speed: float
    wall_time: float = 0.0
    journal: str | None = None
    reused: int = 0
    extra: dict = field(default_factory=dict)

    @property
    def scored(self) -> list[ValidationTrial]:
        return [t for t in self.trials if t.scored and t.measured is not None]

    def bracket(self) -> dict:
        """The bracket in measured and commanded approach speed (see the module docstring)."""
        scored = self.scored
        fell = [t for t in scored if t.fell]
        stood = [t for t in scored if not t.fell]
        lowest_fall = min(fell, key=lambda t: t.measured) if fell else None
        below = [t for t in stood if lowest_fall is None or t.measured < lowest_fall.measured]
        survived = max(below, key=lambda t: t.measured) if below else None
        monotonic = not (fell and stood and max(t.measured for t in stood) > lowest_fall.measured)
        fell_c = min((t.speed for t in fell), default=None)
        stood_c = max((t.speed for t in stood if fell_c is None or t.speed < fell_c), default=None)
        return {
            "survived": None if survived is None else survived.measured,
            "fell": None if lowest_fall is None else lowest_fall.measured,
            "survived_commanded": stood_c,
            "fell_commanded": fell_c,
            "monotonic": monotonic,
            "fastest_measured": max((t.measured for t in scored), default=None),
        }

    def contact_break(self) -> dict | None:
        """The slowest trial (measured speed) that broke a contact (fell or not) and its first event."""
        broken = [t for t in self.scored if t.summary["events"]]
        if not broken:
            return None
        first = min(broken, key=lambda t: t.measured)
        event = min(first.summary["events"], key=lambda e: e["time"])
        return {
            "measured": first.measured,
            "commanded": first.speed,
            "outcome": first.outcome,
            **event,
        }

    def post_impact(self, trial: ValidationTrial) -> dict | None:
        """The measured post-impact CoM velocity against the predicted set (composite, the scenario's friction and
        restitution range) at the measured speed from the measured pre-impact CoM velocity: the set's vertices and
        the distance from the measurement to it (m/s, 0 inside).
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

    def to_dict(self) -> dict:
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
                    "reason": s["reason"],
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
        empirical = {**self.bracket(), "tolerance": self.tolerance, "max_speed": self.max_speed}
        return {
            "scenario": self.scenario,
            "joints": self.joints,
            "rigid_impact": self.rigid_impact,
            "zmp_margin": self.zmp_margin,
            "predicted": self.predicted,
            "predicted_with_margin": self.predicted_with_margin,
            "empirical": empirical,
            "contact_break": self.contact_break(),
            "trials": trials,
            "controller": self.controller,
            "outcome_criteria": self.outcome_criteria,
            "journal": self.journal,
            "reused_trials": self.reused,
            "wall_time": self.wall_time,
        }


def validate(
    scenario: Scenario | str,
    joints: str = "servo",
    *,
    tolerance: float = 0.05,
    max_speed: float = 4.0,
    min_speed: float = 0.02,
    options: BalanceTrialOptions | None = None,
    progress: Callable[[ValidationTrial, float | None, float | None], None] | None = None,
    setup: BalanceSetup | None = None,
    zmp_margin: float | None = None,
    journal: TrialJournal | None = None,
) -> ValidationResult:
    """Bracket the approach speed at which the robot starts to fall (m/s); see the module docstring.

    Starts at the CoM criterion's prediction (composite, no margin), doubles (or halves) the commanded
    speed until the outcome changes, then bisects until ``fell - stood <= tolerance * fell`` (commanded).
    If the robot stands at ``max_speed`` (or falls at ``min_speed``), or a trial is aborted, the bracket
    stays open on that side. ``progress(trial, stood, fell)`` is called after every trial.
    """
    wall0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.impact is None:
        raise SimulationError(
            "impact", None, f"scenario {scenario.name!r} has no impact to validate"
        )
    check_tolerance(tolerance)  # numeric_limits: a bracket the bisection can close
    options = options or BalanceTrialOptions()
    margin = controller_margin(options) if zmp_margin is None else float(zmp_margin)
    predicted = predictions(scenario)
    with_margin = predictions(scenario, margin)
    setup = setup or BalanceSetup.create(scenario, joints, options)
    journal = journal or TrialJournal(None, "")
    trials: list[ValidationTrial] = []
    reused = 0

    def trial(speed: float) -> str:
        nonlocal reused
        key = {"speed": round(speed, 9)}
        entry = journal.get(key)
        if entry is None:
            result = run_balance_trial(setup, impact_speed=speed, options=options)
            start = (
                result.disturbance_time if result.disturbance_time is not None else options.settle
            )
            entry = {
                "summary": result.summary(),
                "trajectory": trajectory(result, start - 0.05, start + 1.5),
            }
            journal.add(key, entry)
        else:
            reused += 1
        trials.append(
            ValidationTrial(speed=speed, summary=entry["summary"], trajectory=entry["trajectory"])
        )
        return trials[-1].outcome

    stood: float | None = None
    fell: float | None = None
    ceiling = max_speed  # aborted trials lower it: nothing faster can be tested
    start = predicted["com_criterion"]["composite"] or 0.5
    speed = float(np.clip(start, min_speed, max_speed))
    while True:
        outcome = trial(speed)
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
        if progress:
            progress(trials[-1], stood, fell)
    if progress and trials:
        progress(trials[-1], stood, fell)
    if stood is not None and fell is not None:
        while fell - stood > tolerance * fell:
            mid = 0.5 * (stood + fell)
            outcome = trial(mid)
            if outcome == "aborted":
                break
            if outcome == "fell":
                fell = mid
            else:
                stood = mid
            if progress:
                progress(trials[-1], stood, fell)
    if setup.controller == "id":
        from impact_balance.sim.control.torque import describe

        controller = describe(
            options.id_gains, float(setup.sim.model.opt.timestep), joints == "servo"
        )
    else:
        controller = {
            "name": "dcm-zmp-clamp + pink IK -> joint position servos",
            "gains": options.gains.to_dict(),
            "control_rate_hz": options.gains.rate,
            "sim_timestep": float(setup.sim.model.opt.timestep),
            "servo": {
                "kp": setup.sim.kp.tolist(),
                "kd": setup.sim.kd.tolist(),
                "joints": list(setup.sim.joint_names),
            },
        }
    controller["impact_task"] = {
        "approach": "bounded acceleration, then cruise",
        "acceleration": 20.0,
        "cruise": 0.03,
        "force_threshold": 15.0,
        "retract": 0.05,
    }
    controller["armature"] = setup.sim.armature_source
    repair = setup.sim.inertia_repair
    controller["inertia_repair"] = None if repair is None else repair.to_dict()
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
    )
