"""The 3D view in viser: lights, ground and camera, the robot meshes, and the scene objects.

The scene objects of :mod:`.scene` (world coordinates, m) are sent as few messages as
possible: unchanged objects are skipped, changed ones of the same kind are updated in place.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt

from impact_balance.gui.host import GuiHost
from impact_balance.gui.meshes import RobotMeshes
from impact_balance.gui.scene import (
    Arrows,
    Label,
    Points,
    SceneObject,
    Segments,
    Surface,
    scene_objects,
)

if TYPE_CHECKING:
    import viser

__all__ = ["SceneMixin", "add_object", "update_object"]

#: The arrays viser gets for one scene object (float32 points, uint32 faces), as sent.
Geometry = tuple[npt.NDArray[Any], ...]


def _rgb(color: str) -> tuple[int, int, int]:
    """``#rrggbb`` as (r, g, b), 0..255."""
    c = color.lstrip("#")
    return int(c[0:2], 16), int(c[2:4], 16), int(c[4:6], 16)


def _geometry(obj: SceneObject) -> Geometry | None:
    """The arrays viser gets for a scene object (as sent), None if there is nothing to draw."""
    if isinstance(obj, Segments):
        return (np.asarray(obj.segments, dtype=np.float32),) if len(obj.segments) else None
    if isinstance(obj, Points):
        return (np.asarray(obj.points[0], dtype=np.float32),)
    if isinstance(obj, Arrows):
        return (np.stack([obj.starts, obj.ends], axis=1).astype(np.float32),)
    if isinstance(obj, Surface):
        return np.asarray(obj.vertices, dtype=np.float32), np.asarray(obj.faces, dtype=np.uint32)
    if isinstance(obj, Label):
        return (np.asarray(obj.position, dtype=np.float32),)
    return None


def add_object(
    scene: viser.SceneApi, name: str, obj: SceneObject, data: Geometry
) -> viser.SceneNodeHandle:
    """Add one scene object to the viser ``scene``.

    Args:
        scene: ``server.scene``.
        name: Its name in the scene tree.
        obj: The object (its kind, colour and sizes).
        data: Its arrays as sent (points, or vertices and faces), world, m.

    Returns:
        The handle of the new scene node.
    """
    color = _rgb(obj.color)
    if isinstance(obj, Segments):
        return scene.add_line_segments(name, data[0], color, thickness=obj.width)
    if isinstance(obj, Points):
        return scene.add_icosphere(
            name,
            radius=obj.radius,
            color=color,
            subdivisions=2,
            position=tuple(data[0]),
            cast_shadow=False,
        )
    if isinstance(obj, Arrows):
        return scene.add_arrows(
            name,
            data[0],
            color,
            shaft_radius=obj.radius,
            head_radius=2.5 * obj.radius,
            head_length=6 * obj.radius,
        )
    if isinstance(obj, Label):
        return scene.add_label(name, obj.text, position=tuple(data[0]), anchor="bottom-left")
    return scene.add_mesh_simple(
        name,
        data[0],
        data[1],
        color=color,
        opacity=obj.opacity,
        side="double",
        cast_shadow=False,
        receive_shadow=False,
    )


def update_object(handle: Any, obj: SceneObject, data: Geometry) -> None:
    """Move an object of the same kind in place (one message, no remove and add).

    Args:
        handle: The scene node that :func:`add_object` returned for an object of that kind.
        obj: The object.
        data: Its new arrays as sent, world, m.
    """
    if isinstance(obj, (Segments, Arrows)):
        handle.points = data[0]
    elif isinstance(obj, (Points, Label)):
        handle.position = data[0]
    else:
        handle.vertices, handle.faces = data


class SceneMixin(GuiHost):
    """The 3D view of :class:`~.app.GuiApp`: the robot and the scene objects."""

    #: The drawn scene objects by scene-tree name: their nodes, and the objects with the
    #: arrays last sent (to skip what did not change).
    _scene_handles: dict[str, viser.SceneNodeHandle]
    _scene_data: dict[str, tuple[SceneObject, Geometry]]
    #: The robot's meshes (None before the first draw).
    _meshes: RobotMeshes | None

    def _setup_scene(self) -> None:
        """Up axis, lights, the ground grid and the initial camera."""
        scene = self.server.scene
        scene.set_up_direction("+z")
        # No shadows: they cost a render pass per light, which software WebGL (no GPU, as on
        # this project's machines) pays on every redraw.
        scene.configure_default_lights(True, cast_shadow=False)
        scene.add_grid(
            "/ground",
            width=4.0,
            height=4.0,
            cell_size=0.1,
            section_size=0.5,
            plane="xy",
            shadow_opacity=0.0,
        )
        self.server.initial_camera.position = (1.0, -1.9, 1.25)
        self.server.initial_camera.look_at = (0.1, 0.0, 0.6)

    def _draw_objects(self) -> None:
        """Draw :func:`scene_objects`: skip unchanged objects, update changed ones in place."""
        scene = self.server.scene
        seen: set[str] = set()
        reach = self.session.reach
        for obj in scene_objects(self.session.analysis, None if reach is None else reach.reach):
            name = f"/analysis/{obj.name}"
            data = _geometry(obj)
            if data is None:
                continue
            seen.add(name)
            previous = self._scene_data.get(name)
            if previous is not None and type(previous[0]) is type(obj):
                if all(
                    a.shape == b.shape and np.array_equal(a, b)
                    for a, b in zip(previous[1], data, strict=True)
                ):
                    continue  # most objects do not move when one joint does: send nothing
                update_object(self._scene_handles[name], obj, data)
            else:
                if name in self._scene_handles:
                    self._scene_handles.pop(name).remove()
                self._scene_handles[name] = add_object(scene, name, obj, data)
            self._scene_data[name] = (obj, data)
        for name in list(self._scene_handles):
            if name not in seen:
                self._scene_handles.pop(name).remove()
                self._scene_data.pop(name, None)

    def _draw_robot(self, opacity: float) -> None:
        """Move the robot's meshes to the stance; read them (at ``opacity``) for a new robot."""
        stance = self.session.analysis.stance
        if self._meshes is None or self._meshes.robot is not stance.robot:
            if self._meshes is not None:
                self._meshes.remove()
            self._meshes = RobotMeshes(self.server.scene, stance.robot, opacity=opacity)
        self._meshes.update(stance.data)
