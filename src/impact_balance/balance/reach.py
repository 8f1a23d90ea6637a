"""The CoM's reach at constant height, and the zero-step capture it limits.

The paper's zero-step capture asks the DCM ``xi = c + v / omega`` to lie in the ZMP support
area: then a ZMP held inside the area brings the CoM to rest. It assumes the CoM can travel, at
the LIPM's constant height, wherever that takes it. On a wide stance it cannot: with both feet
kept, the legs' lengths and joint limits bound how far the CoM moves sideways at its height
(:func:`com_reach`, by whole-body IK). This module states the capture with that bound.

Along a direction ``u`` (world, horizontal) from the CoM, let ``e`` be the ZMP area's extent
(m, the ray from the CoM to the area's boundary; inset by the controller's margin) and ``R`` the
CoM's reach at constant height (m). The CoM starts at rest relative to the stance with velocity
``v = s u`` (m/s). Holding the ZMP at the extent decelerates the CoM the most; under
``c'' = omega^2 (c - e)`` the CoM stops after

    x_stop = e - sqrt(e^2 - (s / omega)^2)

(the orbital energy ``c'^2 - omega^2 (c - e)^2`` is conserved), where the ZMP can then be placed
under it. The capture along ``u`` therefore holds, with the CoM within its reach, if
``x_stop <= R``, that is

    s <= omega sqrt(R (2 e - R))      (R < e; for R >= e the paper's s <= omega e).

This is a sufficient condition (one strategy that works), derived from the LIPM and the IK reach
alone: nothing in it is fitted to trials. The reach is computed at ``directions`` azimuths; a
direction between two of them takes the smaller reach of the two.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pink
import pinocchio as pin
from pink.limits import ConfigurationLimit
from pink.tasks import ComTask, FrameTask, PostureTask
from pink.utils import get_root_joint_dim

from impact_balance.contacts.stance import Stance
from impact_balance.exceptions import ScenarioError
from impact_balance.geometry.polygon import Polygon
from impact_balance.robot.ik import chain_dofs, within_limits

__all__ = [
    "ComReach",
    "ReachOptions",
    "com_reach",
    "ray_extent",
    "reach_max_speed",
    "reach_speed_limit",
]

_FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class ReachOptions:
    """How :func:`com_reach` searches.

    Attributes:
        directions: Number of azimuths, evenly spaced from world +x (>= 4).
        max_shift: Largest shift tried, m.
        bisections: Bisection steps per direction (resolution ``max_shift / 2**bisections``).
        iterations: IK steps per trial target (pink, ``dt`` = 0.05, daqp).
        com_tolerance: CoM error (m) under which a target counts as reached.
        contact_tolerance: Contact frame pose error (m and rad) under which a contact is kept.
    """

    directions: int = 16
    max_shift: float = 0.32
    bisections: int = 7
    iterations: int = 400
    com_tolerance: float = 3e-3
    contact_tolerance: float = 1e-3


@dataclass(frozen=True)
class ComReach:
    """How far the CoM moves horizontally at constant height with every contact kept.

    Attributes:
        azimuths: (N,) directions, rad, world, counter-clockwise from +x, evenly spaced.
        radii: (N,) reach along each, m (a lower bound, to the search's resolution).
        height: The CoM height held, m (world z).
        postures: (N, nq) the configuration that reaches each radius (the stance's where the
            radius is 0).
    """

    azimuths: _FloatArray
    radii: _FloatArray
    height: float
    postures: _FloatArray

    def along(self, direction: npt.ArrayLike) -> float:
        """The reach along a horizontal ``direction`` (m): the smaller of its two neighbours.

        Args:
            direction: (2,) world horizontal direction (any length > 0).
        """
        d = np.asarray(direction, dtype=float)[:2]
        angle = math.atan2(float(d[1]), float(d[0])) % (2.0 * math.pi)
        step = 2.0 * math.pi / len(self.azimuths)
        k = angle / step
        n = len(self.radii)
        nearest = round(k)
        if abs(k - nearest) < 1e-9:
            return float(self.radii[nearest % n])
        below = math.floor(k) % n
        return float(min(self.radii[below], self.radii[(below + 1) % n]))

    def polygon(self, centre: npt.ArrayLike) -> _FloatArray:
        """The reach's outline around ``centre``: ``c + R(a) (cos a, sin a)`` per azimuth.

        Args:
            centre: (2,) or (3,) the CoM it was computed from, world, m (x and y are used).

        Returns:
            (N, 2) points, world xy, m, in azimuth order (counter-clockwise from +x).
        """
        c = np.asarray(centre, dtype=float)[:2]
        u = np.column_stack([np.cos(self.azimuths), np.sin(self.azimuths)])
        points: _FloatArray = c + self.radii[:, None] * u
        return points

    def to_dict(self) -> dict[str, object]:
        """JSON form: ``azimuths_deg``, ``radii`` (m), ``height`` (m)."""
        return {
            "azimuths_deg": np.rad2deg(self.azimuths).tolist(),
            "radii": self.radii.tolist(),
            "height": self.height,
        }


def _reached(
    stance: Stance, frames: list[str], target: _FloatArray, options: ReachOptions
) -> _FloatArray | None:
    """The configuration that holds every contact with the CoM at ``target`` (world, m), or None."""
    robot = stance.robot
    model = robot.model
    q0 = within_limits(robot, stance.q)  # a file's rounding can leave a joint 1e-6 outside
    configuration = pink.Configuration(model, model.createData(), q0.copy())
    tasks: list[FrameTask] = []
    for frame in frames:
        full = chain_dofs(robot, frame) >= 6
        task = FrameTask(frame, position_cost=100.0, orientation_cost=100.0 if full else 0.0)
        task.set_target(configuration.get_transform_frame_to_world(frame))
        tasks.append(task)
    com = ComTask(cost=10.0)
    com.set_target(target)
    posture = PostureTask(cost=1e-3)
    posture.set_target(q0)
    limits = [ConfigurationLimit(model)]
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    bounded = np.zeros(model.nq, dtype=bool)
    root = get_root_joint_dim(model)[0]
    bounded[root:] = upper[root:] > lower[root:] + 1e-6  # the joints pink checks
    for _ in range(options.iterations):
        velocity = pink.solve_ik(
            configuration, [*tasks, com, posture], 0.05, solver="daqp", limits=limits
        )
        configuration.integrate_inplace(velocity, 0.05)
        # The QP keeps the limits to its tolerance; project the rest (pink refuses a start
        # 1e-6 outside them at the next step).
        configuration.update(
            np.where(bounded, np.clip(configuration.q, lower, upper), configuration.q)
        )
    q = configuration.q
    c = pin.centerOfMass(model, configuration.data, q)
    if float(np.linalg.norm(c - target)) > options.com_tolerance:
        return None
    for task, frame in zip(tasks, frames, strict=True):
        error = task.transform_target_to_world.actInv(
            configuration.get_transform_frame_to_world(frame)
        )
        residual = pin.log(error).vector
        if chain_dofs(robot, frame) < 6:
            residual = residual[:3]
        if float(np.linalg.norm(residual)) > options.contact_tolerance:
            return None
    return np.array(q, dtype=float)


def com_reach(stance: Stance, options: ReachOptions | None = None) -> ComReach:
    """The CoM's reach at its height along evenly spaced azimuths (pink IK, joint limits hard).

    For each azimuth, bisection on the shift: the CoM target is the stance's CoM moved
    horizontally (height held), every contact frame is held at its pose (its position only on a
    chain of fewer than 6 joints), a light posture task pulls towards the stance, and the joint
    limits are hard constraints. Deterministic.

    Args:
        stance: The stance (its robot, configuration and contacts).
        options: The search (default :class:`ReachOptions`).

    Raises:
        ScenarioError: ``directions`` below 4 (named ``com_reach.directions``).
    """
    options = options or ReachOptions()
    if options.directions < 4:
        raise ScenarioError("com_reach.directions", options.directions, "must be at least 4")
    frames = [c.spec.frame for c in stance.contacts]
    com = np.asarray(stance.com, dtype=float)
    azimuths = np.arange(options.directions, dtype=np.float64) * (
        2.0 * math.pi / options.directions
    )
    radii = np.zeros(options.directions)
    postures = np.tile(np.asarray(stance.q, dtype=float), (options.directions, 1))
    for i, a in enumerate(azimuths):
        u = np.array([math.cos(a), math.sin(a), 0.0])
        lo, hi = 0.0, float(options.max_shift)
        for _ in range(options.bisections):
            mid = 0.5 * (lo + hi)
            q = _reached(stance, frames, com + mid * u, options)
            if q is None:
                hi = mid
            else:
                lo = mid
                postures[i] = q
        radii[i] = lo
    return ComReach(azimuths, radii, float(com[2]), postures)


def ray_extent(area: Polygon, direction: npt.ArrayLike) -> float:
    """Distance from the origin to ``area``'s boundary along ``direction`` (area's units).

    Args:
        area: A polygon containing the origin (e.g. the CoM velocity area, m/s).
        direction: (2,) direction (any length > 0).

    Returns:
        The extent (inf where the area is unbounded that way; <= 0 if the origin is outside).
    """
    G, h = area.halfplanes
    u = np.asarray(direction, dtype=float)[:2]
    u = u / float(np.linalg.norm(u))
    gu = G @ u
    ahead = gu > 1e-12
    if not np.any(ahead):
        return math.inf
    return float(np.min(h[ahead] / gu[ahead]))


def reach_speed_limit(
    area: Polygon, omega: float, reach: ComReach, direction: npt.ArrayLike
) -> float:
    """The largest CoM speed (m/s) along ``direction`` captured within the reach.

    Args:
        area: The CoM velocity area (m/s), inset by the margin the controller keeps.
        omega: LIPM natural frequency, 1/s.
        reach: The CoM's reach (:func:`com_reach`).
        direction: (2,) world horizontal direction of the CoM velocity.

    Returns:
        ``omega sqrt(R (2 e - R))`` with ``e`` the area's extent over omega and ``R`` the reach
        along ``direction``; the area's own extent ``omega e`` where ``R >= e`` (see the module
        docstring); 0 where the origin is outside the area.
    """
    extent = ray_extent(area, direction) / omega
    if not extent > 0.0:
        return 0.0
    R = reach.along(direction)
    if R >= extent:
        return float(omega * extent)
    return float(omega * math.sqrt(R * (2.0 * extent - R)))


def _along(reach: ComReach, directions: _FloatArray) -> _FloatArray:
    """:meth:`ComReach.along` of each row of ``directions`` (N, 2), vectorised (m)."""
    n = len(reach.radii)
    step = 2.0 * math.pi / len(reach.azimuths)
    k = (np.arctan2(directions[:, 1], directions[:, 0]) % (2.0 * math.pi)) / step
    nearest = np.round(k)
    below = np.floor(k).astype(np.int64) % n
    between = np.minimum(reach.radii[below], reach.radii[(below + 1) % n])
    exact = reach.radii[nearest.astype(np.int64) % n]
    return np.where(np.abs(k - nearest) < 1e-9, exact, between)


def _limits(area: Polygon, omega: float, reach: ComReach, velocities: _FloatArray) -> _FloatArray:
    """:func:`reach_speed_limit` along each row of ``velocities`` (N, 2, nonzero), vectorised."""
    G, h = area.halfplanes
    u = velocities / np.hypot(velocities[:, 0], velocities[:, 1])[:, None]
    gu = u @ G.T
    ahead = gu > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        extent = np.min(np.where(ahead, h / np.where(ahead, gu, 1.0), math.inf), axis=1) / omega
    R = _along(reach, u)
    inside = extent > 0.0
    capped = np.where(R >= extent, extent, np.sqrt(np.maximum(R * (2.0 * extent - R), 0.0)))
    return np.where(inside, omega * capped, 0.0)


def _within_each(
    area: Polygon, omega: float, reach: ComReach, velocities: _FloatArray, tol: float
) -> npt.NDArray[np.bool_]:
    """Per row of ``velocities`` (N, 2): within the reach's speed limit along its direction."""
    speed = np.hypot(velocities[:, 0], velocities[:, 1])
    ok = speed <= tol
    moving = ~ok
    if np.any(moving):
        limit = _limits(area, omega, reach, velocities[moving])
        ok[moving] = ~(speed[moving] > limit + tol)
    return ok


