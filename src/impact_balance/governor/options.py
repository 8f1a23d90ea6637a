"""The governor's options: its criterion and the contact-aware model's settings.

A :class:`~impact_balance.governor.Governor` takes a criterion (:data:`Criterion`), a posture
tolerance and, to opt in to the contact-aware impact model, a :class:`ContactAwareOptions`.
The margins are not options: the ZMP margin (m) and the velocity margin (m/s) are the
scenario's own keys, as :func:`~impact_balance.analyze` reads them.
"""

from __future__ import annotations

import numbers
from dataclasses import dataclass
from typing import Literal, get_args

from impact_balance.exceptions import GovernorError

__all__ = ["CRITERIA", "STARTS", "ContactAwareOptions", "Criterion", "Starts"]

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

    Raises:
        GovernorError: ``every`` not an integer >= 1, or unknown ``starts``, naming the field
            (``contact_aware.every``, ``contact_aware.starts``).
    """

    every: int = 5
    starts: Starts = "union"
    asynchronous: bool = False

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
