"""Gains of the balance controllers, and what a trial's options hold of them.

:class:`BalanceGains` tune the kinematic controller (``ik``,
:class:`~impact_balance.sim.control.kinematic.BalanceController`),
:class:`InverseDynamicsGains` the torque controller (``id``,
:class:`~impact_balance.sim.control.torque.InverseDynamicsController`). A trial's options carry
both (:class:`TrialGains`); each controller reads its own.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any, Protocol

__all__ = ["BalanceGains", "InverseDynamicsGains", "TrialGains"]


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
        joint_limit_horizon: T [s] of the joint position limits on the accelerations: braking at
            ``a`` from ``(q, v)`` stays within the limits for T, ``q + v T + a T^2 / 2`` in
            ``[lower, upper]``. MuJoCo enforces the limits with forces the QP would not know.
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
    joint_limit_horizon: float = 0.1

    def to_dict(self) -> dict[str, Any]:
        """The gains by field name (JSON-ready)."""
        return asdict(self)


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
