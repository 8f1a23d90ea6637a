"""The balance controllers by name: ``ik`` and ``id`` (the ``--controller`` values).

- ``ik``: :class:`~impact_balance.sim.control.kinematic.BalanceController`, DCM feedback + pink
  IK to joint position servos;
- ``id``: :class:`~impact_balance.sim.control.torque.InverseDynamicsController`, DCM feedback +
  a whole-body inverse-dynamics QP to torque motors.
"""

from __future__ import annotations

from typing import Any

from impact_balance.exceptions import SimulationError
from impact_balance.sim.control.controller import Controller, ControllerName
from impact_balance.sim.control.kinematic import BalanceController
from impact_balance.sim.control.torque import InverseDynamicsController

__all__ = ["CONTROLLERS", "controller_class"]

#: The controller class of each name, in the order of the command line's choices.
CONTROLLERS: dict[ControllerName, type[Controller[Any]]] = {
    "ik": BalanceController,
    "id": InverseDynamicsController,
}


def controller_class(name: str) -> type[Controller[Any]]:
    """The controller class named ``name``.

    Args:
        name: ``ik`` or ``id``.

    Returns:
        The class (a :class:`~impact_balance.sim.control.controller.Controller`).

    Raises:
        SimulationError: ``name`` is not a controller's.
    """
    for key, cls in CONTROLLERS.items():
        if key == name:
            return cls
    raise SimulationError(
        "--controller", name, f"unknown controller; valid: {', '.join(CONTROLLERS)}"
    )
