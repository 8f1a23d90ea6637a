"""A stance's contacts as a controller enforces them: friction scaled, rectangles inset.

The paper's criterion lets every contact wrench lie anywhere in its contact wrench cone: the
contact's friction ``mu`` and its full rectangle. A controller that keeps its wrenches inside
narrower cones (the ``id`` controller's QP: ``friction_scale * mu``, each rectangle shrunk by
``cop_margin`` on every side) can only realise the balance that those narrower cones give. This
module makes the stance whose contacts are the narrower ones, so that the library's own pipeline
(stance -> constraints -> areas) computes the areas of that contact model.

The rectangle's inset follows the controller's rule: each half size ``X`` becomes
``max(X - cop_margin, X / 2)`` (a contact is never shrunk below half its size); a point contact
stays a point.
"""

from __future__ import annotations

import copy
import dataclasses
import math

from impact_balance.contacts.stance import Contact, ContactSpec, Stance
from impact_balance.exceptions import ScenarioError

__all__ = ["check_friction_scale", "inset_half_size", "scaled_contact", "scaled_stance"]


def check_friction_scale(value: float, field: str = "friction_scale") -> float:
    """``value`` as a float when it is a friction scale: finite, in (0, 1].

    Raises:
        ScenarioError: Otherwise, naming ``field`` and the value.
    """
    try:
        scale = float(value)
    except (TypeError, ValueError):
        raise ScenarioError(field, value, "must be a number in (0, 1]") from None
    if not (math.isfinite(scale) and 0.0 < scale <= 1.0):
        raise ScenarioError(field, value, "must be a number in (0, 1]")
    return scale


def inset_half_size(half: float, cop_margin: float) -> float:
    """A rectangle's half size (m) shrunk by ``cop_margin`` (m), never below half of it."""
    return max(half - cop_margin, 0.5 * half)


def scaled_contact(
    spec: ContactSpec, friction_scale: float, cop_margin: float = 0.0
) -> ContactSpec:
    """``spec``, its friction times ``friction_scale``, its rectangle inset by ``cop_margin``.

    Args:
        spec: The contact as the scenario gives it.
        friction_scale: In (0, 1]: the friction coefficient's factor.
        cop_margin: The rectangle's inset on every side, m (>= 0; see the module docstring).

    Returns:
        The narrower contact; ``spec`` itself when nothing changes.

    Raises:
        ScenarioError: A friction scale outside (0, 1] (field ``friction_scale``) or a negative
            or non-finite ``cop_margin`` (field ``cop_margin``).
    """
    scale = check_friction_scale(friction_scale)
    if not (math.isfinite(cop_margin) and cop_margin >= 0.0):
        raise ScenarioError("cop_margin", cop_margin, "must be a finite number >= 0 (m)")
    if scale == 1.0 and cop_margin == 0.0:
        return spec
    length, width = (2.0 * inset_half_size(0.5 * float(s), cop_margin) for s in spec.size)
    return dataclasses.replace(spec, friction=float(spec.friction) * scale, size=(length, width))


def scaled_stance(stance: Stance, friction_scale: float, cop_margin: float = 0.0) -> Stance:
    """``stance`` with every contact :func:`scaled_contact`: the same robot, posture and points.

    Only the contacts' specifications change (friction, size): the configuration, CoM, mass,
    contact frames, positions and Jacobians are the stance's (the contact's centre does not move).

    Args:
        stance: The stance (world frame).
        friction_scale: In (0, 1].
        cop_margin: The rectangles' inset, m (>= 0).

    Returns:
        The stance of the narrower contacts; ``stance`` itself when nothing changes.

    Raises:
        ScenarioError: See :func:`scaled_contact`.
    """
    if friction_scale == 1.0 and cop_margin == 0.0:  # every contact its own spec: no change
        return stance
    specs = [scaled_contact(c.spec, friction_scale, cop_margin) for c in stance.contacts]
    if all(s is c.spec for s, c in zip(specs, stance.contacts, strict=True)):
        return stance
    narrower = copy.copy(stance)
    narrower.contacts = [
        Contact(
            spec,
            c.rotation.copy(),
            c.position.copy(),
            c.jacobian.copy(),
            None if c.local_position is None else c.local_position.copy(),
        )
        for spec, c in zip(specs, stance.contacts, strict=True)
    ]
    return narrower
