"""Small spatial helpers (frames, skew matrices), on top of pinocchio.

Vectors and rotations are in whatever frame the caller gives; lengths in m, angles in rad.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pinocchio as pin

__all__ = ["aligning_rotation", "pose", "skew", "surface_rotation", "unit"]


def skew(v: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Skew-symmetric matrix ``[v]x`` with ``[v]x @ u == cross(v, u)``.

    Args:
        v: (3,) vector.

    Returns:
        (3, 3) matrix.
    """
    out: npt.NDArray[np.float64] = pin.skew(np.asarray(v, dtype=float))
    return out


def pose(
    position: npt.ArrayLike = (0.0, 0.0, 0.0), rpy: npt.ArrayLike = (0.0, 0.0, 0.0)
) -> pin.SE3:
    """SE3 from a position and roll-pitch-yaw angles.

    Args:
        position: (3,) translation, m.
        rpy: (3,) roll, pitch, yaw, rad (R = Rz(y) Ry(p) Rx(r)).

    Returns:
        The placement.
    """
    angles = np.asarray(rpy, dtype=float).ravel()
    return pin.SE3(pin.rpy.rpyToMatrix(*map(float, angles)), np.asarray(position, dtype=float))


def unit(v: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """``v`` normalised.

    Args:
        v: A non-zero vector.

    Returns:
        ``v / |v|`` (a new array).

    Raises:
        ValueError: ``v`` is zero (norm under 1e-12) or not finite.
    """
    a = np.asarray(v, dtype=float)
    norm = float(np.linalg.norm(a))
    if not np.isfinite(norm) or norm < 1e-12:
        raise ValueError("zero vector")
    out: npt.NDArray[np.float64] = a / norm
    return out


def surface_rotation(
    frame_rotation: npt.ArrayLike, normal: npt.ArrayLike, angle: float = 0.0
) -> npt.NDArray[np.float64]:
    """World rotation of a contact given by its surface normal, from its frame's world rotation.

    The contact's z axis is ``normal`` (normalised; from the surface into the robot). Its x
    axis is the frame's x axis projected on the surface (the frame's y axis, turned by -90
    degrees about the normal, when x is along the normal), then turned by ``angle`` (rad)
    about the normal, counter-clockwise seen from above the surface.

    Args:
        frame_rotation: (3, 3) world rotation of the frame.
        normal: (3,) surface normal, world.
        angle: Turn about the normal, rad.

    Returns:
        (3, 3) world rotation of the contact (columns: its x, y, z axes).
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


def aligning_rotation(a: npt.ArrayLike, b: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """The smallest rotation taking direction ``a`` to direction ``b`` (about ``a x b``).

    Opposite directions: a half turn about an axis orthogonal to ``a``.

    Args:
        a: (3,) direction.
        b: (3,) direction.

    Returns:
        (3, 3) rotation matrix R with ``R a/|a| = b/|b|``.
    """
    ua, ub = unit(a), unit(b)
    axis = np.cross(ua, ub)
    s, c = float(np.linalg.norm(axis)), float(ua @ ub)
    out: npt.NDArray[np.float64]
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        other = np.eye(3)[int(np.argmin(np.abs(ua)))]
        out = pin.exp3(np.pi * unit(np.cross(ua, other)))
        return out
    out = pin.exp3(axis / s * np.arctan2(s, c))
    return out
