"""The governor's cap as a mink limit: a constraint of mink's IK QP on a MuJoCo model.

mink (the ``mink`` extra) solves for a displacement ``Δq`` of a MuJoCo model under limits
``G Δq <= h``. :class:`MinkApproachLimit` adds one row: the impacting point's approach speed
over the step, ``-n . J Δq / dt``, at most the governor's ceiling at the configuration's
state (:mod:`.approach`; the state mapped to pinocchio's conventions by
:class:`~.mujoco_state.MujocoState`). Give it to ``mink.solve_ik(..., limits=[...])`` beside
the configuration limit (a ``limits`` list replaces mink's default)::

    limit = MinkApproachLimit(governor, configuration.model)
    limits = [mink.ConfigurationLimit(configuration.model), limit]
    velocity = mink.solve_ik(configuration, tasks, dt, "daqp", limits=limits)
"""

from __future__ import annotations

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin
from mink import Configuration
from mink.limits import Constraint, Limit
from numpy.typing import ArrayLike

from impact_balance.governor.approach import ApproachRow, ImpactPoint
from impact_balance.governor.governor import Governor
from impact_balance.governor.mujoco_state import MujocoState

__all__ = ["MinkApproachLimit"]


class MinkApproachLimit(Limit):
    """The impacting point's approach speed over one IK step, at most the governor's ceiling.

    Each call of :meth:`compute_qp_inequalities` maps the configuration's ``qpos`` to
    pinocchio's ``q``, asks the governor for its limit there, and returns the row
    ``-n^T J Δq <= ceiling * dt`` in MuJoCo's tangent space, ``J`` the point's translational
    Jacobian (world axes) at that ``q``. The CoM velocity the governor reads comes from
    :attr:`com_velocity` when set, else :attr:`velocity` (MuJoCo's ``qvel``) when set, else
    the configuration's ``data.qvel`` (zero in a purely kinematic mink loop unless you write
    it). Only the upper bound is enforced; with no safe speed the row is ``-n^T J Δq <= 0``;
    an unbounded ceiling gives an inactive constraint.

    Attributes:
        velocity: MuJoCo's ``qvel`` (nv of the MuJoCo model) of the measured state, or None.
        com_velocity: The CoM velocity (world, m/s; 2 or 3 numbers), or None.
        last: The last row, in pinocchio's tangent space (:class:`~.approach.ApproachRow`),
            None before the first call.
        state: The map between MuJoCo's and pinocchio's conventions.

    Args:
        governor: The governor.
        mj_model: A MuJoCo model of the governor's robot (see :class:`~.mujoco_state.MujocoState`).
        free_joint: The robot's free joint in ``mj_model`` (None: its only one).

    Raises:
        GovernorError: A MuJoCo model that is not the governor's robot.
    """

    def __init__(
        self, governor: Governor, mj_model: mujoco.MjModel, free_joint: str | None = None
    ) -> None:
        model = governor.robot.model
        self.point = ImpactPoint(governor, model)
        self.state = MujocoState(model, mj_model, free_joint)
        self._data = model.createData()
        self.velocity: ArrayLike | None = None
        self.com_velocity: ArrayLike | None = None
        self.last: ApproachRow | None = None

    def compute_qp_inequalities(self, configuration: Configuration, dt: float) -> Constraint:
        """The row ``G Δq <= h`` at the configuration (``Δq`` in MuJoCo's tangent space).

        Args:
            configuration: mink's configuration (its ``data.qpos``, and ``data.qvel``).
            dt: The IK step, s.

        Returns:
            The constraint (1 x nv of the MuJoCo model), inactive when the ceiling is unbounded.

        Raises:
            GovernorError: A state or velocity the governor refuses, a bad ``dt``.
        """
        qpos = configuration.data.qpos
        q = self.state.q(qpos)
        qvel = configuration.data.qvel if self.velocity is None else self.velocity
        v = self.state.v(qpos, qvel)
        pin.computeJointJacobians(self.point.model, self._data, q)
        row = self.point.row(q, self._data, dt, v, self.com_velocity)
        self.last = row
        if not np.isfinite(row.h[0]):
            return Constraint()
        G: npt.NDArray[np.float64] = self.state.columns(qpos, row.G)
        return Constraint(G=G, h=row.h)
