"""``--rigid-impact``: the simulated robot is the paper's rigid robot during the impact only.

The paper's impact model (the ``composite`` inertia) assumes that the impulse changes only the
floating base's velocity: every joint keeps the velocity it had when the contact began (the
robot moves as one rigid body through the impact). A stiff position servo does not do that at
the impact's time scale (the arm gives way and the palm bounces off), and a joint locked at
*zero* velocity would stop the hand instead.

:class:`RigidImpactHold` makes it so in MuJoCo: at the first contact it raises every actuated
joint's armature (the rotor inertia MuJoCo adds to the joint's diagonal of the mass matrix) to
``armature`` (1e4 kg m^2 by default). Any finite torque, from the servo, the motor, gravity or
the impact, then changes a joint's velocity by a negligible amount (the hold reports the largest
change), while the free base responds to the contact impulse as the composite rigid body does.
The joints' real armature comes back, and the controller acts again, when the contact's normal
velocity reaches zero: the end of the compression phase, when the impact point has stopped
approaching the surface (or after ``max_duration`` at the latest). Held longer, the hold turns
the impact into a push; released earlier, the impulse is short of the plastic one.

The hold ends at the end of compression, so the impulse it transmits as a rigid body is the
plastic one (restitution 0, the lower bound of the usual range); what the soft contact gives
back afterwards acts on the robot with its joints free.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from impact_balance.sim.model.build import SimModel

__all__ = ["HOLD_ARMATURE", "RigidImpactHold"]

#: Armature of every held joint during the impact, kg m^2.
HOLD_ARMATURE = 1e4


@dataclass
class RigidImpactHold:
    """Holds every actuated joint's velocity from the first contact to the end of compression.

    Attributes:
        sim: The simulated model (its ``dof_armature`` is changed during the hold, then restored).
        armature: Armature of every joint during the hold (kg m^2).
        max_duration: Longest hold (s).
        start: When the hold began (s), None before.
        end: When it ended (s), None before.
        velocity_change: Largest change of a held joint's velocity during the hold (rad/s).
    """

    sim: SimModel
    armature: float = HOLD_ARMATURE
    max_duration: float = 0.02
    start: float | None = field(default=None, init=False)
    end: float | None = field(default=None, init=False)
    velocity_change: float = field(default=0.0, init=False)
    _saved: np.ndarray | None = field(default=None, init=False)
    _velocity: np.ndarray | None = field(default=None, init=False)

    @property
    def active(self) -> bool:
        """Whether the joints are held now."""
        return self.start is not None and self.end is None

    @property
    def duration(self) -> float | None:
        """How long the hold lasted (s), None until it ended."""
        return None if self.start is None or self.end is None else self.end - self.start

    def begin(self, t: float) -> None:
        """The contact began at ``t`` (s): hold every joint at its current velocity."""
        if self.start is not None:
            return
        dofs = self.sim.dof_adr
        self._saved = self.sim.model.dof_armature[dofs].copy()
        self._velocity = self.sim.data.qvel[dofs].copy()
        self.sim.model.dof_armature[dofs] = self.armature
        self.start = float(t)

    def update(self, t: float, approach_speed: float) -> None:
        """After a step: end the hold once the point no longer approaches, or after the longest.

        The point approaches while ``approach_speed`` = ``-n . v`` > 0 (m/s); the hold lasts at most
        ``max_duration``.
        """
        if not self.active:
            return
        dofs = self.sim.dof_adr
        change = np.abs(self.sim.data.qvel[dofs] - self._velocity)
        self.velocity_change = max(
            self.velocity_change, float(change.max()) if change.size else 0.0
        )
        if self.start is None or approach_speed <= 0.0 or t - self.start >= self.max_duration:
            self.release(t)

    def release(self, t: float) -> None:
        """Give the joints their own armature back (idempotent)."""
        if self.active:
            self.sim.model.dof_armature[self.sim.dof_adr] = self._saved
            self.end = float(t)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready."""
        return {
            "start": self.start,
            "end": self.end,
            "duration": self.duration,
            "armature": self.armature,
            "max_joint_velocity_change": self.velocity_change,
        }
