"""Frictional impact model at a point contact (paper sec. V-A).

During the impact the kinematically controlled robot behaves as one composite rigid body,
so an impulse ``iota`` (N s, world axes) at point p changes the contact-point velocity by
``W iota`` with

    W = I / m - [r]x Ic^-1 [r]x,   r = p - c,

and the CoM velocity by ``iota / m``. With the discretised friction cone (generators K_i)
and the restitution range [c_lo, c_hi], the impulse set is the polytope with 2N vertices
``lambda K_i`` on the two planes of restitution ``n^T W (lambda K_i) = (1 + c_r) v_n``,
v_n >= 0 being the approach speed. Every vertex is linear in v_n.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance._jit import njit
from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ImpactModelError
from impact_balance.geometry.spatial import skew, unit
from impact_balance.robot.robot import Scratch

__all__ = [
    "INERTIA_MODELS",
    "ImpactModel",
    "ImpactSpec",
    "composite_inertia_map",
    "composite_map_kernel",
    "cone_tangents",
    "friction_cone",
    "impact_cone",
    "impact_model",
    "impulse_rates_kernel",
    "impulse_to_velocity",
    "joint_space_inertia_map",
    "model_from_inertia_map",
]

#: "composite": the robot as one rigid body (paper, default); "joint_space": J M^-1 J^T.
INERTIA_MODELS = ("composite", "joint_space")


@dataclass(frozen=True)
class ImpactSpec:
    """An intended impact.

    Attributes:
        frame: Robot frame of the impacting end-effector.
        normal: World unit vector from the impacted surface into the robot (direction of
            the normal impulse on the robot).
        friction: Friction coefficient at the impact (>= 0).
        restitution: (lo, hi) restitution range, 0 <= lo <= hi <= 1.
        cone_edges: N, number of friction-cone generators (>= 3).
        reference_velocity: Desired end-effector velocity, world, m/s.
        duration: Impact duration for the ZMP-based comparison, s.
        offset: Fixed pose of the impact point in the frame.
        inertia: "composite" (default) or "joint_space".
    """

    frame: str
    normal: tuple[float, float, float]
    friction: float = 0.24
    restitution: tuple[float, float] = (0.0, 0.2)
    cone_edges: int = 16
    reference_velocity: tuple[float, float, float] | None = None
    duration: float = 0.005
    offset: pin.SE3 = field(default_factory=pin.SE3.Identity)
    inertia: str = "composite"


def cone_tangents(normal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t1, t2): t1 is world z made orthogonal to n (world x if n is vertical), t2 = n x t1."""
    n = unit(normal)
    for axis in (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])):
        t = axis - (axis @ n) * n
        if np.linalg.norm(t) > 1e-9:
            t = t / np.linalg.norm(t)
            # Second Gram-Schmidt pass: with n nearly along the axis, the first one cancels
            # (n = (0, 1e-8, 1) left t1 . n = 1e-8); a no-op when axis . n = 0.
            t = t - (t @ n) * n
            t1 = t / np.linalg.norm(t)
            return t1, np.cross(n, t1)
    raise AssertionError("unreachable")  # pragma: no cover


def friction_cone(normal: npt.ArrayLike, mu: float, edges: int) -> npt.NDArray[np.float64]:
    """Generators K (3 x N): K_i = n + mu (cos a_i t1 + sin a_i t2), a_i = 2 pi i / N.

    Args:
        normal: (3,) surface normal, world (normalised here).
        mu: Friction coefficient.
        edges: N, the number of generators.

    Returns:
        (3, N) generators, world.

    Raises:
        ValueError: ``normal`` is zero.
    """
    n = unit(normal)
    t1, t2 = cone_tangents(n)
    a = 2.0 * np.pi * np.arange(edges) / edges
    return n[:, None] + mu * (np.outer(t1, np.cos(a)) + np.outer(t2, np.sin(a)))


@functools.lru_cache(maxsize=64)
def _normal_and_cone(
    normal: tuple[float, float, float], mu: float, edges: int
) -> tuple[np.ndarray, np.ndarray]:
    """Unit normal and :func:`friction_cone` (read-only), cached: they do not depend on q."""
    n = unit(normal)
    K = friction_cone(n, mu, edges)
    n.setflags(write=False)
    K.setflags(write=False)
    return n, K


