"""The governor's optional second impact model: the robot standing on its supports.

The paper's impact model lets the composite robot float through the impact (the post-impact
CoM velocities form a set, one vertex per friction-cone edge and restitution bound). On some
stances the supports change the jump: G1's feet keep it from turning about its CoM, so its
CoM velocity jump is larger than any vertex of the floating set (docs/validation.md, "A
contact-aware impact model"). :class:`ContactAwareLimit` adds, to the criterion's post-impact
set, the jumps of :func:`impact_balance.impact.contact_aware.contact_impact` (every support corner a
unilateral, frictional, plastic point contact; no preload) at both ends of the restitution
range: the governor then answers for the union of the two models' post-impact CoM velocities,
i.e. the smaller of the two maximum approach speeds (``Governor(..., contact_aware=True)``).

Several solutions: the union (default, ``starts="union"``). The frictional impact LCP is not
convex and may have several solutions (on ``palm_push_ramp`` near the wall, two: lateral jump
+0.12 and +0.043 per m/s; docs/contact_aware_governor.md, section 4). The De Saxce fixed point
reaches one of them, depending on its starting gauges. Since the model cannot say which one the
robot will follow, the criterion must hold for every solution found: at each recomputation and
each restitution bound, the fixed point is run from a fixed, deterministic set of starts,

1. every distinct solution kept from the previous recomputation (the first of them continues the
   first posture's answer: the frozen warm-started option's branch). A solution of the LCP moves
   continuously with the posture while it exists, so continuing each one tracks every branch
   found so far; a branch that ends makes its start converge to another solution (merged);
2. the cold start (gauges 0, Anitescu's relaxation first): the solution reached from no
   knowledge of the past, which finds a branch that appears during the approach;

and every distinct solution reached is kept (rates (k, 2), k >= 2): the limit is the smallest
over all of them, the safe interval the intersection. Nothing here depends on any trial's
outcome. ``starts="warm"`` is the option as frozen in commit 5e477e6 (one start, the previous
answer) and ``starts="cold"`` the post hoc cold start, both kept for the record.

Scored (docs/contact_aware_governor.md, section 5; frozen in commit e0ce502): the union changes
no outcome on the four stances of the wall study. It lowers the ramp's cap by 2 to 2.5 % where
the cold start finds a second branch before the contact (trials that stood either way); where the
ramp falls (walls 12 and 13.5 cm) the LCP has one solution at the contact posture, the cap is
honoured to 0.1 %, and the model's residual at the inset edge (-0.008 to +0.005 m/s) decides.

Cost. The contact-aware jump is a fixed point of small QPs (2 to 40 ms per start and posture);
it changes slowly with the posture, so it is recomputed on the first posture and then every
``every``-th posture evaluation (default 5: every 10 ms at 500 Hz) and, in between, the last jump
rates are used with the current posture's area and CoM velocity. The jump is linear in the
approach speed (no preload), so one solve per start and restitution bound at 1 m/s gives the
rates. The union costs one fixed point per start, the cold start the slowest: median 8 to 67 ms
per recomputation on the wall study's stances (up to 164 ms on the ramp with two solutions kept),
2.2 to 2.8 times the warm start's (docs/contact_aware_governor.md, section 5).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from impact_balance.contacts.stance import Stance
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.linear_exit import speed_interval
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.exceptions import GovernorError
from impact_balance.impact.contact_aware import contact_impact
from impact_balance.impact.model import ImpactSpec

__all__ = [
    "STARTS",
    "ContactAwareAnswer",
    "ContactAwareLimit",
    "ContactAwareSolutions",
    "contact_aware_rates",
    "contact_aware_solutions",
]

#: The fixed-point starts of :class:`ContactAwareLimit` (module docstring): "union" (default:
#: every solution reached from the kept solutions and the cold start), "warm" (the previous
#: answer only, as frozen in commit 5e477e6), "cold" (gauges 0 only, the post hoc variant).
STARTS = ("union", "warm", "cold")

#: Two fixed points are the same solution when their body velocity changes per m/s of approach
#: speed differ by at most this (max norm; m/s and rad/s per m/s). The fixed point stops when no
#: gauge changes by more than 1e-9 m/s per m/s, so runs to one solution agree to ~1e-8; the
#: ramp's two branches differ by ~0.08 m/s per m/s in the lateral jump.
SAME_SOLUTION = 1e-6


def contact_aware_rates(
    stance: Stance, spec: ImpactSpec, warm: list[np.ndarray] | None = None
) -> tuple[np.ndarray, list[np.ndarray], bool]:
    """One fixed point per restitution bound (the frozen option's ``starts="warm"``): the
    contact-aware CoM velocity jump per m/s of approach speed, world xy, at the lower and the
    upper restitution bound: ``(rates (2, 2), body velocity changes (6,) per m/s: (dv_c, dw),
    world, for a warm start, converged)``. ``warm``: one such change per bound, or None (cold).
    """
    solutions = _one_per_bound(stance, spec, warm)
    return solutions.rates, list(solutions.states), bool(solutions.converged.all())


@dataclass(frozen=True)
class ContactAwareSolutions:
    """Every distinct contact-aware jump found from a set of starts (:func:`contact_aware_solutions`).

    Attributes:
        rates: (k, 2) CoM velocity jump per m/s of approach speed, world xy (m/s per m/s), one
            row per distinct solution, grouped by restitution bound (lower bound's first); within
            a bound, in the order of the starts that reached them.
        restitution: (k,) the restitution coefficient c_r of each row.
        states: (k, 6) each row's body velocity change per m/s, (dv_c m/s, dw rad/s) per m/s,
            world: the starts of the next recomputation.
        converged: (k,) whether each row's fixed point was reached (else its last iterate,
            kept: the criterion answers for it too, as the frozen option did).
        iterations: QP solves of all the starts (the cost).
        starts: Fixed points run (starts times restitution bounds).
    """

    rates: np.ndarray
    restitution: np.ndarray
    states: np.ndarray
    converged: np.ndarray
    iterations: int
    starts: int

    def of_bound(self, c_r: float) -> np.ndarray:
        """The states (m, 6) of the converged solutions at restitution ``c_r`` (the next starts)."""
        keep = (self.restitution == c_r) & self.converged
        return self.states[keep]


def contact_aware_solutions(
    stance: Stance,
    spec: ImpactSpec,
    previous: ContactAwareSolutions | None = None,
    cold: bool = True,
    tolerance: float = SAME_SOLUTION,
) -> ContactAwareSolutions:
    """The union of the contact-aware impact's solutions reached from several starts, per
    restitution bound (module docstring): starts are every converged solution of ``previous`` at
    that bound (in its order), then, when ``cold``, gauges 0. Fixed points within ``tolerance``
    (max norm of the body velocity change per m/s) of a kept one are the same solution; a
    non-converged fixed point is kept as a row (flagged) but not carried as a start.

    Args:
        stance: The posture (its sustained contacts and composite inertia).
        spec: The impact (composite inertia model); its restitution bounds.
        previous: The last recomputation's solutions, or None (then the cold start only).
        cold: Also run the cold start (forced when there is no previous solution at a bound).
        tolerance: See :data:`SAME_SOLUTION`.
    """
    rates, restitution, states, converged = [], [], [], []
    iterations = starts = 0
    for c_r in (float(c) for c in spec.restitution):
        guesses: list[np.ndarray | None] = (
            list(previous.of_bound(c_r)) if previous is not None else []
        )
        if cold or not guesses:
            guesses.append(None)
        found: list[np.ndarray] = []
        for guess in guesses:
            r = contact_impact(stance, spec, 1.0, restitution=c_r, initial_dxi=guess)
            iterations, starts = iterations + r.iterations, starts + 1
            state = np.concatenate([r.com_velocity_jump_3d, r.angular_velocity_jump])
            # One LCP solution reached from two starts is one row: the criterion reads each once.
            if any(float(np.max(np.abs(state - s))) <= tolerance for s in found):
                continue
            found.append(state)
            rates.append(r.com_velocity_jump.copy())
            restitution.append(c_r)
            states.append(state)
            converged.append(r.converged)
    return ContactAwareSolutions(
        np.array(rates),
        np.array(restitution),
        np.array(states),
        np.array(converged, dtype=bool),
        iterations,
        starts,
    )


def _one_per_bound(stance: Stance, spec: ImpactSpec, guesses) -> ContactAwareSolutions:
    """One fixed point per restitution bound, from ``guesses[k]`` (a body velocity change (6,)
    per m/s) or, without guesses, gauges 0: 2 rows even when both bounds give the same jump
    (the frozen option's ``starts="warm"`` and the post hoc ``"cold"``).
    """
    rows, iterations = [], 0
    for k, c_r in enumerate(float(c) for c in spec.restitution):
        r = contact_impact(
            stance, spec, 1.0, restitution=c_r, initial_dxi=None if guesses is None else guesses[k]
        )
        rows.append(
            (
                r.com_velocity_jump.copy(),
                c_r,
                np.concatenate([r.com_velocity_jump_3d, r.angular_velocity_jump]),
                r.converged,
            )
        )
        iterations += r.iterations
    rates, restitution, states, converged = (np.array(x) for x in zip(*rows))
    return ContactAwareSolutions(
        rates, restitution, states, converged.astype(bool), iterations, len(rows)
    )


@dataclass(frozen=True)
class ContactAwareAnswer:
    """The contact-aware model's part of one tick's answer.

    Attributes:
        limit: Largest approach speed (m/s) keeping every contact-aware post-impact CoM velocity
            in the area, as :class:`~impact_balance.criteria.velocity_limit.ContactVelocityLimit`
            (its vertex j: row j of ``rates``).
        interval: The approach speeds ``(lo, hi)`` (m/s) that keep them all in (the
            intersection over the rows), or None.
        rates: (k, 2) the jumps per m/s used (world xy, m/s per m/s): with ``starts`` "warm" or
            "cold", k = 2 (row 0: the lower restitution bound, 1: the upper); with "union",
            every distinct solution found at each bound (k >= 2).
        age: Posture evaluations since the rates were computed (0: this posture's).
        converged: Whether every fixed point was reached when they were computed.
        restitution: (k,) the restitution coefficient c_r of each row of ``rates``.
        starts: The option's starts ("union", "warm" or "cold"; module docstring).
        solves: QP solves of the last recomputation (all its fixed points; the cost).
    """

    limit: ContactVelocityLimit
    interval: tuple[float, float] | None
    rates: np.ndarray
    age: int
    converged: bool
    restitution: np.ndarray = field(default_factory=lambda: np.zeros(0))
    starts: str = "warm"
    solves: int = 0


class ContactAwareLimit:
    """The contact-aware jump's speed limit for a governor (module docstring); not thread-safe
    (its governor calls it under its lock).

    Args:
        spec: The scenario's impact (composite inertia model).
        every: Recompute the jump rates every this many posture evaluations (>= 1).
        starts: "union" (default: every solution reached from the kept solutions and the cold
            start), "warm" (the frozen option: the previous answer only) or "cold" (gauges 0
            only); see :data:`STARTS`.
    """

    def __init__(self, spec: ImpactSpec, every: int = 5, starts: str = "union"):
        if spec.inertia != "composite":
            raise GovernorError(
                "contact_aware", spec.inertia, "the contact-aware model is the composite one"
            )
        if not (isinstance(every, (int, np.integer)) and every >= 1):
            raise GovernorError("contact_aware_every", every, "must be an integer >= 1")
        if starts not in STARTS:
            raise GovernorError(
                "contact_aware_starts", starts, f"must be one of {', '.join(STARTS)}"
            )
        self.spec = spec
        self.every = int(every)
        self.starts = starts
        self._solutions: ContactAwareSolutions | None = None
        self._converged = False  # whether every fixed point of _solutions was reached
        self._age = 0
        self._count = 0

    def _solve(self, stance: Stance, kept: ContactAwareSolutions | None) -> ContactAwareSolutions:
        """The rates at ``stance`` from the option's starts, continuing ``kept``."""
        if self.starts == "union":
            return contact_aware_solutions(stance, self.spec, kept, cold=True)
        # "warm": the previous answer per bound (row k of the previous 2 rows); "cold": none.
        return _one_per_bound(
            stance, self.spec, kept.states if self.starts == "warm" and kept is not None else None
        )

    def solve(
        self, stance: Stance, kept: ContactAwareSolutions | None = None
    ) -> ContactAwareSolutions:
        """The rates at ``stance`` from the option's starts, continuing ``kept`` (the solutions
        to start from; default: this limit's own), without adopting them (:meth:`adopt`): what
        a worker process computes for its governor (:mod:`.worker`).
        """
        return self._solve(stance, self._solutions if kept is None else kept)

    def adopt(self, solutions: ContactAwareSolutions) -> None:
        """Use ``solutions`` from now on (age 0), e.g. a worker's answer."""
        self._solutions = solutions
        self._converged = bool(solutions.converged.all())
        self._age = 0

    def aged(self) -> None:
        """A posture was evaluated and the rates were not recomputed for it (age + 1)."""
        self._age += 1

    def new_posture(self, stance_of: Callable[[], Stance]) -> None:
        """A posture was evaluated; ``stance_of()`` builds its :class:`Stance` (called only when
        the rates are due).
        """
        if self._solutions is None or self._count % self.every == 0:
            self.adopt(self._solve(stance_of(), self._solutions))
        else:
            self._age += 1
        self._count += 1

    def answer(self, criterion: ComCriterion, com_velocity: np.ndarray) -> ContactAwareAnswer:
        """The limit and interval (m/s of approach speed) for the CoM velocity area of
        ``criterion`` (world xy, m/s; the posture's :class:`~impact_balance.criteria.com.ComCriterion`,
        its velocity margin included) and the pre-impact CoM velocity (world, m/s): the first
        exit over every row of the rates (the smallest speed), the intersection of their safe
        intervals.
        """
        return self.answers(criterion, com_velocity)[1]

    def answers(
        self, criterion: ComCriterion, com_velocity: np.ndarray
    ) -> tuple[ContactVelocityLimit, ContactAwareAnswer]:
        """``criterion.limit(com_velocity)`` (the floating model's limit) and :meth:`answer`,
        in one compiled call: a governor's tick.
        """
        s = self._solutions
        if s is None:
            raise GovernorError("contact_aware", None, "no posture evaluated yet")
        floating, limit = criterion.limits(com_velocity, s.rates)
        if criterion.G is None:
            interval = None
        elif limit.from_inside:
            interval = limit.interval_from_inside()
        else:
            interval = speed_interval(criterion.margins(com_velocity), s.rates @ criterion.G.T)
        return floating, ContactAwareAnswer(
            limit,
            interval,
            s.rates,
            self._age,
            self._converged,
            s.restitution,
            self.starts,
            s.iterations,
        )


def combine(
    floating: tuple[float, float] | None, aware: tuple[float, float] | None
) -> tuple[float, float] | None:
    """The approach speeds (m/s) safe for both models: the intersection of two safe intervals
    (or None).
    """
    if floating is None or aware is None:
        return None
    lo, hi = max(floating[0], aware[0]), min(floating[1], aware[1])
    return (lo, hi) if lo <= hi else None
