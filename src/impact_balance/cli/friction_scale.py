"""``--friction-scale S``: the criterion sees every contact's friction times S.

The option sets the scenario key ``friction_scale`` (in (0, 1]; docs/robots.md) for one
command: the areas (and every answer from them) are those of contacts whose friction is S times
their own, the balance a controller that keeps its contact forces within that share of the
friction cone can realise. 1 is the paper's criterion. The simulation commands also take
``controller``: S is the trial controller's own friction scale (the ``id`` controller's
``friction_scale`` gain); the simulated contacts keep their friction.
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
    "CONTROLLER",
    "FRICTION_SCALE_OPTION",
    "add_friction_scale_option",
    "friction_scale_for_trials",
    "friction_scale_value",
    "with_friction_scale",
]

#: The option's name.
FRICTION_SCALE_OPTION = "--friction-scale"
#: The simulation commands' value: the trial controller's friction scale.
CONTROLLER = "controller"


def friction_scale_value(controller: bool) -> Callable[[str], float | str]:
    """Argparse type: a number in (0, 1], or (``controller``) the word ``controller``.

    Args:
        controller: Whether ``controller`` is accepted (the simulation commands).

    Returns:
        The type: text to a float or to the word; a :class:`CommandLineError` naming the
        option and the value otherwise.
    """
    words = f" or {CONTROLLER}" if controller else ""
    return number_or_words(
        FRICTION_SCALE_OPTION,
        (CONTROLLER,) if controller else (),
        lambda value: 0.0 < value <= 1.0,
        f"not a number in (0, 1]{words}",
        f"must be in (0, 1]{words}",
        "friction scale",
    )


def add_friction_scale_option(parser: argparse.ArgumentParser, controller: bool) -> None:
    """Add ``--friction-scale S``.

    Args:
        parser: The command's parser.
        controller: Whether the value ``controller`` is offered (simulation commands).
    """
    extra = (
        f"; {CONTROLLER}: the trial controller's own (the id controller's friction_scale gain, "
        "0.65)"
        if controller
        else ""
    )
    parser.add_argument(
        FRICTION_SCALE_OPTION,
        type=friction_scale_value(controller),
        default=None,
        metavar="S",
        help="the criterion sees every contact's friction times S, in (0, 1]: the balance a "
        "controller that uses that share of the friction cones can realise (1: the paper's"
        f"{extra}; default: the scenario's friction_scale, 1 unless set)",
    )


def with_friction_scale(
    scenario: Scenario, value: float | str | None, controller_scale: float | None = None
) -> Scenario:
    """``scenario`` with the option's value (None: the scenario's own).

    Args:
        scenario: The command's scenario.
        value: The option's value: a number or ``controller``.
        controller_scale: The trial controller's friction scale, for ``controller``.

    Returns:
        The scenario to use.

    Raises:
        ScenarioError: A value the schema refuses, named as the option; ``controller`` where
            the controller has no friction scale.
    """
    from impact_balance.exceptions import ScenarioError

    if value is None:
        return scenario
    if value == CONTROLLER:
        if controller_scale is None:
            raise ScenarioError(
                FRICTION_SCALE_OPTION,
                value,
                "the trial's controller has no friction scale (only the id controller does)",
            )
        scale = float(controller_scale)
    else:
        scale = float(value)
    try:
        return scenario.replace(friction_scale=scale)
    except ScenarioError as exc:
        raise ScenarioError(FRICTION_SCALE_OPTION, exc.value, exc.reason) from None


def friction_scale_for_trials(
    scenario: Scenario, value: float | str | None, options: BalanceTrialOptions
) -> Scenario:
    """:func:`with_friction_scale` with the trial controller's friction scale (``controller``).

    Args:
        scenario: The command's scenario.
        value: The option's value (None: the scenario's own).
        options: The trials' options (their controller and its gains).

    Returns:
        The scenario the predictions use.
    """
    scale = options.id_gains.friction_scale if options.controller == "id" else None
    return with_friction_scale(scenario, value, scale)