@dataclass(frozen=True)
class ImpactModel:
    """Impulse set and CoM velocity jumps of an impact, per unit approach speed.

    Attributes:
        spec: The impact specification.
        point: Impact point, world, m.
        normal: Unit normal, world.
        cone: Friction-cone generators K (3 x N).
        W: Impulse-to-velocity map at the impact point (3 x 3), 1/kg.
        mass: Robot mass, kg.
        jacobian: 3 x nv translational Jacobian of the impact point (world axes).
        impulse_rates: (2N, 3) impulse vertices per unit approach speed, N s / (m/s); rows
            2i and 2i+1 are generator i on the planes c_hi and c_lo (paper's ordering).
    """

    spec: ImpactSpec
    point: np.ndarray
    normal: np.ndarray
    cone: np.ndarray
    W: np.ndarray
    mass: float
    jacobian: np.ndarray
    impulse_rates: np.ndarray

    @functools.cached_property
    def com_jump_rates(self) -> np.ndarray:
        """(2N, 2) planar CoM velocity jumps per unit approach speed (iota_xy / m), read-only."""
        rates = self.impulse_rates[:, :2] / self.mass
        rates.setflags(write=False)
        return rates

    def impulse_vertices(self, approach_speed: float) -> np.ndarray:
        """(2N, 3) impulse vertices, N s, at approach speed v_n (m/s)."""
        return approach_speed * self.impulse_rates

    def com_velocity_jumps(self, approach_speed: float) -> np.ndarray:
        """(2N, 3) CoM velocity jumps iota / m, m/s."""
        return approach_speed * self.impulse_rates / self.mass

    def post_impact_com_velocities(
        self, com_velocity: npt.ArrayLike, approach_speed: float
    ) -> npt.NDArray[np.float64]:
        """The vertices of the post-impact planar CoM velocity set.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).
            approach_speed: v_n, m/s.

        Returns:
            (2N, 2) post-impact CoM velocities, world xy, m/s.
        """
        out: npt.NDArray[np.float64] = (
            np.asarray(com_velocity, dtype=float)[None, :2] + approach_speed * self.com_jump_rates
        )
        return out

    def approach_speed(self, velocity: npt.ArrayLike) -> float:
        """Approach speed -n . v of an end-effector velocity.

        Args:
            velocity: (3,) end-effector velocity, world, m/s.

        Returns:
            m/s, positive towards the surface.
        """
        return float(-self.normal @ np.asarray(velocity, dtype=float))


def impulse_to_velocity(
    stance: Stance,
    point: np.ndarray,
    jacobian: np.ndarray,
    model: str = "composite",
    arm: np.ndarray | None = None,
) -> np.ndarray:
    """W at ``point``: composite rigid body (default) or joint space J M^-1 J^T.

    ``arm`` is ``point - com`` when the caller has it exactly (stance-frame positions);
    by default it is computed from the world positions. Joints that move no mass (Romeo's
    massless fingers: zero rows of M) are left out of the joint-space model; an impact point
    that such a joint moves has no finite W and is refused.
    """
    if model == "composite":
        return composite_inertia_map(
            point - stance.com if arm is None else arm, stance.mass, stance.com_inertia
        )
    if model == "joint_space":
        return joint_space_inertia_map(stance.workspace(), stance.model, stance.q, jacobian)
    raise ImpactModelError("impact.inertia", model, f"must be one of {', '.join(INERTIA_MODELS)}")


def composite_inertia_map(arm: np.ndarray, mass: float, com_inertia: np.ndarray) -> np.ndarray:
    """W = I / m - [r]x Ic^-1 [r]x (1/kg) of the robot as one rigid body.

    ``arm`` r = point - CoM (m), ``mass`` (kg), ``com_inertia`` Ic about the CoM in world axes
    (kg m^2).
    """
    arm = np.ascontiguousarray(arm, dtype=float)
    com_inertia = np.ascontiguousarray(com_inertia, dtype=float)
    W = np.empty((3, 3))
    if _composite_map(arm, float(mass), com_inertia, W):
        return W
    r = skew(arm)  # Ic not positive definite (not a rigid body's): LAPACK's LU says what it can
    out: npt.NDArray[np.float64] = np.eye(3) / mass - r @ np.linalg.solve(com_inertia, r)
    return out


