"""Quantities read from a MuJoCo model on its own terms (its bodies, not pinocchio's)."""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["mujoco_composite_inertia"]


def mujoco_composite_inertia(sim: Any) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, CoM and rotational inertia about the CoM (world axes) summed from MuJoCo's bodies."""
    m, d = sim.model, sim.data
    masses = m.body_mass[1:]
    mass = masses.sum()
    com = (masses[:, None] * d.xipos[1:]).sum(axis=0) / mass
    inertia = np.zeros((3, 3))
    for b in range(1, m.nbody):
        R = d.ximat[b].reshape(3, 3)
        r = d.xipos[b] - com
        inertia += R @ np.diag(m.body_inertia[b]) @ R.T + m.body_mass[b] * (
            r @ r * np.eye(3) - np.outer(r, r)
        )
    return mass, com, inertia
