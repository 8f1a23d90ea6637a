"""Mesh files as triangle arrays, for the GUI and the simulation's display geometry.

URDFs name meshes in several formats: binary and ASCII STL, Wavefront OBJ, COLLADA ``.dae``
(Romeo, iCub, Go1). MuJoCo decodes binary STL, OBJ and its own MSH only, so the other
formats are read here with trimesh (COLLADA through pycollada, a declared dependency) and
handed over as vertex and face arrays. Each file is read once per process (cached by path,
modification time and size).

Units: vertices in the file's units after the COLLADA ``<unit meter=...>`` scale that
trimesh applies (metres for every bundled robot); the URDF ``scale`` attribute is applied by
the caller, as for any mesh.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np

from impact_balance.exceptions import RobotLoadError

__all__ = ["MUJOCO_FORMATS", "mujoco_reads", "read_mesh"]

#: File suffixes MuJoCo decodes itself (STL only when binary, see :func:`mujoco_reads`).
MUJOCO_FORMATS = (".stl", ".obj", ".msh")


def _binary_stl(path: Path) -> bool:
    """True if ``path`` is a binary STL (84-byte header + 50 bytes per triangle)."""
    try:
        size = path.stat().st_size
        with path.open("rb") as f:
            head = f.read(84)
    except OSError:
        return False
    if len(head) < 84:
        return False
    count = int.from_bytes(head[80:84], "little")
    return count > 0 and size == 84 + 50 * count


def mujoco_reads(path: str | Path) -> bool:
    """Whether MuJoCo's own decoders read this mesh file (binary STL, OBJ, MSH)."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".stl":
        return _binary_stl(path)
    return suffix in MUJOCO_FORMATS


@functools.lru_cache(maxsize=512)
def _read(path: str, _stamp: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    try:
        import trimesh
    except ImportError:  # pragma: no cover - declared dependency
        raise RobotLoadError(path, "cannot read the mesh: trimesh is not installed") from None
    try:
        mesh = trimesh.load(path, force="mesh")
    except ImportError as exc:  # trimesh's optional readers (pycollada for .dae)
        raise RobotLoadError(path, f"cannot read the mesh: {exc}".splitlines()[0]) from None
    except Exception as exc:
        raise RobotLoadError(path, f"cannot read the mesh ({type(exc).__name__})") from None
    vertices = np.asarray(getattr(mesh, "vertices", ()), dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(getattr(mesh, "faces", ()), dtype=np.int64).reshape(-1, 3)
    if not len(faces):
        raise RobotLoadError(path, "the mesh has no triangles")
    for array in (vertices, faces):
        array.setflags(write=False)
    return vertices, faces


def read_mesh(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) and triangles (k, 3) of a mesh file, read-only arrays.

    Raises:
        RobotLoadError: the file is missing, unreadable, or has no triangles.
    """
    path = Path(path)
    try:
        st = path.stat()
    except OSError:
        raise RobotLoadError(str(path), "no such mesh file") from None
    return _read(str(path.resolve()), (st.st_mtime_ns, st.st_size))