@njit(cache=True)
def _composite_map(arm, mass, Ic, W):
    """``W`` = I / m - [r]x Ic^-1 [r]x by a 3 x 3 Cholesky of ``Ic``, in floats.

    False (W untouched) when ``Ic`` is not positive definite. Compiled (a governor builds W every
    tick). Python floats when interpreted: an overflow gives inf (reported by the caller), not a
    warning.
    """
    a, b, c = float(Ic[0, 0]), float(Ic[0, 1]), float(Ic[0, 2])
    d, e, f = float(Ic[1, 1]), float(Ic[1, 2]), float(Ic[2, 2])
    if not a > 0.0:
        return False
    l00 = math.sqrt(a)
    l10, l20 = b / l00, c / l00
    p11 = d - l10 * l10
    if not p11 > 0.0:
        return False
    l11 = math.sqrt(p11)
    l21 = (e - l20 * l10) / l11
    p22 = f - l20 * l20 - l21 * l21
    if not p22 > 0.0:
        return False
    l22 = math.sqrt(p22)
    rx, ry, rz = float(arm[0]), float(arm[1]), float(arm[2])
    # Columns of S = [r]x; X = Ic^-1 S by L y = s, L^T x = y; W = I/m - S X.
    S = ((0.0, rz, -ry), (-rz, 0.0, rx), (ry, -rx, 0.0))  # S[j] = column j of [r]x
    X = np.empty((3, 3))
    for j in range(3):
        s0, s1, s2 = S[j]
        y0 = s0 / l00
        y1 = (s1 - l10 * y0) / l11
        y2 = (s2 - l20 * y0 - l21 * y1) / l22
        x2 = y2 / l22
        x1 = (y1 - l21 * x2) / l11
        X[0, j], X[1, j], X[2, j] = (y0 - l10 * x1 - l20 * x2) / l00, x1, x2
    inverse_mass = 1.0 / mass
    for i in range(3):  # row i of [r]x is minus column i
        for j in range(3):
            acc = -(S[i][0] * X[0, j] + S[i][1] * X[1, j] + S[i][2] * X[2, j])
            W[i, j] = (inverse_mass if i == j else 0.0) - acc
    return True


def joint_space_inertia_map(
    workspace: Scratch, model: pin.Model, q: np.ndarray, jacobian: np.ndarray
) -> np.ndarray:
    """W = J M(q)^-1 J^T (1/kg) of the translational Jacobian ``jacobian`` (3 x nv).

    M is computed in ``workspace``'s Data (a :class:`~impact_balance.robot.robot.Scratch` or
    :class:`~impact_balance.robot.robot.ThreadData`; its held kinematics are marked stale).
    """
    M = pin.crba(model, workspace.data, q)  # scratch Data: createData costs up to ~2 ms
    M = np.triu(M) + np.triu(M, 1).T
    workspace.holder = None  # crba rewrote the joint placements: point() recomputes them
    diagonal = np.diag(M)
    moving = diagonal > 1e-12 * diagonal.max()
    if not moving.all():  # joints that move no mass (a massless finger): no finite inertia there
        if np.abs(jacobian[:, ~moving]).max() > 1e-12:
            raise ImpactModelError(
                "impact.inertia",
                "joint_space",
                "the impact point is moved by a joint "
                "that moves no mass: no finite joint-space inertia there (use composite)",
            )
        M, jacobian = M[np.ix_(moving, moving)], jacobian[:, moving]
    return jacobian @ np.linalg.solve(M, jacobian.T)


def _short(v: np.ndarray) -> list[float]:
    """A vector as 4-significant-digit floats, for messages."""
    return [float(f"{x:.4g}") for x in np.asarray(v, dtype=float)]


def impact_cone(spec: ImpactSpec) -> tuple[np.ndarray, np.ndarray]:
    """The unit normal and the friction-cone generators (3 x N) of ``spec`` (copies)."""
    try:
        n, K = _normal_and_cone(tuple(spec.normal), spec.friction, spec.cone_edges)
    except ValueError:  # from unit(): friction_cone raises nothing once n is a unit vector
        raise ImpactModelError(
            "impact.normal", list(spec.normal), "must be a non-zero vector"
        ) from None
    return n.copy(), K.copy()