def _within(
    area: Polygon, omega: float, reach: ComReach, velocities: _FloatArray, tol: float
) -> bool:
    """Whether every velocity (k, 2) is within the reach's speed limit along its direction."""
    return bool(np.all(_within_each(area, omega, reach, velocities, tol)))


def _never_binds(area: Polygon, omega: float, reach: ComReach) -> bool:
    """Whether the reach exceeds the area's extent (over omega) in every direction.

    Then the reach's speed limit is the area's own boundary along every direction: within
    reach is inside the area. Needs the origin strictly inside the area.
    """
    _, h = area.halfplanes
    if area.vertices.shape[0] < 3 or not np.all(h > 0.0):
        return False
    farthest = float(np.max(np.hypot(area.vertices[:, 0], area.vertices[:, 1]))) / omega
    return float(np.min(reach.radii)) >= farthest


def _area_exit(area: Polygon, start: _FloatArray, jumps: _FloatArray, cap: float) -> float:
    """The largest ``s <= cap`` with every ``start + s d_j`` in the area (0 if start is out)."""
    G, h = area.halfplanes
    slack = h - G @ start
    if np.any(slack < 0.0):
        return 0.0
    rates = jumps @ G.T  # (k, m)
    ahead = rates > 1e-12
    with np.errstate(divide="ignore", invalid="ignore"):
        exits = np.where(ahead, slack[None, :] / np.where(ahead, rates, 1.0), math.inf)
    return float(min(cap, float(np.min(exits)) if exits.size else math.inf))


