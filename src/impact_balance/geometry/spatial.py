"""Small spatial helpers (frames, skew matrices), on top of pinocchio."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

__all__ = ["aligning_rotation", "pose", "skew", "surface_rotation", "unit"]


def skew(v: Sequence[float]) -> np.ndarray:
    """Skew-symmetric matrix ``[v]x`` with ``[v]x @ u == cross(v, u)``."""
    return pin.skew(np.asarray(v, dtype=float))


def pose(
    position: Sequence[float] = (0.0, 0.0, 0.0), rpy: Sequence[float] = (0.0, 0.0, 0.0)
) -> pin.SE3:
    """SE3 from a position (m) and roll-pitch-yaw angles (rad, R = Rz(y) Ry(p) Rx(r))."""
    return pin.SE3(pin.rpy.rpyToMatrix(*map(float, rpy)), np.asarray(position, dtype=float))


def unit(v: Sequence[float]) -> np.ndarray:
    """``v`` normalised (raises ValueError on a zero vector)."""
    v = np.asarray(v, dtype=float)
    norm = float(np.linalg.norm(v))
    if not np.isfinite(norm) or norm < 1e-12:
        raise ValueError("zero vector")
    return v / norm


def surface_rotation(
    frame_rotation: np.ndarray, normal: Sequence[float], angle: float = 0.0
) -> np.ndarray:
    """World rotation of a contact given by its surface normal, from its frame's world rotation.

    The contact's z axis is ``normal`` (normalised; from the surface into the robot). Its x
    axis is the frame's x axis projected on the surface (the frame's y axis, turned by -90
    degrees about the normal, when x is along the normal), then turned by ``angle`` (rad)
    about the normal, counter-clockwise seen from above the surface.
    """
    n = unit(normal)
    R = np.asarray(frame_rotation, dtype=float)
    x = R[:, 0] - (R[:, 0] @ n) * n
    if np.linalg.norm(x) < 1e-6:
        y = R[:, 1] - (R[:, 1] @ n) * n
        x = np.cross(y, n)
    x /= np.linalg.norm(x)
    x = np.cos(angle) * x + np.sin(angle) * np.cross(n, x)
    return np.column_stack([x, np.cross(n, x), n])


def aligning_rotation(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """The smallest rotation taking direction ``a`` to direction ``b`` (about ``a x b``).

    Opposite directions: a half turn about an axis orthogonal to ``a``.
    """
    a, b = unit(a), unit(b)
    axis = np.cross(a, b)
    s, c = float(np.linalg.norm(axis)), float(a @ b)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        other = np.eye(3)[int(np.argmin(np.abs(a)))]
        axis = unit(np.cross(a, other))
        return pin.exp3(np.pi * axis)
    return pin.exp3(axis / s * np.arctan2(s, c))