def impact_model(stance: Stance, spec: ImpactSpec) -> ImpactModel:
    """Build the impact model of ``spec`` at the stance's configuration."""
    placement, J6 = stance.local_point(spec.frame, spec.offset, field="impact.frame")
    n, K = impact_cone(spec)
    arm = placement.translation - stance.com_local  # exact far from the origin (stance frame)
    point = placement.translation + stance.origin
    J = J6[:3].copy()
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is reported just below
        W = impulse_to_velocity(stance, point, J, spec.inertia, arm=arm)
    return model_from_inertia_map(spec, point, arm, n, K, W, stance.mass, J)


def model_from_inertia_map(
    spec: ImpactSpec,
    point: np.ndarray,
    arm: np.ndarray,
    normal: np.ndarray,
    cone: np.ndarray,
    W: np.ndarray,
    mass: float,
    jacobian: np.ndarray,
) -> ImpactModel:
    """The impact model from its map W (what :func:`impact_model` computes from a stance).

    Args:
        spec: The impact specification.
        point: Impact point, world, m.
        arm: point - CoM, m (for messages).
        normal: Unit normal, from :func:`impact_cone`.
        cone: Friction-cone generators (3 x N), from :func:`impact_cone`.
        W: Impulse-to-velocity map at the point, 3 x 3, 1/kg.
        mass: kg.
        jacobian: 3 x nv translational Jacobian of the point (world axes).

    Raises:
        ImpactModelError: W is not finite, or a cone edge would not separate the contact.
    """
    lo, hi = spec.restitution
    finite, smallest, rates = _impulse_rates(
        np.ascontiguousarray(normal, dtype=float),
        np.ascontiguousarray(W, dtype=float),
        np.ascontiguousarray(cone, dtype=float),
        float(lo),
        float(hi),
    )
    if not finite:
        raise ImpactModelError(
            "impact.offset",
            _short(arm),
            "the impact point is too far from the CoM: W is not finite",
        )
    if not smallest > 1e-12:  # the kernel's own threshold
        raise ImpactModelError(
            "impact.friction",
            spec.friction,
            f"a friction-cone edge gives n^T W K_i = {smallest:.3g} <= 0: the impulse "
            "would not separate the contact (lower the friction or change the normal)",
        )
    return ImpactModel(spec, point, normal, cone, W, mass, jacobian, rates)


@njit(cache=True)
def _impulse_rates(normal, W, K, lo, hi):
    """``(W finite, min_i n^T W K_i, rates)``, compiled.

    Rows 2i and 2i+1 of ``rates`` (2N, 3) are ``(1 + c) / (n^T W K_i) K_i`` for c = hi and lo
    (the impulse vertices per unit approach speed); n^T W K_i > 0 for an impulse that pushes the
    point back.
    """
    N = K.shape[1]
    rates = np.empty((2 * N, 3))
    for r in range(3):
        for c in range(3):
            if not math.isfinite(W[r, c]):
                return False, math.nan, rates
    nW = np.zeros(3)
    for c in range(3):
        for r in range(3):
            nW[c] += normal[r] * W[r, c]
    normal_response = np.zeros(N)
    for i in range(N):
        for c in range(3):
            normal_response[i] += nW[c] * K[c, i]
    smallest = math.inf
    for i in range(N):
        if not normal_response[i] >= smallest:  # also takes a NaN, which fails the caller's check
            smallest = normal_response[i]
    if not smallest > 1e-12:
        return True, smallest, rates  # refused by the caller: no division by a vanishing response
    for i in range(N):
        r = normal_response[i]
        a, b = (1.0 + hi) / r, (1.0 + lo) / r
        for c in range(3):
            rates[2 * i, c] = a * K[c, i]
            rates[2 * i + 1, c] = b * K[c, i]
    return True, smallest, rates


#: The compiled steps of :func:`composite_inertia_map` and :func:`model_from_inertia_map`, for
#: compiled callers that build a posture's impact model in their own call (a governor's tick):
#: ``composite_map_kernel(arm, mass, Ic, W)`` writes W and answers whether Ic was positive
#: definite (else the caller takes :func:`composite_inertia_map`);
#: ``impulse_rates_kernel(normal, W, K, lo, hi)`` answers ``(W finite, min_i n^T W K_i, rates)``,
#: which :func:`model_from_inertia_map` checks (``> 1e-12``) before it builds the model.
composite_map_kernel = _composite_map
impulse_rates_kernel = _impulse_rates
