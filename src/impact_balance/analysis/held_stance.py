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
- the angular momentum term (``angular_momentum_damping_time``) and the CoM's reach are not
  counted: the fallback is the paper's answer without them.
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
from impact_balance.impact.held_stance import held_stance_jumps

__all__ = ["HeldStanceLimit", "held_stance_max_contact_velocity"]


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
    """

    max_contact_velocity: float
    status: LimitStatus
    restitution: tuple[float, float]
    jumps: np.ndarray
    converged: bool
    fell_back: bool
    binding_restitution: float | None
    iterations: int

    def to_dict(self) -> dict[str, Any]:
        """JSON form (strict: an unbounded maximum is null), ``validate``'s ``held_stance``."""
        speed = self.max_contact_velocity
        return {
            "max_contact_velocity": float(speed) if math.isfinite(speed) else None,
            "status": self.status,
            "restitution": list(self.restitution),
            "jumps": self.jumps.tolist(),
            "converged": self.converged,
            "fell_back": self.fell_back,
            "binding_restitution": self.binding_restitution,
            "iterations": self.iterations,
        }


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
    )
