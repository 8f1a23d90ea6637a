"""Test helpers for the CoM's reach: a reach of given radii, and an area's extent found apart
from the module's own :func:`~impact_balance.balance.reach.ray_extent`."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from impact_balance.balance.reach import ComReach
from impact_balance.geometry.polygon import Polygon


def evenly_spaced_reach(radii: npt.ArrayLike, height: float = 0.8, nq: int = 1) -> ComReach:
    """A reach of ``radii`` (m) at evenly spaced azimuths from +x, placeholder postures."""
    r = np.asarray(radii, dtype=float)
    n = len(r)
    return ComReach(np.arange(n) * 2 * math.pi / n, r, height, np.zeros((n, nq)))


def extent_by_bisection(area: Polygon, u: np.ndarray) -> float:
    """The area's extent along ``u`` by bisection on ``contains`` (not the module's margins)."""
    lo, hi = 0.0, 10.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if area.contains(mid * u, tol=0.0) else (lo, mid)
    return lo
