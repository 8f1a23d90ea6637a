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

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from .constants import GRAVITY
from .cwc import cwc_faces_world
from .spatial import skew
from .stance import Contact, Stance

__all__ = ["WrenchPolytope", "grasp_matrix", "contact_polytope", "torque_limit_rows", "wrench_polytope"]


def grasp_matrix(positions: np.ndarray) -> np.ndarray:
    """6 x 6m map from stacked contact wrenches to the resultant wrench at the world origin.

    Block i is ``[[I, 0], [[p_i]x, I]]``: forces add up, and each force adds ``p_i x f_i``.
    """
    positions = np.atleast_2d(positions)
    G = np.zeros((6, 6 * len(positions)))
    for i, p in enumerate(positions):
        G[:3, 6 * i : 6 * i + 3] = np.eye(3)
        G[3:, 6 * i : 6 * i + 3] = skew(p)
        G[3:, 6 * i + 3 : 6 * i + 6] = np.eye(3)
    return G


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
    n = 6 * len(contacts)
    A = np.zeros((16 * len(contacts), n))
    for i, c in enumerate(contacts):
        A[16 * i : 16 * i + 16, 6 * i : 6 * i + 6] = cwc_faces_world(
            c.spec.friction, c.half_length, c.half_width, c.rotation
        )
    com = np.asarray(com, dtype=float)
    G = grasp_matrix(np.array([c.position for c in contacts]).reshape(-1, 3))
    # Moment about the CoM: tau_O - c x f = 0; vertical force: f_z = m g.
    L = np.zeros((4, 6))
    L[0, 2] = 1.0
    L[1:, :3] = -skew(com)
    L[1:, 3:] = np.eye(3)
    d = np.array([mass * gravity, 0.0, 0.0, 0.0])
    return WrenchPolytope(A, np.zeros(A.shape[0]), L @ G, d, G[:2].copy(), G, A.shape[0], float(mass), com.copy(), gravity)


def torque_limit_rows(stance: Stance) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``(A_tau, b_tau)`` of the actuated joint-torque limits on the stacked wrenches.

    ``tau = g_a(q) - (J^T w)_a`` and ``|tau| <= tau_max`` give ``J_a^T w <= tau_max + g_a``
    and ``-J_a^T w <= tau_max - g_a``. Joints without a finite positive effort limit are free.
    """
    idx, limit = stance.robot.actuated_effort_limits()
    n = 6 * len(stance.contacts)
    if idx.size == 0 or n == 0:
        return np.zeros((0, n)), np.zeros(0)
    JT = np.hstack([c.jacobian.T for c in stance.contacts])[idx]
    g = stance.gravity_torques[idx]
    return np.vstack([JT, -JT]), np.concatenate([limit + g, limit - g])


def wrench_polytope(stance: Stance, torque_limits: bool = True, gravity: float = GRAVITY) -> WrenchPolytope:
    """Assemble the contact-wrench polytope of ``stance`` (CWC + torque limits + LIPM)."""
    poly = contact_polytope(stance.contacts, stance.mass, stance.com, gravity)
    if not torque_limits:
        return poly
    A_tau, b_tau = torque_limit_rows(stance)
    return replace(poly, A=np.vstack([poly.A, A_tau]), b=np.concatenate([poly.b, b_tau]))
