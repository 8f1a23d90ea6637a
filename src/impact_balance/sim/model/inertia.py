"""Repair of the URDF inertias MuJoCo refuses, so that any robot pinocchio loads simulates.

pinocchio accepts any inertial; MuJoCo's compiler refuses three kinds, found in
example-robot-data's robots:

- a non-physical body inertia (an eigenvalue <= 0, or the triangle inequality
  ``A + B >= C`` of the principal moments broken): iCub's ``l_ankle_2`` (all zero with
  0.27 kg, a point mass), Go1's ``base`` (a 1e-6 placeholder whose products of inertia
  equal its moments);
- a moving body (one with a joint, after the jointless links are fused into it) whose mass
  or principal moments are below ``mjMINVAL`` (1e-15): Romeo's 24 finger links (mass 0).

The rule, applied to each moving body and the jointless links MuJoCo fuses into it (its
*group*), and only to groups that MuJoCo would refuse:

1. **Merge.** The group's inertials are summed into the moving body (mass, centre of mass,
   inertia about it: exactly what MuJoCo's fusion computes) and the fused links carry none.
   This changes nothing physical; it is enough for iCub's ankles and Go1's base.
2. **Floor.** If the merged inertial is still refused (a massless finger, a point mass),
   its mass is raised to at least ``m_floor`` and its principal moments to at least
   ``i_floor`` (then the two smallest just enough for ``A + B >= C``). The floors are set
   from the whole robot at its standing configuration so that all the raises together stay
   below 1e-7 of the total mass and of the smallest principal moment of the composite
   inertia about the CoM:

   ``i_floor = 1e-7 I_min / n``, ``m_floor = 1e-7 min(M, I_min / R^2) / n``

   with ``M`` the total mass, ``I_min`` that smallest moment, ``R`` twice the largest
   distance of a joint from the CoM and ``n`` the number of floored bodies. The tests
   check the total mass and the composite inertia against pinocchio's to 1e-6 relative.

Only zero and tiny inertials are repaired: a URDF with a non-finite or absurd mass or inertia
(negative principal moments, the triangle inequality badly broken, magnitudes beyond the bounds
of :mod:`impact_balance.robot.urdf_check`) is refused before, by the check pinocchio's load
applies too.

The repairs are reported once (:func:`repair_message`), naming the bodies.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt
import pinocchio as pin
from numpy.typing import ArrayLike

from impact_balance.exceptions import RobotLoadError
from impact_balance.robot.robot import Robot

__all__ = ["FLOOR_FRACTION", "InertiaRepair", "repair_inertias", "repair_message"]

_FloatArray = npt.NDArray[np.float64]

#: Share of the total mass and of the smallest composite moment that all floors together may add.
FLOOR_FRACTION = 1e-7
_MINVAL = mujoco.mjMINVAL
#: Slack of the triangle inequality, relative to the largest moment (MuJoCo allows mjEPS).
_TRIANGLE_SLACK = 1e-12


@dataclass(frozen=True)
class InertiaRepair:
    """What :func:`repair_inertias` changed.

    Attributes:
        merged: Moving bodies that received their fused links' inertials (name, links merged).
        floored: Moving bodies raised to the floors.
        mass_floor: kg; inertia_floor: kg m^2 (0 when nothing was floored).
        added_mass: Total mass added, kg.
    """

    merged: tuple[tuple[str, tuple[str, ...]], ...]
    floored: tuple[str, ...]
    mass_floor: float
    inertia_floor: float
    added_mass: float

    @property
    def bodies(self) -> tuple[str, ...]:
        """Every moving body whose inertial changed, merged first."""
        return tuple(dict.fromkeys([name for name, _ in self.merged] + list(self.floored)))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready: bodies merged and floored, the floors and the mass added."""
        return {
            "merged": {name: list(links) for name, links in self.merged},
            "floored": list(self.floored),
            "mass_floor": self.mass_floor,
            "inertia_floor": self.inertia_floor,
            "added_mass": self.added_mass,
        }


def _quat_matrix(quat: ArrayLike) -> _FloatArray:
    out = np.empty(9)
    mujoco.mju_quat2Mat(out, np.asarray(quat, dtype=float))
    return out.reshape(3, 3)


