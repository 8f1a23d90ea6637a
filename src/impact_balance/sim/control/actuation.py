"""How the joints are driven in balance trials: stiffer support limbs, stiff servos, torque motors.

The servo rule of :mod:`.joints` suits a limb moving freely; a limb that carries the robot
needs at least the robot's gravity stiffness (:func:`stiffen_support_limbs`). The ``rigid``
joint model cannot be controlled (welded), so balance trials use :data:`STIFF_SERVOS` for it;
the ``id`` controller drives torque motors (:func:`use_torque_motors`).
"""

from __future__ import annotations

import numpy as np

from impact_balance.analysis.analyze import Analysis
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.model.joints import ServoOptions

__all__ = [
    "STIFF_SERVOS",
    "SUPPORT_STIFFNESS_FACTOR",
    "stiffen_support_limbs",
    "support_joints",
    "use_torque_motors",
]

#: Support-limb servo stiffness floor, in units of the robot's gravity stiffness m g h (see
#: stiffen_support_limbs).
SUPPORT_STIFFNESS_FACTOR = 0.4

#: Servos of the ``rigid`` joint model in balance trials: 30 Hz bandwidth, no effort limits. A
#: welded robot cannot be controlled; this is the closest a controlled robot gets to the paper's
#: rigid body.
STIFF_SERVOS = ServoOptions(bandwidth=2.0 * np.pi * 30.0, effort_limits=False)


def support_joints(sim: SimModel, analysis: Analysis) -> list[str]:
    """Simulated joints on the chain from the root to a sustained contact (the support limbs)."""
    model = analysis.stance.model
    names: set[str] = set()
    for contact in analysis.stance.contacts:
        j = model.frames[model.getFrameId(contact.spec.frame)].parentJoint
        while j > 1:
            names.add(model.names[j])
            j = model.parents[j]
    return [n for n in sim.joint_names if n in names]


def stiffen_support_limbs(
    sim: SimModel, analysis: Analysis, factor: float = SUPPORT_STIFFNESS_FACTOR
) -> None:
    """Raise the servo gains of the support limbs to a floor set by the robot's gravity stiffness.

    The servo rule of :mod:`.joints` scales each joint's gains by the inertia the joint moves with
    the base free (``M_jj``): for an ankle, that is the foot alone, about 0.03 kg m^2, so ``kp``
    is 88 N m/rad (ankle roll) to 230 N m/rad (ankle pitch) at 15 Hz, against a gravity stiffness
    ``m g h`` of about 820 N m/rad for Talos standing on that ankle. Every joint of a support limb
    gets at least ``kp = factor m g h`` and ``kd = 2 sqrt(kp m h^2)`` (critical damping of the whole
    robot swinging about that joint at the CoM height ``h``); effort limits are kept. The
    DCM/ZMP feedback holds the rest of the pendulum. The default factor,
    :data:`SUPPORT_STIFFNESS_FACTOR`, comes from push trials (``docs/studies/design-history.md``).

    Args:
        sim: The trials' MuJoCo model (servos).
        analysis: The scenario's analysis (stance, gravity).
        factor: Stiffness floor in units of the gravity stiffness ``m g h``.
    """
    m = analysis.stance.mass
    h = float(analysis.stance.com[2] - analysis.stance.lowest_contact_height())
    kp_min = factor * m * analysis.areas.gravity * h
    kd_min = 2.0 * np.sqrt(kp_min * m * h * h)
    chosen = set(support_joints(sim, analysis))
    for k, name in enumerate(sim.joint_names):
        if name not in chosen:
            continue
        a = sim.actuator_ids[k]
        kp, kd = max(sim.kp[k], kp_min), max(sim.kd[k], kd_min)
        sim.model.actuator_gainprm[a, 0] = kp
        sim.model.actuator_biasprm[a, 1] = -kp
        sim.model.actuator_biasprm[a, 2] = -kd
        sim.kp[k], sim.kd[k] = kp, kd


def use_torque_motors(sim: SimModel) -> None:
    """Turn the servo actuators into torque motors (force = ctrl), for the ``id`` controller.

    The servo actuators are MuJoCo ``general`` actuators with force ``kp ctrl - kp q - kd qdot``;
    setting the gain to 1 and the bias to 0 leaves ``force = ctrl``, clipped to the same force range
    (the URDF effort limit with ``servo`` joints, none with ``rigid``). ``kp``/``kd`` become 0.
    """
    ids = sim.actuator_ids
    sim.model.actuator_gainprm[ids, 0] = 1.0
    sim.model.actuator_biasprm[ids, :3] = 0.0
    sim.kp[:] = 0.0
    sim.kd[:] = 0.0
