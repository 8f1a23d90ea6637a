"""Linear constraints on the stacked contact wrenches of a stance.

The decision variable is ``w = [w_1; ...; w_m]`` with ``w_i = [f_i; tau_i]`` the wrench of
contact i at its contact point, in world-aligned axes (N, N m). Three groups of constraints
define a polytope in that 6m-dimensional space:

1. contact wrench cones, ``C_i w_i <= 0`` (16 rows each);
2. joint torque limits on the actuated joints, quasi-static:
   ``|g_a(q) - (sum_i J_i^T w_i)_a| <= tau_max`` (two rows per limited joint);
3. LIPM equalities on the resultant wrench: vertical force ``m g`` and zero moment about the CoM.

The floating-base rows of the equations of motion are deliberately NOT constraints: with zero
accelerations they would force static equilibrium and contradict the LIPM's horizontal CoM
acceleration (see CONVENTIONS).
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .constants import GRAVITY
from .cwc import cwc_faces_world
from .stance import Contact, Stance

__all__ = ["WrenchPolytope", "grasp_matrix", "contact_polytope", "torque_limit_rows", "wrench_polytope"]


#: Grasp-matrix block entries [p]x: rows, columns, and the component of p and sign of each.
_SKEW_ROWS, _SKEW_COLS = (3, 3, 4, 4, 5, 5), (1, 2, 0, 2, 0, 1)
_SKEW_COMPONENTS = np.array([2, 1, 2, 0, 1, 0])
_SKEW_SIGNS = np.array([-1.0, 1.0, 1.0, -1.0, -1.0, 1.0])


def grasp_matrix(positions: np.ndarray) -> np.ndarray:
    """6 x 6m map from stacked contact wrenches to the resultant wrench at the world origin.

    Block i is ``[[I, 0], [[p_i]x, I]]``: forces add up, and each force adds ``p_i x f_i``.
    """
    positions = np.atleast_2d(np.asarray(positions, dtype=float))
    identity, rows, cols = _grasp_pattern(len(positions))
    G = identity.copy()
    # [p]x = [[0, -z, y], [z, 0, -x], [-y, x, 0]]: its 6 off-diagonal entries, contact by contact.
    G[rows, cols] = (positions[:, _SKEW_COMPONENTS] * _SKEW_SIGNS).ravel()
    return G


@functools.lru_cache(maxsize=16)
def _grasp_pattern(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grasp matrix's constant part for m contacts (identity blocks, read-only) and the
    (row, column) indices of its skew entries, in the order of ``_SKEW_COMPONENTS``."""
    identity = np.zeros((6, 6 * m))
    for r in range(6):
        identity[r, r::6] = 1.0
    identity.setflags(write=False)
    rows = np.tile(_SKEW_ROWS, m)
    cols = (6 * np.arange(m)[:, None] + _SKEW_COLS).ravel()
    return identity, rows, cols


@dataclass(frozen=True)
class WrenchPolytope:
    """``{w : A w <= b, C w = d}`` and the map ``F`` from w to the resultant horizontal force.

    Attributes:
        A, b: Inequalities (CWC rows first, then torque-limit rows).
        C, d: LIPM equalities (4 rows: resultant f_z = m g; moment about the CoM = 0).
        F: 2 x 6m map, ``F @ w`` = resultant horizontal force (f_x, f_y), N.
        grasp: 6 x 6m grasp matrix at the world origin.
        n_cwc_rows: How many of A's rows are CWC rows.
        mass, com, gravity: The stance's mass (kg), CoM (m) and g (m/s^2).
    """

    A: np.ndarray
    b: np.ndarray
    C: np.ndarray
    d: np.ndarray
    F: np.ndarray
    grasp: np.ndarray
    n_cwc_rows: int
    mass: float
    com: np.ndarray
    gravity: float

    @property
    def dim(self) -> int:
        return self.A.shape[1]

    @property
    def weight(self) -> float:
        """m g, N."""
        return self.mass * self.gravity


