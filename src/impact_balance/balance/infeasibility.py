"""Why a stance cannot balance: torque limits, friction, or the contacts themselves.

A stance "cannot balance" when its contact-wrench polytope (contact wrench cones, joint
torque limits, LIPM equalities: vertical force m g, zero moment about the CoM) is empty.
The diagnosis relaxes one group of constraints at a time, with LPs (HiGHS):

1. Torque limits. Without them, is the polytope non-empty? Then the limits are the cause,
   and for each torque-limited joint it computes the smallest factor ``s_j`` on that
   joint's effort limit alone (every other limit unchanged) that makes the polytope
   non-empty: ``min s_j  s.t.  CWC, LIPM, |tau_i| <= tau_max_i (i != j),
   |tau_j| <= s_j tau_max_j``. Joints for which no factor suffices alone get None. It also
   computes the smallest common factor ``t`` on all the limits together.
2. Friction. With every contact's friction raised to :data:`HIGH_FRICTION` (and no torque
   limits), is it non-empty? Then friction is the cause, and a bisection on a common
   friction coefficient finds the smallest one that suffices.
3. Otherwise no friction and no torque can help: the resultant of the contact forces
   cannot be the weight through the CoM, i.e. the CoM is outside the static-equilibrium
   region of these contacts (for example a single vertical wall contact).

This runs only for a stance that cannot balance (a few tens of LPs, tens of ms).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance.constants import GRAVITY
from impact_balance.contacts.stance import Contact, Stance
from impact_balance.contacts.wrench_polytope import contact_polytope, wrench_polytope
from impact_balance.solvers import HighsLP, LinearProgram

__all__ = [
    "FRICTION_RTOL",
    "HIGH_FRICTION",
    "BindingJoint",
    "CannotBalanceReason",
    "explain_cannot_balance",
]

#: Friction coefficient taken as "as much friction as one wants" (the polytope is then
#: already the limit one up to 1e-6 of the weight for any practical geometry).
HIGH_FRICTION = 1e3
#: Relative tolerance of the friction bisection.
FRICTION_RTOL = 1e-3


@dataclass(frozen=True)
class BindingJoint:
    """A joint whose torque limit prevents balance.

    Attributes:
        joint: Joint name.
        effort: Its URDF effort limit, N m (or N).
        min_scale: Smallest factor on this limit alone (others unchanged) that restores
            balance; None when raising this limit alone cannot.
    """

    joint: str
    effort: float
    min_scale: float | None

    def to_dict(self) -> dict[str, Any]:
        """The JSON object of ``cannot_balance_reason.binding_joints[i]``."""
        return {"joint": self.joint, "effort": self.effort, "min_scale": self.min_scale}


@dataclass(frozen=True)
class CannotBalanceReason:
    """Why the contacts cannot hold the robot at rest.

    Attributes:
        kind: "torque_limits", "friction" or "com_outside" (see the module docstring),
            "zmp_margin" when the stance balances but its ZMP support area is too small for the
            margin asked (:mod:`impact_balance.balance.areas`), or "unknown" when an LP of the
            diagnosis failed.
        message: One line for people.
        binding_joints: For "torque_limits": the joints whose limit alone, raised by
            ``min_scale``, restores balance (smallest first), then those that bind at the
            common scaling but cannot restore it alone (``min_scale`` None).
        uniform_scale: For "torque_limits": the smallest common factor on every effort limit.
        min_friction: For "friction": the smallest common friction coefficient that suffices.
    """

    kind: str
    message: str
    binding_joints: tuple[BindingJoint, ...] = ()
    uniform_scale: float | None = None
    min_friction: float | None = None

    def __str__(self) -> str:
        return self.message

    def to_dict(self) -> dict[str, Any]:
        """The JSON object ``cannot_balance_reason`` of ``impact-balance analyze --json``."""
        return {
            "kind": self.kind,
            "message": self.message,
            "binding_joints": [j.to_dict() for j in self.binding_joints],
            "uniform_scale": self.uniform_scale,
            "min_friction": self.min_friction,
        }


def _feasible(A: np.ndarray, b: np.ndarray, C: np.ndarray, d: np.ndarray) -> bool:
    lp = HighsLP(LinearProgram(A, b, C, d), warm=False)
    return lp.maximize(np.zeros(A.shape[1])).status != "infeasible"


def _min_scale(
    A: npt.NDArray[np.float64],
    b: npt.NDArray[np.float64],
    C: npt.NDArray[np.float64],
    d: npt.NDArray[np.float64],
    rows: npt.NDArray[np.int_],
    limits: npt.NDArray[np.float64],
) -> float | None:
    """``min s`` over ``{A w - s L <= b, C w = d}`` where L is ``limits`` on ``rows`` (else 0).

    None when infeasible for every s (or unbounded below: then any s >= 0 works, 0).
    """
    L = np.zeros(A.shape[0])
    L[rows] = limits
    A_s = np.column_stack([A, -L])
    C_s = np.column_stack([C, np.zeros(C.shape[0])])
    c = np.zeros(A_s.shape[1])
    c[-1] = -1.0  # maximise -s
    # s >= 0 (a negative scale means nothing); HiGHS's free columns, so as a row.
    A_s = np.vstack([A_s, c])
    b_s = np.append(b, 0.0)
    sol = HighsLP(LinearProgram(A_s, b_s, C_s, d), warm=False).maximize(c)
    if sol.status == "infeasible":
        return None
    if sol.status == "unbounded" or sol.x is None:  # cannot happen: s >= 0, bounded objective
        return 0.0
    return float(sol.x[-1])


def _joint_names(stance: Stance, velocity_indices: np.ndarray) -> list[str]:
    model = stance.model
    owner = {}
    for jid in range(1, model.njoints):
        joint = model.joints[jid]
        for k in range(joint.idx_v, joint.idx_v + joint.nv):
            owner[k] = model.names[jid]
    return [owner.get(int(k), f"v[{int(k)}]") for k in velocity_indices]


def explain_cannot_balance(
    stance: Stance, torque_limits: bool = True, gravity: float = GRAVITY
) -> CannotBalanceReason:
    """Why ``stance`` cannot balance (call it only when its areas are empty).

    See the module docstring for what is computed.
    """
    weight = stance.mass * gravity
    if torque_limits:
        full = wrench_polytope(stance, True, gravity)
        n_cwc = full.n_cwc_rows
        # Units of m g (as the projection): limits and forces of order 1.
        A, b, C, d = full.A, full.b / weight, full.C, full.d / weight
        if _feasible(A[:n_cwc], b[:n_cwc], C, d):
            return _torque_reason(stance, A, b, C, d, n_cwc, weight)
    contacts = stance.contacts
    loose = [
        dataclasses.replace(c, spec=dataclasses.replace(c.spec, friction=HIGH_FRICTION))
        for c in contacts
    ]
    if contacts and _contacts_feasible(stance, loose, gravity):
        mu = _min_friction(stance, gravity)
        return CannotBalanceReason(
            "friction",
            f"not enough friction: even without torque limits the contacts slip; a friction "
            f"coefficient of {mu:.3g} on every contact would hold the robot",
            min_friction=mu,
        )
    return CannotBalanceReason(
        "com_outside",
        "the CoM is outside the static-equilibrium region of these contacts: no friction and "
        "no torque can make the contact forces carry the weight through the CoM",
    )


def _contacts_feasible(stance: Stance, contacts: Sequence[Contact], gravity: float) -> bool:
    """Whether CWC + LIPM (no torque limits) is feasible for ``contacts`` at this stance.

    Uses the stance-frame lever arms (contact positions relative to the CoM).
    """
    local = [dataclasses.replace(c, position=c.local_position - stance.com_local) for c in contacts]
    P = contact_polytope(local, stance.mass, np.zeros(3), gravity)
    weight = stance.mass * gravity
    return _feasible(P.A, P.b / weight, P.C, P.d / weight)


def _min_friction(stance: Stance, gravity: float) -> float:
    """Smallest common friction coefficient that makes CWC + LIPM feasible.

    A bisection in log scale between the largest current friction and :data:`HIGH_FRICTION`.
    """

    def ok(mu: float) -> bool:
        cs = [
            dataclasses.replace(c, spec=dataclasses.replace(c.spec, friction=mu))
            for c in stance.contacts
        ]
        return _contacts_feasible(stance, cs, gravity)

    lo = max(c.spec.friction for c in stance.contacts)
    hi = HIGH_FRICTION
    if ok(lo):  # the contacts' own frictions differ: the largest one on all suffices
        return lo
    while hi / lo > 1.0 + FRICTION_RTOL:
        mid = math.sqrt(lo * hi)
        lo, hi = (lo, mid) if ok(mid) else (mid, hi)
    return hi


def _torque_reason(
    stance: Stance,
    A: npt.NDArray[np.float64],
    b: npt.NDArray[np.float64],
    C: npt.NDArray[np.float64],
    d: npt.NDArray[np.float64],
    n_cwc: int,
    weight: float,
) -> CannotBalanceReason:
    idx, limits = stance.robot.effort_limits
    k = idx.size
    names = _joint_names(stance, idx)
    scaled = limits / weight
    # Common factor t on every limit: rows n_cwc + j (upper) and n_cwc + k + j (lower).
    all_rows = np.arange(n_cwc, n_cwc + 2 * k)
    b0 = b.copy()
    b0[all_rows] -= np.concatenate([scaled, scaled])  # b = tau_max +- g: keep only +- g
    uniform = _min_scale(A, b0, C, d, all_rows, np.concatenate([scaled, scaled]))
    joints = []
    for j in range(k):
        rows = np.array([n_cwc + j, n_cwc + k + j])
        bj = b.copy()
        bj[rows] -= scaled[j]
        s = _min_scale(A, bj, C, d, rows, np.array([scaled[j], scaled[j]]))
        if s is not None and s > 1.0 + 1e-9:
            joints.append(BindingJoint(names[j], float(limits[j]), s))
    joints.sort(key=lambda jt: math.inf if jt.min_scale is None else jt.min_scale)
    if not joints and uniform is not None:
        # No joint alone: list those at their (scaled) limit at the common optimum.
        joints = [
            BindingJoint(n, float(lim), None)
            for n, lim in _active_at_uniform(
                A, b0, C, d, all_rows, np.concatenate([scaled, scaled]), uniform, names, limits
            )
        ]
    if joints and joints[0].min_scale is not None:
        alone = ", ".join(f"{j.joint} x{j.min_scale:.3g} (limit {j.effort:g})" for j in joints[:3])
        more = f" (+{len(joints) - 3} more)" if len(joints) > 3 else ""
        detail = f"raising one joint's effort limit suffices: {alone}{more}"
    else:
        detail = "no single joint's limit suffices" + (
            f" (binding: {', '.join(j.joint for j in joints[:5])})" if joints else ""
        )
    common = f"; or every limit x{uniform:.3g}" if uniform is not None else ""
    return CannotBalanceReason(
        "torque_limits",
        "the joint torque limits: the contacts could hold the robot without them; "
        f"{detail}{common}",
        tuple(joints),
        uniform,
    )


def _active_at_uniform(
    A: npt.NDArray[np.float64],
    b0: npt.NDArray[np.float64],
    C: npt.NDArray[np.float64],
    d: npt.NDArray[np.float64],
    rows: npt.NDArray[np.int_],
    L: npt.NDArray[np.float64],
    t: float,
    names: list[str],
    limits: npt.NDArray[np.float64],
) -> list[tuple[str, float]]:
    """Joints whose torque is at t times its limit at a solution with the common factor t."""
    Lfull = np.zeros(A.shape[0])
    Lfull[rows] = L
    sol = HighsLP(LinearProgram(A, b0 + t * (1 + 1e-9) * Lfull, C, d), warm=False).maximize(
        np.zeros(A.shape[1])
    )
    if not sol.optimal or sol.x is None:
        return []
    slack = (b0 + t * Lfull - A @ sol.x)[rows]
    k = len(names)
    tight = np.minimum(slack[:k], slack[k:]) <= 1e-6 * np.maximum(L[:k], 1e-12) * max(t, 1.0)
    return [(names[j], limits[j]) for j in np.flatnonzero(tight)]
