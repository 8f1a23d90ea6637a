"""The governor's cap as one linear inequality on a displacement: the row of an IK limit.

An IK step moves the configuration by ``Δq`` (in the tangent space, nv) over ``dt`` seconds.
The impacting point then moves by ``J Δq`` (``J``: its 3 x nv translational Jacobian, world
axes), so its approach speed towards the surface (normal ``n``, pointing into the robot) is
``-n . J Δq / dt``. Bounding it by the governor's ceiling gives one row::

    -n^T J Δq <= ceiling * dt

which :mod:`.pink_limit` and :mod:`.mink_limit` hand to their QPs. The Jacobian is computed
from the configuration each call, not taken from the governor's cache.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import ArrayLike

from impact_balance.contacts.stance import frame_point
from impact_balance.exceptions import GovernorError
from impact_balance.governor.governor import Governor
from impact_balance.governor.limit import SpeedLimit

__all__ = ["ApproachRow", "ImpactPoint"]


@dataclass(frozen=True)
class ApproachRow:
    """One tick's inequality ``G Δq <= h`` (pinocchio's tangent space) and what gave it.

    Attributes:
        G: The row ``-n^T J`` (1 x nv), 1 (m per unit of Δq, projected on the normal).
        h: ``ceiling * dt`` (1,), m: the largest approach displacement in one step.
        limit: The governor's answer at this configuration.
        jacobian: The impact point's translational Jacobian (3 x nv, world axes).
    """

    G: npt.NDArray[np.float64]
    h: npt.NDArray[np.float64]
    limit: SpeedLimit
    jacobian: npt.NDArray[np.float64]


class ImpactPoint:
    """The governor's impact point on a pinocchio model of its robot, and the row at a state.

    Args:
        governor: The governor (its scenario's impact frame, offset and normal).
        model: A pinocchio model of the governor's robot (the same joints in the same order,
            e.g. ``governor.robot.model``, or a pink configuration's); its frame is looked up by
            name.

    Raises:
        GovernorError: A model of other sizes than the governor's, or without the impact frame.
    """

    def __init__(self, governor: Governor, model: pin.Model) -> None:
        impact = governor.scenario.impact
        assert impact is not None  # a governor always has an impact
        spec = impact.spec()
        if (model.nq, model.nv) != (governor.nq, governor.nv):
            raise GovernorError(
                "model",
                f"nq {model.nq}, nv {model.nv}",
                f"must be the governor's robot (nq {governor.nq}, nv {governor.nv})",
            )
        if not model.existFrame(spec.frame):
            raise GovernorError("impact.frame", spec.frame, "is not a frame of the model")
        self.governor = governor
        self.model = model
        self.frame_id = model.getFrameId(spec.frame)
        self.offset: pin.SE3 | None = spec.offset

    def jacobian(self, data: pin.Data) -> npt.NDArray[np.float64]:
        """The point's 3 x nv translational Jacobian (world axes) from ``data``.

        ``data`` must hold the joint placements and joint Jacobians of the configuration
        (``pin.computeJointJacobians``, which pink's ``Configuration.update`` runs).
        """
        _, J = frame_point(self.model, data, self.frame_id, self.offset)
        assert J is not None
        out: npt.NDArray[np.float64] = np.array(J[:3])
        return out

    def position(self, data: pin.Data) -> npt.NDArray[np.float64]:
        """The point's world position (m) from ``data``'s joint placements."""
        placement, _ = frame_point(self.model, data, self.frame_id, self.offset, jacobian=False)
        return np.array(placement.translation)

    def row(
        self,
        q: ArrayLike,
        data: pin.Data,
        dt: float,
        velocity: ArrayLike | None = None,
        com_velocity: ArrayLike | None = None,
    ) -> ApproachRow:
        """The row at configuration ``q`` (pinocchio's), its kinematics in ``data``.

        Args:
            q: The configuration (nq), pinocchio's order.
            data: Pinocchio data holding ``q``'s joint placements and Jacobians.
            dt: The step's duration, s (> 0).
            velocity: The generalized velocity (nv, pinocchio's) the governor's CoM velocity
                comes from; None: zero (or ``com_velocity``).
            com_velocity: The CoM velocity (world, m/s), used instead of ``velocity`` when given.

        Returns:
            The row, with the governor's answer.

        Raises:
            GovernorError: A bad ``dt``, state or velocity (the governor's checks).
        """
        if not (isinstance(dt, (int, float)) and np.isfinite(dt) and dt > 0.0):
            raise GovernorError("dt", dt, "must be a finite number of seconds > 0")
        if com_velocity is not None:
            limit = self.governor.limit_com(q, com_velocity)
        else:
            v = np.zeros(self.governor.nv) if velocity is None else velocity
            limit = self.governor.limit(q, v)
        J = self.jacobian(data)
        G = -(limit.normal @ J)[None, :]
        h = np.array([limit.ceiling * float(dt)])
        return ApproachRow(G, h, limit, J)
