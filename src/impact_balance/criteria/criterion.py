"""The family of criteria: what every criterion answers, and their names.

A criterion decides how fast the contact may be hit from one posture: given the pre-impact
CoM velocity (world, m/s), :meth:`Criterion.limit` answers the maximum contact velocity as a
:class:`~impact_balance.criteria.velocity_limit.ContactVelocityLimit`. The members are
:class:`~impact_balance.criteria.com.ComCriterion` (the paper's CoM velocity criterion,
sec. V-C) and :class:`~impact_balance.criteria.zmp.ZmpCriterion` (the predicted ZMP, the
paper's Experiment 1 comparison).
"""

from __future__ import annotations

from typing import ClassVar, Literal, Protocol

import numpy.typing as npt

from impact_balance.criteria.velocity_limit import ContactVelocityLimit

__all__ = ["CRITERION_NAMES", "Criterion", "CriterionName"]

#: The name of a criterion: "com" (CoM velocity area) or "zmp" (predicted ZMP).
CriterionName = Literal["com", "zmp"]

#: Every criterion name, the paper's first.
CRITERION_NAMES: tuple[CriterionName, ...] = ("com", "zmp")


class Criterion(Protocol):
    """A criterion of one posture and one impact model.

    Attributes:
        name: Its name.
    """

    name: ClassVar[CriterionName]

    def limit(self, com_velocity: npt.ArrayLike) -> ContactVelocityLimit:
        """The maximum contact velocity from the pre-impact CoM velocity.

        Args:
            com_velocity: Pre-impact CoM velocity, world, m/s (x and y are read).

        Returns:
            The criterion's limit.
        """
        ...
