"""The held-stance impact model: the contact-aware jump at the two restitution bounds.

The held-stance model is the contact-aware model of :mod:`impact_balance.impact.contact_aware`
(the locked composite robot; every corner of every sustained contact a unilateral, frictional,
plastic point contact, solved at the same instant as the impact point), evaluated once at each
end ``lo`` and ``hi`` of the scenario's restitution range, from rest (gauges 0: the cold start),
at an approach speed of 1 m/s. The jump is linear in the approach speed, so each answer is the
CoM velocity jump per m/s of approach speed, world xy.

Each solution also has the locked body's angular velocity jump dw (rad/s), hence the
centroidal angular momentum the impact leaves, ``L = Ic dw`` (N m s per m/s, world axes, about
the CoM, Ic the composite inertia about the CoM): the moment about the CoM of *all* the
impulses, the impact point's and the sustained contacts' (``sum_p (p - c) x iota_p``), the
held-stance counterpart of the floating model's ``(p - c) x iota``.

:func:`held_stance_jumps` gives the two jumps and whether both fixed points were reached. The
maximum contact velocity built on them, with its fallback to the paper's floating model where a
fixed point is not reached, is
:func:`impact_balance.analysis.held_stance.held_stance_max_contact_velocity`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from impact_balance.contacts.stance import Stance
from impact_balance.impact.contact_aware import contact_impact
from impact_balance.impact.model import ImpactSpec

__all__ = ["HeldStanceJumps", "held_stance_jumps"]


@dataclass(frozen=True)
class HeldStanceJumps:
    """The held-stance CoM velocity jump at each restitution bound.

    Attributes:
        restitution: ``(lo, hi)``, the restitution coefficients c_r used (the scenario's bounds).
        jumps: (2, 2) CoM velocity jump per m/s of approach speed, world xy (m/s per m/s); row 0
            at ``lo``, row 1 at ``hi``.
        converged: (2,) whether each fixed point was reached (else its last iterate).
        iterations: QP solves of both fixed points.
        angular_momentum: (2, 3) centroidal angular momentum ``Ic dw`` the impact leaves per
            m/s of approach speed, world axes, about the CoM (N m s per m/s); row 0 at ``lo``,
            row 1 at ``hi`` (module docstring).
    """

    restitution: tuple[float, float]
    jumps: np.ndarray
    converged: tuple[bool, bool]
    iterations: int
    angular_momentum: np.ndarray

    @property
    def all_converged(self) -> bool:
        """Whether both fixed points were reached."""
        return all(self.converged)


def held_stance_jumps(
    stance: Stance, spec: ImpactSpec, max_iterations: int = 1000
) -> HeldStanceJumps:
    """The held-stance jump per m/s of approach speed at ``spec``'s restitution bounds.

    Args:
        stance: The robot and its sustained contacts.
        spec: The impact (composite inertia model); its ``restitution`` ``(lo, hi)`` is used.
        max_iterations: Most QP solves of each fixed point (see
            :func:`~impact_balance.impact.contact_aware.contact_impact`).

    Returns:
        The two jumps, from the cold start at 1 m/s.

    Raises:
        ImpactModelError: ``spec.inertia`` is not "composite" (field ``impact.inertia``).
        SolverError: A QP of the fixed point failed.
    """
    lo, hi = (float(c) for c in spec.restitution)
    answers = [
        contact_impact(stance, spec, 1.0, restitution=c, max_iterations=max_iterations)
        for c in (lo, hi)
    ]
    return HeldStanceJumps(
        restitution=(lo, hi),
        jumps=np.array([a.com_velocity_jump for a in answers], dtype=float),
        converged=(bool(answers[0].converged), bool(answers[1].converged)),
        iterations=sum(a.iterations for a in answers),
        angular_momentum=np.array(
            [stance.com_inertia @ a.angular_velocity_jump for a in answers], dtype=float
        ),
    )
