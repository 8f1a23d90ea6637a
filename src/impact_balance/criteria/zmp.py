"""The ZMP criterion (paper Experiment 1): :class:`ZmpCriterion`.

The impulsive force ``F = iota / dt`` at the impact point is added to the
gravity-compensating wrench (m g up, through the CoM). The predicted ZMP
``z = N(F) / (m g + F_z)`` stays in ``{G z <= h}`` iff ``G N(F) <= h (m g + F_z)`` while
``m g + F_z > 0``: linear in the approach speed per vertex and per edge, so the maximum
contact velocity is exact, as the CoM criterion's. The answer does not depend on the CoM
velocity.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import numpy.typing as npt

from impact_balance.criteria.criterion import CriterionName
from impact_balance.criteria.linear_exit import first_exit
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel

__all__ = ["ZmpCriterion", "zmp_max_contact_velocity"]


class ZmpCriterion:
    """The ZMP criterion of one ZMP support area, one impact model and one CoM.

    Attributes:
        name: "zmp".
        zmp_area: ZMP support area (world x, y on the plane), m.
        impact: The impact model.
        com: CoM (3,), world, m.
        plane_height: h, the height of the ZMP plane, m.
        gravity: m/s^2.
        duration: Impact duration dt, s (impulsive force = impulse / dt).
    """

    name: ClassVar[CriterionName] = "zmp"

    def __init__(
        self,
        zmp_area: Polygon,
        impact: ImpactModel,
        com: npt.ArrayLike,
        plane_height: float,
        gravity: float,
        duration: float,
    ):
        self.zmp_area = zmp_area
        self.impact = impact
        self.com = np.asarray(com, dtype=float)
        self.plane_height = plane_height
        self.gravity = gravity
        self.duration = duration

    def limit(self, com_velocity: npt.ArrayLike = (0.0, 0.0)) -> ContactVelocityLimit:
        """Largest approach speed keeping the predicted ZMP in the ZMP area.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s: not used (the ZMP criterion
                does not depend on it).

        Returns:
            The limit (m/s); "cannot_balance" (0) for an empty area, "already_falling" (0)
            when the CoM's vertical is outside the area.
        """
        return zmp_max_contact_velocity(
            self.zmp_area,
            self.impact,
            self.com,
            self.plane_height,
            self.gravity,
            self.duration,
        )


def zmp_max_contact_velocity(
    zmp_area: Polygon,
    impact: ImpactModel,
    com: npt.ArrayLike,
    plane_height: float,
    gravity: float,
    duration: float,
) -> ContactVelocityLimit:
    """Largest approach speed keeping the predicted ZMP in ``zmp_area`` (paper Experiment 1).

    Args:
        zmp_area: ZMP support area (world x, y on the plane), m.
        impact: The impact model.
        com: CoM (3,), world, m.
        plane_height: h, the height of the ZMP plane, m.
        gravity: m/s^2.
        duration: Impact duration dt, s (impulsive force = impulse / dt).

    Returns:
        The limit (m/s); "cannot_balance" (0) for an empty area, "already_falling" (0)
        when the CoM's vertical is outside the area; the lift-off bound (no limiting edge)
        when the impulse would lift the robot first.
    """
    if zmp_area.is_empty:
        return ContactVelocityLimit(0.0, "cannot_balance")
    G, h = zmp_area.halfplanes
    weight = impact.mass * gravity
    p = impact.point
    # With F = iota / dt at p, N(F) - m g c_xy = (plane_height - p_z) F_xy + F_z p_xy, so
    # half-plane k is used up at the rate G_k N_F - h_k F_z = iota . M_k per unit approach
    # speed, with M_k = [(plane_height - p_z) G_k, G_k p_xy - h_k] / dt.
    M = np.empty((3, len(h)))
    M[:2] = ((plane_height - float(p[2])) / duration) * G.T
    M[2] = (G @ p[:2] - h) / duration
    margins = weight * (h - G @ np.asarray(com, dtype=float)[:2])
    limit = first_exit(margins, impact.impulse_rates @ M)
    # The ZMP exists only while the vertical force stays positive (no lift-off).
    fz = impact.impulse_rates[:, 2] / duration  # N per (m/s)
    pulling = fz < 0
    if limit.status != "already_falling" and pulling.any():
        # a vanishing pull (friction ~1e-300) never lifts: inf is right
        with np.errstate(over="ignore"):
            lift = weight / -fz[pulling]
        j = int(lift.argmin())
        if lift[j] < limit.max_contact_velocity:
            return ContactVelocityLimit(float(lift[j]), "ok", int(np.flatnonzero(pulling)[j]), None)
    return limit
