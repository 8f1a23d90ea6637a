"""Warnings: valid input that is probably not what the user meant, or an answer with a caveat.

An analysis never refuses these (they can be deliberate), but it says so: each is a
:class:`Diagnostic` in ``Analysis.warnings``, a line of the text report, an entry of the
JSON's ``warnings`` list, and an error under ``--strict``.

The rules (codes):

- ``robot_not_z_up``: the robot's feet-to-CoM axis is more than 45° from the world's +z
  (:meth:`impact_balance.robot.robot.Robot.up_axis_problem`): a model whose up axis is not z
  (example-robot-data's y-up ``human``) lies on its side, and its contacts look short of
  friction. The message gives the ``base`` that stands it up.
- ``contact_normal_down``: a contact normal (the frame's z axis after its offset, which must
  point from the surface into the robot) has a negative world z, i.e. the surface would be
  above the contact, like a ceiling. Usually a flipped offset (``rpy: [3.14159, 0, 0]``).
- ``contact_normal_tilted``: a contact normal between :data:`FLOOR_TILT` (40°) and
  :data:`WALL_TILT` (70°) from the vertical. Plausible surfaces are floors and ramps (tilt
  up to 40°, steeper than any walkable ramp) and walls (tilt 70° to 90°); in between is usually
  a frame whose z axis is not the sole's normal (some robots' foot frames are tilted 45°).
- ``impact_moving_away``: the reference velocity does not move towards the impacted surface
  (approach speed ``-n . v <= 0``): there is no impact to cap. Usually ``impact.normal``
  has the wrong sign (it points from the surface into the robot).
- ``qp_capped_by_reference``: the paper's QP tracks the reference velocity, so its approach
  speed never exceeds the reference's; when that is below the maximum contact velocity, the
  QP's answer is the reference, not the limit.
- ``figure_skipped``: ``--plots`` could not draw one of the figures (reported by
  :func:`impact_balance.plots.save_figures`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.analysis.result import Diagnostic, ImpactAnswer

if TYPE_CHECKING:
    from impact_balance.contacts.stance import Stance
    from impact_balance.scenario import Scenario

__all__ = [
    "FLOOR_TILT",
    "WALL_TILT",
    "Diagnostic",
    "contact_diagnostics",
    "diagnose",
    "diagnostics_to_json",
    "impact_diagnostics",
]

#: Steepest floor or ramp, degrees from the vertical.
FLOOR_TILT = 40.0
#: Least steep wall, degrees from the vertical.
WALL_TILT = 70.0
#: The identity pose: a contact without offset sits at its frame's origin.
_IDENTITY = pin.SE3.Identity()
#: Relative tolerance under which the QP's approach speed "equals" the reference's.
_CAP_TOLERANCE = 1e-6


def _tilt_degrees(normal: np.ndarray) -> float:
    """Angle between a unit vector and the world's up axis, degrees."""
    return math.degrees(math.acos(max(-1.0, min(1.0, float(normal[2])))))


#: Above this world z, a unit normal is surely less than FLOOR_TILT from the vertical (the
#: margin keeps rounding out of the question): no warning to compute.
_FLAT_NORMAL_Z = math.cos(math.radians(FLOOR_TILT)) + 1e-9


def contact_diagnostics(stance: Stance) -> list[Diagnostic]:
    """Contact normals pointing down or tilted between a floor and a wall."""
    out = []
    for i, contact in enumerate(stance.contacts):
        if float(contact.rotation[2, 2]) > _FLAT_NORMAL_Z:  # a floor or gentle ramp: no warning
            continue
        tilt = _tilt_degrees(contact.normal)
        field = f"contacts[{i}]"
        frame = contact.spec.frame
        if contact.normal[2] < 0.0:
            out.append(
                Diagnostic(
                    "contact_normal_down",
                    field,
                    f"the normal of {frame} points down ({tilt:.0f}° from vertical): "
                    "the surface would be above the contact; the frame's z axis (after offset) "
                    "must point from the surface into the robot",
                )
            )
        elif FLOOR_TILT < tilt < WALL_TILT:
            out.append(
                Diagnostic(
                    "contact_normal_tilted",
                    field,
                    f"the normal of {frame} is {tilt:.0f}° from vertical, neither a floor or ramp "
                    f"(<= {FLOOR_TILT:.0f}°) nor a wall (>= {WALL_TILT:.0f}°): "
                    "is its z axis the surface normal? "
                    "(give the contact the surface's normal, normal: [0, 0, 1] for the ground, "
                    "or turn it with offset.rpy)",
                )
            )
    return out


