"""Push recovery (paper Exp. 2): impulsive pushes at the torso in every direction, several magnitudes.

For every push the trial (:func:`~.trial.run_balance_trial`) gives the outcome (fell or not), and what each
criterion predicted from the measured motion:

- the CoM criterion: at the end of the push, the measured CoM velocity lies in the CoM velocity area
  (equivalently, the DCM lies in the ZMP support area);
- the ZMP criterion: the measured ZMP stays in the ZMP support area throughout the push.

A criterion's prediction "safe" is compared with "did not fall" in a confusion matrix.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from ..scenario import Scenario, load_scenario
from ..exceptions import SimulationError
from ..numeric_limits import finite_or_none as _finite_or_none
from .balance_trial import Push, BalanceTrialOptions, BalanceTrialResult, BalanceSetup, run_balance_trial

__all__ = ["check_push_arguments", "PushOutcome", "PushTestResult", "push_test", "confusion", "DEFAULT_MAGNITUDES"]

#: Default impulses (N s): for a 90 kg robot, CoM velocity changes of about 0.06 to 0.33 m/s.
DEFAULT_MAGNITUDES = (5.0, 10.0, 15.0, 20.0, 25.0, 30.0)


@dataclass
class PushOutcome:
    push: Push
    result: BalanceTrialResult

    def to_dict(self) -> dict:
        r = self.result
        return {
            "direction": float(self.push.direction), "magnitude": float(self.push.magnitude),
            "duration": float(self.push.duration), "fell": r.fell, "reason": r.reason, "detail": r.detail,
            "com_criterion_safe": r.com_criterion_safe, "zmp_criterion_safe": r.zmp_criterion_safe,
            # How close the CoM criterion's call was: m/s inside (>= 0) or outside the area at the push's end.
            "com_velocity_margin_at_end": (None if r.com_velocity_margin_at_end is None
                                           or not np.isfinite(r.com_velocity_margin_at_end)
                                           else r.com_velocity_margin_at_end),
            # null when undefined: no ZMP while the robot is off the ground (a push that throws it).
            "max_zmp_excursion": _finite_or_none(r.max_zmp_excursion),
            "max_com_velocity_excursion": _finite_or_none(r.max_com_velocity_excursion),
        }


def confusion(predicted_safe: Sequence[bool], fell: Sequence[bool]) -> dict:
    """Confusion matrix of a criterion: counts, accuracy, and the rate of "predicted safe, fell"."""
    p = np.asarray(predicted_safe, dtype=bool)
    f = np.asarray(fell, dtype=bool)
    n = len(p)
    out = {
        "safe_survived": int(np.sum(p & ~f)), "safe_fell": int(np.sum(p & f)),
        "unsafe_survived": int(np.sum(~p & ~f)), "unsafe_fell": int(np.sum(~p & f)), "total": n,
    }
    out["accuracy"] = (out["safe_survived"] + out["unsafe_fell"]) / n if n else None
    out["safe_fell_rate"] = out["safe_fell"] / n if n else None
    return out


@dataclass
class PushTestResult:
    scenario: str
    outcomes: list[PushOutcome]
    controller: dict
    fall_criteria: dict
    setup: BalanceSetup
    wall_time: float

    def confusion(self) -> dict:
        fell = [o.result.fell for o in self.outcomes]
        return {"com": confusion([bool(o.result.com_criterion_safe) for o in self.outcomes], fell),
                "zmp": confusion([bool(o.result.zmp_criterion_safe) for o in self.outcomes], fell)}

    def to_dict(self) -> dict:
        return {"scenario": self.scenario, "pushes": [o.to_dict() for o in self.outcomes],
                "confusion": self.confusion(), "controller": self.controller,
                "fall_criteria": self.fall_criteria, "wall_time": self.wall_time}


def check_push_arguments(directions: int, magnitudes: Sequence[float], duration: float) -> None:
    """Refuse bad push-test arguments with one clear error naming the option."""
    if not (isinstance(directions, int) and 1 <= directions <= 360):
        raise SimulationError("--directions", directions, "must be an integer in [1, 360]")
    if not magnitudes or any(not (np.isfinite(m) and 0 < m <= 1000) for m in magnitudes):
        raise SimulationError("--magnitudes", list(magnitudes), "each must be in (0, 1000] N s")
    if not (0.001 <= duration <= 0.2):
        raise SimulationError("--duration", duration, "must be in [0.001, 0.2] s (an impulsive push: 10-50 ms)")


def push_test(scenario: Scenario | str, directions: int = 16, magnitudes: Sequence[float] = DEFAULT_MAGNITUDES,
              duration: float = 0.02, body: str | None = None, options: BalanceTrialOptions | None = None,
              progress: Callable[[PushOutcome], None] | None = None, setup: BalanceSetup | None = None) -> PushTestResult:
    """Push the robot in ``directions`` evenly spaced directions at every magnitude (N s) for ``duration`` s."""
    import time

    wall0 = time.perf_counter()
    if not isinstance(scenario, Scenario):
        scenario = load_scenario(scenario)
    check_push_arguments(directions, magnitudes, duration)
    options = options or BalanceTrialOptions()
    setup = setup or BalanceSetup.create(scenario, "servo", options)
    outcomes = []
    for magnitude in magnitudes:
        for k in range(directions):
            push = Push(2 * np.pi * k / directions, float(magnitude), duration, options.settle, body)
            outcome = PushOutcome(push, run_balance_trial(setup, push=push, options=options))
            outcomes.append(outcome)
            if progress:
                progress(outcome)
    if setup.controller == "id":
        from .inverse_dynamics import describe

        controller = describe(options.id_gains, float(setup.sim.model.opt.timestep), True)
    else:
        controller = {"name": "dcm-zmp-clamp + pink IK -> joint position servos", "gains": options.gains.to_dict()}
    return PushTestResult(scenario.name, outcomes, controller, options.criteria.to_dict(), setup,
                          time.perf_counter() - wall0)
