"""An MP4 of a trial, rendered offscreen by MuJoCo and encoded by imageio's ffmpeg plugin.

Each frame (1280 x 720 by default) shows the robot lit from the camera on a light background,
and, drawn over the picture (so that the robot never hides them), a yellow disc at the CoM
with a line down to its ground projection and a red disc at the impact point, ringed while
the impact force acts, each labelled. A caption gives the simulated time from the impact,
the slow-motion factor and what the markers are.

Offscreen rendering needs a GL backend: on a headless Linux machine EGL (``MUJOCO_GL=egl``,
set by the command line before MuJoCo is imported) works; OSMesa does not render MuJoCo's
scenes. Without a backend, :func:`write_video` raises :class:`SimulationError` (one line).
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from impact_balance.exceptions import SimulationError
from impact_balance.sim.model.build import SimModel
from impact_balance.sim.trials.impact_trial import TrialRecord

__all__ = ["VIDEO_SIZE", "frame_caption", "project", "write_video"]

#: A pixel (column, row).
_Pixel = tuple[float, float]
#: The markers of a frame: CoM, its ground projection and impact point pixels, and contact.
_Marks = tuple[_Pixel | None, _Pixel | None, _Pixel | None, bool]

#: Default frame size, pixels (width, height).
VIDEO_SIZE = (1280, 720)
#: Background colour where nothing is drawn (RGB, 0-255): light, so that the robot stands out.
BACKGROUND = np.array([228, 234, 240], dtype=np.uint8)


#: What the markers are, written at the bottom of every frame.
LEGEND = (
    "yellow: CoM, with its line down to the ground;  red: impact point, ringed while in contact"
)


def frame_caption(t: float, impact_start: float, slowdown: float, in_contact: bool) -> list[str]:
    """Lines written on a frame: time from the impact, slow motion, the markers' meaning."""
    lines = [
        f"t = {1e3 * (t - impact_start):+7.1f} ms from the impact (simulated)",
        f"slow motion: {slowdown:g}x slower than real time",
    ]
    if in_contact:
        lines.append("IMPACT: contact force acting")
    return lines


def project(
    scene: mujoco.MjvScene, point: ArrayLike, width: int, height: int
) -> tuple[float, float] | None:
    """Pixel (column, row) of a world point in the last rendered view, None behind the camera.

    Uses the scene's OpenGL camera (position, forward and up axes, frustum at the near plane).
    """
    cam = scene.camera[0]
    forward, up = np.asarray(cam.forward, dtype=float), np.asarray(cam.up, dtype=float)
    right = np.cross(forward, up)
    d = np.asarray(point, dtype=float) - np.asarray(cam.pos, dtype=float)
    depth = float(d @ forward)
    if depth <= 1e-9:
        return None
    x = float(d @ right) * cam.frustum_near / depth
    y = float(d @ up) * cam.frustum_near / depth
    # A frustum width of 0 means "from the viewport's aspect ratio", as mjr_render does.
    half = cam.frustum_width or 0.5 * (cam.frustum_top - cam.frustum_bottom) * width / height
    u = (x - (cam.frustum_center - half)) / (2.0 * half) * width
    v = (cam.frustum_top - y) / (cam.frustum_top - cam.frustum_bottom) * height
    return u, v


def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: a fixed bitmap font
        return ImageFont.load_default()


