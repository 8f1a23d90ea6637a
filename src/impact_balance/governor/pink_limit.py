"""The governor's cap as a pink limit: a constraint of pink's IK QP, not a scaled target.

pink (``pin-pink``, a core dependency) solves for a displacement ``Δq`` under limits
``G Δq <= h``. :class:`PinkApproachLimit` adds one row: the impacting point's approach speed
over the step, ``-n . J Δq / dt``, at most the governor's ceiling at the configuration's ``q``
(:mod:`.approach`). Give it to ``pink.solve_ik(..., limits=[...])`` beside the model's own
limits (a ``limits`` list replaces pink's defaults)::

    limit = PinkApproachLimit(governor, configuration.model)
    limits = [configuration.model.configuration_limit, configuration.model.velocity_limit, limit]
    limit.velocity = v_measured                      # each tick, before solve_ik (or None: zero)
    velocity = pink.solve_ik(configuration, tasks, dt, solver="daqp", limits=limits)
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import ArrayLike
from pink import Configuration
from pink.limits import Limit

from impact_balance.governor.approach import ApproachRow, ImpactPoint
from impact_balance.governor.governor import Governor

__all__ = ["PinkApproachLimit"]


class PinkApproachLimit(Limit):  # type: ignore[misc]  # pink ships no type information
    """The impacting point's approach speed over one IK step, at most the governor's ceiling.

    Each call of :meth:`compute_qp_inequalities` asks the governor for its limit at the
    configuration's ``q`` and the velocity :attr:`velocity` (or the CoM velocity
    :attr:`com_velocity`), and returns the row ``-n^T J Δq <= ceiling * dt`` with ``J`` the
    point's translational Jacobian (world axes) from the configuration's kinematics. Only the
    upper bound is enforced (from a falling start the safe speeds may start above 0; the
    limit does not push the point at the surface). With no safe speed the row is
    ``-n^T J Δq <= 0``: the point does not approach. An unbounded ceiling gives no row.

    Attributes:
        velocity: The generalized velocity (nv, pinocchio's convention: base velocities in the
            base frame) the governor reads the CoM velocity from; set it each tick from the
            measured state. None (default): zero, pink's ``Configuration`` has no velocity.
        com_velocity: The CoM velocity (world, m/s; 2 or 3 numbers) from your own estimator;
            when set, it is used instead of :attr:`velocity`.
        last: The last row computed (:class:`~.approach.ApproachRow`: ``G``, ``h``, the
            governor's answer and the Jacobian), None before the first call.

    Args:
        governor: The governor.
        model: The pinocchio model pink's configuration uses (the governor's robot).

    Raises:
        GovernorError: ``model`` is not the governor's robot, or lacks the impact frame.
    """

    def __init__(self, governor: Governor, model: pin.Model) -> None:
        self.point = ImpactPoint(governor, model)
        self.velocity: ArrayLike | None = None
        self.com_velocity: ArrayLike | None = None
        self.last: ApproachRow | None = None

    def compute_qp_inequalities(
        self, configuration: Configuration, dt: float
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]] | None:
        """The row ``G Δq <= h`` at the configuration (``Δq`` in pinocchio's tangent space).

        Args:
            configuration: pink's configuration (its ``q`` and kinematics).
            dt: The IK step, s.

        Returns:
            ``(G, h)`` (1 x nv, 1), or None when the ceiling is unbounded.

        Raises:
            GovernorError: A state or velocity the governor refuses, a bad ``dt``.
        """
        row = self.point.row(
            configuration.q, configuration.data, dt, self.velocity, self.com_velocity
        )
        self.last = row
        if not np.isfinite(row.h[0]):
            return None
        return row.G, row.h
