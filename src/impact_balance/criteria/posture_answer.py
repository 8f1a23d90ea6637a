"""A posture's answer from its compiled call: the pipeline's objects, or the steps' turn.

:func:`~impact_balance.criteria.posture_kernel.posture_kernel` answers a posture's areas, impact
model and CoM criterion rates as arrays; :func:`posture_answer` makes them the objects the steps
one by one make (:class:`~impact_balance.balance.areas.Projected`,
:class:`~impact_balance.impact.model.ImpactModel`,
:class:`~impact_balance.criteria.com.ComCriterion`), or says that the steps must answer (None).
Every caller of the compiled call goes through it: :func:`~impact_balance.analyze` (and with it
the sweep's evaluator) from a stance, a governor from pinocchio's arrays.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from impact_balance.balance.areas import Projected
from impact_balance.criteria.com import ComCriterion
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel, ImpactSpec

__all__ = ["PostureAnswer", "posture_answer"]


class PostureAnswer(NamedTuple):
    """One posture's objects, made from the compiled call's arrays by :func:`posture_answer`.

    Attributes:
        projected: The ZMP support area (world, m; shrunk by the ZMP margin) and the CoM
            velocity area (m/s, with its half-planes) as arrays
            (:meth:`~impact_balance.balance.areas.Projected.areas` builds the
            :class:`~impact_balance.balance.areas.BalanceAreas`).
        impact: The impact model.
        criterion: The paper's CoM criterion of the CoM velocity area and the impact model,
            with the velocity margin (no angular momentum term).
    """

    projected: Projected
    impact: ImpactModel
    criterion: ComCriterion


def posture_answer(
    out: tuple,  # type: ignore[type-arg]
    spec: ImpactSpec,
    point: np.ndarray,
    normal: np.ndarray,
    cone: np.ndarray,
    jacobian: np.ndarray,
    *,
    mass: float,
    omega: float,
    com: np.ndarray,
    plane_height: float,
    gravity: float,
    zmp_margin: float,
    velocity_margin: float,
) -> PostureAnswer | None:
    """The objects of a posture from the compiled call's answer ``out``, or None.

    ``out`` is :func:`~impact_balance.criteria.posture_kernel.posture_kernel`'s answer. None
    when the kernel left the posture to the steps (its code is
    :data:`~impact_balance.criteria.posture_kernel.FALLBACK`): the caller then takes them one by
    one. Else the same objects (to the last digit) as the steps
    make: :func:`~impact_balance.balance.areas.posture_areas`'s areas,
    :func:`~impact_balance.impact.model.impact_model`'s model and
    ``ComCriterion(area, model, velocity_margin)``.

    Args:
        out: The compiled call's answer (its first twelve entries are read).
        spec: The impact specification the kernel was called with.
        point: The impact point, world, m.
        normal: (3,) the impact normal (world), as the kernel had it.
        cone: (3, N) the impact's friction-cone generators, as the kernel had them.
        jacobian: (3, nv) the impact point's translational Jacobian (world axes).
        mass: kg.
        omega: The LIPM's omega, 1/s.
        com: (3,) the CoM, world, m.
        plane_height: The LIPM plane's height h, m.
        gravity: m/s^2.
        zmp_margin: The ZMP margin the kernel's areas were shrunk by, m.
        velocity_margin: The CoM criterion's velocity margin, m/s.

    Returns:
        The areas, the impact model and the CoM criterion; None where the steps must answer.
    """
    code, force, bounded, zmp, zmp_bounded, vel, vel_bounded, G, h, W, impulse, rates = out[:12]
    if code:
        return None
    area = Polygon.with_halfplanes(vel, bool(vel_bounded), G, h)
    projected = Projected(
        force, bool(bounded), zmp, bool(zmp_bounded), area, 1, omega, com, plane_height, mass,
        gravity, float(zmp_margin),
    )  # fmt: skip
    impact = ImpactModel(spec, point, normal, cone, W, mass, jacobian, impulse)
    margin = float(velocity_margin)
    criterion = ComCriterion.from_rates(area, impact, margin, G, h - margin if margin else h, rates)
    return PostureAnswer(projected, impact, criterion)
