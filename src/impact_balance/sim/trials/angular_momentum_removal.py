"""How fast a trial's controller removed the angular momentum a disturbance left.

The CoM criterion's angular momentum term (:mod:`impact_balance.impact.angular_momentum`)
counts the centroidal angular momentum ``L0`` (N m s, world, about the CoM) that an impulse
leaves, and what removing it costs the capture: removed through the contacts as ``L(t)``, the
cost is ``sum_k exp(-omega t_k) (L(t_{k-1}) - L(t_k))``, the decrements of L weighted by the
LIPM's divergence ``exp(-omega t)`` (t from the disturbance's end). Removed at once it is
``L0``; removed exponentially with time constant tau it is ``L0 / (1 + omega tau)``, the
term's factor. A trial measures the weighted decrements per world axis
(``angular_momentum_removed``); over ``angular_momentum_at_end`` they give the controller's
*realised* share ``rho`` of the immediate removal's cost, and the time constant that would cost
the same, ``tau = (1 / rho - 1) / omega`` (:func:`equivalent_damping_time`). A controller that
declares a gain ``K_L`` may realise a slower removal (its angular momentum task weighs little
against its CoM task): this is how to tell, per robot and axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt

__all__ = ["AngularMomentumRemoval", "equivalent_damping_time"]


@dataclass
class AngularMomentumRemoval:
    """Accumulates the divergence-weighted decrements of L after a disturbance.

    Attributes:
        omega: The stance's LIPM natural frequency, 1/s.
        start: When the disturbance ended (s): the weights' origin.
        last: L at the last sample, world, N m s.
        removed: ``sum exp(-omega (t_k - start)) (L_{k-1} - L_k)``, world, N m s.
        samples: Samples added after the first.
    """

    omega: float
    start: float
    last: npt.NDArray[np.float64]
    removed: npt.NDArray[np.float64] = field(default_factory=lambda: np.zeros(3))
    samples: int = 0

    def add(self, t: float, angular_momentum: npt.ArrayLike) -> None:
        """One sample of L (N m s, world) at time ``t`` (s, at or after ``start``)."""
        now = np.asarray(angular_momentum, dtype=float)
        weight = math.exp(-self.omega * max(0.0, t - self.start))
        self.removed = self.removed + weight * (self.last - now)
        self.last = now
        self.samples += 1


def equivalent_damping_time(removed: float, at_end: float, omega: float) -> float | None:
    """The exponential removal's time constant (s) that costs what was measured, on one axis.

    Args:
        removed: The axis' weighted decrements (N m s, :attr:`AngularMomentumRemoval.removed`).
        at_end: The axis' angular momentum when the disturbance ended, N m s (nonzero).
        omega: LIPM natural frequency, 1/s (> 0).

    Returns:
        ``(1 / rho - 1) / omega`` with ``rho = removed / at_end``: 0 for ``rho >= 1`` (removed
        at once, or overshooting), None for ``rho <= 0`` (never removed: the paper's case) or a
        zero ``at_end``.
    """
    if at_end == 0.0 or not (omega > 0.0):
        return None
    rho = removed / at_end
    if not rho > 0.0:
        return None
    return max(0.0, (1.0 / rho - 1.0) / omega)
