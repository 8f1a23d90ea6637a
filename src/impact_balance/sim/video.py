"""An MP4 of a trial, rendered offscreen by MuJoCo and encoded by imageio's ffmpeg plugin.

Offscreen rendering needs a GL backend: on a headless Linux machine EGL (``MUJOCO_GL=egl``,
set by the command line before MuJoCo is imported) works; OSMesa does not render MuJoCo's
scenes. Without a backend, :func:`write_video` raises :class:`SimulationError` (one line).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import mujoco
import numpy as np

from ..exceptions import SimulationError
from .model import SimModel
from .trial import TrialRecord

__all__ = ["write_video"]


def write_video(sim: SimModel, record: TrialRecord, path: str | Path, fps: int = 60, slowdown: float = 10.0,
                size: tuple[int, int] = (640, 480)) -> Path:
    """Render ``record`` to ``path`` (MP4), ``slowdown`` times slower than real time.

    The camera looks at the CoM from the side of the impact, at the robot's scale.
    """
    path = Path(path)
    if path.suffix.lower() != ".mp4":
        raise SimulationError("--video", str(path)[:80], "the video is an .mp4 file")
    width, height = size
    model, data = sim.model, mujoco.MjData(sim.model)
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    try:
        with warnings.catch_warnings():  # GLFW warns before failing: the error line says it all
            warnings.simplefilter("ignore")
            renderer = mujoco.Renderer(model, height, width)
    except Exception as exc:  # no GL context: the error type depends on the backend
        raise SimulationError("--video", str(path)[:80], f"no offscreen OpenGL here ({type(exc).__name__}); "
                              "set MUJOCO_GL=egl on a machine with EGL") from None
    try:
        import imageio.v2 as imageio
    except ImportError:  # pragma: no cover - declared dependency
        raise SimulationError("--video", str(path)[:80], "imageio is not installed") from None
    camera = mujoco.MjvCamera()
    camera.lookat[:] = sim.stance.com
    camera.distance = 3.0
    camera.elevation = -15.0
    normal = np.asarray(sim.scenario.impact.normal, dtype=float)
    # Side view: look along the horizontal direction orthogonal to the impact normal.
    side = np.cross([0.0, 0.0, 1.0], normal)
    side = side if np.linalg.norm(side) > 1e-6 else np.array([0.0, 1.0, 0.0])
    camera.azimuth = float(np.degrees(np.arctan2(side[1], side[0]))) + 180.0
    options = mujoco.MjvOption()
    dt_frame = 1.0 / (fps * slowdown)
    times = np.arange(record.time[0], record.time[-1], dt_frame)
    rows = np.searchsorted(record.time, times)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with imageio.get_writer(path, fps=fps, codec="libx264", macro_block_size=8) as writer:
            for k in rows:
                data.qpos[:] = record.qpos[k]
                mujoco.mj_forward(model, data)
                renderer.update_scene(data, camera=camera, scene_option=options)
                writer.append_data(renderer.render())
    finally:
        renderer.close()
    return path
