"""The centroidal angular momentum an impulse leaves, and what it costs the capture.

The paper's LIPM keeps the centroidal angular momentum L (N m s, world axes, about the CoM)
at zero. An impulse iota (N s, world) at a point p leaves ``dL = (p - c) x iota`` (Newton-Euler
of the whole robot: the angular rows of the centroidal momentum matrix times the joint-velocity
jump, whatever the joints do). On the LIPM plane (height ``h = g / omega^2`` of the CoM above
the ZMP plane), a rate of change of L moves the centroidal moment pivot
``p_cmp = p_zmp + S(dL/dt) / (m g)``, ``S(L) = (L_y, -L_x)``. The robot at rest has L = 0, so
the contacts must remove what the impulse left; removed exponentially with time constant tau
(s), the zero-step capture condition becomes: the *effective* post-impact CoM velocity

    v_eff = v + S(dL) / (m h (1 + omega tau))

lies in the CoM velocity area. tau = 0 (removed at once) is the conservative bound; tau -> inf
(never removed) is the paper's criterion. See docs/angular-momentum.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import ScenarioError

__all__ = [
    "AngularMomentumTerm",
    "angular_momentum_gain",
    "angular_momentum_jump_rates",
    "centroidal_angular_momentum_jump",
    "effective_impulse_rates",
]


def angular_momentum_gain(omega: float, gravity: float, damping_time: float | None) -> float:
    """``1 / (h (1 + omega tau))`` (1/m), ``h = g / omega^2`` the LIPM height.

    Args:
        omega: LIPM natural frequency, 1/s.
        gravity: g, m/s^2.
        damping_time: tau, s (>= 0); None or inf: the paper's criterion (gain 0).

    Returns:
        The gain that turns ``S(dL) / m`` (m^2/s) into a CoM velocity (m/s).

    Raises:
        ScenarioError: ``damping_time`` is negative or NaN (naming
            ``angular_momentum_damping_time``).
    """
    if damping_time is None or damping_time == math.inf:
        return 0.0
    if not damping_time >= 0.0:
        raise ScenarioError(
            "angular_momentum_damping_time", damping_time, "must be a number >= 0 (s)"
        )
    height = gravity / (omega * omega)
    return 1.0 / (height * (1.0 + omega * damping_time))


@dataclass(frozen=True)
class AngularMomentumTerm:
    """What the CoM criterion needs to see the angular momentum an impulse leaves.

    Attributes:
        arm: Impact point minus CoM, world, m.
        gain: ``1 / (h (1 + omega tau))``, 1/m (:func:`angular_momentum_gain`).
        damping_time: tau, s (reported).
    """

    arm: npt.NDArray[np.float64]
    gain: float
    damping_time: float


def angular_momentum_jump_rates(
    arm: npt.ArrayLike, impulse_rates: npt.ArrayLike
) -> npt.NDArray[np.float64]:
    """``dL = (p - c) x iota`` of each impulse row, N m s per row unit.

    Args:
        arm: (3,) impact point minus CoM, world, m.
        impulse_rates: (k, 3) impulses (or impulses per m/s of approach speed), world, N s.

    Returns:
        (k, 3) centroidal angular momentum jumps, world, N m s (per the same unit).
    """
    out: npt.NDArray[np.float64] = np.cross(
        np.asarray(arm, dtype=float)[None, :], np.asarray(impulse_rates, dtype=float)
    )
    return out


def effective_impulse_rates(
    impulse_rates: npt.ArrayLike, term: AngularMomentumTerm | None
) -> npt.NDArray[np.float64]:
    """Impulses whose planar part over the mass is the effective CoM velocity jump.

    Row j is ``iota_j,xy + gain S((p - c) x iota_j)`` (N s); the third column is iota_j,z
    unchanged. Without a term (None), a copy of ``impulse_rates``.

    Args:
        impulse_rates: (k, 3) impulses, world, N s (or per m/s of approach speed).
        term: The angular momentum term, or None (the paper's criterion).

    Returns:
        (k, 3) effective impulses, N s.
    """
    rates = np.array(impulse_rates, dtype=float)
    if term is None or term.gain == 0.0:
        return rates
    dL = angular_momentum_jump_rates(term.arm, rates)
    rates[:, 0] += term.gain * dL[:, 1]
    rates[:, 1] -= term.gain * dL[:, 0]
    return rates


def centroidal_angular_momentum_jump(
    model: pin.Model,
    q: npt.ArrayLike,
    joint_velocity_jump: npt.ArrayLike,
) -> npt.NDArray[np.float64]:
    """The angular rows of the centroidal momentum matrix Ag(q) times a velocity jump.

    Args:
        model: The robot's pinocchio model (free-flyer root).
        q: Configuration (pinocchio's).
        joint_velocity_jump: (nv,) jump of the generalized velocity (base in its local frame,
            pinocchio's convention).

    Returns:
        (3,) jump of the centroidal angular momentum, world axes, about the CoM, N m s.
    """
    data = model.createData()
    Ag = pin.computeCentroidalMap(model, data, np.asarray(q, dtype=float))
    out: npt.NDArray[np.float64] = Ag[3:] @ np.asarray(joint_velocity_jump, dtype=float)
    return out
