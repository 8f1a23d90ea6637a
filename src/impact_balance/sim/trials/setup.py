"""What a balance trial runs on: the push, the trial's options, and the prepared scenario.

:class:`BalanceSetup` prepares a scenario once for many trials (:mod:`.balance_trial`): its
analysis (without ZMP margin: the controller is configured on its own, a score applies its
margin afterwards), the MuJoCo model with the controller's actuators, and the start
configurations (one per standoff of the impacting point, by whole-body IK).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from impact_balance.analysis.analyze import Analysis, analyze, contact_model_areas
from impact_balance.balance.areas import BalanceAreas
from impact_balance.exceptions import SimulationError
from impact_balance.scenario import Scenario, load_scenario
from impact_balance.sim.control.actuation import STIFF_SERVOS, support_joints
from impact_balance.sim.control.controller import ControllerName
from impact_balance.sim.control.gains import BalanceGains, InverseDynamicsGains
from impact_balance.sim.control.kinematic import retracted_stance
from impact_balance.sim.control.registry import CONTROLLERS, controller_class
from impact_balance.sim.model.build import SimModel, SimOptions, build_model
from impact_balance.sim.model.joints import JointModel, ServoOptions, check_joint_model
from impact_balance.sim.trials.outcomes import OutcomeCriteria

#: Iterations of MuJoCo's no-slip solver in balance trials.
NOSLIP_ITERATIONS = 10

__all__ = [
    "CONTROLLERS",
    "NOSLIP_ITERATIONS",
    "STIFF_SERVOS",
    "BalanceSetup",
    "BalanceTrialOptions",
    "Push",
    "controller_margin",
    "push_body",
]


@dataclass(frozen=True)
class Push:
    """A horizontal force on a body for a short time (MuJoCo ``xfrc_applied``, at the body's CoM).

    Attributes:
        direction: Direction of the force in the horizontal plane (rad, from world x).
        magnitude: Impulse (N s); the force is ``magnitude / duration``.
        duration: How long the force acts (s), 10-50 ms for an impulsive push.
        start: When it starts (s).
        body: MuJoCo body name (None: the deepest body named like "torso", else the root).
    """

    direction: float
    magnitude: float
    duration: float = 0.05
    start: float = 0.3
    body: str | None = None

    @property
    def force(self) -> np.ndarray:
        """The force (N, world): ``magnitude / duration`` along ``direction``, horizontal."""
        f = self.magnitude / self.duration
        return np.array([f * np.cos(self.direction), f * np.sin(self.direction), 0.0])


def push_body(sim: SimModel, name: str | None) -> int:
    """The MuJoCo body a :class:`Push` acts on.

    Args:
        sim: The trial's model.
        name: MuJoCo body name, or None for the deepest body named like "torso" with a mass
            (the root body when there is none).

    Returns:
        The body's id in ``sim.model``.

    Raises:
        SimulationError: No body of the model has that name.
    """
    m = sim.model
    if name is not None:
        try:
            return int(m.body(name).id)
        except KeyError:
            valid = ", ".join(m.body(i).name for i in range(1, m.nbody))
            raise SimulationError("--body", name, f"no such body; valid: {valid}") from None
    torso = [i for i in range(m.nbody) if "torso" in m.body(i).name and m.body_mass[i] > 0]
    return max(torso) if torso else sim.root_body


@dataclass(frozen=True)
class BalanceTrialOptions:
    """Options of a trial.

    Attributes:
        after: Simulated time after the disturbance (contact or end of push) (s); a robot still
            moving then gets ``criteria.extra_time`` more (see :mod:`.outcomes`).
        settle: Time standing still before the disturbance (s).
        max_approach_time: Longest time after the reference reached the surface before the trial
            gives up waiting for the contact (s).
        gains: Gains of the ``ik`` controller.
        criteria: Outcome thresholds (:mod:`.outcomes`).
        record: Keep a log (:mod:`impact_balance.logs` columns) in the result.
        controller: ``ik`` (pink IK, position servos) or ``id`` (inverse-dynamics QP, torque
            motors); it decides the actuators, so it is read when the :class:`BalanceSetup` is
            created.
        id_gains: Gains of the ``id`` controller.
        rigid_impact: Hold every joint's velocity through the impact (:mod:`.rigid_impact`).
        robot_gains: Derive the robot-dependent fields of ``gains`` and ``id_gains`` from the
            robot (mass, CoM height, omega, inertia, simulation step:
            :mod:`impact_balance.sim.control.gains`); False: use them as given.
    """

    after: float = 2.5
    settle: float = 0.3
    max_approach_time: float = 1.0
    gains: BalanceGains = field(default_factory=BalanceGains)
    criteria: OutcomeCriteria = field(default_factory=OutcomeCriteria)
    record: bool = False
    controller: ControllerName = "ik"
    id_gains: InverseDynamicsGains = field(default_factory=InverseDynamicsGains)
    rigid_impact: bool = False
    robot_gains: bool = True


def controller_margin(options: BalanceTrialOptions) -> float:
    """The ZMP margin (m) the trials' controller keeps inside the ZMP support area.

    The ZMP margin the trials' controller keeps inside the ZMP support area (m): the scores'
    default.
    """
    return controller_class(options.controller).zmp_margin(options)


@dataclass
class BalanceSetup:
    """A scenario prepared for trials: analysis, MuJoCo model, start configurations.

    The analysis is without ZMP margin and at the contacts' own frictions (the controller is
    configured on its own); one start configuration per standoff of the impacting point.
    ``criterion_areas`` are the areas the predictions use when the scenario's
    ``friction_scale`` is below 1 (without ZMP margin); None: the analysis's.
    """

    scenario: Scenario
    joints: JointModel
    analysis: Analysis
    sim: SimModel
    support_v_index: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    controller: ControllerName = "ik"
    criterion_areas: BalanceAreas | None = None
    _starts: dict[float, np.ndarray] = field(default_factory=dict)

    @classmethod
    def create(
        cls,
        scenario: Scenario | str,
        joints: str = "servo",
        options: BalanceTrialOptions | None = None,
        sim_options: SimOptions | None = None,
        meshes: bool = False,
    ) -> BalanceSetup:
        """Analyse ``scenario`` and build its MuJoCo model for trials.

        ``joints`` and ``options`` are the trials'; ``sim_options`` the model's own (default 1 ms
        steps); ``meshes``: load the robot's meshes, visual only, for a video.
        """
        options = options or BalanceTrialOptions()
        if not isinstance(scenario, Scenario):
            scenario = load_scenario(scenario)
        joint_model = check_joint_model(joints)
        controller = controller_class(options.controller)
        # The controller works on the areas themselves: a scoring margin is applied afterwards;
        # the criterion's friction_scale is a prediction's setting, not the controller's.
        analysis = analyze(scenario.model_copy(update={"zmp_margin": 0.0, "friction_scale": 1.0}))
        if not analysis.areas.can_balance:
            raise SimulationError(
                "scenario",
                scenario.name,
                f"the stance cannot balance ({analysis.areas.reason}): there is nothing to test",
            )
        if sim_options is None:
            # 1 ms steps: the stiffest contact (impact, time constant 4 ms) still spans 4 steps.
            servo = ServoOptions() if joints == "servo" else STIFF_SERVOS
            sim_options = SimOptions(timestep=0.001, meshes=meshes, servo=servo)
        # Welded joints admit no controller: "rigid" balance trials use stiff servos without
        # effort limits.
        sim = build_model(scenario, "servo", sim_options)
        # MuJoCo's soft friction lets a loaded contact creep (a sole on the 30 degree ramp slides
        # about 3 mm/s within its friction cone); the no-slip pass removes that drift, which would
        # otherwise count as a slip after a few seconds.
        sim.model.opt.noslip_iterations = NOSLIP_ITERATIONS
        controller.prepare_model(sim, analysis)
        support = [analysis.stance.robot.joint_slot(n) for n in support_joints(sim, analysis)]
        support_v = np.array([analysis.stance.model.joints[j.id].idx_v for j in support], dtype=int)
        criterion = None
        if scenario.friction_scale != 1.0:
            criterion = contact_model_areas(
                analysis.scenario, analysis.stance, scenario.friction_scale
            )
        return cls(scenario, joint_model, analysis, sim, support_v, options.controller, criterion)

    def start_configuration(self, standoff: float = 0.0) -> np.ndarray:
        """The stance with the impact point backed off ``standoff`` (m) along the normal (cached).

        Whole-body IK, cached by standoff.
        """
        key = round(float(standoff), 6)
        if key not in self._starts:
            self._starts[key] = retracted_stance(self.analysis, key)
        return self._starts[key]
