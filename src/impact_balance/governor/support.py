"""The governor's optional second impact model: the robot standing on its supports.

The paper's impact model lets the composite robot float through the impact (the post-impact
CoM velocities form a set, one vertex per friction-cone edge and restitution bound). On some
stances the supports change the jump (docs/validation.md, "A contact-aware impact model").
:class:`ContactAwareLimit` adds, to the criterion's post-impact set, the jumps of
:func:`impact_balance.impact.contact_aware.contact_impact` (every support corner a unilateral,
frictional, plastic point contact; no preload) at both ends of the restitution range: the
governor then answers for the union of the two models' post-impact CoM velocities, i.e. the
smaller of the two maximum approach speeds (``Governor(..., contact_aware=True)``).

Several solutions. The frictional impact LCP is not convex and may have several solutions;
the De Saxce fixed point reaches one of them, depending on its starting gauges. With
``starts="union"`` (the default) the criterion holds for every solution found: at each
recomputation and each restitution bound, the fixed point is run from a fixed, deterministic
set of starts,

1. every distinct converged solution kept from the previous recomputation, in order (a
   solution moves continuously with the posture while it exists, so continuing each one
   tracks every branch found so far; a branch that ends converges onto another: merged);
2. the cold start (gauges 0), which finds a branch that appears during the approach;

and every distinct solution reached is kept (rates (k, 2), k >= 2): the limit is the smallest
over all of them, the safe interval the intersection. ``starts="warm"`` runs one fixed point
per bound from the previous answer, ``starts="cold"`` one from gauges 0
(:data:`~impact_balance.governor.options.Starts`).

Cost and freshness. The jump is a fixed point of small QPs (milliseconds to a few hundred
milliseconds per recomputation, more with more starts). It is recomputed on the first posture
and then every ``every``-th posture evaluation; in between, the last rates are used with the
current posture's area and CoM velocity (:attr:`ContactAwareAnswer.age` counts the postures
since). The jump is linear in the approach speed (no preload), so one solve per start and
restitution bound at 1 m/s gives the rates. Units: rates in m/s of CoM velocity (world xy)
per m/s of approach speed. Not thread-safe: the governor calls it under its lock.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from impact_balance.contacts.stance import Stance
from impact_balance.criteria.com import ComCriterion
from impact_balance.criteria.linear_exit import speed_interval
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.exceptions import GovernorError
from impact_balance.governor.options import STARTS, ContactAwareOptions, Starts
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

#: Two fixed points are the same solution when their body velocity changes per m/s of approach
#: speed differ by at most this (max norm; m/s and rad/s per m/s). The fixed point stops when no
#: gauge changes by more than 1e-9 m/s per m/s, so runs to one solution agree to ~1e-8; the
#: ramp's two branches differ by ~0.08 m/s per m/s in the lateral jump.
SAME_SOLUTION = 1e-6


def contact_aware_rates(
    stance: Stance, spec: ImpactSpec, warm: list[np.ndarray] | None = None
) -> tuple[np.ndarray, list[np.ndarray], bool]:
    """One fixed point per restitution bound (``starts="warm"``).

    The contact-aware CoM velocity jump per m/s of approach speed, world xy, at the lower and
    the upper restitution bound: ``(rates (2, 2), body velocity changes (6,) per m/s: (dv_c,
    dw), world, for a warm start, converged)``. ``warm``: one such change per bound, or None
    (cold).
    """
    solutions = _one_per_bound(stance, spec, warm)
    return solutions.rates, list(solutions.states), bool(solutions.converged.all())


@dataclass(frozen=True)
class ContactAwareSolutions:
    """Every distinct contact-aware jump found from a set of starts.

    See :func:`contact_aware_solutions`.

    Attributes:
        rates: (k, 2) CoM velocity jump per m/s of approach speed, world xy (m/s per m/s), one
            row per distinct solution, grouped by restitution bound (lower bound's first); within
            a bound, in the order of the starts that reached them.
        restitution: (k,) the restitution coefficient c_r of each row.
        states: (k, 6) each row's body velocity change per m/s, (dv_c m/s, dw rad/s) per m/s,
            world: the starts of the next recomputation.
        converged: (k,) whether each row's fixed point was reached (else its last iterate,
            kept: the criterion answers for it too).
        iterations: QP solves of all the starts (the cost).
        starts: Fixed points run (starts times restitution bounds).
    """

    rates: np.ndarray
    restitution: np.ndarray
    states: np.ndarray
    converged: np.ndarray
    iterations: int
    starts: int

    def of_bound(self, c_r: float) -> npt.NDArray[np.float64]:
        """The states (m, 6) of the converged solutions at restitution ``c_r`` (the next starts)."""
        keep = (self.restitution == c_r) & self.converged
        states: npt.NDArray[np.float64] = self.states[keep]
        return states


def contact_aware_solutions(
    stance: Stance,
    spec: ImpactSpec,
    previous: ContactAwareSolutions | None = None,
    cold: bool = True,
    tolerance: float = SAME_SOLUTION,
) -> ContactAwareSolutions:
    """The union of the contact-aware impact's solutions reached from several starts.

    Per restitution bound (module docstring), the starts are every converged solution of
    ``previous`` at that bound (in its order), then, when ``cold``, gauges 0. Fixed points
    within ``tolerance`` (max norm of the body velocity change per m/s) of a kept one are the
    same solution; a non-converged fixed point is kept as a row (flagged) but not carried as a
    start.

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


