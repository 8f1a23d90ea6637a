"""The robot's visual meshes (URDF ``<visual>`` geometry) in the viser scene.

The meshes are read once per robot with pinocchio's visual ``GeometryModel`` and
:func:`impact_balance.robot.meshes.read_mesh` (trimesh; COLLADA ``.dae`` through pycollada, as
Romeo's and iCub's meshes are); an update only moves them (one pose per mesh), which is what
keeps redraws cheap. Meshes that cannot be read are skipped with one warning naming them.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import numpy.typing as npt
import pinocchio as pin

from impact_balance.exceptions import RobotLoadError
from impact_balance.robot.meshes import read_mesh
from impact_balance.robot.robot import Robot

if TYPE_CHECKING:
    import viser

__all__ = ["RobotMeshes", "VisualMesh", "load_visual_meshes"]

log = logging.getLogger(__name__)

#: Colour of meshes whose URDF gives none (or pure black), RGB 0..1.
DEFAULT_COLOR = (0.75, 0.75, 0.78)


@dataclass(frozen=True)
class VisualMesh:
    """One visual geometry: triangles in its own frame (m), colour, and where it is attached."""

    name: str
    vertices: npt.NDArray[np.float32]
    faces: npt.NDArray[np.uint32]
    color: tuple[float, float, float]
    opacity: float
    index: int  # in the GeometryModel


def _package_dirs(robot: Robot) -> list[str]:
    # URDFs refer to meshes as package://<package>/...: every ancestor of the URDF is a
    # candidate root (example-robot-data's meshes live under the cmeel prefix's share/).
    dirs = list(robot.package_dirs) + [str(p) for p in robot.urdf_path.resolve().parents]
    return list(dict.fromkeys(dirs))


def _triangles(
    obj: Any, problems: list[str]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int64]] | None:
    """Vertices and faces of a geometry object (m, its own frame), or None if unreadable.

    A mesh file that cannot be read is said in ``problems``; a primitive (box, sphere, cylinder,
    capsule) is triangulated.
    """
    import trimesh

    geom = obj.geometry
    kind = type(geom).__name__
    scale = np.asarray(obj.meshScale, dtype=float)
    if obj.meshPath and Path(obj.meshPath).is_file():
        try:
            vertices, faces = read_mesh(obj.meshPath)
            return vertices * scale, faces
        except RobotLoadError as exc:  # a bad mesh must not stop the GUI
            problems.append(f"{Path(obj.meshPath).name} ({exc})")
    if kind == "Box":
        mesh = trimesh.creation.box(extents=2.0 * np.asarray(geom.halfSide))
    elif kind == "Sphere":
        mesh = trimesh.creation.icosphere(radius=geom.radius, subdivisions=2)
    elif kind == "Cylinder":
        mesh = trimesh.creation.cylinder(radius=geom.radius, height=2.0 * geom.halfLength)
    elif kind == "Capsule":
        mesh = trimesh.creation.capsule(radius=geom.radius, height=2.0 * geom.halfLength)
    else:
        return None
    return np.asarray(mesh.vertices), np.asarray(mesh.faces)


def load_visual_meshes(robot: Robot) -> tuple[pin.GeometryModel, list[VisualMesh]]:
    """The robot's visual geometry model and its meshes; unreadable meshes are skipped.

    Raises:
        RobotLoadError: pinocchio cannot read the URDF's visual geometry.
    """
    try:
        gmodel = pin.buildGeomFromUrdf(
            robot.model,
            str(robot.urdf_path),
            pin.GeometryType.VISUAL,
            package_dirs=_package_dirs(robot),
        )
    except (RuntimeError, ValueError, OSError) as exc:
        raise RobotLoadError(str(robot.urdf_path), f"cannot read the visual meshes: {exc}") from exc
    meshes: list[VisualMesh] = []
    problems: list[str] = []
    for i, obj in enumerate(gmodel.geometryObjects):
        tri = _triangles(obj, problems)
        if tri is None:
            problems.append(f"{obj.name} ({type(obj.geometry).__name__})")
            continue
        rgba = np.asarray(obj.meshColor, dtype=float)
        color = (float(rgba[0]), float(rgba[1]), float(rgba[2]))
        if not np.any(rgba[:3] > 0.05):
            color = DEFAULT_COLOR
        opacity = float(rgba[3]) if 0.0 < rgba[3] <= 1.0 else 1.0
        meshes.append(
            VisualMesh(
                obj.name, tri[0].astype(np.float32), tri[1].astype(np.uint32), color, opacity, i
            )
        )
    if problems:
        log.warning(
            "robot %s: %d visual geometries not drawn: %s",
            robot.name,
            len(problems),
            "; ".join(problems[:5]) + ("; ..." if len(problems) > 5 else ""),
        )
    return gmodel, meshes


class RobotMeshes:
    """The robot's meshes in a viser scene, moved by :meth:`update`.

    Args:
        scene: ``server.scene`` of a :class:`viser.ViserServer`.
        robot: The robot.
        root: Scene-tree name under which the meshes are added.
        opacity: Opacity of the whole robot, 0..1 (below 1 the CoM shows through).
    """

    def __init__(
        self, scene: viser.SceneApi, robot: Robot, root: str = "/robot", opacity: float = 1.0
    ):
        self.robot = robot
        self.geometry_model, self.meshes = load_visual_meshes(robot)
        self.geometry_data = self.geometry_model.createData()
        self.handles: list[viser.MeshHandle] = []
        self._last: list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]] = []
        for mesh in self.meshes:
            r, g, b = (round(255 * c) for c in mesh.color)
            self.handles.append(
                scene.add_mesh_simple(
                    f"{root}/{mesh.name}",
                    mesh.vertices,
                    mesh.faces,
                    color=(r, g, b),
                    opacity=self._opacity(mesh, opacity),
                    cast_shadow=False,
                    receive_shadow=False,
                )
            )

    @staticmethod
    def _opacity(mesh: VisualMesh, opacity: float) -> float | None:
        value = mesh.opacity * float(np.clip(opacity, 0.0, 1.0))
        return None if value >= 1.0 else value

    def set_opacity(self, opacity: float) -> None:
        """Opacity of the whole robot, 0..1."""
        for mesh, handle in zip(self.meshes, self.handles, strict=True):
            handle.opacity = self._opacity(mesh, opacity)

    def poses(
        self, data: pin.Data
    ) -> list[tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]:
        """World (position, wxyz) of every mesh, from joint placements already in ``data``."""
        pin.updateGeometryPlacements(
            self.robot.model, data, self.geometry_model, self.geometry_data
        )
        out = []
        for mesh in self.meshes:
            M = self.geometry_data.oMg[mesh.index]
            xyzw = pin.Quaternion(M.rotation).coeffs()
            out.append((np.array(M.translation), np.array([xyzw[3], xyzw[0], xyzw[1], xyzw[2]])))
        return out

    def update(self, data: pin.Data) -> None:
        """Move the meshes to the configuration whose kinematics are in ``data``.

        Only meshes whose pose changed are sent: moving one joint moves a few links.
        """
        poses = self.poses(data)
        for k, (handle, (position, wxyz)) in enumerate(zip(self.handles, poses, strict=True)):
            last = self._last[k] if k < len(self._last) else None
            if (
                last is not None
                and np.array_equal(last[0], position)
                and np.array_equal(last[1], wxyz)
            ):
                continue
            handle.position = position
            handle.wxyz = wxyz
        self._last = poses

    def remove(self) -> None:
        """Remove the meshes from the scene."""
        for handle in self.handles:
            handle.remove()
        self.handles = []
