"""Experimental: the composite robot's impact with its sustained contacts taking impulses too.

The paper's impact model (:mod:`impact_balance.impact.model`) lets the robot float through the
impact: only the impacting end-effector takes an impulse, and the CoM velocity jump is that
impulse over the mass. Here the same rigid robot (every joint keeps its velocity: one rigid
body of mass m and rotational inertia Ic about the CoM) also meets its supports: every corner
of every sustained contact rectangle is a unilateral, frictional, plastic point contact, solved
at the same instant as the impacting point.

Formulation (all world axes, SI units). The unknown is the body's velocity change
``dxi = (dv_c, dw)`` (CoM velocity, m/s, and angular velocity, rad/s). A point p with arm
r = p - c moves with ``u_p = u_p^- + J_p dxi``, ``J_p = [I, -[r]x]``. Each contact point
carries a friction pyramid with generators d_j = n + mu t_j (normal component 1): the
scenario's impact cone (:func:`impact_balance.impact.model.impact_cone`) at the impact point and
the contact wrench cone's corner edges (:func:`impact_balance.contacts.cwc.cwc_span`) at the soles.
Pre-impact velocities: ``-v_n n`` at the impact point (the limb moves, the robot stands), 0 at
the sustained corners; restitution c_r at the impact point, 0 (plastic) at the corners.

Coulomb's law with maximal dissipation and Newton's restitution is the classic frictional
impact LCP (Stewart & Trinkle 1996, Anitescu & Potra 1997); it is not convex. It is solved as
the fixed point of convex QPs (De Saxce's change of variable, Acary, Cadoux, Lemarechal &
Malick, CRAS 2011):

    min_dxi  1/2 dxi^T M dxi                       (Gauss's principle, M = diag(m I, Ic))
    s.t.     d_j^T (u_p + c_r (n^T u_p^-) n) + s_p >= 0    for every point p and generator j

with ``s_p`` the friction gauge of the previous iterate's sliding velocity,
``s_p = max_j -(d_j - n)^T u_p`` (>= 0). With s = 0 this is Anitescu's convex relaxation (the
family of MuJoCo's own contact model, which drops strict complementarity), whose sliding
contacts drift apart at mu |u_t|;
the shift s removes that drift, so at the fixed point a sliding point keeps its normal velocity
(c_r v_n at the impact, 0 at a corner) and the multipliers are the Coulomb impulses. Gauss's
principle makes ``dxi`` unique at each step; the impulses (the QP's multipliers, N s) are not
when the supports are statically indeterminate, but their resultant is ``M dxi``: the ones
returned are those of least norm.

Why this formulation: the criterion reads the CoM velocity jump, and Gauss's principle gives
one (the floating model's impulse set becomes one point: maximal dissipation picks the friction
direction); each step is a dense QP in 6 unknowns (daqp); and the fixed point is the
LCP's Coulomb answer, not the relaxation's, whose drift would add mu |u_t| of separation at a
palm that slides (0.1 to 0.9 m/s in the simulated impacts). The fixed point is not guaranteed
to exist or be reached in general: ``converged`` says whether it was.

Limits: the impact is instantaneous, so the supports' pre-impact load (the weight) plays no
part: a corner cannot give back part of the load it carried (its impulse is >= 0), and a foot
the impact does not press has no friction during the impact. Experimental: the paper's criteria do
not use it; the held-stance model (:mod:`impact_balance.impact.held_stance`) and the governor's
contact-aware option do.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from impact_balance.contacts.cwc import cwc_span
from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ImpactModelError, SolverError
from impact_balance.geometry.spatial import skew
from impact_balance.impact.model import ImpactSpec, impact_cone

__all__ = [
    "ContactImpact",
    "PointContact",
    "contact_impact",
    "corner_contacts",
    "rigid_body_impact",
]


@dataclass(frozen=True)
class PointContact:
    """A unilateral frictional point contact of the rigid robot.

    Attributes:
        arm: Point minus CoM, world axes, m.
        normal: Unit normal from the surface into the robot, world.
        generators: (3, N) friction-pyramid generators d_j = n + mu t_j, world (n^T d_j = 1).
        velocity: Pre-impact velocity of the point, world, m/s.
        restitution: Newton restitution coefficient c_r (0: plastic).
    """

    arm: np.ndarray
    normal: np.ndarray
    generators: np.ndarray
    velocity: np.ndarray
    restitution: float = 0.0


@dataclass(frozen=True)
class ContactImpact:
    """The predicted impact of the rigid robot on its impact point and sustained contacts.

    Attributes:
        approach_speed: v_n, m/s. restitution: c_r used at the impact point.
        com_velocity_jump: CoM velocity jump, world xy, m/s (what the criterion reads).
        com_velocity_jump_3d: The same with z, m/s (= total impulse / m).
        angular_velocity_jump: Body angular velocity jump, world, rad/s.
        post_impact_com_velocity: Pre-impact planar CoM velocity + the jump, world xy, m/s.
        impact_impulse: Impulse on the robot at the impact point, world, N s.
        contact_impulses: (k, 3) impulse on the robot at each sustained contact (sum over its
            4 corners), world, N s; the least-norm distribution (see the module doc).
        corner_impulses: (k, 4, 3) the same per corner (cwc_span's corner order
            (+X,+Y), (+X,-Y), (-X,+Y), (-X,-Y) in the contact frame).
        iterations: Fixed-point iterations (QP solves). converged: the fixed point was reached.
    """

    approach_speed: float
    restitution: float
    com_velocity_jump: np.ndarray
    com_velocity_jump_3d: np.ndarray
    angular_velocity_jump: np.ndarray
    post_impact_com_velocity: np.ndarray
    impact_impulse: np.ndarray
    contact_impulses: np.ndarray
    corner_impulses: np.ndarray
    iterations: int
    converged: bool


def _unique_columns(D: np.ndarray) -> np.ndarray:
    """Generators without repeats.

    mu = 0 makes every edge the normal, and an active-set QP solver dislikes identical
    constraint rows.
    """
    _, index = np.unique(np.round(D.T, 12), axis=0, return_index=True)
    return D[:, np.sort(index)]


def corner_contacts(stance: Stance) -> list[list[PointContact]]:
    """The 4 corners of each sustained contact of ``stance`` as plastic point contacts at rest.

    Each has the friction-pyramid edges (+-mu, +-mu, 1) of
    :func:`~impact_balance.contacts.cwc.cwc_span`.
    """
    out = []
    for c in stance.contacts:
        X, Y, mu = c.half_length, c.half_width, float(c.spec.friction)
        span = cwc_span(mu, X, Y)  # columns 4k..4k+3: the pyramid edges at corner k
        centre = (
            c.local_position if c.local_position is not None else c.position - stance.origin
        ) - stance.com_local
        corners = []
        for k, (px, py) in enumerate(((X, Y), (X, -Y), (-X, Y), (-X, -Y))):
            arm = centre + c.rotation @ np.array([px, py, 0.0])
            D = _unique_columns(c.rotation @ span[:3, 4 * k : 4 * k + 4])
            corners.append(PointContact(arm, c.normal.copy(), D, np.zeros(3)))
        out.append(corners)
    return out


def rigid_body_impact(
    mass: float,
    com_inertia: np.ndarray,
    points: Sequence[PointContact],
    solver: str = "daqp",
    tolerance: float = 1e-9,
    max_iterations: int = 1000,
    initial_dxi: np.ndarray | None = None,
) -> tuple[np.ndarray, list[np.ndarray], int, bool]:
    """Solve the frictional impact of one rigid body on ``points`` (see the module docstring).

    Args:
        mass: kg.
        com_inertia: Rotational inertia about the CoM, world axes, kg m^2.
        points: The contact points, pre-impact velocities included.
        solver: qpsolvers backend (returning the multipliers: "daqp", "highs").
        tolerance: Fixed point reached when no gauge s_p changes by more than this (m/s).
        max_iterations: Most QP solves.
        initial_dxi: A guess of the answer (6,), e.g. the previous posture's: the first
            gauges are those of its sliding velocities (a warm start; the fixed point reached
            is the same one when it is unique, in fewer QP solves; when the LCP has several
            solutions it tends to stay on the guess's branch). Default: gauges 0.

    Returns:
        ``(dxi, impulses, iterations, converged)``: the 6-vector (dv_c m/s, dw rad/s), the
        impulse on the body at each point (world, N s), the QP solves, and whether the fixed
        point was reached (else the last iterate).
    """
    import qpsolvers  # its import takes ~0.4 s: only when this model is used

    M = np.zeros((6, 6))
    M[:3, :3] = mass * np.eye(3)
    M[3:, 3:] = 0.5 * (com_inertia + com_inertia.T)
    jacobians = [np.hstack([np.eye(3), -skew(p.arm)]) for p in points]
    # Velocity targets: the pre-impact velocity, shifted along n by the restitution term.
    targets = [p.velocity + p.restitution * float(p.normal @ p.velocity) * p.normal for p in points]
    rows = [-(p.generators.T @ J) for p, J in zip(points, jacobians, strict=True)]
    G = np.vstack(rows)
    base = np.concatenate([p.generators.T @ t for p, t in zip(points, targets, strict=True)])
    sizes = [p.generators.shape[1] for p in points]
    owner = np.repeat(np.arange(len(points)), sizes)
    gauges = np.zeros(len(points))
    if initial_dxi is not None:
        guess = np.asarray(initial_dxi, dtype=float).reshape(6)
        gauges = np.array(
            [
                max(0.0, float(np.max(-(p.generators - p.normal[:, None]).T @ (t + J @ guess))))
                for p, t, J in zip(points, targets, jacobians, strict=True)
            ]
        )
    dxi = np.zeros(6)
    z = np.zeros(len(base))
    converged = False
    iterations = 0
    for iterations in range(1, max_iterations + 1):  # noqa: B007 (returned: the count)
        problem = qpsolvers.Problem(M, np.zeros(6), G, base + gauges[owner])
        try:
            solution = qpsolvers.solve_problem(problem, solver=solver)
        except (
            qpsolvers.SolverNotFound,
            qpsolvers.SolverError,
            ValueError,
        ) as exc:  # as qp.py: our error, one line
            raise SolverError(
                solver,
                type(exc).__name__,
                str(exc).splitlines()[0] if str(exc) else "",
                field="contact_impact",
            ) from None
        if not solution.found or solution.x is None or solution.z is None:
            raise SolverError(solver, "not solved", "the contact impact QP", field="contact_impact")
        dxi, z = (
            np.asarray(solution.x, dtype=float),
            np.maximum(np.asarray(solution.z, dtype=float), 0.0),
        )
        new = np.array(
            [
                max(0.0, float(np.max(-(p.generators - p.normal[:, None]).T @ (t + J @ dxi))))
                for p, t, J in zip(points, targets, jacobians, strict=True)
            ]
        )
        change = float(np.max(np.abs(new - gauges))) if len(new) else 0.0
        gauges = new
        if change <= tolerance:
            converged = True
            break
    z = _least_norm_multipliers(G, base + gauges[owner], M @ dxi, dxi, z, solver)
    impulses = []
    start = 0
    for p, size in zip(points, sizes, strict=True):
        impulses.append(p.generators @ z[start : start + size])
        start += size
    return dxi, impulses, iterations, converged


def _least_norm_multipliers(
    G: np.ndarray, h: np.ndarray, resultant: np.ndarray, dxi: np.ndarray, z: np.ndarray, solver: str
) -> np.ndarray:
    """The multipliers of least norm with the same resultant and the same active rows.

    The resultant is ``M dxi = -G^T z``: with more support corners than the body has freedoms
    (two flat feet) the active-set solver returns one vertex of many (one foot taking
    everything); this spreads the impulses as evenly as the constraints allow. The solver's own
    multipliers if it fails.
    """
    import qpsolvers

    slack = h - G @ dxi
    inactive = slack > 1e-9 * max(1.0, float(np.abs(h).max(initial=0.0)))
    upper = np.where(inactive, 0.0, np.inf)
    try:
        least = qpsolvers.solve_qp(
            np.eye(len(z)),
            np.zeros(len(z)),
            A=-G.T,
            b=resultant,
            lb=np.zeros(len(z)),
            ub=upper,
            solver=solver,
        )
    except (
        qpsolvers.SolverNotFound,
        qpsolvers.SolverError,
        ValueError,
    ):  # a selection among equivalent answers
        least = None
    if least is None or np.abs(-G.T @ least - resultant).max() > 1e-6 * max(
        1.0, float(np.abs(resultant).max())
    ):
        return z
    out: npt.NDArray[np.float64] = np.maximum(least, 0.0)
    return out


def contact_impact(
    stance: Stance,
    spec: ImpactSpec,
    approach_speed: float,
    com_velocity: npt.ArrayLike | None = None,
    restitution: float | None = None,
    solver: str = "daqp",
    tolerance: float = 1e-9,
    max_iterations: int = 1000,
    initial_dxi: np.ndarray | None = None,
) -> ContactImpact:
    """The rigid (composite) robot's impact with its sustained contacts (module docstring).

    Args:
        stance: The robot and its sustained contacts (their corners are at rest before).
        spec: The impact: frame, offset, normal, friction and cone edges are used; the
            model is the composite one (``spec.inertia`` must be "composite").
        approach_speed: v_n >= 0, m/s, of the impact point along -n.
        com_velocity: Pre-impact planar CoM velocity, world xy, m/s (default 0). The jump does
            not depend on it (the contacts' pre-impact velocities do not): it is only added.
        restitution: c_r at the impact point (default: the upper end of ``spec.restitution``).
        solver: See :func:`rigid_body_impact`.
        tolerance: Fixed-point tolerance relative to ``approach_speed``.
        initial_dxi: Warm start, see :func:`rigid_body_impact` (the body's velocity change
            (6,) expected at this ``approach_speed``, e.g. a previous answer's
            ``concatenate([com_velocity_jump_3d, angular_velocity_jump])``).
        max_iterations: See :func:`rigid_body_impact`.

    The jump is linear in ``approach_speed``.
    """
    if spec.inertia != "composite":
        raise ImpactModelError(
            "impact.inertia", spec.inertia, "the contact-aware model is the composite one"
        )
    v_n = float(approach_speed)
    if not (np.isfinite(v_n) and v_n >= 0.0):
        raise ImpactModelError("approach_speed", approach_speed, "must be a finite speed >= 0")
    c_r = float(spec.restitution[1] if restitution is None else restitution)
    if not 0.0 <= c_r <= 1.0:
        raise ImpactModelError("impact.restitution", c_r, "must be in [0, 1]")
    placement, _ = stance.local_point(spec.frame, spec.offset, field="impact.frame")
    n, K = impact_cone(spec)
    impact = PointContact(
        placement.translation - stance.com_local, n, _unique_columns(K), -v_n * n, c_r
    )
    corners = corner_contacts(stance)
    points = [impact] + [p for contact in corners for p in contact]
    dxi, impulses, iterations, converged = rigid_body_impact(
        stance.mass,
        stance.com_inertia,
        points,
        solver,
        tolerance * max(v_n, 1e-12),
        max_iterations,
        initial_dxi,
    )
    jump = dxi[:3]
    corner_impulses = (
        np.array(impulses[1:]).reshape(len(corners), 4, 3) if corners else np.zeros((0, 4, 3))
    )
    before = np.zeros(2) if com_velocity is None else np.asarray(com_velocity, dtype=float)[:2]
    return ContactImpact(
        approach_speed=v_n,
        restitution=c_r,
        com_velocity_jump=jump[:2].copy(),
        com_velocity_jump_3d=jump.copy(),
        angular_velocity_jump=dxi[3:].copy(),
        post_impact_com_velocity=before + jump[:2],
        impact_impulse=impulses[0],
        contact_impulses=corner_impulses.sum(axis=1),
        corner_impulses=corner_impulses,
        iterations=iterations,
        converged=converged,
    )
