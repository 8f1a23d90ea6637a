"""Legends and notes inside an axes, where they hide no data.

:func:`place_inside` puts each box (a legend, or a text with a frame) in the first corner of
the axes where it covers no drawn line, marker or filled area and no box placed before it;
when no corner is free, it widens the view on the side that costs the least room (above the
data, or right of it) and tries again. Everything is measured on the drawn figure, in display
coordinates.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.backend_bases import RendererBase
from matplotlib.collections import Collection, PathCollection
from matplotlib.legend import Legend
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.path import Path
from matplotlib.text import Text
from matplotlib.transforms import Bbox

__all__ = ["BACKGROUND", "CORNERS", "covered_points", "place_inside"]

#: An artist with this gid is background (a full-height band, a reference line): a box may
#: cover it.
BACKGROUND = "background"
#: The corners tried, in order, with the text anchor of each (x, y in axes fraction).
Corner = Literal["upper left", "upper right", "lower left", "lower right"]
CORNERS: dict[Corner, tuple[float, float, Literal["left", "right"], Literal["top", "bottom"]]] = {
    "upper left": (0.015, 0.985, "left", "top"),
    "upper right": (0.985, 0.985, "right", "top"),
    "lower left": (0.015, 0.015, "left", "bottom"),
    "lower right": (0.985, 0.015, "right", "bottom"),
}
#: Spacing of the points sampled along a path, pixels.
_STEP = 3.0
#: Gap kept between a box and the data, pixels.
_PAD = 4.0

Box = Legend | Text


def _path_points(path: Path, transform: Any) -> npt.NDArray[np.float64]:
    """Points along ``path`` (its vertices and every few pixels between), display coordinates."""
    out = []
    for poly in path.to_polygons(transform=transform, closed_only=False):
        poly = np.asarray(poly, dtype=float)
        poly = poly[np.all(np.isfinite(poly), axis=1)]
        if len(poly) == 0:
            continue
        out.append(poly)
        seg = np.diff(poly, axis=0)
        n = np.ceil(np.hypot(seg[:, 0], seg[:, 1]) / _STEP).astype(int)
        for p, d, k in zip(poly[:-1], seg, n, strict=True):
            if k > 1:
                out.append(p + np.linspace(0.0, 1.0, min(k, 2000))[1:-1, None] * d)
    return np.vstack(out) if out else np.zeros((0, 2))


def covered_points(ax: Axes) -> tuple[npt.NDArray[np.float64], list[Path]]:
    """What a box must not cover: points of the drawn data, and the filled outlines.

    Returns:
        The points (k, 2) of every visible line, marker, patch edge and collection, and the
        outlines (display coordinates) of the filled patches and collections.
    """
    points, fills = [], []
    for artist in [*ax.lines, *ax.patches, *ax.collections]:
        if not artist.get_visible() or artist.get_gid() == BACKGROUND:
            continue
        if isinstance(artist, Line2D):
            xy = artist.get_transform().transform(artist.get_xydata())
            points.append(xy)
            if artist.get_linestyle() not in ("None", "", " "):
                points.append(_path_points(artist.get_path(), artist.get_transform()))
        elif isinstance(artist, Patch):
            path = artist.get_transform().transform_path(artist.get_path())
            points.append(_path_points(path, None))
            face = artist.get_facecolor()
            if artist.get_fill() and float(face[3]) > 0:  # type: ignore[misc]
                fills.append(path)
        elif isinstance(artist, Collection):
            offsets = np.asarray(artist.get_offsets())
            paths = artist.get_paths()
            if isinstance(artist, PathCollection):  # scatter markers
                points.append(artist.get_offset_transform().transform(offsets))
                continue
            for path in paths:
                shown = artist.get_transform().transform_path(path)
                points.append(_path_points(shown, None))
                if len(artist.get_facecolor()):
                    fills.append(shown)
    pts = np.vstack(points) if points else np.zeros((0, 2))
    return pts[np.all(np.isfinite(pts), axis=1)], fills


def _hides_data(box: Bbox, points: npt.NDArray[np.float64], fills: Sequence[Path]) -> bool:
    """Whether ``box`` (grown by the pad) covers a data point or lies over a filled area."""
    b = box.padded(_PAD)
    inside = (
        (points[:, 0] > b.x0)
        & (points[:, 0] < b.x1)
        & (points[:, 1] > b.y0)
        & (points[:, 1] < b.y1)
    )
    if inside.any():
        return True
    xs, ys = np.linspace(b.x0, b.x1, 7), np.linspace(b.y0, b.y1, 5)
    grid = np.array([(x, y) for x in xs for y in ys])
    return any(path.contains_points(grid).any() for path in fills)


def _put(artist: Box, ax: Axes, loc: Corner) -> None:
    """Anchor ``artist`` at corner ``loc`` of ``ax``."""
    if isinstance(artist, Legend):
        artist.set_loc(loc)
        return
    x, y, ha, va = CORNERS[loc]
    artist.set_transform(ax.transAxes)
    artist.set_position((x, y))
    artist.set_horizontalalignment(ha)
    artist.set_verticalalignment(va)


def _grow(ax: Axes, box: Bbox) -> float:
    """Widen the view by the room ``box`` needs, above the data or right of it (the smaller).

    Returns:
        The growth, a fraction of the view's span on that side.
    """
    frame = ax.get_window_extent()
    up = (box.height + 3 * _PAD) / max(frame.height, 1.0)
    right = (box.width + 3 * _PAD) / max(frame.width, 1.0)
    wide_enough = box.width + 2 * _PAD <= frame.width
    if (up <= right and wide_enough) or ax.get_xscale() != "linear":
        grow = min(up, 0.8) / max(1.0 - min(up, 0.8), 0.2)
        lo, hi = ax.get_ylim()
        if ax.get_yscale() == "log":
            ax.set_ylim(lo, hi * (hi / lo) ** grow)
        else:
            ax.set_ylim(lo, hi + (hi - lo) * grow)
    else:
        grow = min(right, 0.8) / max(1.0 - min(right, 0.8), 0.2)
        lo, hi = ax.get_xlim()
        ax.set_xlim(lo, hi + (hi - lo) * grow)
    return grow


def place_inside(
    ax: Axes,
    boxes: Sequence[Box | None],
    corners: Sequence[Corner] = tuple(CORNERS),
    max_growth: float = 0.6,
    relayout: Callable[[], None] | None = None,
) -> bool:
    """Put each of ``boxes`` in a corner of ``ax`` where it hides no data and no other box.

    When no corner is free for a box, the view is widened by the room it needs (above the
    data or right of it) and the placement starts again, until the view has grown by
    ``max_growth`` of its span in all; then the view is restored and False returned (the
    caller puts the boxes elsewhere).

    Args:
        ax: The axes (its data drawn, its limits set).
        boxes: Legends of ``ax`` and texts (placed in axes fraction), in order of importance
            (None, e.g. an axes without legend, is skipped).
        corners: The corners tried, in order (keys of :data:`CORNERS`).
        max_growth: The most the view may grow, a fraction of its span.
        relayout: Called after each widening (e.g. to size the figure to its new views).

    Returns:
        True when every box found a free corner.
    """
    fig = ax.get_figure(root=True)
    assert fig is not None
    placed = [b for b in boxes if b is not None]
    limits = (ax.get_xlim(), ax.get_ylim())
    grown = 0.0
    while True:
        fig.canvas.draw()  # the layout and the boxes' sizes at the figure's size
        renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
        stuck = _first_stuck(ax, placed, corners, renderer)
        if stuck is None:
            return True
        if grown >= max_growth:
            ax.set_xlim(limits[0])
            ax.set_ylim(limits[1])
            if relayout is not None:
                relayout()
            return False
        grown += _grow(ax, stuck)
        if relayout is not None:
            relayout()


def _first_stuck(
    ax: Axes, boxes: Sequence[Box], corners: Sequence[Corner], renderer: RendererBase
) -> Bbox | None:
    """Place ``boxes`` in turn; the first one no corner is free for (None when all fit)."""
    points, fills = covered_points(ax)
    # The axes' other texts (values written on bars, labels) are obstacles too.
    taken: list[Bbox] = [
        t.get_window_extent(renderer)
        for t in ax.texts
        if t.get_visible() and t.get_text().strip() and t not in boxes
    ]
    for artist in boxes:
        for loc in corners:
            _put(artist, ax, loc)
            box = artist.get_window_extent(renderer)
            if not _hides_data(box, points, fills) and not any(
                box.overlaps(t.padded(_PAD)) for t in taken
            ):
                taken.append(box)
                break
        else:
            return box
    return None
