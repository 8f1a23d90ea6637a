"""Scoring a balance criterion against trial outcomes: confusion matrices with Wilson intervals.

A criterion predicts "safe" or "unsafe" for each trial; the trial's outcome says whether the robot
**fell** (:mod:`.outcomes`). ``contact_broken`` counts as *not fell*: the robot came to rest without
a step, which is what the balance criterion promises (contact breaks are reported on their own).
Aborted trials test nothing and are left out.

Rates are given with their 95 % Wilson score interval (Wilson 1927), which stays inside [0, 1] and
is sound for small counts and for rates near 0 or 1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["MARGIN_GRID", "confusion", "wilson"]

#: ZMP margins (m) searched for the smallest one that brings "predicted safe, fell" to a target
#: rate.
MARGIN_GRID = tuple(round(0.001 * k, 3) for k in range(61))


def wilson(successes: int, total: int, z: float = 1.959963984540054) -> list[float] | None:
    """95 % Wilson score interval ``[lo, hi]`` of a proportion (None when ``total`` is 0)."""
    if total <= 0:
        return None
    p = successes / total
    denominator = 1.0 + z * z / total
    centre = (p + z * z / (2 * total)) / denominator
    half = z * math.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / denominator
    return [max(0.0, centre - half), min(1.0, centre + half)]


def confusion(predicted_safe: Sequence[bool], fell: Sequence[bool]) -> dict[str, Any]:
    """Counts of a criterion's predictions against the falls, and its rates with Wilson intervals.

    ``accuracy``: share of trials whose outcome it predicted; ``safe_fell_rate``: share of all
    trials it called safe that fell; ``fell_given_safe``: share of those it called safe that fell;
    ``survived_given_unsafe``: share of those it called unsafe that did not fall.
    """
    p = np.asarray(predicted_safe, dtype=bool)
    f = np.asarray(fell, dtype=bool)
    n = len(p)
    safe_survived, safe_fell = int(np.sum(p & ~f)), int(np.sum(p & f))
    unsafe_survived, unsafe_fell = int(np.sum(~p & ~f)), int(np.sum(~p & f))
    right = safe_survived + unsafe_fell
    safe, unsafe = safe_survived + safe_fell, unsafe_survived + unsafe_fell
    return {
        "safe_survived": safe_survived,
        "safe_fell": safe_fell,
        "unsafe_survived": unsafe_survived,
        "unsafe_fell": unsafe_fell,
        "total": n,
        "accuracy": right / n if n else None,
        "accuracy_ci95": wilson(right, n),
        "safe_fell_rate": safe_fell / n if n else None,
        "safe_fell_rate_ci95": wilson(safe_fell, n),
        "fell_given_safe": safe_fell / safe if safe else None,
        "survived_given_unsafe": unsafe_survived / unsafe if unsafe else None,
    }
