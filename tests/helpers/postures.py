"""Random postures near a scenario's, as a control loop visits them (a walk in joint space)."""

from __future__ import annotations

import numpy as np

from impact_balance.governor import Governor

__all__ = ["postures"]


def postures(g: Governor, n: int, seed: int, spread: float) -> np.ndarray:
    """``n`` configurations near the scenario's: joints moved by up to ``spread`` rad, the base by
    a few cm (a walk: each one near the previous, as in a control loop)."""
    rng = np.random.default_rng(seed)
    q = g.configuration.copy()
    out = []
    for _ in range(n):
        for name in g.robot.joint_names:
            slot = g.robot.joint_slot(name)
            if slot.nq == 1:
                moved = q[slot.idx_q] + rng.uniform(-spread, spread)
                q[slot.idx_q] = np.clip(moved, slot.lower, slot.upper)
        q[:3] += rng.uniform(-0.01, 0.01, 3)
        out.append(q.copy())
    return np.array(out)
