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
import numpy.typing as npt

from impact_balance._jit import njit
from impact_balance.constants import GRAVITY
from impact_balance.contacts.cwc import local_faces
from impact_balance.contacts.stance import Contact, Stance

__all__ = [
    "WrenchPolytope",
    "assemble_arrays",
    "assemble_polytope",
    "contact_polytope",
    "face_blocks",
    "friction_scaling",
    "grasp_matrix",
    "torque_limit_rows",
    "wrench_polytope",
]


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
    G: npt.NDArray[np.float64] = identity.copy()
    # [p]x = [[0, -z, y], [z, 0, -x], [-y, x, 0]]: its 6 off-diagonal entries, contact by contact.
    G[rows, cols] = (positions[:, _SKEW_COMPONENTS] * _SKEW_SIGNS).ravel()
    return G


@functools.lru_cache(maxsize=16)
def _grasp_pattern(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grasp matrix's constant part for m contacts, and the indices of its skew entries.

    The constant part is the identity blocks (read-only); the (row, column) indices are in the
    order of ``_SKEW_COMPONENTS``.
    """
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
        scaling: 6m x 6m block-diagonal change of variables ``w = scaling @ v`` (None: the
            identity). In ``v`` each contact's wrench is in its contact frame with f_x, f_y
            and tau_z divided by its friction mu when mu > 1, where such a contact wrench
            cone is the mu = 1 cone (see :meth:`projection_data`).
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
    scaling: np.ndarray | None = None

    @property
    def dim(self) -> int:
        """The number of variables (6 per contact)."""
        return int(self.A.shape[1])

    def projection_data(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(A', b', C', d', F')``: the same polytope and map in friction-normalised variables.

        The variables are ``v`` (``w = scaling @ v``), forces in units of m g: ``A' = A S``,
        ``b' = b / (m g)``, ``C' = C S``, ``d' = d / (m g)``, ``F' = F S`` with ``S = scaling``.
        ``F' v`` is the resultant horizontal force over m g, so both describe the same force area.

        Why: in ``w`` the rows of a cone with a large mu (|f_x| <= mu f_z, tau_z bounds with mu
        times tau_x, tau_y and f_z) are nearly parallel to each other and to the centre-of-
        pressure rows, 1/mu apart; a vertex basis holding them has a condition number up to
        mu^2, so a projection loses up to mu^2 eps of precision (a vertex 0.5 outside a
        row at mu = 1e8, 4e-7 at 1e6). In ``v`` such a cone is the mu = 1 cone, and mu moves
        to the columns of the
        torque, LIPM and force-map rows, which stay well conditioned. (A small mu makes the
        pyramid rows nearly opposite instead, which the projections handle as they are.)
        """
        w = self.weight
        if self.scaling is None:
            return self.A, self.b / w, self.C, self.d / w, self.F
        S = self.scaling
        return self.A @ S, self.b / w, self.C @ S, self.d / w, self.F @ S

    @property
    def weight(self) -> float:
        """M g, N."""
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


def wrench_polytope(
    stance: Stance, torque_limits: bool = True, gravity: float = GRAVITY
) -> WrenchPolytope:
    """Assemble the contact-wrench polytope of ``stance`` (CWC + torque limits + LIPM)."""
    # Lever arms from stance-frame positions: exact however far from the origin the stance is.
    arms = (
        np.array([c.local_position for c in stance.contacts], dtype=float).reshape(-1, 3)
        - stance.com_local
    )
    return _assemble(
        stance.contacts, stance.mass, stance.com, arms, gravity, stance if torque_limits else None
    )


def _n_torque_rows(stance: Stance) -> int:
    """Number of torque-limited joints that act on the wrenches (0 without contacts)."""
    return stance.robot.effort_limits[0].size if stance.contacts else 0


def _fill_torque_rows(stance: Stance, A: np.ndarray, b: np.ndarray) -> None:
    """Write :func:`torque_limit_rows` into ``A`` (2k x 6m) and ``b`` (2k), k limited joints."""
    k = A.shape[0] // 2
    if k == 0:
        return
    idx, limit = stance.robot.effort_limits
    J = np.concatenate([c.jacobian for c in stance.contacts])
    _torque_rows(J, idx, limit, stance.gravity_torques, A, b)


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
    faces = np.array(
        [local_faces(float(c.spec.friction), c.half_length, c.half_width) for c in contacts]
    ).reshape(m, 16, 6)
    rotations = np.array([c.rotation for c in contacts], dtype=float).reshape(m, 3, 3)
    positions = np.array([c.position for c in contacts], dtype=float).reshape(m, 3)
    if torque_stance is not None and _n_torque_rows(torque_stance):
        idx, limit = torque_stance.robot.effort_limits
        J = np.concatenate([c.jacobian for c in torque_stance.contacts])
        g = torque_stance.gravity_torques
    else:
        idx, limit, J, g = _NO_ROWS, _NO_LIMITS, np.zeros((0, 0)), _NO_LIMITS
    return assemble_polytope(
        faces, rotations, positions, arms, mass, com, gravity, J, idx, limit, g, _scaling(contacts)
    )


_NO_ROWS = np.zeros(0, dtype=np.int64)
_NO_LIMITS = np.zeros(0)


def assemble_polytope(
    faces: np.ndarray,
    rotations: np.ndarray,
    positions: np.ndarray,
    arms: np.ndarray,
    mass: float,
    com: np.ndarray,
    gravity: float,
    jacobians: np.ndarray,
    torque_indices: np.ndarray,
    torque_limits: np.ndarray,
    gravity_torques: np.ndarray,
    scaling: np.ndarray | None = None,
) -> WrenchPolytope:
    """The polytope from arrays (what :func:`wrench_polytope` builds from a stance).

    Args:
        faces: (m, 16, 6) contact-frame CWC face matrices
            (:func:`~impact_balance.contacts.cwc.cwc_faces`).
        rotations: (m, 3, 3) contact-to-world rotations.
        positions: (m, 3) contact centres in world, m (for :attr:`WrenchPolytope.grasp`).
        arms: (m, 3) contact centres minus the CoM, m (for the LIPM rows).
        mass: kg.
        com: (3,) CoM in world, m.
        gravity: m/s^2.
        jacobians: (6m, nv) contact Jacobians stacked (world-aligned, linear rows first), or
            (0, 0) without torque limits.
        torque_indices: (k,) velocity indices of the torque-limited joints (int64).
        torque_limits: (k,) their effort limits, N m.
        gravity_torques: (nv,) g(q).
        scaling: See :attr:`WrenchPolytope.scaling`.
    """
    m = len(faces)
    A, b, C, G = assemble_arrays(
        face_blocks(faces, rotations),
        np.ascontiguousarray(positions, dtype=float),
        np.ascontiguousarray(arms, dtype=float),
        jacobians,
        torque_indices,
        torque_limits,
        gravity_torques,
    )
    d = np.array([mass * gravity, 0.0, 0.0, 0.0])
    com = np.array(com, dtype=float)
    return WrenchPolytope(A, b, C, d, G[:2].copy(), G, 16 * m, float(mass), com, gravity, scaling)


def face_blocks(faces: np.ndarray, rotations: np.ndarray) -> np.ndarray:
    """Every contact's CWC faces acting on world-axes forces and torques, (m, 32, 3).

    Row 2r (2r + 1) is the force (torque) half of face r (the numbers of cwc_faces_world).

    One batched numpy product, on purpose: these are exactly the numbers of
    :func:`~impact_balance.contacts.cwc.cwc_faces_world` (a compiled loop differs by rounding,
    which an external LP solver given the same faces can be sensitive to).
    """
    m = len(faces)
    out: npt.NDArray[np.float64] = np.matmul(
        np.asarray(faces, dtype=float).reshape(m, 32, 3),
        np.asarray(rotations, dtype=float).transpose(0, 2, 1),
    )
    return out


@njit(cache=True)
def assemble_arrays(
    blocks, positions, arms, jacobians, torque_indices, torque_limits, gravity_torques
):
    """The arrays ``(A, b, C, G)`` of :func:`assemble_polytope` in one compiled call.

    From the contacts' :func:`face_blocks` (a governor's every tick).
    """
    m = blocks.shape[0]
    k = torque_indices.size if jacobians.size else 0
    A = np.zeros((16 * m + 2 * k, 6 * m))
    b = np.zeros(16 * m + 2 * k)
    C = np.zeros((4, 6 * m))
    G = np.zeros((6, 6 * m))
    _fill(blocks, positions, arms, A, C, G)
    if k:
        _torque_rows(
            jacobians, torque_indices, torque_limits, gravity_torques, A[16 * m :], b[16 * m :]
        )
    return A, b, C, G


@njit(cache=True)
def _fill(blocks, positions, arms, A, C, G):
    """The CWC blocks of ``A``, the LIPM rows ``C`` and the grasp matrix ``G``.

    ``blocks`` (m, 32, 3) are each contact's face rows acting on world-axes wrenches as (force,
    torque) halves (:func:`~impact_balance.contacts.cwc.cwc_faces_world` reshaped); ``C`` is rows
    2-5 of the grasp matrix at the arms, ``G`` the grasp matrix at the world positions
    (:func:`grasp_matrix`).
    """
    m = blocks.shape[0]
    for i in range(m):
        for r in range(16):
            for half in range(2):
                for c in range(3):
                    A[16 * i + r, 6 * i + 3 * half + c] = blocks[i, 2 * r + half, c]
        _grasp_block(G, 0, i, positions[i])
        # C = rows 2..5 of the grasp matrix at the arms.
        o = 6 * i
        x, y, z = arms[i, 0], arms[i, 1], arms[i, 2]
        C[0, o + 2] = 1.0
        C[1, o + 3] = 1.0
        C[2, o + 4] = 1.0
        C[3, o + 5] = 1.0
        C[1, o + 1], C[1, o + 2] = -z, y
        C[2, o + 0], C[2, o + 2] = z, -x
        C[3, o + 0], C[3, o + 1] = -y, x


@njit(cache=True)
def _grasp_block(G, row0, i, p):
    """Block i of the grasp matrix, ``[[I, 0], [[p]x, I]]``, into ``G`` from row ``row0``."""
    o = 6 * i
    for r in range(6):
        G[row0 + r, o + r] = 1.0
    x, y, z = p[0], p[1], p[2]
    G[row0 + 3, o + 1], G[row0 + 3, o + 2] = -z, y
    G[row0 + 4, o + 0], G[row0 + 4, o + 2] = z, -x
    G[row0 + 5, o + 0], G[row0 + 5, o + 1] = -y, x


@njit(cache=True)
def _torque_rows(J, idx, limit, g, A, b):
    """:func:`torque_limit_rows` into ``A`` (2k x 6m) and ``b`` (2k).

    Row r is the limited joint idx[r]'s column of every contact Jacobian, ``(J_a^T)[r]``, then
    its negative.
    """
    k = idx.size
    for r in range(k):
        j = idx[r]
        for c in range(J.shape[0]):
            A[r, c] = J[c, j]
            A[k + r, c] = -J[c, j]
        b[r] = limit[r] + g[j]
        b[k + r] = limit[r] - g[j]


#: Components of a wrench [f; tau] (contact frame) divided by mu in the normalised variables.
_TANGENTIAL = np.array([True, True, False, False, False, True])


def _scaling(contacts: Sequence[Contact]) -> np.ndarray | None:
    """:func:`friction_scaling` of the contacts' frictions and rotations."""
    return friction_scaling([c.spec.friction for c in contacts], [c.rotation for c in contacts])


def friction_scaling(
    frictions: Sequence[float], rotations: Sequence[np.ndarray]
) -> np.ndarray | None:
    """Block-diagonal ``S`` (6m x 6m), block i = ``diag(R_i, R_i) diag(s_i)``.

    ``s_i`` is mu_i on f_x, f_y, tau_z and 1 elsewhere, or 1 everywhere when mu_i <= 1 (None when
    every mu_i is; :meth:`WrenchPolytope.projection_data` then skips the products): a small mu
    needs no help. See :meth:`WrenchPolytope.projection_data`.
    """
    if all(float(mu) <= 1.0 for mu in frictions):
        return None  # the identity: no work on the hot path of common stances
    m = len(frictions)
    S = np.zeros((6 * m, 6 * m))
    for i, (mu, rotation) in enumerate(zip(frictions, rotations, strict=True)):
        scale = np.where(_TANGENTIAL, max(float(mu), 1.0), 1.0)
        R = np.asarray(rotation, dtype=float)
        block = S[6 * i : 6 * i + 6, 6 * i : 6 * i + 6]
        block[:3, :3] = R * scale[:3]
        block[3:, 3:] = R * scale[3:]
    return S
