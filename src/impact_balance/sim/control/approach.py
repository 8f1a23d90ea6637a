"""The impacting end-effector's reference: a clean approach, then a withdrawal on contact.

As in the paper's experiment (the palm sent at a wall, pulled back as soon as the force sensor
reads 15 N), :class:`ImpactTask` gives the impact point's world reference (position, velocity,
acceleration) at every control step:

1. *hold* at ``standoff`` from the surface along its normal ``n`` until ``start_time``;
2. *accelerate* along ``-n`` at ``acceleration`` (bounded, 20 m/s^2 by default) up to the
   commanded approach speed;
3. *cruise* at that speed: the standoff leaves ``cruise`` (3 cm) of travel at full speed
   before the surface, so the limb reaches the commanded speed before it touches; the
   reference goes on through the surface at that speed until the contact is felt;
4. once the measured normal force exceeds ``force_threshold``: *stop pushing* (the reference
   jumps back to the surface, at rest), then *withdraw* along ``n`` with the same bounded
   acceleration up to ``withdraw_speed`` until ``retract`` (5 cm) from the surface.

The standoff follows from the speed: ``max(min_standoff, v^2 / (2 a) + cruise)``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
import numpy.typing as npt
import pinocchio as pin

__all__ = [
    "APPROACH_ACCELERATION",
    "CRUISE_DISTANCE",
    "MIN_STANDOFF",
    "ImpactReference",
    "ImpactTask",
    "approach_profile",
]

#: Bounded acceleration of the approach and of the withdrawal, m/s^2.
APPROACH_ACCELERATION = 20.0
#: Travel at full speed before the surface, m.
CRUISE_DISTANCE = 0.03
#: Smallest standoff, m.
MIN_STANDOFF = 0.05


_FloatArray = npt.NDArray[np.float64]


class ImpactReference(Protocol):
    """What the balance controllers and trials need of an impacting point's reference.

    :class:`ImpactTask` is one; :class:`~impact_balance.sim.studies.wall.GovernedApproach`
    another. A reference may also bound the point's approach speed with a method
    ``speed_bound() -> float`` (m/s; ``inf``: unbounded), which the torque controller enforces.

    Attributes:
        frame: Robot frame of the impacting end-effector.
        offset: Pose of the impact point in ``frame``.
        normal: Unit surface normal, from the surface into the robot (world).
        start_time: When the approach starts (s).
        contact_time: When the contact was felt (s), None before.
    """

    frame: str
    offset: pin.SE3
    normal: _FloatArray
    start_time: float
    contact_time: float | None

    def reference(
        self, t: float, normal_force: float = 0.0
    ) -> tuple[_FloatArray, _FloatArray, _FloatArray]:
        """World position (m), velocity (m/s) and acceleration (m/s^2) of the reference at ``t``.

        Args:
            t: Time (s).
            normal_force: Measured normal force at the impact point (N).

        Returns:
            The position, velocity and acceleration (3 each).
        """
        ...

    def target(self, t: float, normal_force: float = 0.0) -> _FloatArray:
        """The reference position alone (m, world) at ``t``.

        Args:
            t: Time (s).
            normal_force: Measured normal force at the impact point (N).

        Returns:
            The position (3,).
        """
        ...


@dataclass
class ImpactTask:
    """Drive an end-effector point into a surface at a commanded speed, then pull back.

    See the module docstring.

    Attributes:
        frame: Robot frame of the impacting end-effector.
        offset: Pose of the impact point in ``frame``.
        surface_point: Impact point on the surface (m, world).
        normal: Unit surface normal, from the surface into the robot (world).
        speed: Commanded approach speed along ``-normal`` (m/s, > 0).
        start_time: When the approach starts (s).
        acceleration: Bound on the reference's acceleration (m/s^2).
        cruise: Distance travelled at full speed before the surface (m).
        min_standoff: Smallest distance from the surface at the start (m).
        force_threshold: Normal force that marks the contact (N).
        retract: Distance from the surface the point withdraws to after the contact (m).
        withdraw_speed: Top speed of the withdrawal (m/s).
    """

    frame: str
    offset: pin.SE3
    surface_point: np.ndarray
    normal: np.ndarray
    speed: float
    start_time: float = 0.3
    acceleration: float = APPROACH_ACCELERATION
    cruise: float = CRUISE_DISTANCE
    min_standoff: float = MIN_STANDOFF
    force_threshold: float = 15.0
    retract: float = 0.05
    withdraw_speed: float = 0.3
    contact_time: float | None = field(default=None, init=False)

    def __post_init__(self) -> None:
        self.surface_point = np.asarray(self.surface_point, dtype=float)
        self.normal = np.asarray(self.normal, dtype=float)

    @property
    def standoff(self) -> float:
        """Distance of the point from the surface at the start (m)."""
        return standoff(self.speed, self.acceleration, self.cruise, self.min_standoff)

    @property
    def start_point(self) -> np.ndarray:
        """The point's start (m, world): ``standoff`` from the surface along the normal."""
        return self.surface_point + self.standoff * self.normal

    @property
    def arrival_time(self) -> float:
        """When the reference reaches the surface (s)."""
        v, a = self.speed, self.acceleration
        ramp = v / a
        return self.start_time + ramp + (self.standoff - 0.5 * v * ramp) / v

    def reference(
        self, t: float, normal_force: float = 0.0
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """World position, velocity and acceleration of the impact point's reference at ``t``.

        World position (m), velocity (m/s) and acceleration (m/s^2) of the impact point's reference
        at ``t`` given the measured normal force (N); the first force above the threshold starts the
        withdrawal.
        """
        n = self.normal
        if self.contact_time is None and normal_force > self.force_threshold:
            self.contact_time = float(t)
        if self.contact_time is not None:
            s, ds, dds = approach_profile(
                t - self.contact_time, self.withdraw_speed, self.acceleration, self.retract
            )
            return self.surface_point + s * n, ds * n, dds * n
        s, ds, dds = approach_profile(t - self.start_time, self.speed, self.acceleration, np.inf)
        return self.start_point - s * n, -ds * n, -dds * n

    def target(self, t: float, normal_force: float = 0.0) -> np.ndarray:
        """The reference position alone (m, world)."""
        return self.reference(t, normal_force)[0]


def standoff(
    speed: float,
    acceleration: float = APPROACH_ACCELERATION,
    cruise: float = CRUISE_DISTANCE,
    minimum: float = MIN_STANDOFF,
) -> float:
    """Start distance from the surface (m) leaving ``cruise`` at full ``speed`` after the ramp."""
    return max(minimum, speed * speed / (2.0 * acceleration) + cruise)


def approach_profile(
    tau: float, speed: float, acceleration: float, stop: float
) -> tuple[float, float, float]:
    """Distance, speed and acceleration after ``tau`` s of a bounded-acceleration start.

    The start ramps up to ``speed`` and holds at ``stop`` (m) once reached (a trapezoid without its
    braking: the point stops where it arrives).
    """
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    ramp = speed / acceleration
    if tau < ramp:
        s, ds, dds = 0.5 * acceleration * tau * tau, acceleration * tau, acceleration
    else:
        s, ds, dds = 0.5 * speed * ramp + speed * (tau - ramp), speed, 0.0
    if s >= stop:
        return stop, 0.0, 0.0
    return s, ds, dds
