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


def pushed_state(accel: float, duration: float, omega: float) -> tuple[float, float]:
    """The LIPM CoM (m) and velocity (m/s) at the end of a constant push, from rest at 0.

    ``c'' = omega^2 (c - 0) + accel`` for ``duration`` s (``accel = F / m``, m/s^2), the ZMP
    held under the starting CoM.
    """

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], omega**2 * y[0] + accel]

    if duration == 0.0:
        return 0.0, 0.0
    out = solve_ivp(rhs, (0.0, duration), [0.0, 0.0], rtol=1e-11, atol=1e-13)
    return float(out.y[0, -1]), float(out.y[1, -1])


def captured_after_push(
    accel: float, duration: float, extent: float, omega: float, horizon: float = 30.0
) -> bool:
    """Whether the CoM comes to rest once the ZMP jumps to ``extent`` (m) at the push's end.

    The push of :func:`pushed_state`, then ``c'' = omega^2 (c - extent)`` until ``c' = 0``
    (captured) or the CoM passes ``extent`` (not).
    """
    c, v = pushed_state(accel, duration, omega)

    def rhs(_t: float, y: np.ndarray) -> list[float]:
        return [y[1], omega**2 * (y[0] - extent)]

    def stopped(_t: float, y: np.ndarray) -> float:
        return float(y[1])

    def passed(_t: float, y: np.ndarray) -> float:
        return float(y[0] - extent)

    stopped.terminal = True  # type: ignore[attr-defined]
    passed.terminal = True  # type: ignore[attr-defined]
    out = solve_ivp(rhs, (0.0, horizon), [c, v], events=[stopped, passed], rtol=1e-11, atol=1e-13)
    return out.t_events[0].size > 0