def _matrix_quat(matrix: np.ndarray) -> np.ndarray:
    out = np.empty(4)
    mujoco.mju_mat2Quat(out, np.ascontiguousarray(matrix, dtype=float).reshape(9))
    return out


def _inertial(body: mujoco.MjsBody) -> tuple[float, _FloatArray, _FloatArray]:
    """Mass (kg), CoM (m) and inertia about it (kg m^2), both in the body's frame."""
    mass = float(body.mass)
    com = np.array(body.ipos, dtype=float)
    if np.isnan(com[0]):
        com = np.zeros(3)
    rotation = _quat_matrix(body.iquat)
    full = np.asarray(body.fullinertia, dtype=float)
    if not np.isnan(full[0]):
        xx, yy, zz, xy, xz, yz = full
        local = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
    else:
        local = np.diag(np.asarray(body.inertia, dtype=float))
    return mass, com, rotation @ local @ rotation.T


def _refused(mass: float, inertia: np.ndarray, moving: bool) -> bool:
    """Would MuJoCo refuse this inertial (of a moving group if ``moving``, else of one link)?"""
    moments = np.linalg.eigvalsh(0.5 * (inertia + inertia.T))
    if mass < 0.0 or moments[0] < -_MINVAL:
        return True
    if moving and (mass <= _MINVAL or moments[0] <= _MINVAL):
        return True
    if not moving and mass == 0.0 and not inertia.any():
        return False  # a link without inertial
    if moments[0] <= _MINVAL and np.any(inertia):
        return True  # a singular inertia tensor given explicitly
    return bool(moments[0] + moments[1] < moments[2] * (1.0 - _TRIANGLE_SLACK))


def _pose(body: mujoco.MjsBody) -> tuple[_FloatArray, _FloatArray]:
    return _quat_matrix(body.quat), np.array(body.pos, dtype=float)


def _group(body: mujoco.MjsBody) -> list[tuple[mujoco.MjsBody, _FloatArray, _FloatArray]]:
    """The jointless links fused into ``body``, with their pose in its frame."""
    out = []
    stack = [(child, *_pose(child)) for child in body.bodies]
    while stack:
        link, rotation, position = stack.pop()
        if len(link.joints):
            continue
        out.append((link, rotation, position))
        for child in link.bodies:
            r, p = _pose(child)
            stack.append((child, rotation @ r, position + rotation @ p))
    return out


def _combined(
    parts: list[tuple[float, np.ndarray, np.ndarray]],
) -> tuple[float, np.ndarray, np.ndarray]:
    """Sum of inertials (mass, CoM, inertia about the CoM) given in one frame."""
    mass = float(sum(m for m, _, _ in parts))
    if mass <= 0.0:
        zero: _FloatArray = np.zeros((3, 3))
        return 0.0, np.zeros(3), sum((i for _, _, i in parts), zero)
    weighted: _FloatArray = np.zeros(3)
    for m, c, _ in parts:
        weighted = weighted + m * c
    com = weighted / mass
    inertia = np.zeros((3, 3))
    for m, c, i in parts:
        r = c - com
        inertia += i + m * (r @ r * np.eye(3) - np.outer(r, r))
    return mass, com, inertia


def _set_inertial(
    body: mujoco.MjsBody, mass: float, com: _FloatArray, inertia: _FloatArray
) -> None:
    moments, axes = np.linalg.eigh(0.5 * (inertia + inertia.T))
    if np.linalg.det(axes) < 0:
        axes[:, 0] = -axes[:, 0]
    body.mass = float(mass)
    body.ipos = com
    body.iquat = _matrix_quat(axes)
    body.inertia = np.maximum(moments, 0.0)
    body.fullinertia = [np.nan, 0.0, 0.0, 0.0, 0.0, 0.0]
    body.explicitinertial = True


def _clear_inertial(body: mujoco.MjsBody) -> None:
    body.mass = 0.0
    body.ipos = [0.0, 0.0, 0.0]
    body.iquat = [1.0, 0.0, 0.0, 0.0]
    body.inertia = [0.0, 0.0, 0.0]
    body.fullinertia = [np.nan, 0.0, 0.0, 0.0, 0.0, 0.0]


