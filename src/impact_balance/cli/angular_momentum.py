"""``--angular-momentum-damping-time TAU``: the CoM criterion counts the angular momentum left.

The option sets the scenario key ``angular_momentum_damping_time`` (s; docs/angular-momentum.md)
for one command. ``off`` is the paper's criterion (the key unset). The simulation commands also
take ``controller``: tau = 1 / K_L, K_L the trial controller's declared angular momentum damping
gain (1/s).
"""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import TYPE_CHECKING

from impact_balance.cli._options import number_or_words

if TYPE_CHECKING:
    from impact_balance.scenario import Scenario
    from impact_balance.sim.trials.setup import BalanceTrialOptions

__all__ = [
    "ANGULAR_MOMENTUM_OPTION",
    "CONTROLLER",
    "OFF",
    "add_angular_momentum_option",
    "controller_damping",
    "damping_time_value",
    "for_trials",
    "with_angular_momentum",
]

#: The option's name.
ANGULAR_MOMENTUM_OPTION = "--angular-momentum-damping-time"
#: The value that turns the term off (the paper's criterion).
OFF = "off"
#: The simulation commands' value: tau = 1 / K_L of the trial's controller.
CONTROLLER = "controller"


def damping_time_value(controller: bool) -> Callable[[str], float | str]:
    """Argparse type: a number of seconds, ``off``, or (``controller``) ``controller``.

    Args:
        controller: Whether ``controller`` is accepted (the simulation commands).

    Returns:
        The type: text to a float or to the words; a :class:`CommandLineError` otherwise.
    """
    words = (OFF, CONTROLLER) if controller else (OFF,)
    return number_or_words(
        ANGULAR_MOMENTUM_OPTION,
        words,
        lambda value: value >= 0.0,
        f"not a number of seconds or one of {', '.join(words)}",
        f"must be a finite number >= 0 (s) or {OFF}",
        "damping time",
    )


def add_angular_momentum_option(parser: argparse.ArgumentParser, controller: bool) -> None:
    """Add ``--angular-momentum-damping-time TAU``.

    Args:
        parser: The command's parser.
        controller: Whether the value ``controller`` is offered (simulation commands).
    """
    extra = (
        f"; {CONTROLLER}: 1 / K_L, the trial controller's angular momentum damping gain"
        if controller
        else ""
    )
    parser.add_argument(
        ANGULAR_MOMENTUM_OPTION,
        type=damping_time_value(controller),
        default=None,
        metavar="TAU",
        help="CoM criterion: count the centroidal angular momentum the impulse leaves, removed "
        "by the contacts with time constant TAU s (0: at once, the conservative bound; "
        f"{OFF}: the paper's criterion{extra}; default: the scenario's "
        "angular_momentum_damping_time)",
    )


def with_angular_momentum(
    scenario: Scenario, value: float | str | None, controller_damping: float | None = None
) -> Scenario:
    """``scenario`` with the option's value (None: the scenario's own).

    Args:
        scenario: The command's scenario.
        value: The option's value: seconds, ``off`` or ``controller``.
        controller_damping: K_L (1/s) of the trial's controller, for ``controller``.

    Returns:
        The scenario to use.

    Raises:
        ScenarioError: A value the schema refuses, named as the option; ``controller`` where
            no controller gain is known.
    """
    from impact_balance.exceptions import ScenarioError

    if value is None:
        return scenario
    tau: float | None
    if value == OFF:
        tau = None
    elif value == CONTROLLER:
        if controller_damping is None or not controller_damping > 0.0:
            raise ScenarioError(
                ANGULAR_MOMENTUM_OPTION,
                value,
                "the trial's controller declares no angular momentum damping gain K_L > 0 "
                "(only the id controller does)",
            )
        tau = 1.0 / controller_damping
    else:
        tau = float(value)
    try:
        return scenario.replace(angular_momentum_damping_time=tau)
    except ScenarioError as exc:
        raise ScenarioError(ANGULAR_MOMENTUM_OPTION, exc.value, exc.reason) from None


def controller_damping(controller: str, id_damping: float) -> float | None:
    """K_L (1/s) of a trial's controller, for ``controller``: the ``id`` controller's gain.

    Args:
        controller: The trial controller's name (``id`` or ``ik``).
        id_damping: The ``id`` controller's ``angular_momentum_damping`` gain, 1/s.

    Returns:
        K_L, or None for a controller that declares none (``ik``).
    """
    return float(id_damping) if controller == "id" else None


def for_trials(
    scenario: Scenario, value: float | str | None, options: BalanceTrialOptions
) -> Scenario:
    """:func:`with_angular_momentum` with the trial controller's K_L (for ``controller``).

    K_L is the gain the trials' ``id`` controller runs with on this scenario's robot (derived
    from the robot unless ``options.robot_gains`` is False).

    Args:
        scenario: The command's scenario.
        value: The option's value (None: the scenario's own).
        options: The trials' options (their controller and its gains).

    Returns:
        The scenario the predictions use.
    """
    from impact_balance.sim.control.gains import declared_angular_momentum_damping
    from impact_balance.sim.model.build import SimOptions

    damping = None
    if value == CONTROLLER and options.controller == "id":
        gain = declared_angular_momentum_damping(
            options,
            scenario.build_stance(),
            scenario.plane_height,
            scenario.gravity,
            SimOptions().timestep,
        )
        damping = controller_damping(options.controller, gain)
    return with_angular_momentum(scenario, value, damping)
