"""The answer of a criterion: how fast may the contact be hit (:class:`ContactVelocityLimit`).

Every criterion (:mod:`impact_balance.criteria.com`, :mod:`impact_balance.criteria.zmp`)
answers with a :class:`ContactVelocityLimit`: the maximum contact velocity (the largest safe
approach speed, m/s, ``-normal . v`` of the end-effector velocity, positive towards the
surface) and a :data:`LimitStatus` saying how it was reached.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

__all__ = ["LIMITED", "ContactVelocityLimit", "LimitStatus"]

#: How a criterion reached its answer:
#:
#: - ``"ok"``: a finite maximum, some post-impact state reaches the area's boundary there;
#: - ``"unbounded"``: no approach speed leaves the area (the maximum is ``inf``);
#: - ``"already_falling"``: the pre-impact state is already outside the area (maximum 0);
#: - ``"cannot_balance"``: the area is empty (maximum 0).
LimitStatus = Literal["ok", "unbounded", "already_falling", "cannot_balance"]

#: The statuses of a limit reached from inside the area: the safe speeds are ``[0, max]``.
LIMITED: tuple[LimitStatus, ...] = ("ok", "unbounded")


@dataclass(frozen=True)
class ContactVelocityLimit:
    """The largest safe approach speed of one criterion.

    Attributes:
        max_contact_velocity: m/s (``inf`` when no approach speed can leave the area; 0 when
            the robot is already falling or cannot balance).
        status: How it was reached (see :data:`LimitStatus`).
        limiting_vertex: Index of the post-impact vertex that reaches the boundary first
            (None unless "ok").
        limiting_edge: Index of the area's half-plane it reaches (None unless "ok"; None also
            for the ZMP criterion's lift-off bound).
    """

    max_contact_velocity: float
    status: LimitStatus
    limiting_vertex: int | None = None
    limiting_edge: int | None = None

    @property
    def is_finite(self) -> bool:
        """Whether :attr:`max_contact_velocity` is a finite number."""
        return math.isfinite(self.max_contact_velocity)

    @property
    def from_inside(self) -> bool:
        """Whether the pre-impact state is inside the area ("ok" or "unbounded")."""
        return self.status in LIMITED

    def interval_from_inside(self) -> tuple[float, float] | None:
        """The safe approach speeds when the limit is reached from inside the area.

        From inside, every speed up to the maximum is safe, so the safe speeds are the
        interval ``(0, max_contact_velocity)`` (m/s; the top may be inf).

        Returns:
            ``(0.0, max_contact_velocity)`` when :attr:`from_inside`, else None (the safe
            speeds, if any, must then be computed from the margins).
        """
        if self.from_inside:
            return 0.0, self.max_contact_velocity
        return None
