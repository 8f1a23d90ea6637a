"""What a governor answers at one control tick: :class:`SpeedLimit`.

The clamp of a reference velocity into the safe speeds is
:func:`~impact_balance.criteria.cap.cap_approach`.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Literal

import numpy as np
import numpy.typing as npt

from impact_balance.criteria.cap import cap_approach
from impact_balance.criteria.criterion import CriterionName
from impact_balance.criteria.velocity_limit import LimitStatus

__all__ = ["Binding", "SpeedLimit"]

#: Which impact model gave a governor's maximum: "floating" (the paper's), "contact_aware",
#: "com_reach" or "held_stance".
Binding = Literal["floating", "contact_aware", "com_reach", "held_stance"]


@dataclass(frozen=True, slots=True)
class SpeedLimit:
    """The impact speed allowed from one posture and CoM velocity.

    Frames and units: world axes (z up), m/s. The approach speed of an end-effector velocity
    ``u`` is ``-normal . u`` (positive towards the surface).

    Attributes:
        criterion: "com" (the CoM velocity area, paper sec. V-C) or "zmp" (the predicted ZMP
            stays in the ZMP support area, the paper's Experiment 1 comparison).
        max_contact_velocity: The criterion's maximum approach speed, m/s (``inf``: no speed
            is unsafe; 0 when the robot is already falling or cannot balance), as
            ``impact-balance analyze`` reports it.
        status: "ok", "unbounded", "already_falling" or "cannot_balance"
            (see :data:`~impact_balance.criteria.velocity_limit.LimitStatus`).
        limiting_vertex: Index of the post-impact vertex (CoM) or impulse vertex (ZMP) that
            reaches the area's boundary first (None unless "ok").
        limiting_edge: Index of the area's edge it reaches (None unless "ok"; None also for
            the ZMP criterion's lift-off bound).
        safe_interval: The approach speeds ``(lo, hi)`` (m/s) that keep the robot balanced,
            or None when there are none. With the CoM velocity inside its area it is
            ``(0, max_contact_velocity)``; outside (a falling start) it is the range of
            impacts that bring it back inside (``lo > 0``), as
            :func:`~impact_balance.criteria.com.safe_interval`.
            The ZMP criterion has no falling start: ``(0, max)`` or None.
        com_velocity: The CoM velocity the answer is for (3,), world, m/s.
        normal: The impact surface's unit normal (3,), world, pointing into the robot.
        point: The impact point at this posture (3,), world, m.
        posture_reused: True when the posture was the previous call's (within the governor's
            ``posture_tolerance``) and only the CoM velocity was new (the fast path).
        binding: Which impact model gave the maximum: "floating" (the paper's set; the only
            one unless the governor is ``contact_aware``) or "contact_aware" (then
            ``limiting_vertex`` is the row of its jump rates, ``ContactAwareAnswer.rates``:
            0 / 1 the lower / upper restitution bound with one start, else one row per
            solution found, ``ContactAwareAnswer.restitution`` giving each row's bound), or
            "com_reach" (a governor with ``com_reach``: the maximum within the CoM's reach was
            smaller; ``limiting_vertex`` and ``limiting_edge`` are then the criterion's own), or
            "held_stance" (a governor with ``impact_model="held-stance"`` whose fixed point was
            reached: the held-stance jumps replace the floating model's; ``limiting_vertex`` 0 /
            1 is the lower / upper restitution bound).
        rates_age: The contact-aware rates' age in postures (posture evaluations since the
            one they were computed for; 0: this posture's); None without contact-aware rates.
        rates_age_seconds: Their age in seconds (since the governor was given the posture
            they are for; 0 while it is the current posture); None without contact-aware rates.
        stale: True when the rates were older than the options allow
            (:class:`~impact_balance.governor.options.ContactAwareOptions` ``max_age``,
            ``max_age_seconds``) and were not used: the answer is then ``on_stale``'s, zero
            approach speed (binding "contact_aware", ``max_contact_velocity`` 0, no safe
            interval) or the floating criterion alone (binding "floating").
    """

    criterion: CriterionName
    max_contact_velocity: float
    status: LimitStatus
    limiting_vertex: int | None
    limiting_edge: int | None
    safe_interval: tuple[float, float] | None
    com_velocity: npt.NDArray[np.float64]
    normal: npt.NDArray[np.float64]
    point: npt.NDArray[np.float64]
    posture_reused: bool
    binding: Binding = "floating"
    rates_age: int | None = None
    rates_age_seconds: float | None = None
    stale: bool = False

    @property
    def ceiling(self) -> float:
        """Largest approach speed :meth:`cap` lets through, m/s.

        The safe interval's top, 0 when there is no safe speed.
        """
        return 0.0 if self.safe_interval is None else self.safe_interval[1]

    def cap(self, reference_velocity: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The reference velocity with its approach speed brought into the safe interval.

        Args:
            reference_velocity: (3,) world, m/s.

        Returns:
            See :func:`~impact_balance.criteria.cap.cap_approach`.
        """
        return cap_approach(reference_velocity, self.normal, self.safe_interval)


# The slots' setters, in field order: a tick builds its answer with them (below).
(
    _criterion,
    _max_contact_velocity,
    _status,
    _limiting_vertex,
    _limiting_edge,
    _safe_interval,
    _com_velocity,
    _normal,
    _point,
    _posture_reused,
    _binding,
    _rates_age,
    _rates_age_seconds,
    _stale,
) = (SpeedLimit.__dict__[f.name].__set__ for f in fields(SpeedLimit))
_new = object.__new__


def _floating_limit(
    criterion: CriterionName,
    max_contact_velocity: float,
    status: LimitStatus,
    limiting_vertex: int | None,
    limiting_edge: int | None,
    safe_interval: tuple[float, float] | None,
    com_velocity: npt.NDArray[np.float64],
    normal: npt.NDArray[np.float64],
    point: npt.NDArray[np.float64],
    posture_reused: bool,
) -> SpeedLimit:
    """``SpeedLimit(...)`` of the floating model (the other fields at their defaults).

    The same object, built by setting its slots directly: the frozen dataclass's ``__init__``
    calls ``object.__setattr__`` once per field, half of a velocity-only tick's answer.
    """
    self = _new(SpeedLimit)
    _criterion(self, criterion)
    _max_contact_velocity(self, max_contact_velocity)
    _status(self, status)
    _limiting_vertex(self, limiting_vertex)
    _limiting_edge(self, limiting_edge)
    _safe_interval(self, safe_interval)
    _com_velocity(self, com_velocity)
    _normal(self, normal)
    _point(self, point)
    _posture_reused(self, posture_reused)
    _binding(self, "floating")
    _rates_age(self, None)
    _rates_age_seconds(self, None)
    _stale(self, False)
    return self
