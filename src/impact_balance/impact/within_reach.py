"""The maximum contact velocity whose post-impact CoM velocities stay within the CoM's reach.

One implementation for :func:`impact_balance.analysis.reach.reach_answer` (``analyze
--com-reach``, ``validate --com-reach``) and the governor's cap within reach
(``Governor(com_reach=...)``): the post-impact CoM velocities ``start + s d_j`` of the impact
model's vertices (and, with the angular momentum term, their effective twins) must each satisfy
:func:`~impact_balance.balance.reach.reach_speed_limit` along its own direction
(:func:`~impact_balance.balance.reach.reach_max_speed`). See docs/com-reach.md.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from impact_balance.balance.reach import ComReach, reach_max_speed
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.angular_momentum import AngularMomentumTerm, effective_impulse_rates
from impact_balance.impact.model import ImpactModel

__all__ = ["max_contact_velocity_within_reach"]


def max_contact_velocity_within_reach(
    area: Polygon,
    omega: float,
    reach: ComReach,
    model: ImpactModel,
    start: npt.ArrayLike,
    angular_momentum: AngularMomentumTerm | None,
    upper: float,
) -> float:
    """The largest approach speed ``s <= upper`` (m/s) keeping the CoM velocities within reach.

    Args:
        area: The CoM velocity area (m/s, world xy), inset by the ZMP margin the controller keeps.
        omega: LIPM natural frequency, 1/s.
        reach: The CoM's reach (:func:`~impact_balance.balance.reach.com_reach`).
        model: The impact model (its CoM velocity jumps per unit approach speed, world xy).
        start: (2,) pre-impact CoM velocity, world xy, m/s.
        angular_momentum: The angular momentum term (its effective velocities must also stay
            within reach), or None (the paper's velocities only).
        upper: The criterion's own maximum contact velocity, m/s (the answer's upper bound).

    Returns:
        The speed, m/s: at most ``upper``; 0 when ``start`` is itself out of reach.
    """
    jumps = [model.com_jump_rates]
    if angular_momentum is not None:
        effective = effective_impulse_rates(model.impulse_rates, angular_momentum)
        jumps.append(effective[:, :2] / model.mass)
    speed = reach_max_speed(area, omega, reach, start, np.vstack(jumps), upper)
    return min(speed, float(upper))
