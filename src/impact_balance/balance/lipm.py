"""LIPM phase portrait along one axis (paper sec. III-B).

With the ZMP z limited to [z_lo, z_hi], the stable standing region is the set of states
(c, cd) whose DCM c + cd / omega lies in [z_lo, z_hi]. At c = c_ref the CoM velocity bounds
are omega (z_lo - c), omega (z_hi - c): for c_z = 0.78 m and z in [-0.13, 0.13] m,
+-0.4610 m/s with g = 9.81 (the paper's 0.4608 corresponds to g = 9.8).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from impact_balance.constants import GRAVITY, GRAVITY_RANGE, MAX_POSITION
from impact_balance.exceptions import ScenarioError

__all__ = [
    "HeightField",
    "PhasePortrait",
    "com_velocity_bounds",
    "finite_push_factor",
    "lipm_omega",
    "phase_portrait",
]

#: The input a caller of :func:`lipm_omega` took from its user: the CoM height or the plane's.
HeightField = Literal["com_height", "plane_height"]


def lipm_omega(
    com_height: float,
    plane_height: float = 0.0,
    gravity: float = GRAVITY,
    *,
    field: HeightField = "com_height",
) -> float:
    """The LIPM natural frequency omega = sqrt(g / (c_z - h)), 1/s.

    Args:
        com_height: c_z, the CoM height, world, m.
        plane_height: h, the height of the ZMP plane, world, m.
        gravity: g, m/s^2.
        field: The input the caller took from its user, named by the error when the CoM is
            not above the plane: "com_height" (a CoM height given for a plane, as in
            :func:`phase_portrait`) or "plane_height" (a plane given for a robot's CoM, as in
            a scenario).

    Returns:
        omega, 1/s.

    Raises:
        ScenarioError: The CoM is not strictly above the plane, or a height is not finite
            (the error names ``field``: "com_height ... must be above the plane height" or
            "plane_height ... must be below the CoM height"); ``gravity`` is not a finite
            number in :data:`~impact_balance.constants.GRAVITY_RANGE` (the error names
            "gravity").
    """
    if not (
        math.isfinite(com_height) and math.isfinite(plane_height) and com_height > plane_height
    ):
        if field == "plane_height":
            raise ScenarioError(
                "plane_height", plane_height, f"must be below the CoM height {com_height:.4g} m"
            )
        raise ScenarioError(
            "com_height", com_height, f"must be above the plane height {plane_height} m"
        )
    if not GRAVITY_RANGE[0] <= gravity <= GRAVITY_RANGE[1]:
        raise ScenarioError(
            "gravity", gravity, f"must be in [{GRAVITY_RANGE[0]:g}, {GRAVITY_RANGE[1]:g}] m/s^2"
        )
    return math.sqrt(gravity / (com_height - plane_height))


def _is_number(x: object) -> bool:
    """Whether ``x`` is a real number (int, float or NumPy's), not a bool."""
    return isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, bool)


def finite_push_factor(omega: float, duration: float) -> float:
    """The DCM's growth over a push of finite duration: kappa = (exp(omega T) - 1) / (omega T).

    A horizontal force ``F`` (N) acts on the LIPM of mass ``m`` (kg) for ``T = duration`` (s),
    an impulse ``J = F T`` (N s). Along the push, the CoM obeys
    ``c'' = omega^2 (c - z) + F / m`` and the DCM ``xi = c + c' / omega``

        xi' = omega (xi - z) + F / (m omega).

    With the robot at rest and the ZMP ``z`` under the CoM at the push's start (``xi(0) = z = 0``,
    the CoM's starting position as origin) and held there while the push acts,

        xi(T) = F / (m omega^2) (exp(omega T) - 1) = kappa J / (m omega).

    The impulsive push (the paper's: the CoM velocity jumps by ``J / m``, the CoM does not
    move) gives ``J / (m omega)``: the finite push's DCM at its end equals the impulsive one's
    with the CoM velocity ``kappa J / m``, the CoM's displacement during the push included.
    kappa is 1 at ``T = 0``, increases with ``omega T`` and is about ``1 + omega T / 2`` for a
    short push.

    Args:
        omega: The LIPM natural frequency, 1/s (:func:`lipm_omega`), > 0.
        duration: The push's duration T, s, >= 0.

    Returns:
        kappa (dimensionless, >= 1).

    Raises:
        ScenarioError: ``omega`` not a finite number > 0 (the error names "omega"), or
            ``duration`` not a finite number >= 0 (names "duration"), or their product over 50.
    """
    if not (_is_number(omega) and math.isfinite(omega) and omega > 0):
        raise ScenarioError("omega", omega, "must be a finite number > 0 (1/s)")
    if not (_is_number(duration) and math.isfinite(duration) and duration >= 0):
        raise ScenarioError("duration", duration, "must be a finite number >= 0 (s)")
    x = float(omega) * float(duration)
    if x > 50.0:
        raise ScenarioError(
            "duration", duration, f"omega * duration = {x:g} is not a push (at most 50)"
        )
    return 1.0 if x == 0.0 else math.expm1(x) / x


