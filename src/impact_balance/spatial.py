"""Small spatial helpers (frames, skew matrices), on top of pinocchio."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

__all__ = ["skew", "pose", "unit"]


def skew(v: Sequence[float]) -> np.ndarray:
    """Skew-symmetric matrix ``[v]x`` with ``[v]x @ u == cross(v, u)``."""
    return pin.skew(np.asarray(v, dtype=float))


def pose(position: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0)) -> pin.SE3:
    """SE3 from a position (m) and roll-pitch-yaw angles (rad, R = Rz(y) Ry(p) Rx(r))."""
    return pin.SE3(pin.rpy.rpyToMatrix(*map(float, rpy)), np.asarray(position, dtype=float))


def unit(v: Sequence[float]) -> np.ndarray:
    """``v`` normalised (raises ValueError on a zero vector)."""
    v = np.asarray(v, dtype=float)
    norm = float(np.linalg.norm(v))
    if not np.isfinite(norm) or norm < 1e-12:
        raise ValueError("zero vector")
    return v / norm