def _floored(
    mass: float, inertia: np.ndarray, m_floor: float, i_floor: float
) -> tuple[float, np.ndarray]:
    moments, axes = np.linalg.eigh(0.5 * (inertia + inertia.T))
    moments = np.maximum(moments, i_floor)
    gap = moments[2] - moments[0] - moments[1]
    if gap > 0.0:  # raise the two smallest equally: A + B = C
        moments[0] += 0.5 * gap
        moments[1] += 0.5 * gap
    return max(mass, m_floor), axes @ np.diag(moments) @ axes.T


def _floors(robot: Robot, count: int) -> tuple[float, float]:
    """(m_floor kg, i_floor kg m^2) for ``count`` floored bodies (see the module docstring)."""
    model = robot.model
    data = model.createData()
    q = robot.configuration()
    pin.ccrba(model, data, q, np.zeros(model.nv))
    com = data.com[0]
    i_min = float(np.linalg.eigvalsh(data.Ig.inertia)[0])
    reach = 2.0 * max(
        (float(np.linalg.norm(data.oMi[j].translation - com)) for j in range(1, model.njoints)),
        default=1.0,
    )
    reach = max(reach, 1e-3)
    share = FLOOR_FRACTION / max(count, 1)
    return share * min(robot.mass, i_min / reach**2), share * i_min


def _check_finite(spec: mujoco.MjSpec, robot: Robot) -> None:
    """Refuse a body whose mass or inertia is not finite (never repaired: not a tiny inertia).

    :func:`impact_balance.robot.urdf_check.check_urdf` refuses such a URDF first; this guards a
    specification built another way.
    """
    for body in spec.bodies:
        if body.name == "world":
            continue
        with np.errstate(all="ignore"):
            mass, com, inertia = _inertial(body)
        if not (np.isfinite(mass) and np.all(np.isfinite(com)) and np.all(np.isfinite(inertia))):
            raise RobotLoadError(
                str(robot.urdf_path), f"link {body.name!r}: a mass or inertia is not finite"
            )


def repair_inertias(spec: mujoco.MjSpec, robot: Robot) -> InertiaRepair | None:
    """Apply the module's rule to ``spec`` (in place; the root must already have its free joint).

    Returns what changed, or None when MuJoCo accepts every inertial as it is.
    """
    _check_finite(spec, robot)
    moving = [b for b in spec.bodies if b.name != "world" and len(b.joints)]
    todo = []
    for body in moving:
        links = _group(body)
        parts = [_inertial(body)]
        for link, rotation, position in links:
            m, c, i = _inertial(link)
            parts.append((m, rotation @ c + position, rotation @ i @ rotation.T))
        own_refused = any(_refused(m, i, False) for m, _, i in parts)
        mass, com, inertia = _combined(parts)
        if own_refused or _refused(mass, inertia, True):
            todo.append((body, links, mass, com, inertia))
    if not todo:
        return None
    needs_floor = [t for t in todo if _refused(t[2], t[4], True)]
    m_floor, i_floor = _floors(robot, len(needs_floor)) if needs_floor else (0.0, 0.0)
    merged, floored, added = [], [], 0.0
    for body, links, mass, com, inertia in todo:
        if _refused(mass, inertia, True):
            new_mass, inertia = _floored(mass, inertia, m_floor, i_floor)
            added += new_mass - mass
            mass = new_mass
            floored.append(body.name)
        _set_inertial(body, mass, com, inertia)
        named = tuple(link.name for link, _, _ in links if link.mass or np.any(_inertial(link)[2]))
        for link, _, _ in links:
            _clear_inertial(link)
        if named:
            merged.append((body.name, named))
    return InertiaRepair(tuple(merged), tuple(floored), m_floor, i_floor, added)


def repair_message(robot_name: str, repair: InertiaRepair) -> str:
    """One line naming what was repaired, for the user."""
    parts = []
    if repair.merged:
        parts.append(
            "merged with the fixed links fused into them: "
            + ", ".join(f"{name} (+{len(links)})" for name, links in repair.merged)
        )
    if repair.floored:
        parts.append(
            f"raised to at least {repair.mass_floor:.2g} kg and {repair.inertia_floor:.2g} kg m^2 "
            f"(total mass +{repair.added_mass:.2g} kg): " + ", ".join(repair.floored)
        )
    return (
        f"robot {robot_name}: MuJoCo refuses some inertias, repaired (docs/simulation.md, "
        '"Robots MuJoCo refuses"): ' + "; ".join(parts)
    )