def _markers(
    draw: Any,
    com_px: _Pixel | None,
    ground_px: _Pixel | None,
    impact_px: _Pixel | None,
    contact: bool,
    size: int,
) -> None:
    """CoM and impact markers drawn over the picture (never hidden inside the robot), labelled."""
    font = _font(size)
    r = max(6, size // 2)
    if com_px is not None:
        if ground_px is not None:
            draw.line([com_px, ground_px], fill=(230, 180, 0, 255), width=3)
            gx, gy = ground_px
            draw.line([(gx - r, gy), (gx + r, gy)], fill=(230, 180, 0, 255), width=3)
        x, y = com_px
        draw.ellipse(
            [x - r, y - r, x + r, y + r], fill=(255, 215, 0, 255), outline=(0, 0, 0, 255), width=2
        )
        draw.text(
            (x + r + 4, y - size // 2),
            "CoM",
            fill=(0, 0, 0, 255),
            font=font,
            stroke_width=2,
            stroke_fill=(255, 255, 255, 255),
        )
    if impact_px is not None:
        x, y = impact_px
        if contact:
            R = 2.5 * r
            draw.ellipse([x - R, y - R, x + R, y + R], outline=(220, 20, 20, 255), width=4)
        draw.ellipse(
            [x - r, y - r, x + r, y + r], fill=(220, 20, 20, 255), outline=(0, 0, 0, 255), width=2
        )
        draw.text(
            (x + r + 4, y + r),
            "impact point",
            fill=(150, 0, 0, 255),
            font=font,
            stroke_width=2,
            stroke_fill=(255, 255, 255, 255),
        )


def _caption(
    image: np.ndarray, lines: list[str], title: str, marks: _Marks | None = None
) -> np.ndarray:
    """Write the caption and the markers on a copy of ``image`` (Pillow, which imageio brings)."""
    from PIL import Image, ImageDraw

    height = image.shape[0]
    size = max(11, height // 42)
    font = _font(size)
    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture, "RGBA")
    if marks:
        _markers(draw, *marks, size=size)
    pad, step = size // 2, int(1.35 * size)
    for rows, bottom in (([title, *lines], False), ([LEGEND], True)):
        width = max(draw.textlength(r, font=font) for r in rows)
        top = height - pad - step * len(rows) - pad if bottom else pad
        draw.rectangle(
            [pad, top, pad + width + 2 * pad, top + step * len(rows) + pad],
            fill=(255, 255, 255, 200),
        )
        for i, row in enumerate(rows):
            color = (170, 0, 0) if row.startswith("IMPACT") else (20, 20, 20)
            draw.text((2 * pad, top + pad // 2 + i * step), row, fill=color, font=font)
    return np.asarray(picture)


def write_video(
    sim: SimModel,
    record: TrialRecord,
    path: str | Path,
    fps: int = 60,
    slowdown: float = 10.0,
    size: tuple[int, int] = VIDEO_SIZE,
    title: str | None = None,
) -> Path:
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
    # A brighter headlight than MuJoCo's default (ambient 0.1): the dark robot stays readable.
    light = model.vis.headlight
    saved = (light.ambient.copy(), light.diffuse.copy(), light.specular.copy())
    light.ambient[:], light.diffuse[:], light.specular[:] = 0.45, 0.7, 0.2
    try:
        with warnings.catch_warnings():  # GLFW warns before failing: the error line says it all
            warnings.simplefilter("ignore")
            renderer = mujoco.Renderer(model, height, width, max_geom=20000)
    except Exception as exc:  # no GL context: the error type depends on the backend
        light.ambient[:], light.diffuse[:], light.specular[:] = saved
        raise SimulationError(
            "--video",
            str(path)[:80],
            f"no offscreen OpenGL here ({type(exc).__name__}); "
            "set MUJOCO_GL=egl on a machine with EGL",
        ) from None
    try:
        import imageio.v2 as imageio
    except ImportError:  # pragma: no cover - the 'sim' extra
        raise SimulationError(
            "--video", str(path)[:80], "imageio is not installed: pip install 'impact-balance[sim]'"
        ) from None
    camera = mujoco.MjvCamera()
    camera.lookat[:] = sim.stance.com
    camera.distance = 3.0
    camera.elevation = -12.0
    impact = sim.scenario.impact
    if impact is None:
        raise SimulationError("--video", str(path)[:80], "the scenario has no impact to film")
    normal = np.asarray(impact.normal, dtype=float)
    # Side view: look along the horizontal direction orthogonal to the impact normal.
    side = np.cross([0.0, 0.0, 1.0], normal)
    side = side if np.linalg.norm(side) > 1e-6 else np.array([0.0, 1.0, 0.0])
    camera.azimuth = float(np.degrees(np.arctan2(side[1], side[0]))) + 180.0
    options = mujoco.MjvOption()
    impact_force = np.linalg.norm(
        record.forces.get("impact", np.zeros((len(record.time), 3))), axis=1
    )
    touching = np.flatnonzero(impact_force > 0.0)
    impact_start = float(record.time[touching[0]]) if touching.size else float(record.time[-1])
    dt_frame = 1.0 / (fps * slowdown)
    times = np.arange(record.time[0], record.time[-1], dt_frame)
    rows = np.minimum(np.searchsorted(record.time, times), len(record.time) - 1)
    name = title or f"{sim.scenario.name or 'scenario'}: {sim.joints} joints"
    ground = float(sim.scenario.plane_height)
    far = 0.999 * model.vis.map.zfar * model.stat.extent  # the depth image is in metres
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with imageio.get_writer(path, fps=fps, codec="libx264", macro_block_size=8) as writer:
            for k in rows:
                data.qpos[:] = record.qpos[k]
                mujoco.mj_forward(model, data)
                renderer.update_scene(data, camera=camera, scene_option=options)
                rgb = renderer.render()
                scene = renderer.scene
                com = record.com[k]
                contact = bool(impact_force[k] > 0.0)
                point = data.geom_xpos[sim.impact_geom] if sim.impact_geom is not None else None
                marks = (
                    project(scene, com, width, height),
                    project(scene, [com[0], com[1], ground], width, height),
                    None if point is None else project(scene, point, width, height),
                    contact,
                )
                renderer.enable_depth_rendering()
                depth = renderer.render()
                renderer.disable_depth_rendering()
                rgb = rgb.copy()
                rgb[depth >= far] = BACKGROUND  # nothing drawn there: the far clipping plane
                frame = _caption(
                    rgb,
                    frame_caption(float(record.time[k]), impact_start, slowdown, contact),
                    name,
                    marks,
                )
                writer.append_data(frame)  # type: ignore[attr-defined]  # imageio's v2 writer
    finally:
        renderer.close()
        light.ambient[:], light.diffuse[:], light.specular[:] = saved
    return path
