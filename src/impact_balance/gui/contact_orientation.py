"""A contact's orientation in the GUI: ``offset.rpy`` in its frame, or world ``normal``, ``angle``.

A scenario gives a contact's orientation one of two ways (see
:class:`impact_balance.scenario.schema.ContactConfig`): roll, pitch, yaw of the contact in its
robot frame (``offset.rpy``, rad), or the surface normal in the world (``normal``, from the
surface into the robot, any scale) with a turn ``angle`` (rad) about it. The Contacts tab shows
the form the scenario uses and switches between them without moving the contact:
:func:`switch_changes` computes the other form of the same world rotation.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.gui.state import FieldPath

__all__ = [
    "ORIENTATION_MODES",
    "RPY_MODE",
    "WORLD_NORMAL_MODE",
    "mode_of",
    "normal_angle",
    "switch_changes",
]

#: The Contacts tab's label of the ``offset.rpy`` form (in the contact's robot frame).
RPY_MODE = "offset rpy (in the frame)"
#: The Contacts tab's label of the ``normal``/``angle`` form (in the world).
WORLD_NORMAL_MODE = "world normal and angle"
#: The two forms, in the order the Contacts tab offers them.
ORIENTATION_MODES = (RPY_MODE, WORLD_NORMAL_MODE)


def mode_of(contact: Mapping[str, Any]) -> str:
    """The form a contact's mapping (scenario-file schema) gives its orientation in."""
    return WORLD_NORMAL_MODE if contact.get("normal") is not None else RPY_MODE


def normal_angle(
    frame_rotation: npt.ArrayLike, contact_rotation: npt.ArrayLike
) -> tuple[list[float], float]:
    """The world normal and the angle about it of a contact's world rotation.

    Inverse of :func:`impact_balance.geometry.spatial.surface_rotation`: the angle (rad, in
    (-pi, pi]) turns the frame's x axis projected on the surface onto the contact's x axis,
    counter-clockwise seen from above the surface.

    Args:
        frame_rotation: (3, 3) world rotation of the contact's robot frame.
        contact_rotation: (3, 3) world rotation of the contact (columns: its x, y, z axes).

    Returns:
        The unit normal (world) and the angle, rad.
    """
    R = np.asarray(frame_rotation, dtype=float)
    C = np.asarray(contact_rotation, dtype=float)
    n, x = C[:, 2], C[:, 0]
    x0 = R[:, 0] - (R[:, 0] @ n) * n
    if np.linalg.norm(x0) < 1e-6:
        y0 = R[:, 1] - (R[:, 1] @ n) * n
        x0 = np.cross(y0, n)
    x0 /= np.linalg.norm(x0)
    angle = math.atan2(float(np.cross(x0, x) @ n), float(x0 @ x))
    return [float(v) for v in n], angle


def switch_changes(
    index: int,
    mode: str,
    frame_rotation: npt.ArrayLike,
    contact_rotation: npt.ArrayLike,
    position: npt.ArrayLike,
) -> dict[FieldPath, Any]:
    """Scenario changes that give contact ``index`` its orientation in form ``mode``.

    The contact keeps its world rotation: ``contact_rotation`` written as ``offset.rpy`` in its
    frame, or as its world ``normal`` and ``angle``.

    Args:
        index: The contact's index in the scenario's ``contacts``.
        mode: :data:`RPY_MODE` or :data:`WORLD_NORMAL_MODE`.
        frame_rotation: (3, 3) world rotation of the contact's robot frame at the configuration.
        contact_rotation: (3, 3) world rotation of the contact.
        position: (3,) the contact's ``offset.position`` in its frame, m (kept).

    Returns:
        ``{path: value}`` for :meth:`~impact_balance.gui.state.GuiState.with_changes`.

    Raises:
        ValueError: ``mode`` is not one of :data:`ORIENTATION_MODES`.
    """
    if mode not in ORIENTATION_MODES:
        raise ValueError(f"contact orientation: {mode!r} is not one of {ORIENTATION_MODES}")
    base: FieldPath = ("contacts", index)
    pos = [float(v) for v in np.asarray(position, dtype=float)]
    if mode == RPY_MODE:
        local = np.asarray(frame_rotation, dtype=float).T @ np.asarray(contact_rotation, float)
        rpy = [float(v) for v in pin.rpy.matrixToRpy(local)]
        return {
            (*base, "normal"): None,
            (*base, "angle"): None,
            (*base, "offset"): {"position": pos, "rpy": rpy},
        }
    normal, angle = normal_angle(frame_rotation, contact_rotation)
    return {
        (*base, "offset"): {"position": pos},
        (*base, "normal"): normal,
        (*base, "angle"): angle,
    }
