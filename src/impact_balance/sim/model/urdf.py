"""The robot's URDF as a MuJoCo model specification (``mujoco.MjSpec``).

MuJoCo reads URDF itself; three things make its model the same robot as pinocchio's:

- ``package://PKG/...`` mesh paths are resolved to files (MuJoCo has no ROS package
  look-up): against the robot's package folders, as pinocchio does.
- The root link gets a free joint. Without one MuJoCo would fuse the root (and its mass)
  into the world, since static bodies are fused (``fusestatic``, the URDF default, which
  also merges every fixed-joint link into its parent, as pinocchio merges their inertias).
- Inertias come from the URDF ``<inertial>`` tags only (``inertiafromgeom`` off), so that
  geoms added later for collision or display carry no mass.

- The URDF is read and checked by :func:`impact_balance.robot.urdf_check.check_urdf`, the
  rule pinocchio's load follows: a file with a non-finite or absurd mass, inertia, origin or
  axis is refused with the file, link or joint and field named.
- Inertials MuJoCo refuses (massless moving links, singular inertia tensors) are repaired by
  the rule of :mod:`.inertia` (merged into the moving body they are fused with, else raised
  to a floor below 1e-7 of the robot's mass and inertia); :func:`robot_spec` returns what
  it changed.
- URDF ``<mimic>`` joints (Romeo's fingers) are independent joints in pinocchio's model, so
  the equality constraints MuJoCo makes of them are dropped.
- Meshes in formats MuJoCo does not decode (COLLADA ``.dae``, ASCII STL) are read by
  :func:`impact_balance.robot.meshes.read_mesh` and given to MuJoCo as vertex arrays.

MuJoCo keeps the URDF ``effort`` limits as joint actuator force ranges (``actfrcrange``;
Talos' wrists are limited to 3-6.6 N m) and imports ``damping`` and ``friction``
(friction loss). Collision meshes are imported and made visual only (``contype`` =
``conaffinity`` = 0, geom group 1): the contacts are the scenario's boxes (see
:mod:`.environment`).
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import mujoco

from impact_balance.exceptions import RobotLoadError
from impact_balance.robot.meshes import mujoco_reads, read_mesh
from impact_balance.robot.robot import Robot
from impact_balance.robot.urdf_check import check_urdf, read_robot_file
from impact_balance.sim.model.inertia import InertiaRepair, repair_inertias

__all__ = ["ROOT_JOINT", "VISUAL_GROUP", "resolve_package_uri", "robot_spec"]

#: Geom group of the robot's meshes (display only).
VISUAL_GROUP = 1
#: Name of the free joint added at the root link.
ROOT_JOINT = "root_free"

_PACKAGE = re.compile(r"package://([^/\"'<>\s]+)/([^\"'<>\s]*)")


def resolve_package_uri(package: str, relative: str, search: list[str]) -> Path | None:
    """File of ``package://package/relative``, looked up in ``search`` folders (and their parents).

    A folder may be the package itself (its name is ``package``), hold it
    (``folder/package``), or be the package's content root (``folder/relative``).
    """
    seen: set[Path] = set()
    for folder in search:
        for base in (Path(folder), *Path(folder).parents):
            if base in seen:
                continue
            seen.add(base)
            for candidate in (base / package / relative, base / relative):
                if candidate.is_file():
                    return candidate
            if base.name == package and (base / relative).is_file():
                return base / relative
    return None


def _resolved_urdf(robot: Robot) -> str:
    # The rule of the robot layer: the bytes checked are the bytes MuJoCo reads.
    text = check_urdf(read_robot_file(robot.urdf_path), str(robot.urdf_path)).text
    search = [*robot.package_dirs, str(robot.urdf_path.parent)]
    search += [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if p]

    def replace(match: re.Match[str]) -> str:
        found = resolve_package_uri(match.group(1), match.group(2), search)
        return str(found) if found is not None else match.group(0)

    text = _PACKAGE.sub(replace, text)
    # Relative mesh paths are relative to the URDF's folder, as for pinocchio.
    return text


def _mesh_arrays(spec: mujoco.MjSpec) -> None:
    """Give MuJoCo the vertices of the meshes it cannot decode itself (.dae, ASCII STL)."""
    for mesh in spec.meshes:
        path = Path(mesh.file) if Path(mesh.file).is_absolute() else Path(spec.meshdir) / mesh.file
        if not mesh.file or mujoco_reads(path):
            continue
        vertices, faces = read_mesh(path)
        mesh.file = ""
        mesh.uservert = vertices.reshape(-1).tolist()
        mesh.userface = faces.reshape(-1).tolist()


def robot_spec(robot: Robot, meshes: bool = True) -> tuple[mujoco.MjSpec, InertiaRepair | None]:
    """The robot as an ``MjSpec``: free joint at the root, meshes visual only, no actuators.

    Args:
        robot: A robot loaded by :func:`impact_balance.robot.robot.load_robot`.
        meshes: Keep the URDF's collision geoms, as visual geoms (for display and video).
            Without them the model compiles faster and has no geom but those added for the
            contacts.

    Returns:
        The specification, and the inertia repairs made (see :mod:`.inertia`), or None.
    """
    text = _resolved_urdf(robot)
    try:
        spec = mujoco.MjSpec.from_string(text)
    except ValueError as exc:
        raise RobotLoadError(
            str(robot.urdf_path), f"MuJoCo cannot read it: {str(exc).strip().splitlines()[0]}"
        ) from None
    spec.meshdir = str(robot.urdf_path.parent)
    spec.compiler.inertiafromgeom = mujoco.mjtInertiaFromGeom.mjINERTIAFROMGEOM_FALSE
    # The parser already kept the URDF <collision> geoms only (<visual> ones are often .dae,
    # which MuJoCo cannot read). Compiling must not discard them once they are made visual.
    spec.compiler.discardvisual = False
    root = spec.worldbody.first_body()
    if root is None:
        raise RobotLoadError(str(robot.urdf_path), "no link in the URDF")
    root.add_freejoint(name=ROOT_JOINT)
    for equality in list(spec.equalities):  # <mimic> couplings: pinocchio's joints are independent
        spec.delete(equality)
    for geom in list(spec.geoms):
        if not meshes:
            spec.delete(geom)
            continue
        geom.contype = 0
        geom.conaffinity = 0
        geom.group = VISUAL_GROUP
    if not meshes:
        for mesh in list(spec.meshes):
            spec.delete(mesh)
    else:
        _mesh_arrays(spec)
    return spec, repair_inertias(spec, robot)
