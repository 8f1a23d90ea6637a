"""An analysis's maximum contact velocity by the held-stance impact model (``--impact-model``).

The paper's maximum contact velocity (the analysis's ``impact.com``) is the largest approach
speed s keeping every post-impact CoM velocity ``c0 + s d_k`` in the CoM velocity area, over the
floating model's vertices d_k. :func:`held_stance_max_contact_velocity` answers the same
question for the held-stance jumps of :func:`impact_balance.impact.held_stance.held_stance_jumps`
(the contact-aware model at the restitution bounds lo and hi, cold start):

- it is the smallest of the two speeds ``s(j(lo))`` and ``s(j(hi))``, each the largest s with
  ``c0 + s j(c)`` in the area (the jump being affine in c, the two bounds cover every c
  between). The area, its ZMP margin, the velocity margin and the pre-impact CoM velocity c0
  are the analysis's own, those of the paper's answer;
- **fallback**: when either fixed point is not reached, the answer is the paper's (the
  analysis's ``impact.com``) and ``fell_back`` is True;
- the CoM's reach is not counted, nor, in ``max_contact_velocity``, the angular momentum
  term: the fallback there is the paper's answer without them.

**With the angular momentum it leaves** (the analysis's ``angular_momentum_damping_time`` tau
set, s: its ``impact.angular_momentum``), the answer also has ``angular_momentum``
(:class:`HeldStanceAngularMomentum`). The held-stance solution at each bound leaves the
centroidal angular momentum ``L(c) = Ic dw(c)`` per m/s of approach speed (world, about the
CoM: the moment of all the impulses, the point's and the feet's), and, as the floating default
does with ``(p - c) x iota``, its effective jump is

    j_eff(c) = j(c) + gain S(L(c)) / m,   S(L) = (L_y, -L_x),   gain = 1 / (h (1 + omega tau))

(1/m, :func:`~impact_balance.impact.angular_momentum.angular_momentum_gain`; m the mass, kg).
The contacts remove L at a rate between 1/tau and 0, so, the area being convex, the capture
holds at every rate when both ends lie in the area: its maximum is the smallest ray of the four
jumps ``j(lo), j(hi), j_eff(lo), j_eff(hi)`` (it can only be lower than ``max_contact_velocity``).
Where a fixed point is not reached it falls back to the analysis's default answer, the paper's
extended by the same term (``impact.default``). Without tau, no ``angular_momentum``: the
answer is exactly as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from impact_balance.analysis.result import Analysis
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.velocity_limit import LimitStatus
from impact_balance.exceptions import ImpactModelError
from impact_balance.impact.angular_momentum import AngularMomentumTerm
from impact_balance.impact.held_stance import HeldStanceJumps, held_stance_jumps

__all__ = [
    "HeldStanceAngularMomentum",
    "HeldStanceLimit",
    "effective_jumps",
    "held_stance_max_contact_velocity",
]


@dataclass(frozen=True)
class HeldStanceAngularMomentum:
    """The held-stance maximum counting the angular momentum it leaves (module docstring).

    Attributes:
        damping_time: tau, s (the analysis's ``angular_momentum_damping_time``).
        gain: ``1 / (h (1 + omega tau))``, 1/m.
        angular_momentum: (2, 3) ``L = Ic dw`` per m/s of approach speed at ``lo`` (row 0) and
            ``hi`` (row 1), world axes, about the CoM, N m s per m/s.
        effective_jumps: (2, 2) ``j + gain S(L) / m`` at ``lo`` and ``hi``, world xy, m/s per
            m/s.
        max_contact_velocity: m/s, the smallest ray of the jumps and the effective jumps (inf:
            unbounded; 0: already falling or cannot balance); the analysis's default answer
            (the paper's with the same term) when the parent answer fell back.
        status: How it was reached, as
            :data:`~impact_balance.criteria.velocity_limit.LimitStatus`.
        binding_restitution: The bound whose jump or effective jump reaches the area's
            boundary first; None when fallen back or when no speed leaves the area.
        binding_effective: Whether that is the effective jump (True) or the jump itself
            (False); None with ``binding_restitution`` None.
    """

    damping_time: float
    gain: float
    angular_momentum: np.ndarray
    effective_jumps: np.ndarray
    max_contact_velocity: float
    status: LimitStatus
    binding_restitution: float | None
    binding_effective: bool | None

    def to_dict(self) -> dict[str, Any]:
        """JSON form (strict: an unbounded maximum is null), ``held_stance.angular_momentum``."""
        speed = self.max_contact_velocity
        return {
            "damping_time": self.damping_time,
            "gain": self.gain,
            "angular_momentum": self.angular_momentum.tolist(),
            "effective_jumps": self.effective_jumps.tolist(),
            "max_contact_velocity": float(speed) if math.isfinite(speed) else None,
            "status": self.status,
            "binding_restitution": self.binding_restitution,
            "binding_effective": self.binding_effective,
        }


@dataclass(frozen=True)
class HeldStanceLimit:
    """The held-stance model's maximum contact velocity (module docstring).

    Attributes:
        max_contact_velocity: m/s (inf: unbounded; 0: already falling or cannot balance); the
            paper's answer when ``fell_back``.
        status: How it was reached, as
            :data:`~impact_balance.criteria.velocity_limit.LimitStatus`.
        restitution: ``(lo, hi)``, the restitution bounds used.
        jumps: (2, 2) the held-stance CoM velocity jump per m/s of approach speed at ``lo``
            (row 0) and ``hi`` (row 1), world xy, m/s per m/s (the last iterate where a fixed
            point was not reached).
        converged: Whether both fixed points were reached.
        fell_back: Whether the answer is the paper's (a fixed point was not reached).
        binding_restitution: The bound (``lo`` or ``hi``) whose jump reaches the area's
            boundary first; None when ``fell_back`` or when no speed leaves the area.
        iterations: QP solves of both fixed points.
        angular_momentum: The answer counting the angular momentum the impact leaves, when the
            analysis sets ``angular_momentum_damping_time``; None otherwise.
    """

    max_contact_velocity: float
    status: LimitStatus
    restitution: tuple[float, float]
    jumps: np.ndarray
    converged: bool
    fell_back: bool
    binding_restitution: float | None
    iterations: int
    angular_momentum: HeldStanceAngularMomentum | None = None

    def to_dict(self) -> dict[str, Any]:
        """JSON form (strict: an unbounded maximum is null), ``validate``'s ``held_stance``."""
        speed = self.max_contact_velocity
        out: dict[str, Any] = {
            "max_contact_velocity": float(speed) if math.isfinite(speed) else None,
            "status": self.status,
            "restitution": list(self.restitution),
            "jumps": self.jumps.tolist(),
            "converged": self.converged,
            "fell_back": self.fell_back,
            "binding_restitution": self.binding_restitution,
            "iterations": self.iterations,
        }
        if self.angular_momentum is not None:
            out["angular_momentum"] = self.angular_momentum.to_dict()
        return out


def held_stance_max_contact_velocity(
    analysis: Analysis, max_iterations: int = 1000
) -> HeldStanceLimit:
    """The held-stance maximum contact velocity of ``analysis`` (module docstring).

    Args:
        analysis: An analysis with an impact of the composite inertia model (its stance, areas
            with their ZMP margin, velocity margin, pre-impact CoM velocity and paper's answer).
        max_iterations: Most QP solves of each fixed point (see
            :func:`~impact_balance.impact.held_stance.held_stance_jumps`).

    Returns:
        The answer.

    Raises:
        ImpactModelError: The analysis has no impact (field ``impact``), or its inertia model
            is not "composite" (field ``impact.inertia``).
    """
    impact = analysis.impact
    if impact is None:
        raise ImpactModelError("impact", None, "the held-stance model needs an impact")
    model = impact.model
    held = held_stance_jumps(analysis.stance, model.spec, max_iterations)
    term = impact.angular_momentum
    if not held.all_converged:
        paper = impact.com
        return HeldStanceLimit(
            paper.max_contact_velocity,
            paper.status,
            held.restitution,
            held.jumps,
            False,
            True,
            None,
            held.iterations,
            None if term is None else _fallen_back_with_angular_momentum(analysis, held, term),
        )
    criterion = ComCriterion(
        analysis.areas.com_velocity_area, model, analysis.scenario.velocity_margin
    )
    _, limit = criterion.limits(analysis.com_velocity, held.jumps)
    binding = None if limit.limiting_vertex is None else held.restitution[limit.limiting_vertex]
    return HeldStanceLimit(
        limit.max_contact_velocity,
        limit.status,
        held.restitution,
        held.jumps,
        True,
        False,
        binding,
        held.iterations,
        None if term is None else _with_angular_momentum(analysis, criterion, held, term),
    )


def effective_jumps(held: HeldStanceJumps, gain: float, mass: float) -> np.ndarray:
    """``j + gain S(L) / m`` at each bound (module docstring), world xy, m/s per m/s.

    Args:
        held: The held-stance jumps and the angular momentum they leave.
        gain: ``1 / (h (1 + omega tau))``, 1/m.
        mass: m, kg.

    Returns:
        (2, 2) effective jumps at ``lo`` (row 0) and ``hi`` (row 1).
    """
    L = held.angular_momentum
    shift = np.column_stack([L[:, 1], -L[:, 0]]) * (gain / mass)
    out: np.ndarray = held.jumps + shift
    return out


def _with_angular_momentum(
    analysis: Analysis, criterion: ComCriterion, held: HeldStanceJumps, term: AngularMomentumTerm
) -> HeldStanceAngularMomentum:
    """The converged held-stance answer with the angular momentum term (module docstring)."""
    effective = effective_jumps(held, term.gain, float(analysis.stance.mass))
    _, limit = criterion.limits(analysis.com_velocity, np.vstack([held.jumps, effective]))
    vertex = limit.limiting_vertex
    return HeldStanceAngularMomentum(
        term.damping_time,
        term.gain,
        held.angular_momentum,
        effective,
        limit.max_contact_velocity,
        limit.status,
        None if vertex is None else held.restitution[vertex % 2],
        None if vertex is None else vertex >= 2,
    )


def _fallen_back_with_angular_momentum(
    analysis: Analysis, held: HeldStanceJumps, term: AngularMomentumTerm
) -> HeldStanceAngularMomentum:
    """The fallback with the term: the analysis's default (the paper's with the same term)."""
    assert analysis.impact is not None  # checked by the caller
    default = analysis.impact.default
    return HeldStanceAngularMomentum(
        term.damping_time,
        term.gain,
        held.angular_momentum,
        effective_jumps(held, term.gain, float(analysis.stance.mass)),
        default.max_contact_velocity,
        default.status,
        None,
        None,
    )
