"""Gains of the balance controllers, and what a trial's options hold of them.

:class:`BalanceGains` tune the kinematic controller (``ik``,
:class:`~impact_balance.sim.control.kinematic.BalanceController`),
:class:`InverseDynamicsGains` the torque controller (``id``,
:class:`~impact_balance.sim.control.torque.InverseDynamicsController`). A trial's options carry
both (:class:`TrialGains`); each controller reads its own.

**Gains derived from the robot.** A trial's controller does not use these defaults as they
are: :func:`robot_gains` and :func:`robot_id_gains` replace every field that depends on the
robot by a rule of its :class:`RobotScales` (mass m, CoM height h above the plane, LIPM
omega = sqrt(g / h), radius of gyration rho about the CoM, the simulation step), so that a
16 kg quadruped and a 90 kg humanoid get gains of the same meaning. The rules (the defaults
below are what they give on Talos, m = 90.3 kg, h = 0.904 m, omega = 3.30 1/s, rho = 0.445 m,
1 ms steps, within 2.5 %, the angular momentum weight within 4 %):

- control rate: half the simulation rate (500 Hz at 1 ms steps);
- task bandwidth ``w_c = min(3 omega, rate / 20)`` [1/s]: every PD is critically damped at it
  (stiffness ``w_c^2``, damping ``2 w_c``: CoM height, posture, base orientation), the
  impact point's at ``2 w_c``; angular momentum damping ``w_c``, contact damping ``2 w_c``;
- DCM gain ``0.6 omega`` (``id``), ``0.3 omega`` (``ik``, and its ZMP admittance);
- ``ik``: the measured ZMP filtered over 5 control periods; the CoM command's speed at most
  ``0.1 omega h``;
- weights of angular tasks against the CoM's: ``(h / 0.9 m)^2`` times the defaults (a joint
  acceleration moves the CoM in proportion to the leg's length); angular momentum weight
  ``0.1 (h / 0.9 m)^2 (0.44 m / rho)^4``;
- regularisations per unit weight: wrenches ``0.08 / (m g)^2`` [1/N^2], contact torques
  ``6.4 / (m g h)^2`` [1/(N m)^2]; minimum normal force ``max(0.0225 m g, 2 N)`` per contact (twice
  the 1 N below which a trial counts a contact as unloaded).

Margins (ZMP, friction, centre of pressure), the joint-limit horizon, the acceleration
regularisation, the IK costs and the solver are not robot-dependent: they keep their values.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any, Protocol

import numpy as np

from impact_balance.balance.lipm import lipm_omega
from impact_balance.contacts.stance import Stance
from impact_balance.sim.model.build import SimModel

__all__ = [
    "REFERENCE_GYRATION",
    "REFERENCE_HEIGHT",
    "BalanceGains",
    "InverseDynamicsGains",
    "RobotScales",
    "TrialGains",
    "capture_angular_momentum_weight",
    "declared_angular_momentum_damping",
    "robot_gains",
    "robot_id_gains",
    "trial_gains",
]

#: The floor of the derived minimum normal force, N: twice the outcome monitor's ``min_force``.
MIN_NORMAL_FORCE = 2.0
#: Reference leg length (m) and radius of gyration (m) of the weight rules (Talos' values).
REFERENCE_HEIGHT = 0.9
REFERENCE_GYRATION = 0.44


@dataclass(frozen=True)
class BalanceGains:
    """Gains and rates of the kinematic controller (units in brackets).

    The gains of :class:`~impact_balance.sim.control.kinematic.BalanceController`.

    Attributes:
        rate: Control rate [Hz].
        dcm_gain: DCM error decay rate k [1/s] (p = xi + k/omega (xi - xi_ref)).
        zmp_margin: Desired ZMP kept this far inside the ZMP support area [m].
        zmp_admittance: K_zmp, CoM command velocity per metre of ZMP error [1/s].
        zmp_filter: Time constant of the first-order filter on the measured ZMP [s].
        max_com_speed: Bound on the CoM command's speed [m/s].
        com_cost: Weight of the CoM task [1/m].
        contact_cost: Weight of each contact frame task (position [1/m] and orientation [1/rad]).
        impact_cost: Weight of the impact point task [1/m] (its orientation: a tenth).
        posture_cost: Weight of the posture task [1/rad].
        damping: Levenberg-Marquardt regularisation of the IK step's QP.
        solver: QP solver of pink (qpsolvers name).
    """

    rate: float = 500.0
    dcm_gain: float = 1.0
    zmp_margin: float = 0.01
    zmp_admittance: float = 1.0
    zmp_filter: float = 0.01
    max_com_speed: float = 0.3
    com_cost: float = 10.0
    contact_cost: float = 10.0
    impact_cost: float = 1.0
    posture_cost: float = 1e-2
    damping: float = 1e-6
    solver: str = "daqp"

    def to_dict(self) -> dict[str, Any]:
        """The gains by field name (JSON-ready)."""
        return asdict(self)


@dataclass(frozen=True)
class InverseDynamicsGains:
    """Gains, weights and rate of the torque controller (units in brackets).

    The gains of :class:`~impact_balance.sim.control.torque.InverseDynamicsController`.

    Task weights multiply squared accelerations (m/s^2, rad/s^2; the angular momentum rate per
    unit mass, m^2/s^2); the wrench regularisation multiplies squared newtons and newton-metres.

    Attributes:
        rate: Control rate [Hz].
        dcm_gain: DCM error decay rate k [1/s].
        zmp_margin: Desired ZMP kept this far inside the ZMP support area [m].
        com_height_stiffness, com_height_damping: PD on the CoM height [1/s^2], [1/s].
        angular_momentum_damping: K_L in L_dot = -K_L L [1/s].
        contact_damping: K_c in the contact acceleration J a + J_dot v = -K_c J v [1/s].
        posture_stiffness, posture_damping: PD to the start configuration [1/s^2], [1/s].
        base_orientation_stiffness, base_orientation_damping: PD on the base orientation [1/s^2],
            [1/s].
        impact_stiffness, impact_damping: PD of the impact point to its target [1/s^2], [1/s].
        com_weight, angular_momentum_weight, posture_weight, base_orientation_weight, impact_weight,
        impact_orientation_weight: task weights.
        acceleration_regularization, wrench_regularization: regularisation weights (the latter on
            the contact forces).
        torque_regularization: regularisation weight of the contact torques (N m): keeps the centres
            of pressure central and the yaw torques small.
        friction_scale: The QP's friction coefficient is this fraction of the contact's: a margin
            against slipping, as MuJoCo's contact, like a real one, is not exactly the ideal cone.
        cop_margin: The QP's contact rectangles are shrunk by this much on every side [m].
        min_normal_force: Every contact carries at least this normal force [N]. The ZMP support area
            includes ZMPs reached only by unloading a contact (its cone contains zero); the fall
            detector counts an unloaded contact as lost, so the QP keeps each one loaded.
        friction_velocity: v_f [rad/s]: the motors compensate a joint's dry friction F by
            ``F clip(qdot / v_f, -1, 1)``
            (:func:`~impact_balance.sim.control.torque.motor_compensation`): in full above v_f,
            linearly below, so that a joint at rest gets no switching torque.
        joint_limit_horizon: T [s] of the joint position limits on the accelerations: braking at
            ``a`` from ``(q, v)`` stays within the limits for T, ``q + v T + a T^2 / 2`` in
            ``[lower, upper]``. MuJoCo enforces the limits with forces the QP would not know.
        touch_contact: From the impact point's first touch (a positive measured normal force)
            until its withdrawal starts, the impact point is a contact of the QP: a point
            contact that stays (zero relative acceleration), its force in the impact's friction
            cone times ``friction_scale``, pressing with at least the impact task's
            ``force_threshold`` (see :mod:`impact_balance.sim.control.torque`). False: the
            impact is no contact of the QP.
        implicit_damping_inertia: The QP's joint-space inertia is the simulated plant's,
            ``M + h D`` (h the simulation step, s; D each joint's viscous damping, N m s/rad):
            the inertia MuJoCo's integrator adds when it integrates the damping implicitly
            (:func:`~impact_balance.sim.model.integrator.implicit_damping_inertia`; zero with an
            explicit integrator). False: the QP plans with ``M`` alone.
    """

    rate: float = 500.0
    dcm_gain: float = 2.0
    zmp_margin: float = 0.01
    com_height_stiffness: float = 100.0
    com_height_damping: float = 20.0
    angular_momentum_damping: float = 10.0
    contact_damping: float = 20.0
    posture_stiffness: float = 100.0
    posture_damping: float = 20.0
    base_orientation_stiffness: float = 100.0
    base_orientation_damping: float = 20.0
    impact_stiffness: float = 400.0
    impact_damping: float = 40.0
    com_weight: float = 1000.0
    angular_momentum_weight: float = 0.1
    posture_weight: float = 1e-2
    base_orientation_weight: float = 0.1
    impact_weight: float = 10.0
    impact_orientation_weight: float = 1.0
    acceleration_regularization: float = 1e-6
    wrench_regularization: float = 1e-7
    torque_regularization: float = 1e-5
    friction_scale: float = 0.65
    cop_margin: float = 0.0
    min_normal_force: float = 20.0
    friction_velocity: float = 0.01
    joint_limit_horizon: float = 0.1
    touch_contact: bool = False
    implicit_damping_inertia: bool = True

    def to_dict(self) -> dict[str, Any]:
        """The gains by field name (JSON-ready)."""
        return asdict(self)


@dataclass(frozen=True)
class RobotScales:
    """What the gains are derived from (SI units).

    Attributes:
        mass: Total mass m, kg.
        com_height: CoM height h above the contact plane, m.
        omega: LIPM natural frequency sqrt(g / h), 1/s.
        gyration: Radius of gyration about the CoM, sqrt(trace(I) / (2 m)), m.
        gravity: g, m/s^2.
        timestep: Simulation step, s.
    """

    mass: float
    com_height: float
    omega: float
    gyration: float
    gravity: float
    timestep: float

    @classmethod
    def of(
        cls, stance: Stance, plane_height: float, gravity: float, timestep: float
    ) -> RobotScales:
        """The scales of ``stance`` over the plane at ``plane_height`` (m), steps of ``timestep`` s.

        Raises:
            ValueError: ``timestep`` not positive and finite.
        """
        if not (np.isfinite(timestep) and timestep > 0):
            raise ValueError(f"timestep must be positive and finite, not {timestep!r}")
        height = float(stance.com[2]) - float(plane_height)
        gyration = float(np.sqrt(max(np.trace(stance.com_inertia), 0.0) / (2.0 * stance.mass)))
        return cls(
            stance.mass,
            height,
            lipm_omega(float(stance.com[2]), plane_height, gravity),
            gyration,
            float(gravity),
            float(timestep),
        )

    @classmethod
    def of_sim(cls, sim: SimModel) -> RobotScales:
        """The scales of a trial's MuJoCo model: its stance, plane, gravity and step."""
        scenario = sim.scenario
        return cls.of(
            sim.stance, scenario.plane_height, scenario.gravity, float(sim.model.opt.timestep)
        )

    @property
    def rate(self) -> float:
        """The control rate: half the simulation rate, Hz."""
        return 0.5 / self.timestep

    @property
    def bandwidth(self) -> float:
        """The task bandwidth ``w_c = min(3 omega, rate / 20)``, 1/s."""
        return float(min(3.0 * self.omega, self.rate / 20.0))


def robot_gains(scales: RobotScales, base: BalanceGains | None = None) -> BalanceGains:
    """``base`` (the defaults) with its robot-dependent fields derived from ``scales``.

    See the module docstring for the rules.
    """
    base = base or BalanceGains()
    rate = scales.rate
    return replace(
        base,
        rate=rate,
        dcm_gain=0.3 * scales.omega,
        zmp_admittance=0.3 * scales.omega,
        zmp_filter=5.0 / rate,
        max_com_speed=0.1 * scales.omega * scales.com_height,
    )


def robot_id_gains(
    scales: RobotScales, base: InverseDynamicsGains | None = None
) -> InverseDynamicsGains:
    """``base`` (the defaults) with its robot-dependent fields derived from ``scales``.

    See the module docstring for the rules.
    """
    base = base or InverseDynamicsGains()
    wc = scales.bandwidth
    length = (scales.com_height / REFERENCE_HEIGHT) ** 2
    weight = scales.mass * scales.gravity
    return replace(
        base,
        rate=scales.rate,
        dcm_gain=0.6 * scales.omega,
        com_height_stiffness=wc**2,
        com_height_damping=2.0 * wc,
        angular_momentum_damping=wc,
        contact_damping=2.0 * wc,
        posture_stiffness=wc**2,
        posture_damping=2.0 * wc,
        base_orientation_stiffness=wc**2,
        base_orientation_damping=2.0 * wc,
        impact_stiffness=(2.0 * wc) ** 2,
        impact_damping=4.0 * wc,
        angular_momentum_weight=0.1 * length * (REFERENCE_GYRATION / scales.gyration) ** 4,
        posture_weight=1e-2 * length,
        base_orientation_weight=0.1 * length,
        impact_orientation_weight=1.0 * length,
        wrench_regularization=0.08 / weight**2,
        torque_regularization=6.4 / (weight * scales.com_height) ** 2,
        min_normal_force=max(0.0225 * weight, MIN_NORMAL_FORCE),
    )


def capture_angular_momentum_weight(scales: RobotScales, com_weight: float) -> float:
    """The angular momentum task's weight that costs the capture what the CoM task's does.

    The ``id`` QP weighs the CoM task's residual ``e_c`` (m/s^2, the CoM acceleration's) by
    ``com_weight`` and the angular momentum task's ``e_L`` (m^2/s^2, the rate of L about the CoM
    per unit mass) by the returned weight. Under the LIPM (CoM at height h, omega^2 = g / h), a
    horizontal CoM acceleration error ``e_c`` moves the centroidal moment pivot by
    ``e_c / omega^2 = e_c h / g`` (m), and a horizontal moment error ``m e_L`` about the CoM moves
    the ZMP away from the CMP by ``m e_L / (m g) = e_L / g`` (m). Equal cost per metre of either
    displacement, ``com_weight (g / h)^2 = w_L g^2``, gives ``w_L = com_weight / h^2`` (1/m^2 times
    the CoM task's units): nothing fitted, only h of ``scales``.

    Args:
        scales: The robot's scales (its CoM height h, m).
        com_weight: The CoM task's weight.

    Raises:
        ValueError: h or ``com_weight`` not positive and finite.
    """
    h = float(scales.com_height)
    if not (np.isfinite(h) and h > 0):
        raise ValueError(f"scales.com_height must be positive and finite, not {h!r}")
    if not (np.isfinite(com_weight) and com_weight > 0):
        raise ValueError(f"com_weight must be positive and finite, not {com_weight!r}")
    return float(com_weight) / h**2


def trial_gains(options: TrialGains, sim: SimModel) -> tuple[BalanceGains, InverseDynamicsGains]:
    """The gains of a trial on ``sim``: ``options``' own, derived from the robot unless told not.

    Returns:
        ``(ik gains, id gains)``: :func:`robot_gains` and :func:`robot_id_gains` of
        ``options.gains`` and ``options.id_gains`` when ``options.robot_gains``, else those as
        they are.
    """
    if not options.robot_gains:
        return options.gains, options.id_gains
    scales = RobotScales.of_sim(sim)
    return robot_gains(scales, options.gains), robot_id_gains(scales, options.id_gains)


def declared_angular_momentum_damping(
    options: TrialGains, stance: Stance, plane_height: float, gravity: float, timestep: float
) -> float:
    """K_L (1/s): the ``id`` controller's angular momentum damping gain in a trial on ``stance``.

    The gain the trial's controller runs with: derived from the robot
    (:func:`robot_id_gains`, ``K_L = w_c``) unless ``options.robot_gains`` is False, then
    ``options.id_gains``' own. The same number as :func:`trial_gains` on the trial's model.

    Args:
        options: The trial's options (their ``id_gains`` and ``robot_gains``).
        stance: The scenario's stance (its mass, CoM and inertia).
        plane_height: Height of the contact plane, m.
        gravity: g, m/s^2.
        timestep: The simulation's step, s.
    """
    if not options.robot_gains:
        return float(options.id_gains.angular_momentum_damping)
    scales = RobotScales.of(stance, plane_height, gravity, timestep)
    return float(robot_id_gains(scales, options.id_gains).angular_momentum_damping)


class TrialGains(Protocol):
    """What a trial's options hold for the controllers: the gains of each."""

    @property
    def gains(self) -> BalanceGains:
        """Gains of the kinematic (``ik``) controller."""
        ...

    @property
    def id_gains(self) -> InverseDynamicsGains:
        """Gains of the torque (``id``) controller."""
        ...

    @property
    def robot_gains(self) -> bool:
        """Derive the robot-dependent gains from the robot (:func:`robot_gains`)."""
        ...
