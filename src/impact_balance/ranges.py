"""What the numerics can do: the ranges of the simulation commands' numbers and the size of a sweep.

Each limit says why it is where it is. A value outside is refused at once, naming the option
and the range, rather than accepted and run for ever, or answered with NaN:

- **approach speed** (``simulate --speed``) in [:data:`MIN_APPROACH_SPEED`,
  :data:`MAX_APPROACH_SPEED`] m/s: a trial starts the impact point at least 2 cm from the
  surface, so 0.01 m/s is already 2 s of simulated approach (1e-300 m/s would be 10^298 s); beyond
  5 m/s MuJoCo's soft
  contact at its time step is no longer an impact model;
- **bisection tolerance** (``validate --tolerance``) in :data:`TOLERANCE_RANGE`: each halving of
  the bracket is one more simulated trial (10 trials for 0.001); below 0.001 the bracket is
  narrower than the simulator's own repeatability, and below the float resolution it never closes;
- **sweep size**: at most :data:`MAX_SWEEP_POINTS` points (grid: the product of the axes' counts,
  computed exactly before anything is allocated; quasi-random: ``samples``), at most
  :data:`MAX_SWEEP_CHUNKS` chunks. The summary reads every row into memory (about 1 kB a row).

This module imports nothing heavy: the command line checks options with it before it loads
MuJoCo.
"""

from __future__ import annotations

import math

from impact_balance.exceptions import SimulationError

__all__ = [
    "MAX_APPROACH_SPEED",
    "MAX_SWEEP_CHUNKS",
    "MAX_SWEEP_POINTS",
    "MIN_APPROACH_SPEED",
    "TOLERANCE_RANGE",
    "check_approach_speed",
    "check_tolerance",
]

#: Slowest approach speed of an impact trial, m/s (2 cm of approach take 2 s at this speed).
MIN_APPROACH_SPEED = 0.01
#: Fastest approach speed of an impact trial, m/s (beyond, MuJoCo's soft contact at this step is
#: not an impact model).
MAX_APPROACH_SPEED = 5.0
#: Relative width of the fall-threshold bracket of ``validate``: [tightest, loosest].
TOLERANCE_RANGE = (1e-3, 0.5)
#: Most points in one sweep (grid or quasi-random).
MAX_SWEEP_POINTS = 1_000_000
#: Most chunks in one sweep (each is one part file).
MAX_SWEEP_CHUNKS = 100_000


def check_approach_speed(value: float, field: str = "--speed") -> float:
    """``value`` if it is a usable approach speed (m/s).

    Raises:
        SimulationError: Otherwise, naming ``field``.
    """
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or not MIN_APPROACH_SPEED <= value <= MAX_APPROACH_SPEED
    ):
        raise SimulationError(
            field,
            value,
            f"approach speed must be in [{MIN_APPROACH_SPEED:g}, {MAX_APPROACH_SPEED:g}] m/s "
            f"(slower never reaches the surface in a simulation of sensible length)",
        )
    return float(value)


def check_tolerance(value: float, field: str = "--tolerance") -> float:
    """``value`` if it is a usable relative bracket width.

    Raises:
        SimulationError: Otherwise, naming ``field``.
    """
    lo, hi = TOLERANCE_RANGE
    if (
        isinstance(value, bool)
        or not isinstance(value, (int, float))
        or not math.isfinite(value)
        or not lo <= value <= hi
    ):
        raise SimulationError(
            field,
            value,
            f"must be in [{lo:g}, {hi:g}] (each halving of the bracket is one more "
            f"trial; a tighter bracket is below the simulator's repeatability)",
        )
    return float(value)
