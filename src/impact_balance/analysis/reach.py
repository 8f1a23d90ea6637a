"""An analysis's answer within the CoM's reach (``analyze --com-reach``).

:func:`reach_answer` computes the CoM's reach of an :class:`~.result.Analysis`'s stance
(:func:`impact_balance.balance.reach.com_reach`, whole-body IK) and what it limits: the CoM
speed captured within reach along each azimuth, and the project's default maximum contact
velocity lowered so that every post-impact CoM velocity (the paper's vertices, and their
effective twins when the angular momentum is counted) also stays within reach. The areas are
the analysis's own, inset by its ZMP margin. See docs/com-reach.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance.analysis.result import Analysis
from impact_balance.balance.reach import (
    ComReach,
    ReachOptions,
    com_reach,
    reach_speed_limit,
)
from impact_balance.impact.within_reach import max_contact_velocity_within_reach

__all__ = ["ReachAnswer", "reach_answer"]


@dataclass(frozen=True)
class ReachAnswer:
    """The CoM's reach of a stance and what it limits.

    Attributes:
        reach: The reach (m) per azimuth, with the postures that reach it.
        speed_limits: (N,) the CoM speed captured within reach along each azimuth, m/s.
        max_contact_velocity: The default maximum contact velocity lowered to keep every
            post-impact CoM velocity within reach, m/s (None without an impact; 0 when the
            robot cannot balance or the pre-impact velocity is already out of reach).
        default_max_contact_velocity: The default's own answer, for comparison, m/s (None
            without an impact).
    """

    reach: ComReach
    speed_limits: npt.NDArray[np.float64]
    max_contact_velocity: float | None
    default_max_contact_velocity: float | None

    def to_dict(self) -> dict[str, Any]:
        """JSON form (``analyze --com-reach --json``'s ``com_reach``)."""

        def number(x: float | None) -> float | None:
            return None if x is None or not math.isfinite(x) else float(x)

        return {
            **self.reach.to_dict(),
            "speed_limits": self.speed_limits.tolist(),
            "max_contact_velocity": number(self.max_contact_velocity),
            "default_max_contact_velocity": number(self.default_max_contact_velocity),
        }


def reach_answer(
    analysis: Analysis, options: ReachOptions | None = None, *, reach: ComReach | None = None
) -> ReachAnswer:
    """The CoM's reach of ``analysis``'s stance and what it limits (module docstring).

    Args:
        analysis: An analysis (its stance, areas with their margin, and impact answer).
        options: The reach search (default :class:`~impact_balance.balance.reach.ReachOptions`).
        reach: A reach already computed (e.g. of the stance's initial posture, as a governor
            keeps it); then ``options`` is not used and no search runs.
    """
    reach = com_reach(analysis.stance, options) if reach is None else reach
    areas = analysis.areas
    omega = float(areas.omega)
    area = areas.com_velocity_area
    if not areas.can_balance or area.is_empty:
        limits = np.zeros(len(reach.azimuths))
    else:
        directions = np.column_stack([np.cos(reach.azimuths), np.sin(reach.azimuths)])
        limits = np.array([reach_speed_limit(area, omega, reach, u) for u in directions])
    impact = analysis.impact
    if impact is None:
        return ReachAnswer(reach, limits, None, None)
    default = float(impact.default.max_contact_velocity)
    if not areas.can_balance or area.is_empty or not impact.default.from_inside:
        return ReachAnswer(reach, limits, 0.0, default)
    speed = max_contact_velocity_within_reach(
        area,
        omega,
        reach,
        impact.model,
        analysis.com_velocity[:2],
        impact.angular_momentum,
        default,
    )
    return ReachAnswer(reach, limits, speed, default)
