"""Empirical fall threshold of an impact (paper Exp. 1): bisection on the commanded approach speed.

:func:`validate` runs balance trials (:func:`~.trial.run_balance_trial`) at increasing commanded approach
speeds until the robot falls, then bisects until the bracket ``[survived, fell]`` is within a relative
tolerance (5 %), and puts it beside the predictions: the maximum contact velocity by the CoM criterion
and by the ZMP criterion, each with both inertia models (``composite`` and ``joint_space``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..analysis import analyze
from ..exceptions import SimulationError
from ..numeric_limits import check_tolerance
from ..scenario import Scenario, load_scenario
from .balance_trial import BalanceTrialOptions, BalanceTrialResult, BalanceSetup, run_balance_trial

__all__ = ["predictions", "ValidationResult", "validate", "INERTIA_MODELS"]

INERTIA_MODELS = ("composite", "joint_space")


def _num(x: float | None) -> float | None:
    return None if x is None or not np.isfinite(x) else float(x)


def predictions(scenario: Scenario) -> dict[str, dict[str, float | None]]:
    """Maximum contact velocity (m/s; None if unbounded) by each criterion and inertia model."""
    out: dict[str, dict[str, float | None]] = {"com_criterion": {}, "zmp_criterion": {}}
    for inertia in INERTIA_MODELS:
        variant = scenario.model_copy(update={"impact": scenario.impact.model_copy(update={"inertia": inertia})})
        answer = analyze(variant).impact
        out["com_criterion"][inertia] = _num(answer.max_contact_velocity)
        out["zmp_criterion"][inertia] = _num(answer.zmp_max_contact_velocity)
    return out


@dataclass
class ValidationResult:
    """Predictions beside the empirical bracket; ``to_dict()`` is ``validate --json``."""

    scenario: str
    joints: str
    predicted: dict
    survived: float | None
    fell: float | None
    trials: list[tuple[float, BalanceTrialResult]]
    controller: dict
    fall_criteria: dict
    tolerance: float
    max_speed: float
    wall_time: float = 0.0
    extra: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "scenario": self.scenario,
            "joints": self.joints,
            "predicted": self.predicted,
            "empirical": {"survived": _num(self.survived), "fell": _num(self.fell),
                          "tolerance": self.tolerance, "max_speed": self.max_speed},
            "trials": [
                {"speed": v, "fell": r.fell, "reason": r.reason, "detail": r.detail,
                 "approach_speed_measured": _num(r.approach_speed_measured),
                 "max_zmp_excursion": _num(r.max_zmp_excursion),
                 "max_com_velocity_excursion": _num(r.max_com_velocity_excursion),
                 "min_com_velocity_margin": _num(r.min_com_velocity_margin),
                 "max_tilt_deg": float(np.rad2deg(r.max_tilt)), "max_slip": float(r.max_slip),
                 "sim_time": r.sim_time, "wall_time": r.wall_time}
                for v, r in self.trials
            ],
            "controller": self.controller,
            "fall_criteria": self.fall_criteria,
            "wall_time": self.wall_time,
        }


def validate(scenario: Scenario | str, joints: str = "servo", *, tolerance: float = 0.05, max_speed: float = 4.0,
             min_speed: float = 0.02, options: BalanceTrialOptions | None = None,
             progress: Callable[[float, BalanceTrialResult, float | None, float | None], None] | None = None,
             setup: BalanceSetup | None = None) -> ValidationResult:
    """Bracket the commanded approach speed at which the robot starts to fall (m/s).

    Starts at the CoM criterion's prediction (composite), doubles (or halves) until the outcome
    changes, then bisects until ``fell - survived <= tolerance * fell``. If the robot survives
    ``max_speed`` (or falls at ``min_speed``) the bracket stays open (``fell`` or ``survived`` None).
    ``progress(speed, result, survived, fell)`` is called after every trial.
    """
    import time

    wall0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    if scenario.impact is None:
        raise SimulationError("impact", None, f"scenario {scenario.name!r} has no impact to validate")
    check_tolerance(tolerance)  # numeric_limits: a bracket the bisection can close
    options = options or BalanceTrialOptions()
    predicted = predictions(scenario)
    setup = setup or BalanceSetup.create(scenario, joints, options)
    trials: list[tuple[float, BalanceTrialResult]] = []

    def trial(speed: float) -> bool:
        result = run_balance_trial(setup, impact_speed=speed, options=options)
        trials.append((speed, result))
        return result.fell

    survived: float | None = None
    fell: float | None = None
    start = predicted["com_criterion"]["composite"] or 0.5
    speed = float(np.clip(start, min_speed, max_speed))
    while True:
        if trial(speed):
            fell = speed
            if survived is not None or speed <= min_speed:
                break
            speed = max(min_speed, speed / 2)
        else:
            survived = speed
            if fell is not None or speed >= max_speed:
                break
            speed = min(max_speed, speed * 2)
        if progress:
            progress(trials[-1][0], trials[-1][1], survived, fell)
    if progress and trials:
        progress(trials[-1][0], trials[-1][1], survived, fell)
    if survived is not None and fell is not None:
        while fell - survived > tolerance * fell:
            mid = 0.5 * (survived + fell)
            if trial(mid):
                fell = mid
            else:
                survived = mid
            if progress:
                progress(mid, trials[-1][1], survived, fell)
    setup_controller = {"name": "dcm-zmp-clamp + pink IK -> joint position servos",
                        "gains": options.gains.to_dict(), "control_rate_hz": options.gains.rate,
                        "sim_timestep": float(setup.sim.model.opt.timestep),
                        "servo": {"kp": setup.sim.kp.tolist(), "kd": setup.sim.kd.tolist(),
                                  "joints": list(setup.sim.joint_names)},
                        "impact_task": {"standoff": setup.standoff, "force_threshold": 15.0, "retract": 0.05}}
    if setup.controller == "id":
        from .inverse_dynamics import describe

        setup_controller = describe(options.id_gains, float(setup.sim.model.opt.timestep), joints == "servo")
        setup_controller["impact_task"]["standoff"] = setup.standoff
    return ValidationResult(scenario.name, joints, predicted, survived, fell, trials, setup_controller,
                            options.criteria.to_dict(), tolerance, max_speed, time.perf_counter() - wall0,
                            {"setup": setup})