def contact_polytope(
    contacts: Sequence[Contact], mass: float, com: np.ndarray, gravity: float = GRAVITY
) -> WrenchPolytope:
    """CWC and LIPM constraints only (no torque limits): needs no robot model.

    ``contacts`` only need ``spec``, ``rotation`` and ``position`` (the Jacobian is unused).
    """
    com = np.array(com, dtype=float)
    arms = np.array([c.position for c in contacts], dtype=float).reshape(-1, 3) - com
    return _assemble(contacts, mass, com, arms, gravity, None)


def torque_limit_rows(stance: Stance) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``(A_tau, b_tau)`` of the actuated joint-torque limits on the stacked wrenches.

    ``tau = g_a(q) - (J^T w)_a`` and ``|tau| <= tau_max`` give ``J_a^T w <= tau_max + g_a``
    and ``-J_a^T w <= tau_max - g_a``. Joints without a finite positive effort limit are free.
    """
    n = 6 * len(stance.contacts)
    k = _n_torque_rows(stance)
    A, b = np.zeros((2 * k, n)), np.zeros(2 * k)
    _fill_torque_rows(stance, A, b)
    return A, b


def wrench_polytope(stance: Stance, torque_limits: bool = True, gravity: float = GRAVITY) -> WrenchPolytope:
    """Assemble the contact-wrench polytope of ``stance`` (CWC + torque limits + LIPM)."""
    # Lever arms from stance-frame positions: exact however far from the origin the stance is.
    arms = np.array([c.local_position for c in stance.contacts], dtype=float).reshape(-1, 3) - stance.com_local
    return _assemble(stance.contacts, stance.mass, stance.com, arms, gravity, stance if torque_limits else None)


def _n_torque_rows(stance: Stance) -> int:
    """Number of torque-limited joints that act on the wrenches (0 without contacts)."""
    return stance.robot.effort_limits[0].size if stance.contacts else 0


def _fill_torque_rows(stance: Stance, A: np.ndarray, b: np.ndarray) -> None:
    """Write :func:`torque_limit_rows` into ``A`` (2k x 6m) and ``b`` (2k), k limited joints."""
    k = A.shape[0] // 2
    if k == 0:
        return
    idx, limit = stance.robot.effort_limits
    # Row r is the actuated joint idx[r]'s column of every contact Jacobian: (J_a^T)[r].
    J = np.concatenate([c.jacobian for c in stance.contacts])
    A[:k] = J[:, idx].T
    np.negative(A[:k], out=A[k:])
    g = stance.gravity_torques[idx]
    np.add(limit, g, out=b[:k])
    np.subtract(limit, g, out=b[k:])


def _assemble(
    contacts: Sequence[Contact],
    mass: float,
    com: np.ndarray,
    arms: np.ndarray,
    gravity: float,
    torque_stance: Stance | None,
) -> WrenchPolytope:
    """The polytope, with the torque-limit rows of ``torque_stance`` when given, in one allocation.

    ``arms`` (m x 3) are the contact positions minus the CoM: the LIPM rows use them, not
    world positions, so that they keep their precision far from the origin.
    """
    m = len(contacts)
    n, n_cwc = 6 * m, 16 * m
    k = _n_torque_rows(torque_stance) if torque_stance is not None else 0
    A = np.zeros((n_cwc + 2 * k, n))
    b = np.zeros(n_cwc + 2 * k)
    for i, c in enumerate(contacts):
        A[16 * i : 16 * i + 16, 6 * i : 6 * i + 6] = cwc_faces_world(
            c.spec.friction, c.half_length, c.half_width, c.rotation
        )
    if k:
        _fill_torque_rows(torque_stance, A[n_cwc:], b[n_cwc:])
    com = np.array(com, dtype=float)
    positions = np.array([c.position for c in contacts], dtype=float).reshape(-1, 3)
    G = grasp_matrix(positions)
    # LIPM: vertical force f_z = m g, and moment about the CoM sum (p_i - c) x f_i + tau_i = 0:
    # rows 2-5 of the grasp matrix taken at the CoM (the same numbers as [[e_z^T], [-[c]x, I]] G).
    C = grasp_matrix(arms)[2:]
    d = np.array([mass * gravity, 0.0, 0.0, 0.0])
    return WrenchPolytope(A, b, C, d, G[:2].copy(), G, n_cwc, float(mass), com, gravity)
