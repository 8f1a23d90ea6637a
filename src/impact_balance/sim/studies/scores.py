"""Scoring a balance criterion against trial outcomes: confusion matrices with Wilson intervals.

A criterion predicts "safe" or "unsafe" for each trial; the trial's outcome says whether the robot
**failed**. Two outcomes are scored (:mod:`impact_balance.sim.trials.outcomes`):

- *lenient*: the trial ``fell``; ``contact_broken`` counts as standing (the robot came to rest
  without a step);
- *strict*: the trial fell, or broke a contact beyond the strict bounds (``strict_fail``): the
  criterion's premise, sustained contacts, no longer held.

Aborted trials test nothing and are left out.

The headline rates are the ones a safety criterion is judged by, each with its counts:

- ``fell_given_safe``: P(failed | predicted safe), the **false-safe rate**;
- ``stood_given_unsafe``: P(stood | predicted unsafe), how conservative the criterion is;
- ``safe_given_stood``: the share of the trials that stood which the criterion calls safe.

Rates are given with their 95 % Wilson score interval (Wilson 1927), which stays inside [0, 1] and
is sound for small counts and for rates near 0 or 1.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

__all__ = ["FALSE_SAFE_TARGET", "MARGIN_GRID", "confusion", "rate", "wilson"]

#: ZMP margins (m) searched for the smallest one that brings the false-safe rate to a target.
MARGIN_GRID = tuple(round(0.001 * k, 3) for k in range(61))
#: Target false-safe rate P(fell | predicted safe) of the margin study.
FALSE_SAFE_TARGET = 0.05


def wilson(successes: int, total: int, z: float = 1.959963984540054) -> list[float] | None:
    """95 % Wilson score interval ``[lo, hi]`` of a proportion (None when ``total`` is 0)."""
    if total <= 0:
        return None
    p = successes / total
    denominator = 1.0 + z * z / total
    centre = (p + z * z / (2 * total)) / denominator
    half = z * math.sqrt(p * (1 - p) / total + z * z / (4 * total * total)) / denominator
    lo = 0.0 if successes <= 0 else max(0.0, centre - half)  # exact ends, no rounding residue
    hi = 1.0 if successes >= total else min(1.0, centre + half)
    return [lo, hi]


def rate(successes: int, total: int) -> dict[str, Any]:
    """A proportion with its counts and its Wilson interval: ``{rate, ci95, count, of}``.

    ``rate`` and ``ci95`` are None when ``total`` is 0.
    """
    return {
        "rate": successes / total if total else None,
        "ci95": wilson(successes, total),
        "count": int(successes),
        "of": int(total),
    }


def confusion(predicted_safe: Sequence[bool], fell: Sequence[bool]) -> dict[str, Any]:
    """A criterion's predictions against the failures: the conditional rates first, then counts.

    Args:
        predicted_safe: Whether the criterion called each trial safe.
        fell: Whether each trial failed (fell, or failed strictly: whichever outcome is scored).

    Returns:
        ``fell_given_safe`` (P(failed | predicted safe), the false-safe rate),
        ``stood_given_unsafe`` (P(stood | predicted unsafe)) and ``safe_given_stood`` (the share
        of the trials that stood called safe), each as :func:`rate`; the four counts
        (``safe_survived``, ``safe_fell``, ``unsafe_survived``, ``unsafe_fell``), ``total``,
        ``accuracy`` with ``accuracy_ci95``, and ``safe_and_fell_share`` with its interval (the
        share of *all* trials called safe that failed: not a conditional rate).
    """
    p = np.asarray(predicted_safe, dtype=bool)
    f = np.asarray(fell, dtype=bool)
    if p.shape != f.shape:
        raise ValueError(f"predicted_safe ({p.size}) and fell ({f.size}) differ in length")
    n = len(p)
    safe_survived, safe_fell = int(np.sum(p & ~f)), int(np.sum(p & f))
    unsafe_survived, unsafe_fell = int(np.sum(~p & ~f)), int(np.sum(~p & f))
    right = safe_survived + unsafe_fell
    safe, unsafe = safe_survived + safe_fell, unsafe_survived + unsafe_fell
    return {
        "fell_given_safe": rate(safe_fell, safe),
        "stood_given_unsafe": rate(unsafe_survived, unsafe),
        "safe_given_stood": rate(safe_survived, safe_survived + unsafe_survived),
        "safe_survived": safe_survived,
        "safe_fell": safe_fell,
        "unsafe_survived": unsafe_survived,
        "unsafe_fell": unsafe_fell,
        "total": n,
        "accuracy": right / n if n else None,
        "accuracy_ci95": wilson(right, n),
        "safe_and_fell_share": safe_fell / n if n else None,
        "safe_and_fell_share_ci95": wilson(safe_fell, n),
    }