def _check_com_height(com_height: float) -> None:
    """Refuse a CoM height (above a plane at 0) that the one-axis LIPM does not take.

    Refused: not finite, not above the plane, or more than twice the largest position above it.
    """
    if not (math.isfinite(com_height) and 0 < com_height <= 2 * MAX_POSITION):
        raise ScenarioError(
            "com_height",
            com_height,
            f"must be above the plane height 0.0 m (at most {2 * MAX_POSITION:g} m above)",
        )


def com_velocity_bounds(
    com_height: float,
    zmp_range: tuple[float, float],
    com_position: float = 0.0,
    gravity: float = GRAVITY,
) -> tuple[float, float]:
    """CoM velocity interval (m/s) from which the CoM can be brought to rest at ``com_position``."""
    lo, hi = zmp_range
    if not -MAX_POSITION <= lo <= hi <= MAX_POSITION:
        raise ScenarioError(
            "zmp_range",
            [lo, hi],
            f"must be [lo, hi] with lo <= hi, within [{-MAX_POSITION:g}, {MAX_POSITION:g}] m",
        )
    _check_com_height(com_height)
    w = lipm_omega(com_height, 0.0, gravity)
    return w * (lo - com_position), w * (hi - com_position)


@dataclass(frozen=True)
class PhasePortrait:
    """Phase portrait data of the saturated-ZMP LIPM along one axis.

    Attributes:
        omega: 1/s.  zmp_range: (lo, hi), m.  com_velocity_bounds: (lo, hi) at c = 0, m/s.
        trajectories: list of (T, 2) arrays of (c, cd) under a ZMP that brakes as hard as
            allowed (saturated), for plotting.
    """

    omega: float
    com_height: float
    zmp_range: tuple[float, float]
    com_velocity_bounds: tuple[float, float]
    trajectories: list[np.ndarray]

    def is_capturable(self, com: float, com_velocity: float) -> bool:
        """Whether the DCM c + cd / omega lies in the ZMP range (stable standing region)."""
        dcm = com + com_velocity / self.omega
        return self.zmp_range[0] <= dcm <= self.zmp_range[1]


def phase_portrait(
    com_height: float,
    zmp_range: tuple[float, float],
    gravity: float = GRAVITY,
    n_trajectories: int = 9,
    gain: float = 1.0,
    horizon: float = 2.0,
) -> PhasePortrait:
    """LIPM phase portrait with a saturated ZMP (paper Fig. lipm-pplane, after Sugihara 2009).

    Trajectories follow the capture feedback ``z = clip((1 + gain) xi, z_lo, z_hi)`` on the
    DCM xi = c + cd / omega: inside the stable standing region they converge to rest at the
    origin, outside it they diverge whatever the (bounded) ZMP does.
    """
    _check_com_height(com_height)
    w = lipm_omega(com_height, 0.0, gravity)
    bounds = com_velocity_bounds(com_height, zmp_range, 0.0, gravity)
    lo, hi = zmp_range
    width = max(hi - lo, 1e-3)
    limit = 3.0 * width + max(abs(lo), abs(hi))
    starts = [
        (c0, v0)
        for c0 in np.linspace(lo - 0.5 * width, hi + 0.5 * width, n_trajectories)
        for v0 in (1.4 * bounds[0], 1.4 * bounds[1])
    ]
    dt = 1e-3
    trajectories = []
    for c0, v0 in starts:
        c, cd, path = c0, v0, [(c0, v0)]
        for _ in range(int(horizon / dt)):
            xi = c + cd / w
            z = min(max((1.0 + gain) * xi, lo), hi)
            cd += dt * w * w * (c - z)
            c += dt * cd
            path.append((c, cd))
            if abs(c) > limit:
                break
        trajectories.append(np.array(path))
    return PhasePortrait(w, com_height, (lo, hi), bounds, trajectories)