def _one_per_bound(
    stance: Stance,
    spec: ImpactSpec,
    guesses: Sequence[npt.NDArray[Any]] | npt.NDArray[Any] | None,
) -> ContactAwareSolutions:
    """One fixed point per restitution bound (``starts="warm"`` and ``"cold"``).

    From ``guesses[k]`` (a body velocity change (6,) per m/s) or, without guesses, gauges 0:
    2 rows even when both bounds give the same jump.
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
    rates, restitution, states, converged = (np.array(x) for x in zip(*rows, strict=True))
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
    starts: Starts = "warm"
    solves: int = 0


class ContactAwareLimit:
    """The contact-aware jump's speed limit for a governor (module docstring).

    Not thread-safe (its governor calls it under its lock).

    Args:
        spec: The scenario's impact (composite inertia model).
        every: Recompute the jump rates every this many posture evaluations (>= 1).
        starts: "union" (default: every solution reached from the kept solutions and the cold
            start), "warm" (the previous answer only) or "cold" (gauges 0
            only); see :data:`STARTS`.
    """

    def __init__(self, spec: ImpactSpec, every: int = 5, starts: Starts = "union"):
        if spec.inertia != "composite":
            raise GovernorError(
                "contact_aware", spec.inertia, "the contact-aware model is the composite one"
            )
        options = ContactAwareOptions(every, starts)  # checks both
        self.spec = spec
        self.every: int = options.every
        self.starts: Starts = options.starts
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
        """The rates at ``stance`` from the option's starts, without adopting them.

        What a worker process computes for its governor (:mod:`.worker`); :meth:`adopt` makes
        them this limit's.

        Args:
            stance: The posture.
            kept: The solutions to start from (default: this limit's own).

        Returns:
            The solutions found.
        """
        return self._solve(stance, self._solutions if kept is None else kept)

    def adopt(self, solutions: ContactAwareSolutions, age: int = 0) -> None:
        """Use ``solutions`` from now on, e.g. a worker's answer.

        ``age``: postures evaluated since the one they were computed for (0: the current).
        """
        self._solutions = solutions
        self._converged = bool(solutions.converged.all())
        self._age = age

    @property
    def age(self) -> int:
        """Posture evaluations since the one the rates in use were computed for."""
        return self._age

    def aged(self) -> None:
        """A posture was evaluated and the rates were not recomputed for it (age + 1)."""
        self._age += 1

    def new_posture(self, stance_of: Callable[[], Stance]) -> None:
        """A posture was evaluated.

        ``stance_of()`` builds its :class:`Stance` (called only when the rates are due).
        """
        if self._solutions is None or self._count % self.every == 0:
            self.adopt(self._solve(stance_of(), self._solutions))
        else:
            self._age += 1
        self._count += 1

    def answer(self, criterion: ComCriterion, com_velocity: np.ndarray) -> ContactAwareAnswer:
        """The contact-aware limit and safe interval (m/s of approach speed).

        The first exit over every row of the rates (the smallest speed), and the intersection
        of their safe intervals.

        Args:
            criterion: The posture's :class:`~impact_balance.criteria.com.ComCriterion` (its
                CoM velocity area, world xy, m/s, and its velocity margin).
            com_velocity: The pre-impact CoM velocity (world, m/s).

        Returns:
            The contact-aware answer.
        """
        return self.answers(criterion, com_velocity)[1]

    def answers(
        self, criterion: ComCriterion, com_velocity: np.ndarray
    ) -> tuple[ContactVelocityLimit, ContactAwareAnswer]:
        """The floating model's limit and :meth:`answer`, in one compiled call (a tick).

        Args:
            criterion: As in :meth:`answer`.
            com_velocity: As in :meth:`answer`.

        Returns:
            ``criterion.limit(com_velocity)`` and :meth:`answer`'s answer.

        Raises:
            GovernorError: No posture evaluated yet.
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
    """The approach speeds (m/s) safe for both models.

    The intersection of two safe intervals (or None).
    """
    if floating is None or aware is None:
        return None
    lo, hi = max(floating[0], aware[0]), min(floating[1], aware[1])
    return (lo, hi) if lo <= hi else None
