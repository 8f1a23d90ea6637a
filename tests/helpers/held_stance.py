"""Test helpers for the held-stance impact model: a frozen stance whose fixed point is not
reached, and a ray against an area's half-planes computed apart from the library's own."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

#: A frozen held-out stance whose fixed point is not reached in 1000 QP solves at either bound
#: (docs/studies/impact-held-stance.md).
NOT_CONVERGING = (
    Path(__file__).resolve().parents[2]
    / "studies"
    / "held_out_5"
    / "icub_wide_ramp_left_hand_side.yaml"
)


def ray(G: np.ndarray, h: np.ndarray, c0: np.ndarray, jump: np.ndarray) -> float:
    """Largest s with G (c0 + s jump) <= h (inf when no half-plane is approached)."""
    rates = G @ jump
    ahead = rates > 1e-12
    return float(np.min((h - G @ c0)[ahead] / rates[ahead])) if ahead.any() else math.inf
