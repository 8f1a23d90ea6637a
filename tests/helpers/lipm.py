"""A LIPM integrated by scipy, independent of the project's formulas."""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp


def stop_distance(speed: float, extent: float, omega: float) -> float:
    """Where a LIPM CoM leaving 0 at ``speed`` (m/s) stops, the ZMP held at ``extent`` (m).

    ``c'' = omega^2 (c - extent)`` integrated until ``c' = 0``; inf if it never stops (it runs
    past the ZMP).
    """

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], omega**2 * (y[0] - extent)]

    def stopped(_t: float, y: np.ndarray) -> float:
        return float(y[1])

    stopped.terminal = True  # type: ignore[attr-defined]
    out = solve_ivp(rhs, (0.0, 20.0), [0.0, speed], events=stopped, rtol=1e-10, atol=1e-12)
    if out.t_events[0].size == 0:
        return math.inf
    return float(out.y_events[0][0][0])