def impact_diagnostics(
    answer: ImpactAnswer, reference_velocity: npt.ArrayLike | None
) -> list[Diagnostic]:
    """An impact that does not approach its surface, a QP capped by its reference."""
    out: list[Diagnostic] = []
    if reference_velocity is None:
        return out
    approach = answer.model.approach_speed(reference_velocity)
    if approach <= 0.0:
        out.append(
            Diagnostic(
                "impact_moving_away",
                "impact.reference_velocity",
                "the reference velocity does not move towards the impacted surface "
                f"(approach speed -n.v = {approach:.3g} m/s <= 0), so there is no impact and "
                "nothing to cap; impact.normal must point from the surface into the robot "
                "(is its sign flipped?)",
            )
        )
    qp = answer.qp
    limit = answer.max_contact_velocity
    if (
        qp is not None
        and qp.status == "optimal"
        and approach > 0.0
        and math.isfinite(qp.approach_speed)
        and approach < limit
        and abs(qp.approach_speed - approach) <= _CAP_TOLERANCE * max(1.0, approach)
    ):
        out.append(
            Diagnostic(
                "qp_capped_by_reference",
                "impact.qp",
                f"the paper's QP gives the reference approach speed {approach:.3f} m/s, "
                f"not the maximum {limit:.3f} m/s: it tracks the reference velocity and never "
                "exceeds it",
            )
        )
    return out


#: The robot surely stands when its feet-to-CoM axis, read from the stance, is this close to +z
#: (a cosine): the up-axis check's 45 degrees, with a margin far above the rounding between the
#: stance frame's numbers and the check's world ones (see :func:`_surely_upright`).
_SURELY_UPRIGHT = math.cos(math.radians(45.0)) + 1e-6


def _surely_upright(stance: Stance) -> bool:
    """Whether ``robot_not_z_up`` surely cannot fire at the stance (False: ask the robot).

    True for a robot whose feet are unknown (the check never fires). The feet-to-CoM axis is
    the stance's CoM less the mean of the foot frames
    (:attr:`~impact_balance.robot.robot.Robot.foot_frames`; stance frame, m): a foot that is a
    contact at the frame's own origin (no offset) is that contact's point, another one (in the
    air, offset) the frame's placement in the stance's kinematics
    (:meth:`~impact_balance.contacts.stance.Stance.local_frame_position`). At least 1 mm
    long, within 1e6 m of the origin and at least :data:`_SURELY_UPRIGHT` along +z, the robot
    stands (the check's own numbers, in world coordinates, differ from these by less than 1e-7
    in that cosine). Otherwise (a tilt near the check's) the robot's check answers.
    """
    feet = stance.robot.foot_frames
    if not feet:
        return True
    com, o, n = stance.com_local, stance.origin, len(feet)
    ox, oy, oz = float(o[0]), float(o[1]), float(o[2])
    if not max(abs(ox), abs(oy), abs(oz)) <= 1e6:
        return False
    points = {c.spec.frame: c.local_position for c in stance.contacts if c.spec.offset == _IDENTITY}
    x = y = z = 0.0
    for frame in feet:
        p = points.get(frame)
        if p is None:  # not a contact: where the stance's kinematics place the frame
            p = stance.local_frame_position(frame)
        x, y, z = x + float(p[0]), y + float(p[1]), z + float(p[2])
    dx, dy, dz = float(com[0]) - x / n, float(com[1]) - y / n, float(com[2]) - z / n
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    return length >= 1e-3 and dz >= _SURELY_UPRIGHT * length


def diagnose(
    scenario: Scenario, stance: Stance, impact: ImpactAnswer | None
) -> tuple[Diagnostic, ...]:
    """Every warning of one analysis, in scenario order."""
    problem = None if _surely_upright(stance) else stance.robot.up_axis_problem(stance.q)
    out = [Diagnostic("robot_not_z_up", "base", problem)] if problem else []
    out += contact_diagnostics(stance)
    if impact is not None and scenario.impact is not None:
        out += impact_diagnostics(impact, scenario.impact.reference_velocity)
    return tuple(out)


def diagnostics_to_json(diagnostics: Sequence[Diagnostic]) -> list[dict[str, Any]]:
    """The JSON form: a list of {code, field, message}."""
    return [d.to_dict() for d in diagnostics]
