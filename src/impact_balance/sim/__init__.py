"""Simulation of a scenario in MuJoCo: the model (:mod:`.model`), its joint models (:mod:`.joints`),
an impact trial (:mod:`.trial`) and its measurement against the impact model (:mod:`.measure`).

See :func:`build_model`, :class:`SimModel` and :func:`simulate`.
"""

from impact_balance.sim.model.build import SimModel, SimOptions, build_model
from impact_balance.sim.model.environment import ContactParameters
from impact_balance.sim.model.joints import JOINT_MODELS, ServoOptions
from impact_balance.sim.trials.impact_trial import TrialOptions, TrialRecord, run_trial
from impact_balance.sim.trials.measure import Prediction, TrialResult, measure

__all__ = [
    "JOINT_MODELS",
    "ContactParameters",
    "Prediction",
    "ServoOptions",
    "SimModel",
    "SimOptions",
    "TrialOptions",
    "TrialRecord",
    "TrialResult",
    "build_model",
    "measure",
    "run_trial",
    "simulate",
]


def simulate(
    scenario,
    approach_speed: float,
    joints: str = "rigid",
    options: SimOptions | None = None,
    after: float = 0.15,
) -> TrialResult:
    """Build the model, run one impact trial at ``approach_speed`` (m/s) and measure it."""
    sim = build_model(scenario, joints, options)
    record = run_trial(sim, TrialOptions(approach_speed, after=after))
    return measure(sim, record, approach_speed)
