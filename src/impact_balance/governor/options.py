"""The governor's options: its criterion, the contact-aware model's settings, the CoM's reach.

A :class:`~impact_balance.governor.Governor` takes a criterion (:data:`Criterion`), a posture
tolerance, to opt in to the contact-aware impact model a :class:`ContactAwareOptions`, and to
cap within the CoM's reach a reach (:func:`reach_option`).
The margins are not options: the ZMP margin (m) and the velocity margin (m/s) are the
scenario's own keys, as :func:`~impact_balance.analyze` reads them.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal, get_args

from impact_balance.exceptions import GovernorError
from impact_balance.impact import IMPACT_MODELS

if TYPE_CHECKING:
    from impact_balance.balance.reach import ComReach, ReachOptions
    from impact_balance.contacts.stance import Stance

__all__ = [
    "CRITERIA",
    "IMPACT_MODELS",
    "ON_STALE",
    "STARTS",
    "ContactAwareOptions",
    "Criterion",
    "OnStale",
    "Starts",
    "held_stance_option",
    "reach_option",
]

#: A governor's criterion: "com", the CoM velocity area (the paper's); "zmp", the predicted
#: ZMP stays in the ZMP support area (the paper's Experiment 1 comparison).
Criterion = Literal["com", "zmp"]
#: Every :data:`Criterion`, in order.
CRITERIA: tuple[Criterion, ...] = get_args(Criterion)

#: The contact-aware fixed point's starts (see :mod:`impact_balance.governor.support`):
#: "union" (every solution reached from the kept solutions and the cold start), "warm" (the
#: previous answer only) or "cold" (gauges 0 only).
Starts = Literal["union", "warm", "cold"]
#: Every :data:`Starts`, in order.
STARTS: tuple[Starts, ...] = get_args(Starts)

#: What an asynchronous governor answers when its contact-aware rates are older than the
#: options' ages allow: "zero" (no approach speed: ``max_contact_velocity`` 0, the approach
#: component removed by the cap), "floating" (the floating criterion alone, with the velocity
#: margin: the paper's governor, which is above the contact-aware cap where that binds) or
#: "raise" (:class:`~impact_balance.exceptions.GovernorError`).
OnStale = Literal["zero", "floating", "raise"]
#: Every :data:`OnStale`, in order.
ON_STALE: tuple[OnStale, ...] = get_args(OnStale)


@dataclass(frozen=True)
class ContactAwareOptions:
    """The contact-aware impact model's settings (a governor with the "com" criterion).

    The governor then also bounds the speed by the CoM velocity jump of the robot standing on
    its supports (:mod:`impact_balance.governor.support`), and answers the smaller maximum.

    Attributes:
        every: Recompute its jump rates every this many posture evaluations (>= 1).
        starts: The fixed point's starts (:data:`Starts`; default "union").
        asynchronous: Recompute the rates in a worker process (:mod:`.worker`, POSIX) instead
            of in the tick: the tick never waits and uses rates one recomputation old; close
            the governor (or use ``with``) to stop the worker.
        max_age: With ``asynchronous``: the oldest rates the governor answers with, in
            postures (posture evaluations since the one the rates were computed for;
            :attr:`~impact_balance.governor.limit.SpeedLimit.rates_age`). Default 250 (0.5 s
            of postures at 500 Hz; a recomputation takes 12 to 170 ms on the bundled stances).
        max_age_seconds: With ``asynchronous``: the oldest rates in seconds (since the governor
            handed the worker the posture they are for; 0 while that is still the current
            posture). Default 0.5 s.
        on_stale: What an asynchronous governor answers beyond either age (:data:`OnStale`):
            "zero" (default), "floating" or "raise". The synchronous governor recomputes the
            rates in the tick every ``every`` postures: its rates are never stale.

    Raises:
        GovernorError: ``every`` not an integer >= 1, unknown ``starts`` or ``on_stale``, an
            age that is not a number >= 0, naming the field (``contact_aware.every``...).
    """

    every: int = 5
    starts: Starts = "union"
    asynchronous: bool = False
    max_age: int = 250
    max_age_seconds: float = 0.5
    on_stale: OnStale = "zero"

    def __post_init__(self) -> None:
        """Check the settings (see the class docstring)."""
        every = self.every
        if isinstance(every, bool) or not isinstance(every, numbers.Integral) or every < 1:
            raise GovernorError("contact_aware.every", every, "must be an integer >= 1")
        object.__setattr__(self, "every", int(every))
        if self.starts not in STARTS:
            raise GovernorError(
                "contact_aware.starts", self.starts, f"must be one of {', '.join(STARTS)}"
            )
        age = self.max_age
        if isinstance(age, bool) or not isinstance(age, numbers.Integral) or age < 0:
            raise GovernorError("contact_aware.max_age", age, "must be an integer >= 0 (postures)")
        object.__setattr__(self, "max_age", int(age))
        seconds = self.max_age_seconds
        if (
            isinstance(seconds, bool)
            or not isinstance(seconds, numbers.Real)
            or not math.isfinite(float(seconds))
            or seconds < 0
        ):
            raise GovernorError(
                "contact_aware.max_age_seconds", seconds, "must be a finite number >= 0 (s)"
            )
        object.__setattr__(self, "max_age_seconds", float(seconds))
        if self.on_stale not in ON_STALE:
            raise GovernorError(
                "contact_aware.on_stale", self.on_stale, f"must be one of {', '.join(ON_STALE)}"
            )


def reach_option(
    value: ComReach | ReachOptions | bool | None, criterion: Criterion, stance: Stance
) -> ComReach | None:
    """The CoM's reach a governor caps within, from its ``com_reach`` argument.

    Args:
        value: None or False (no reach); True (:func:`~impact_balance.balance.reach.com_reach`
            of ``stance`` with the default search, a few seconds); a
            :class:`~impact_balance.balance.reach.ReachOptions` (that search of ``stance``); or
            a :class:`~impact_balance.balance.reach.ComReach` already computed (used as is).
        criterion: The governor's criterion (the reach needs "com").
        stance: The stance the governor is built on (its initial posture and contacts).

    Returns:
        The reach, or None.

    Raises:
        GovernorError: another type, or a reach with the "zmp" criterion (field ``com_reach``).
    """
    from impact_balance.balance.reach import ComReach, ReachOptions, com_reach

    if value is None or value is False:
        return None
    if not isinstance(value, ComReach | ReachOptions) and value is not True:
        raise GovernorError(
            "com_reach", value, "must be True, False, None, a ReachOptions or a ComReach"
        )
    if criterion != "com":
        raise GovernorError("com_reach", value, 'the reach caps the "com" criterion only')
    if isinstance(value, ComReach):
        return value
    return com_reach(stance, None if value is True else value)


def held_stance_option(
    impact_model: object, criterion: Criterion, contact_aware: object, com_reach: object
) -> None:
    """Check a governor's ``impact_model`` against its other options.

    Args:
        impact_model: One of :data:`IMPACT_MODELS`.
        criterion: The governor's criterion ("held-stance" needs "com").
        contact_aware: The governor's ``contact_aware`` (off with "held-stance").
        com_reach: The governor's ``com_reach`` (off with "held-stance").

    Raises:
        GovernorError: An unknown model, or "held-stance" with the "zmp" criterion,
            ``contact_aware`` or ``com_reach`` (field ``impact_model``).
    """
    if not isinstance(impact_model, str) or impact_model not in IMPACT_MODELS:
        raise GovernorError(
            "impact_model", impact_model, f"must be one of {', '.join(IMPACT_MODELS)}"
        )
    if impact_model == "floating":
        return
    if criterion != "com":
        raise GovernorError("impact_model", impact_model, 'answers the "com" criterion only')
    for name, value in (("contact_aware", contact_aware), ("com_reach", com_reach)):
        if value is not None and value is not False:
            raise GovernorError("impact_model", impact_model, f"does not combine with {name}")
