"""What the 3D view draws, as plain data: an :class:`Analysis` to named scene objects.

Nothing here knows about the browser: :func:`scene_objects` returns line segments, points,
arrows and translucent surfaces in world coordinates (m), and the app draws them with viser.
Names are stable ("contacts/0/outline", "impact/cone"...) so that a redraw replaces objects.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from impact_balance.analysis.analyze import Analysis
from impact_balance.contacts.stance import Stance
from impact_balance.geometry.polygon import Polygon
from impact_balance.impact.model import ImpactModel

if TYPE_CHECKING:
    from impact_balance.balance.reach import ComReach

__all__ = [
    "COLORS",
    "CONE_LENGTH",
    "IMPULSE_LENGTH",
    "Arrows",
    "Label",
    "Points",
    "SceneObject",
    "Segments",
    "Surface",
    "scene_objects",
]

#: Colours (hex), the same as the figures' (plots/style.py).
COLORS = {
    "contact": "#8c564b",
    "contact_normal": "#8c564b",
    "com": "#111111",
    "com_projection": "#111111",
    "com_velocity": "#1f77b4",
    "zmp_area": "#8fbc8f",
    "zmp_edge": "#2e6b2e",
    "impact": "#d62728",
    "impact_normal": "#d62728",
    "cone": "#d62728",
    "impulse": "#ff7f0e",
    "com_reach": "#9467bd",
}
#: Length of the drawn friction cone along the normal, m.
CONE_LENGTH = 0.15
#: Length of the longest drawn impulse direction, m.
IMPULSE_LENGTH = 0.3
#: Lift of drawings on the ZMP plane, so they do not flicker against the floor grid, m.
PLANE_LIFT = 2e-3


@dataclass(frozen=True)
class Segments:
    """Line segments, ``segments`` (N, 2, 3) m; ``width`` m."""

    name: str
    segments: npt.NDArray[np.float64]
    color: str
    width: float = 0.006


@dataclass(frozen=True)
class Points:
    """Spheres at ``points`` (N, 3) m, of radius ``radius`` m."""

    name: str
    points: npt.NDArray[np.float64]
    color: str
    radius: float = 0.02


@dataclass(frozen=True)
class Arrows:
    """Arrows from ``starts`` to ``ends`` (N, 3) m."""

    name: str
    starts: npt.NDArray[np.float64]
    ends: npt.NDArray[np.float64]
    color: str
    radius: float = 0.006


@dataclass(frozen=True)
class Surface:
    """A triangle mesh: ``vertices`` (N, 3) m, ``faces`` (M, 3) indices."""

    name: str
    vertices: npt.NDArray[np.float64]
    faces: npt.NDArray[np.uint32]
    color: str
    opacity: float = 0.5


@dataclass(frozen=True)
class Label:
    """A text label at ``position`` (3,) m, drawn on top of everything."""

    name: str
    text: str
    position: npt.NDArray[np.float64]
    color: str = "#111111"


SceneObject = Segments | Points | Arrows | Surface | Label


def polyline_segments(points: npt.ArrayLike, closed: bool = True) -> npt.NDArray[np.float64]:
    """(N, 2, 3) segments joining consecutive points (and the last to the first if closed)."""
    p = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(p) < 2:
        return np.zeros((0, 2, 3))
    ends = np.roll(p, -1, axis=0) if closed and len(p) > 2 else p[1:]
    starts = p if closed and len(p) > 2 else p[:-1]
    return np.stack([starts, ends], axis=1)


def _fan(
    polygon: npt.NDArray[np.float64],
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32]]:
    """Triangles of a convex polygon (N, 3), both sides (so it shows from below too)."""
    n = len(polygon)
    front = np.array([[0, i, i + 1] for i in range(1, n - 1)], dtype=np.uint32).reshape(-1, 3)
    return polygon, np.vstack([front, front[:, ::-1]])


def _on_plane(vertices: npt.ArrayLike, height: float) -> npt.NDArray[np.float64]:
    """Planar ``vertices`` (N, 2) lifted to ``height`` (m): (N, 3)."""
    v = np.asarray(vertices, dtype=float).reshape(-1, 2)
    return np.column_stack([v, np.full(len(v), height)])


def _area_objects(
    prefix: str, area: Polygon, height: float, fill: str, edge: str
) -> list[SceneObject]:
    if area.is_empty:
        return []
    pts = _on_plane(area.vertices, height)
    out: list[SceneObject] = [Segments(f"{prefix}/outline", polyline_segments(pts), edge, 0.006)]
    if len(pts) >= 3:
        vertices, faces = _fan(pts)
        out.append(Surface(f"{prefix}/fill", vertices, faces, fill, 0.55))
    elif len(pts) == 1:
        out.append(Points(f"{prefix}/point", pts, edge, 0.01))
    return out


def _contact_objects(stance: Stance) -> list[SceneObject]:
    """Each contact rectangle on its surface (a point contact: a dot) and its normal, world, m.

    The normal points into the robot; a point's arrow is 5 cm long.
    """
    out: list[SceneObject] = []
    for i, contact in enumerate(stance.contacts):
        if contact.is_point:  # a point foot: a dot, no sole
            out.append(
                Points(f"contacts/{i}/point", contact.position[None], COLORS["contact"], 0.02)
            )
        else:
            out.append(
                Segments(
                    f"contacts/{i}/outline",
                    polyline_segments(contact.corners()),
                    COLORS["contact"],
                    0.008,
                )
            )
        size = min(contact.spec.size) if not contact.is_point else 0.1
        out.append(
            Arrows(
                f"contacts/{i}/normal",
                contact.position[None],
                (contact.position + 0.5 * size * contact.normal)[None],
                COLORS["contact_normal"],
                0.004,
            )
        )
    return out


def _com_objects(
    com: npt.ArrayLike, com_velocity: npt.ArrayLike, height: float
) -> list[SceneObject]:
    """The CoM (world, m), its projection on the plane at ``height`` (m) and its velocity (m/s).

    The velocity arrow is drawn at the CoM, 1 m per m/s, and only when it is not zero.
    """
    c = np.asarray(com, dtype=float)
    projection = np.array([c[0], c[1], height + PLANE_LIFT])
    out: list[SceneObject] = [
        Points("com/point", c[None], COLORS["com"], 0.035),
        Label("com/label", "CoM", c),
        Points("com/projection", projection[None], COLORS["com_projection"], 0.015),
        Segments("com/drop", np.array([[c, projection]]), COLORS["com_projection"], 0.003),
    ]
    c0 = np.asarray(com_velocity, dtype=float)
    if np.linalg.norm(c0) > 1e-9:
        out.append(
            Arrows(
                "com/velocity",
                c[None],
                (c + np.array([c0[0], c0[1], 0.0]))[None],
                COLORS["com_velocity"],
                0.008,
            )
        )
    return out


def _cone_objects(point: npt.NDArray[np.float64], cone: npt.ArrayLike) -> list[SceneObject]:
    """The impact friction cone: a translucent surface and its edges.

    The apex is at ``point`` (world, m); the generators ``cone`` (3, k) are drawn
    :data:`CONE_LENGTH` long along the normal.
    """
    # Cone generators K_i = n + mu t_i: scaled to CONE_LENGTH along n.
    rim = point + CONE_LENGTH * np.asarray(cone, dtype=float).T
    vertices = np.vstack([point, rim])
    k = len(rim)
    faces = np.array([[0, 1 + j, 1 + (j + 1) % k] for j in range(k)], dtype=np.uint32)
    return [
        Surface("impact/cone", vertices, np.vstack([faces, faces[:, ::-1]]), COLORS["cone"], 0.25),
        Segments(
            "impact/cone_edges",
            np.stack([np.repeat(point[None], k, 0), rim], axis=1),
            COLORS["cone"],
            0.002,
        ),
    ]


def _impulse_objects(
    point: npt.NDArray[np.float64], impulse_rates: npt.ArrayLike
) -> list[SceneObject]:
    """The impulse vertices' directions from ``point`` (world, m) and the impulse set.

    The longest direction is drawn :data:`IMPULSE_LENGTH` long; the set is their ends on the
    two restitution planes (rows ``2i``: the high restitution, ``2i + 1``: the low one).
    Nothing is drawn when every rate is zero.
    """
    rates = np.asarray(impulse_rates, dtype=float)
    longest = float(np.max(np.linalg.norm(rates, axis=1))) if len(rates) else 0.0
    if longest <= 0:
        return []
    ends = point + IMPULSE_LENGTH * rates / longest
    return [
        Segments(
            "impact/impulses",
            np.stack([np.repeat(point[None], len(ends), 0), ends], axis=1),
            COLORS["impulse"],
            0.003,
        ),
        Segments("impact/impulse_set_hi", polyline_segments(ends[0::2]), COLORS["impulse"], 0.004),
        Segments("impact/impulse_set_lo", polyline_segments(ends[1::2]), COLORS["impulse"], 0.004),
    ]


def _impact_objects(model: ImpactModel) -> list[SceneObject]:
    """The impact point, its normal (into the robot), its friction cone and impulse set."""
    p = np.asarray(model.point, dtype=float)
    n = np.asarray(model.normal, dtype=float)
    out: list[SceneObject] = [
        Points("impact/point", p[None], COLORS["impact"], 0.018),
        Label("impact/label", "impact", p, COLORS["impact"]),
        Arrows("impact/normal", p[None], (p + 0.25 * n)[None], COLORS["impact_normal"], 0.006),
    ]
    out += _cone_objects(p, model.cone)
    out += _impulse_objects(p, model.impulse_rates)
    return out


def scene_objects(analysis: Analysis, reach: ComReach | None = None) -> list[SceneObject]:
    """Everything the 3D view shows besides the robot, by stable name.

    - ``contacts/<i>/outline``, ``contacts/<i>/normal``: each contact rectangle on its surface
      and its normal (from the environment into the robot).
    - ``com/point``, ``com/label``, ``com/projection``, ``com/drop``: the CoM, its vertical
      projection on the ZMP plane and the line joining them; ``com/velocity``: the pre-impact
      CoM velocity (drawn at the CoM, 1 m per m/s) when not zero.
    - ``zmp_area/outline``, ``zmp_area/fill``: the ZMP support area on its plane (absent when
      the stance cannot balance).
    - ``impact/point``, ``impact/label``, ``impact/normal``, ``impact/cone``: the impact point,
      its normal (into the robot) and its friction cone (apex at the point, opening along the
      normal); ``impact/impulses``: the directions of the 2N impulse vertices, scaled so the
      longest is :data:`IMPULSE_LENGTH` (the set's shape does not depend on the approach
      speed), and ``impact/impulse_set_hi`` / ``_lo``: their ends on the two restitution
      planes.
    - ``com_reach/outline``: with ``reach``, the CoM's reach ``c + R(a) u(a)`` around the CoM's
      projection, on the ZMP plane (:mod:`impact_balance.balance.reach`).

    Args:
        analysis: The analysis to draw.
        reach: The CoM's reach of the analysis's stance, or None.

    Returns:
        The scene objects, world coordinates, m.
    """
    areas = analysis.areas
    h = areas.plane_height
    out = _contact_objects(analysis.stance)
    out += _com_objects(areas.com, analysis.com_velocity, h)
    out += _area_objects(
        "zmp_area", areas.zmp_area, h + PLANE_LIFT, COLORS["zmp_area"], COLORS["zmp_edge"]
    )
    if analysis.impact is not None:
        out += _impact_objects(analysis.impact.model)
    if reach is not None:
        outline = _on_plane(reach.polygon(areas.com), h + 2 * PLANE_LIFT)
        out.append(
            Segments("com_reach/outline", polyline_segments(outline), COLORS["com_reach"], 0.005)
        )
    return out
