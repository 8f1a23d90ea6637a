"""Simulation of a scenario in MuJoCo, in four sub-packages from the model up.

- :mod:`~impact_balance.sim.model`: the MuJoCo model of a scenario (:func:`build_model`,
  :class:`SimModel`) and its joint models (``rigid``, ``servo``);
- :mod:`~impact_balance.sim.control`: the balance controllers (``ik``: pink IK to position
  servos; ``id``: an inverse-dynamics QP to torque motors) as one family, and the impacting
  point's reference;
- :mod:`~impact_balance.sim.trials`: an impact trial (:func:`run_trial`) and its measurement
  against the impact model (:func:`measure`), and a balance trial (a controller holds the stance
  through an impact or a push);
- :mod:`~impact_balance.sim.studies`: studies made of balance trials (the fall threshold of an
  impact, push grids, the governed approach to a wall).

:func:`simulate` runs one impact trial from a scenario.
"""

from impact_balance.scenario import Scenario
from impact_balance.sim.model.build import SimModel, SimOptions, build_model
from impact_balance.sim.model.environment import ContactParameters
from impact_balance.sim.model.joints import JOINT_MODELS, JointModel, ServoOptions
from impact_balance.sim.trials.impact_trial import TrialOptions, TrialRecord, run_trial
from impact_balance.sim.trials.measure import Prediction, TrialResult, measure

__all__ = [
    "JOINT_MODELS",
    "ContactParameters",
    "JointModel",
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
    scenario: Scenario | str,
    approach_speed: float,
    joints: JointModel = "rigid",
    options: SimOptions | None = None,
    after: float = 0.15,
) -> TrialResult:
    """Build the model, run one impact trial at ``approach_speed`` and measure it.

    Args:
        scenario: The scenario, or its name or file.
        approach_speed: Commanded approach speed of the impact point (m/s).
        joints: Joint model, ``rigid`` or ``servo``.
        options: The model's options (default :class:`SimOptions`).
        after: Simulated time after the contact (s).

    Returns:
        The trial's measurement.
    """
    sim = build_model(scenario, joints, options)
    record = run_trial(sim, TrialOptions(approach_speed, after=after))
    return measure(sim, record, approach_speed)
