"""Contact wrench cone (CWC) of a rectangular contact (Caron et al., ICRA 2015).

Wrenches are ordered ``[f; tau]`` (force first) and taken at the contact point. In the
contact frame, z is the surface normal (from the environment into the robot) and the
rectangle spans ``[-X, X] x [-Y, Y]`` where X, Y are the HALF length and width.
"""

from __future__ import annotations

import functools

import numpy as np
import numpy.typing as npt

__all__ = [
    "cwc_faces",
    "cwc_faces_world",
    "cwc_span",
    "local_faces",
    "rotate_wrench_matrix",
]


def cwc_faces(mu: float, half_length: float, half_width: float) -> np.ndarray:
    """Face matrix ``C`` (16 x 6) with ``C @ [f; tau] <= 0`` in the contact frame.

    Rows: friction pyramid |fx|, |fy| <= mu fz (4), centre of pressure |tau_x| <= Y fz,
    |tau_y| <= X fz (4), then the yaw-torque bounds tau_min <= tau_z <= tau_max (8), as in
    the paper's appendix with its ``[tau; f]`` columns reordered to ``[f; tau]``.
    """
    out: npt.NDArray[np.float64] = local_faces(
        float(mu), float(half_length), float(half_width)
    ).copy()
    return out


@functools.lru_cache(maxsize=256)
def local_faces(m: float, X: float, Y: float) -> np.ndarray:
    """:func:`cwc_faces`, cached per (mu, X, Y) as a read-only array (contacts repeat)."""
    s = -(X + Y) * m
    # Columns in the paper's order: tau_x, tau_y, tau_z, f_x, f_y, f_z.
    paper = np.array(
        [
            [0, 0, 0, -1, 0, -m],
            [0, 0, 0, +1, 0, -m],
            [0, 0, 0, 0, -1, -m],
            [0, 0, 0, 0, +1, -m],
            [-1, 0, 0, 0, 0, -Y],
            [+1, 0, 0, 0, 0, -Y],
            [0, -1, 0, 0, 0, -X],
            [0, +1, 0, 0, 0, -X],
            [+m, +m, -1, -Y, -X, s],
            [+m, -m, -1, -Y, +X, s],
            [-m, +m, -1, +Y, -X, s],
            [-m, -m, -1, +Y, +X, s],
            [+m, +m, +1, +Y, +X, s],
            [+m, -m, +1, +Y, -X, s],
            [-m, +m, +1, -Y, +X, s],
            [-m, -m, +1, -Y, -X, s],
        ],
        dtype=float,
    )
    faces = np.hstack([paper[:, 3:], paper[:, :3]])
    faces.setflags(write=False)
    return faces


def rotate_wrench_matrix(rotation: np.ndarray) -> np.ndarray:
    """6 x 6 block-diagonal ``diag(R, R)``: maps a wrench from the frame R to world axes."""
    T = np.zeros((6, 6))
    T[:3, :3] = rotation
    T[3:, 3:] = rotation
    return T


def cwc_faces_world(
    mu: float, half_length: float, half_width: float, rotation: np.ndarray
) -> np.ndarray:
    """Face matrix acting on the wrench at the contact point in WORLD-aligned axes.

    ``rotation`` maps contact-frame vectors to world vectors (pinocchio's ``oMf.rotation``).
    The result is ``cwc_faces @ rotate_wrench_matrix(rotation).T``, computed blockwise:
    each row's force and torque halves are rotated by one (32 x 3) @ (3 x 3) product.
    """
    faces = local_faces(float(mu), float(half_length), float(half_width))
    out: npt.NDArray[np.float64] = (
        faces.reshape(32, 3) @ np.asarray(rotation, dtype=float).T
    ).reshape(16, 6)
    return out


def cwc_span(mu: float, half_length: float, half_width: float) -> np.ndarray:
    """Generators (6 x 16) of the same cone: the friction-pyramid edges at the 4 corners.

    Column ``k`` is the wrench ``[e; p x e]`` at the contact point of a unit-normal force
    along pyramid edge ``e = (+-mu, +-mu, 1)`` applied at corner ``p = (+-X, +-Y, 0)``.
    """
    X, Y = float(half_length), float(half_width)
    columns = []
    for px, py in ((X, Y), (X, -Y), (-X, Y), (-X, -Y)):
        corner = np.array([px, py, 0.0])
        for ex, ey in ((mu, mu), (mu, -mu), (-mu, mu), (-mu, -mu)):
            edge = np.array([ex, ey, 1.0])
            columns.append(np.concatenate([edge, np.cross(corner, edge)]))
    out: npt.NDArray[np.float64] = np.array(columns).T
    return out
