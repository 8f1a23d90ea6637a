"""The balance controllers' family: what a trial needs from a controller.

A balance trial (:mod:`impact_balance.sim.trials.balance_trial`) drives the robot through a
:class:`Controller` without knowing which one it is: the controller gives the MuJoCo model its
actuators (:meth:`Controller.prepare_model`), is built from the trial's options
(:meth:`Controller.for_trial`), commands the robot at rest before its first step
(:meth:`Controller.hold`), then at every control step measures the CoM (:meth:`Controller.measure`),
computes its command (:meth:`Controller.step`, a :class:`ControlStep`) and writes it to the
actuators (:meth:`Controller.actuate`). The members are
:class:`~impact_balance.sim.control.kinematic.BalanceController` (``ik``) and
:class:`~impact_balance.sim.control.torque.InverseDynamicsController` (``id``);
:mod:`impact_balance.sim.control.registry` maps the CLI names to them.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from typing import Any, ClassVar, Generic, Literal, Protocol, TypeVar

import numpy as np
import numpy.typing as npt

from impact_balance.analysis.analyze import Analysis
from impact_balance.sim.control.approach import ImpactReference
from impact_balance.sim.control.gains import TrialGains
from impact_balance.sim.model.build import SimModel

__all__ = ["ControlStep", "Controller", "ControllerName"]

#: The controllers' names on the command line and in the JSON outputs.
ControllerName = Literal["ik", "id"]

_FloatArray = npt.NDArray[np.float64]


class ControlStep(Protocol):
    """What every control step reports besides its command (world frame)."""

    @property
    def zmp(self) -> _FloatArray:
        """Clamped desired ZMP (m, world)."""

    @property
    def dcm(self) -> _FloatArray:
        """Measured DCM (m, world)."""

    @property
    def clamped(self) -> bool:
        """Whether the desired ZMP was clamped to the area."""

    @property
    def com(self) -> _FloatArray:
        """Measured CoM (m, world)."""

    @property
    def com_velocity(self) -> _FloatArray:
        """Measured CoM velocity (m/s, world)."""


StepT = TypeVar("StepT", bound=ControlStep)


class Controller(ABC, Generic[StepT]):
    """A balance controller as a trial uses it (see the module docstring).

    Attributes:
        name: What the controller is, in a few words (the ``name`` of its JSON description).
        rate: Control rate (Hz).
        omega: The LIPM's omega at the start configuration (1/s).
    """

    name: ClassVar[str]
    rate: float
    omega: float

    @classmethod
    @abstractmethod
    def prepare_model(cls, sim: SimModel, analysis: Analysis) -> None:
        """Give ``sim`` the actuators this controller drives (before any trial).

        Args:
            sim: The trials' MuJoCo model (servos as built).
            analysis: The scenario's analysis.
        """

    @classmethod
    @abstractmethod
    def zmp_margin(cls, options: TrialGains) -> float:
        """The margin (m) this controller keeps inside the ZMP support area with ``options``' gains.

        Args:
            options: A trial's options.

        Returns:
            The margin of this controller's gains (m).
        """

    @classmethod
    @abstractmethod
    def for_trial(
        cls,
        analysis: Analysis,
        q_start: _FloatArray,
        options: TrialGains,
        task: ImpactReference | None,
        sim: SimModel,
        support_v_index: npt.NDArray[np.int_],
    ) -> Controller[StepT]:
        """The controller of one trial.

        Args:
            analysis: The scenario's analysis (stance, areas; the impact if any).
            q_start: Start configuration (nq, pinocchio order).
            options: The trial's options (this controller reads its own gains).
            task: The impact task, if any.
            sim: The trial's MuJoCo model, prepared by :meth:`prepare_model`.
            support_v_index: Velocity indices (pinocchio) of the support limbs' joints.

        Returns:
            The controller.
        """

    @abstractmethod
    def hold(self, sim: SimModel, q_start: _FloatArray) -> None:
        """Command the robot at rest at ``q_start`` until the first control step.

        Args:
            sim: The trial's MuJoCo model.
            q_start: Start configuration (nq, pinocchio order).
        """

    @abstractmethod
    def measure(self, q: _FloatArray, v: _FloatArray) -> tuple[_FloatArray, _FloatArray]:
        """Measured CoM and CoM velocity (m, m/s, world) from pinocchio's ``(q, v)``.

        Args:
            q: Configuration (nq).
            v: Velocity (nv, free-flyer velocity in the base frame).

        Returns:
            The CoM (3,) and the CoM velocity (3,).
        """

    @abstractmethod
    def step(
        self,
        t: float,
        q: _FloatArray,
        v: _FloatArray,
        zmp_measured: _FloatArray | None = None,
        impact_force: float = 0.0,
    ) -> StepT:
        """One control step from the measured state.

        Args:
            t: Time (s).
            q: Measured configuration (nq, pinocchio order).
            v: Measured velocity (nv, free-flyer velocity in the base frame).
            zmp_measured: ZMP of the measured contact forces on the plane (m, world; None or NaN
                when unknown).
            impact_force: Measured normal force at the impact point (N).

        Returns:
            The step's command and what the controller saw.
        """

    @abstractmethod
    def actuate(self, sim: SimModel, out: StepT) -> None:
        """Write the command of a step to ``sim``'s actuators.

        Args:
            sim: The trial's MuJoCo model.
            out: What :meth:`step` returned.
        """

    @abstractmethod
    def describe(self) -> dict[str, Any]:
        """Name and gains of this controller (the ``controller`` object of ``validate --json``)."""

    @classmethod
    @abstractmethod
    def trial_description(
        cls, options: TrialGains, sim: SimModel, effort_limits: bool
    ) -> dict[str, Any]:
        """The ``controller`` object of ``validate --json`` for trials with ``options``.

        Args:
            options: The trials' options.
            sim: The trials' MuJoCo model.
            effort_limits: Whether the joints' effort limits bound the actuators.

        Returns:
            A JSON-ready description (name, gains, rates, actuators).
        """

    @classmethod
    def trial_summary(
        cls, options: TrialGains, sim: SimModel, effort_limits: bool
    ) -> dict[str, Any]:
        """The ``controller`` object of ``push-test --json``: :meth:`trial_description` by default.

        Args:
            options: The trials' options.
            sim: The trials' MuJoCo model.
            effort_limits: Whether the joints' effort limits bound the actuators.

        Returns:
            A JSON-ready description.
        """
        return cls.trial_description(options, sim, effort_limits)