def reach_max_speed(
    area: Polygon,
    omega: float,
    reach: ComReach,
    start: npt.ArrayLike,
    jumps: npt.ArrayLike,
    upper: float,
    tol: float = 1e-9,
) -> float:
    """The largest approach speed ``s <= upper`` whose post-impact velocities stay within reach.

    The post-impact CoM velocities are ``start + s d_j`` (m/s, world xy); each must satisfy
    :func:`reach_speed_limit` along its own direction. From rest (``start`` = 0) every vertex
    keeps its direction and the answer is ``min_j limit(d_j) / |d_j|``, exactly; otherwise the
    directions turn with ``s``: the first speed out of reach on a grid of 256 steps up to
    ``upper``, refined by bisection to ``tol`` (a stretch out of reach narrower than a step
    can be missed).

    Args:
        area: The CoM velocity area (m/s), inset by the margin the controller keeps.
        omega: LIPM natural frequency, 1/s.
        reach: The CoM's reach (:func:`com_reach`).
        start: (2,) pre-impact CoM velocity, world xy, m/s.
        jumps: (k, 2) CoM velocity jumps per unit approach speed, world xy.
        upper: The answer's upper bound (m/s; the area's own maximum contact velocity).
        tol: Tolerance, m/s.

    Returns:
        The speed, m/s (0 when ``start`` itself is out of reach).
    """
    c0 = np.asarray(start, dtype=float)[:2]
    d = np.asarray(jumps, dtype=float).reshape(-1, 2)
    if not _within(area, omega, reach, c0[None, :], tol):
        return 0.0
    cap = float(upper) if math.isfinite(upper) else 1e3
    if _never_binds(area, omega, reach):  # within reach is inside the area: its exit, exactly
        return _area_exit(area, c0, d, cap)
    if float(np.hypot(c0[0], c0[1])) <= tol:
        best = cap
        for dj in d:
            norm = float(np.hypot(dj[0], dj[1]))
            if norm > 0.0:
                best = min(best, reach_speed_limit(area, omega, reach, dj) / norm)
        return float(best)
    # Away from rest the vertices turn with s: the first speed out of reach, found on a grid of
    # 256 steps up to ``upper`` and refined by bisection (every speed below it is within).
    grid = np.linspace(0.0, cap, 257)[1:]
    ok = _within_each(
        area, omega, reach, (c0[None, None, :] + grid[:, None, None] * d).reshape(-1, 2), tol
    )
    failing = np.flatnonzero(~ok.reshape(len(grid), len(d)).all(axis=1))
    if failing.size == 0:
        return cap
    first = int(failing[0])
    hi = float(grid[first])
    lo = 0.0 if first == 0 else float(grid[first - 1])
    while hi - lo > tol * max(1.0, hi):
        mid = 0.5 * (lo + hi)
        if _within(area, omega, reach, c0[None, :] + mid * d, tol):
            lo = mid
        else:
            hi = mid
    return lo
