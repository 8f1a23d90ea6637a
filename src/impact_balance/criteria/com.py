"""The CoM velocity criterion (paper sec. V-C): :class:`ComCriterion`.

Every post-impact vertex is ``c0 + s d_j`` (c0 the pre-impact planar CoM velocity, s the
approach speed, d_j the jump per unit speed), and the CoM velocity area is ``{x : G x <= h}``.
All vertices stay inside for ``s <= min_{k,j: G_k d_j > 0} (h_k - G_k c0) / (G_k d_j)``: that
minimum IS the maximum contact velocity, exactly (no search, no QP). The set of post-impact
velocities is the convex hull of the vertices, so the vertices suffice.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np
import numpy.typing as npt

from impact_balance._jit import cache_depends_on, njit
from impact_balance.criteria import linear_exit
from impact_balance.criteria.criterion import CriterionName
from impact_balance.criteria.linear_exit import (
    BOUNDARY_TOLERANCE,
    exit_kernel,
    limit_of_exit,
    speed_interval,
)
from impact_balance.criteria.velocity_limit import ContactVelocityLimit
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.angular_momentum import AngularMomentumTerm, effective_impulse_rates
from impact_balance.impact.model import ImpactModel

__all__ = ["ComCriterion", "jump_rates_kernel", "max_contact_velocity", "safe_interval"]


@njit(cache=True)
def _jump_rates(impulse_rates, mass, G):
    """``rates[j, k] = (iota_j,xy / m) . G_k``.

    The rate (m/s per m/s of approach speed) at which post-impact vertex j uses up
    half-plane k's margin (``ImpactModel.com_jump_rates @ G.T``, compiled: a governor builds
    it every posture).
    """
    rates = np.empty((impulse_rates.shape[0], G.shape[0]))
    for j in range(impulse_rates.shape[0]):
        x, y = impulse_rates[j, 0] / mass, impulse_rates[j, 1] / mass
        for k in range(G.shape[0]):
            rates[j, k] = x * G[k, 0] + y * G[k, 1]
    return rates


@njit(cache=True)
def _com_exit(G, h, c0x, c0y, rates, tol):
    """:func:`~impact_balance.criteria.linear_exit.exit_kernel` of the margins ``h - G c0``."""
    margins = np.empty(h.size)
    for k in range(h.size):
        margins[k] = h[k] - (G[k, 0] * c0x + G[k, 1] * c0y)
    return exit_kernel(margins, rates, tol)


@njit(cache=True)
def _com_exits(G, h, c0x, c0y, rates, jumps, tol):
    """:func:`_com_exit` for ``rates`` and for the jumps ``jumps`` (k, 2).

    The rates of ``jumps`` per edge are ``jumps G^T``; the answer is the two answers'
    8 numbers.
    """
    margins = np.empty(h.size)
    for k in range(h.size):
        margins[k] = h[k] - (G[k, 0] * c0x + G[k, 1] * c0y)
    edge = np.empty((jumps.shape[0], h.size))
    for j in range(jumps.shape[0]):
        for k in range(h.size):
            edge[j, k] = jumps[j, 0] * G[k, 0] + jumps[j, 1] * G[k, 1]
    a = exit_kernel(margins, rates, tol)
    b = exit_kernel(margins, edge, tol)
    return a[0], a[1], a[2], a[3], b[0], b[1], b[2], b[3]


#: :func:`_jump_rates` for compiled callers that build a criterion's rates in their own call
#: (a governor's tick; :meth:`ComCriterion.from_rates` takes them).
jump_rates_kernel = _jump_rates

cache_depends_on(_com_exit, linear_exit)
cache_depends_on(_com_exits, linear_exit)


class ComCriterion:
    """The CoM velocity criterion of one area and one impact model, for any CoM velocity.

    What does not depend on the CoM velocity is computed once: the area's half-planes
    ``G x <= h`` and the rates ``d_j . G_k`` (m/s per m/s of approach speed) at which the
    post-impact vertices use up each half-plane's margin. :meth:`limit` and :meth:`interval`
    then cost a few microseconds per CoM velocity (a governor's velocity-only tick).
    :func:`max_contact_velocity` and :func:`safe_interval` are these two methods.

    With a ``velocity_margin`` d > 0 (m/s), every post-impact CoM velocity must lie at least d
    inside the area (the area eroded by a disc of radius d: each half-plane moved in by d), a
    margin for the impact model's error; 0 is the paper's criterion.

    With an ``angular_momentum`` term, the post-impact vertices are the paper's ``c0 + s d_j``
    *and* the effective CoM velocities ``c0 + s (d_j + gain S((p - c) x iota_j) / m)`` that
    count the centroidal angular momentum the impulse leaves, removed with time constant tau
    (:mod:`impact_balance.impact.angular_momentum`): the contacts remove it at a rate between
    1/tau and 0, and the area being convex, both ends inside means every rate between is. The
    term can then only lower the paper's answer (an impulse below the CoM, whose effective
    velocity is smaller, keeps the paper's). None is the paper's criterion.

    Attributes:
        name: "com".
        area: The CoM velocity area (world x, y), m/s.
        impact: The impact model.
        velocity_margin: d, m/s.
        G: (n_c, 2) unit outward normals of the area's half-planes (None for an empty area).
        h: (n_c,) their offsets less the velocity margin, m/s (None for an empty area).
        rates: (n_v, n_c) the rates ``d_j . G_k`` (None for an empty area).
        angular_momentum: The angular momentum term, or None (the paper's criterion).
    """

    __slots__ = ("G", "angular_momentum", "area", "h", "impact", "rates", "velocity_margin")

    name: ClassVar[CriterionName] = "com"

    G: npt.NDArray[np.float64] | None
    h: npt.NDArray[np.float64] | None
    rates: npt.NDArray[np.float64] | None

    def __init__(
        self,
        area: Polygon,
        impact: ImpactModel,
        velocity_margin: float = 0.0,
        angular_momentum: AngularMomentumTerm | None = None,
    ):
        self.area = area
        self.impact = impact
        self.velocity_margin = float(velocity_margin)
        self.angular_momentum = angular_momentum
        if area.is_empty:
            self.G = self.h = self.rates = None
            return
        G, h = area.halfplanes  # unit rows: h - G x is the distance inside each edge
        if self.velocity_margin:
            h = h - self.velocity_margin
        self.G, self.h = G, h
        impulse_rates = impact.impulse_rates
        if angular_momentum is not None and angular_momentum.gain != 0.0:
            # The rate at which the contacts remove the angular momentum lies between 1/tau and
            # 0 (never): the capture must hold at both ends, hence (the area being convex) at
            # every rate between. Both vertex sets, the paper's and the effective one.
            impulse_rates = np.vstack(
                [impulse_rates, effective_impulse_rates(impulse_rates, angular_momentum)]
            )
        self.rates = _jump_rates(impulse_rates, float(impact.mass), G)

    @classmethod
    def from_rates(
        cls,
        area: Polygon,
        impact: ImpactModel,
        velocity_margin: float,
        G: npt.NDArray[np.float64],
        h: npt.NDArray[np.float64],
        rates: npt.NDArray[np.float64],
    ) -> ComCriterion:
        """The criterion whose half-planes and rates were computed by the caller.

        The same object as ``ComCriterion(area, impact, velocity_margin)`` (no angular
        momentum term) when ``(G, h)`` are ``area.halfplanes`` (``h`` less the margin) and
        ``rates`` is :data:`jump_rates_kernel` of the impact's ``impulse_rates``, its mass and
        ``G``: a compiled caller (a governor's tick) made them in its own call.
        """
        self = cls.__new__(cls)
        self.area, self.impact = area, impact
        self.velocity_margin = float(velocity_margin)
        self.angular_momentum = None
        self.G, self.h, self.rates = G, h, rates
        return self

    def margins(self, com_velocity: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The slack ``h - G c0`` of the pre-impact CoM velocity in each half-plane.

        Args:
            com_velocity: Pre-impact CoM velocity c0, world, m/s (x and y are read).

        Returns:
            (n_c,) slack less the velocity margin, m/s.

        Raises:
            ValueError: The area is empty (there are no half-planes).
        """
        if self.G is None or self.h is None:
            raise ValueError("an empty area has no margins")
        out: npt.NDArray[np.float64] = self.h - self.G @ np.asarray(com_velocity, dtype=float)[:2]
        return out

    def limit(self, com_velocity: npt.ArrayLike) -> ContactVelocityLimit:
        """Largest approach speed keeping every post-impact CoM velocity in the area.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).

        Returns:
            The limit (m/s); "cannot_balance" (0) for an empty area.
        """
        if self.G is None:
            return ContactVelocityLimit(0.0, "cannot_balance")
        c = np.asarray(com_velocity, dtype=float)
        c0x, c0y = float(c[0]), float(c[1])
        return limit_of_exit(*_com_exit(self.G, self.h, c0x, c0y, self.rates, BOUNDARY_TOLERANCE))

    def limits(
        self, com_velocity: npt.ArrayLike, jumps: npt.ArrayLike
    ) -> tuple[ContactVelocityLimit, ContactVelocityLimit]:
        """:meth:`limit`, and the same limit for other post-impact jumps, in one compiled call.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).
            jumps: (k, 2) CoM velocity jumps per m/s of approach speed, world xy (e.g. another
                impact model's; its vertex j is row j).

        Returns:
            The limit of this criterion's impact model, and the limit of ``jumps``.
        """
        if self.G is None:
            cannot = ContactVelocityLimit(0.0, "cannot_balance")
            return cannot, cannot
        c = np.asarray(com_velocity, dtype=float)
        c0x, c0y = float(c[0]), float(c[1])
        out = _com_exits(
            self.G,
            self.h,
            c0x,
            c0y,
            self.rates,
            np.ascontiguousarray(jumps, dtype=float),
            BOUNDARY_TOLERANCE,
        )
        return limit_of_exit(*out[:4]), limit_of_exit(*out[4:])

    def interval(
        self, com_velocity: npt.ArrayLike, limit: ContactVelocityLimit | None = None
    ) -> tuple[float, float] | None:
        """The safe approach speeds ``(lo, hi)``, m/s (see :func:`safe_interval`).

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).
            limit: :meth:`limit`'s answer for the same velocity when the caller has it.

        Returns:
            ``(lo, hi)`` (``hi`` may be inf), or None when no speed is safe.
        """
        if self.G is None or self.rates is None:
            return None
        if limit is not None and limit.from_inside:
            return limit.interval_from_inside()
        return speed_interval(self.margins(com_velocity), self.rates)


def safe_interval(
    area: Polygon,
    impact: ImpactModel,
    com_velocity: npt.ArrayLike,
    limit: ContactVelocityLimit | None = None,
    angular_momentum: AngularMomentumTerm | None = None,
) -> tuple[float, float] | None:
    """The approach speeds s >= 0 whose whole post-impact CoM velocity set lies in ``area``.

    The post-impact vertices ``c0 + s d_j`` are linear in s, so these speeds form one
    interval ``(s_lo, s_hi)`` (m/s; ``s_hi`` may be inf); None when it is empty (or the
    area is). With ``c0`` inside the area, ``s_lo`` = 0 and ``s_hi`` is the maximum contact
    velocity. With ``c0`` outside (the robot falls without an impact), a non-empty interval
    is the impacts that catch the fall: ``s_lo`` > 0.

    Args:
        area: The CoM velocity area (world x, y), m/s.
        impact: The impact model.
        com_velocity: Pre-impact CoM velocity c0, world, m/s (x and y are read).
        limit: :func:`max_contact_velocity`'s answer for the same data when the caller has
            it: with ``c0`` inside, the interval is ``(0, limit)`` and is not computed again.
        angular_momentum: The angular momentum term (see :class:`ComCriterion`), or None.

    Returns:
        ``(s_lo, s_hi)``, or None.
    """
    if area.is_empty:
        return None
    if limit is not None and limit.from_inside:
        return limit.interval_from_inside()
    return ComCriterion(area, impact, angular_momentum=angular_momentum).interval(com_velocity)


def max_contact_velocity(
    area: Polygon,
    impact: ImpactModel,
    com_velocity: npt.ArrayLike,
    angular_momentum: AngularMomentumTerm | None = None,
) -> ContactVelocityLimit:
    """Largest approach speed keeping every post-impact CoM velocity in ``area``.

    Args:
        area: The CoM velocity area (world x, y), m/s.
        impact: The impact model.
        com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).
        angular_momentum: The angular momentum term (see :class:`ComCriterion`), or None.

    Returns:
        The limit (m/s); "cannot_balance" (0) for an empty area.
    """
    if area.is_empty:
        return ContactVelocityLimit(0.0, "cannot_balance")
    return ComCriterion(area, impact, angular_momentum=angular_momentum).limit(com_velocity)
