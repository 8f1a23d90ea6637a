"""Checks of a rendered matplotlib figure that a reader would otherwise have to make by eye.

:func:`layout_problems` draws the figure and lists, as sentences:

- text or a legend outside the canvas (clipped when saved);
- two texts that overlap (titles, axis labels, tick labels, notes, annotations, legends);
- a legend or a text drawn over data: a point of a plotted line, polygon edge or marker
  (sampled along each path every few pixels, in display coordinates) inside its box, or its
  box over a filled area (a polygon, a band) of the axes;
- a text smaller than :data:`MIN_POINTS` at the saved size;
- an axis label without a unit in parentheses, e.g. ``time (s)``, ``friction (-)``.

:func:`inside_axes` and :func:`data_fill` measure where a box sits and how much of a panel
its data use.

Tests call :func:`assert_layout`, which fails with every problem at once.
"""

from __future__ import annotations

import itertools
import re

import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import PathCollection
from matplotlib.figure import Figure
from matplotlib.legend import Legend
from matplotlib.patches import Patch
from matplotlib.text import Text

#: Pixels of slack in every comparison (anti-aliasing, rounding of the renderer).
SLACK = 1.0
#: Spacing of the points sampled along a path, pixels.
STEP = 3.0
#: The smallest font size of any text, points at the saved size.
MIN_POINTS = 8.0
UNIT = re.compile(r"\(.*\S.*\)|\[.*\S.*\]")
# : An artist with this gid is background (a full-height band, a reference line): legends may cover
# it.
BACKGROUND = "background"


def is_panel(ax: Axes) -> bool:
    """A drawn panel, not a frameless holder of legends (3D axes keep ``axison`` False)."""
    return ax.get_visible() and (ax.axison or ax.name == "3d")


def _visible_text(t: Text) -> bool:
    return t.get_visible() and bool(t.get_text().strip()) and t.get_alpha() != 0


def _texts(fig: Figure) -> list[tuple[str, object, Text | Legend]]:
    """(kind, owner, artist) for every visible text and legend of the figure."""
    out: list[tuple[str, object, Text | Legend]] = []
    suptitle = getattr(fig, "_suptitle", None)
    for t in fig.texts:
        if _visible_text(t):
            out.append(("suptitle" if t is suptitle else "figure text", fig, t))
    for leg in fig.legends:
        out.append(("legend", fig, leg))
    for ax in fig.axes:
        if not ax.get_visible():
            continue
        for t in (ax.title, ax._left_title, ax._right_title):
            if _visible_text(t):
                out.append(("title", ax, t))
        for axis in _axes_axis(ax):
            if _visible_text(axis.label):
                out.append(("axis label", ax, axis.label))
            for tick in _shown_ticks(axis):
                out.append(("tick", axis, tick))
            off = axis.get_offset_text()
            if _visible_text(off):
                out.append(("offset", axis, off))
        for t in ax.texts:
            if _visible_text(t):
                out.append(("text", ax, t))
        if ax.get_legend() is not None and ax.get_legend().get_visible():
            out.append(("legend", ax, ax.get_legend()))
    return out


def _shown_ticks(axis) -> list[Text]:
    """The major tick labels matplotlib draws: those within the view (it lists others too)."""
    lo, hi = sorted(axis.get_view_interval())
    eps = 1e-9 * max(abs(hi - lo), 1e-300)
    return [
        t.label1
        for t in axis.get_major_ticks()
        if lo - eps <= t.get_loc() <= hi + eps
        and t.label1.get_visible()
        and _visible_text(t.label1)
    ]


def _axes_axis(ax: Axes):
    axes = [ax.xaxis, ax.yaxis]
    if hasattr(ax, "zaxis"):
        axes.append(ax.zaxis)
    return axes


def _box(artist, renderer):
    return artist.get_window_extent(renderer)


def _overlap(a, b) -> bool:
    return (
        a.x0 < b.x1 - SLACK and b.x0 < a.x1 - SLACK and a.y0 < b.y1 - SLACK and b.y0 < a.y1 - SLACK
    )


def _name(kind: str, artist) -> str:
    if isinstance(artist, Legend):
        return "legend"
    return f"{kind} {artist.get_text()[:40]!r}"


def _samples(path, transform) -> np.ndarray:
    """Points along a path (its vertices and every STEP px between them), display coordinates."""
    out = []
    for poly in path.to_polygons(transform=transform, closed_only=False):
        poly = np.asarray(poly, dtype=float)
        poly = poly[np.all(np.isfinite(poly), axis=1)]
        if len(poly) == 0:
            continue
        out.append(poly)
        seg = np.diff(poly, axis=0)
        length = np.hypot(seg[:, 0], seg[:, 1])
        for p, d, n in zip(poly[:-1], seg, np.ceil(length / STEP).astype(int), strict=True):
            if n > 1:
                t = np.linspace(0.0, 1.0, min(n, 2000))[1:-1, None]
                out.append(p + t * d)
    return np.vstack(out) if out else np.zeros((0, 2))


def data_points(ax: Axes) -> list[tuple[str, np.ndarray]]:
    """(label, display points) of every visible data artist of an axes, clipped to the axes."""
    out = []
    clip = ax.get_window_extent()
    artists = list(ax.lines) + list(ax.patches) + list(ax.collections)
    for artist in artists:
        if not artist.get_visible() or artist.get_gid() == BACKGROUND:
            continue
        label = str(artist.get_label())
        try:
            if hasattr(artist, "get_path") and not hasattr(artist, "get_paths"):
                if hasattr(artist, "get_xydata"):  # a Line2D: its data, markers included
                    pts = artist.get_transform().transform(artist.get_xydata())
                    path = artist.get_path()
                    pts = (
                        np.vstack([pts, _samples(path, artist.get_transform())])
                        if artist.get_linestyle() not in ("None", "", " ")
                        else pts
                    )
                else:  # the whole transform first: a log axis' is not affine
                    pts = _samples(artist.get_transform().transform_path(artist.get_path()), None)
            else:
                paths = artist.get_paths()
                offsets = artist.get_offsets() if hasattr(artist, "get_offsets") else None
                if offsets is not None and len(offsets) and len(paths) <= 1:  # scatter markers
                    pts = artist.get_offset_transform().transform(offsets)
                else:
                    pts = (
                        np.vstack([_samples(p, artist.get_transform()) for p in paths])
                        if paths
                        else np.zeros((0, 2))
                    )
        except Exception:
            continue
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        inside = (
            (pts[:, 0] >= clip.x0)
            & (pts[:, 0] <= clip.x1)
            & (pts[:, 1] >= clip.y0)
            & (pts[:, 1] <= clip.y1)
        )
        out.append((label, pts[inside]))
    return out


def layout_problems(fig: Figure, units: bool = True, dpi: float = 120) -> list[str]:
    """Every layout problem of ``fig`` drawn at ``dpi`` (the figures are saved at 120), empty
    when there is none; see the module docstring."""
    fig.set_dpi(dpi)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    problems = []
    texts = _texts(fig)
    boxes = [(kind, owner, artist, _box(artist, renderer)) for kind, owner, artist in texts]
    for kind, _, artist, b in boxes:  # inside by a pixel: a frame on the edge loses its line
        if b.x0 < SLACK or b.y0 < SLACK or b.x1 > W - SLACK or b.y1 > H - SLACK:
            problems.append(
                f"{_name(kind, artist)} is outside the canvas ({b.x0:.0f}, {b.y0:.0f}, {b.x1:.0f}, "
                f"{b.y1:.0f}) of {W:.0f} x {H:.0f} px"
            )
    for ax in fig.axes:
        b = ax.get_window_extent(renderer)
        if ax.get_visible() and (
            b.x0 < -SLACK or b.y0 < -SLACK or b.x1 > W + SLACK or b.y1 > H + SLACK
        ):
            problems.append(f"axes {ax.get_title()[:30]!r} is outside the canvas")
    for (k1, _o1, a1, b1), (k2, _o2, a2, b2) in itertools.combinations(boxes, 2):
        if _overlap(b1, b2):  # tick labels of one axis too: a narrow panel crowds them
            problems.append(f"{_name(k1, a1)} overlaps {_name(k2, a2)}")
    # Legends over data.
    for ax in fig.axes:
        if not ax.get_visible() or hasattr(ax, "zaxis"):
            continue  # a 3D axes' projected data has no fixed place to check against
        legends = [ax.get_legend()] if ax.get_legend() is not None else []
        legends += list(fig.legends)
        notes = [t for t in ax.texts if _visible_text(t)]  # boxed notes, labels, annotations
        for box_artist in legends + notes:
            lb = _box(box_artist, renderer)
            for label, pts in data_points(ax):
                hit = (
                    (pts[:, 0] > lb.x0 + SLACK)
                    & (pts[:, 0] < lb.x1 - SLACK)
                    & (pts[:, 1] > lb.y0 + SLACK)
                    & (pts[:, 1] < lb.y1 - SLACK)
                )
                if hit.any():
                    what = (
                        "legend"
                        if isinstance(box_artist, Legend)
                        else f"text {box_artist.get_text()[:30]!r}"
                    )
                    problems.append(f"{what} covers {int(hit.sum())} points of {label!r}")
    problems += _fill_problems(fig, renderer)
    for kind, _, artist in texts:
        for t in artist.get_texts() if isinstance(artist, Legend) else [artist]:
            if _visible_text(t) and t.get_fontsize() < MIN_POINTS - 1e-9:
                problems.append(
                    f"{_name(kind, t)} is {t.get_fontsize():g} pt (< {MIN_POINTS:g} pt)"
                )
        if isinstance(artist, Legend) and artist.get_title().get_text():
            if artist.get_title().get_fontsize() < MIN_POINTS - 1e-9:
                problems.append(f"legend title is {artist.get_title().get_fontsize():g} pt")
    if units:
        for ax in fig.axes:
            if not is_panel(ax):
                continue
            for axis in _axes_axis(ax):
                if not axis.get_visible():
                    continue
                text = axis.label.get_text()
                if _shown_ticks(axis) and not UNIT.search(text):
                    problems.append(f"axis label {text!r} has no unit in parentheses")
    return problems


def _filled_paths(ax: Axes):
    """Display outlines of the filled polygons and bands of an axes (not background ones)."""
    out = []
    for artist in list(ax.patches) + list(ax.collections):
        if not artist.get_visible() or artist.get_gid() == BACKGROUND:
            continue
        if isinstance(artist, Patch):
            face = artist.get_facecolor()
            if artist.get_fill() and face[3] > 0:
                out.append(artist.get_transform().transform_path(artist.get_path()))
        elif hasattr(artist, "get_paths") and len(artist.get_facecolor()):
            if isinstance(artist, PathCollection):
                continue  # scatter markers: points, checked as data points
            out += [artist.get_transform().transform_path(p) for p in artist.get_paths()]
    return out


def _fill_problems(fig: Figure, renderer) -> list[str]:
    """A legend or a note whose box lies over a filled area of an axes (within the axes)."""
    problems = []
    for ax in fig.axes:
        if not ax.get_visible() or hasattr(ax, "zaxis"):
            continue
        frame = ax.get_window_extent(renderer)
        legends = ([ax.get_legend()] if ax.get_legend() is not None else []) + list(fig.legends)
        boxes = legends + [t for t in ax.texts if _visible_text(t) and t.get_bbox_patch()]
        paths = _filled_paths(ax)
        for artist in boxes:
            b = _box(artist, renderer)
            xs = np.linspace(b.x0 + SLACK, b.x1 - SLACK, 9)
            ys = np.linspace(b.y0 + SLACK, b.y1 - SLACK, 7)
            grid = np.array([(x, y) for x in xs for y in ys])
            grid = grid[
                (grid[:, 0] > frame.x0)
                & (grid[:, 0] < frame.x1)
                & (grid[:, 1] > frame.y0)
                & (grid[:, 1] < frame.y1)
            ]
            if len(grid) and any(p.contains_points(grid).any() for p in paths):
                what = (
                    "legend" if isinstance(artist, Legend) else f"text {artist.get_text()[:30]!r}"
                )
                problems.append(f"{what} lies over a filled area")
    return problems


def inside_axes(fig: Figure, ax: Axes, artist) -> bool:
    """Whether the box of ``artist`` (a legend or a text) lies inside the frame of ``ax``."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame, box = ax.get_window_extent(renderer), _box(artist, renderer)
    return (
        box.x0 >= frame.x0 - SLACK
        and box.x1 <= frame.x1 + SLACK
        and box.y0 >= frame.y0 - SLACK
        and box.y1 <= frame.y1 + SLACK
    )


def data_fill(fig: Figure, ax: Axes) -> float:
    """The share of the axes' frame that the bounding box of its data covers (0 to 1)."""
    fig.canvas.draw()
    frame = ax.get_window_extent()
    pts = np.vstack([p for _, p in data_points(ax) if len(p)] or [np.zeros((0, 2))])
    if len(pts) == 0:
        return 0.0
    w = pts[:, 0].max() - pts[:, 0].min()
    h = pts[:, 1].max() - pts[:, 1].min()
    return float(w * h / (frame.width * frame.height))


def assert_layout(fig: Figure, units: bool = True) -> None:
    problems = layout_problems(fig, units=units)
    assert not problems, "\n".join(problems)


def largest_gap(fig: Figure) -> tuple[float, float]:
    """The widest blank band across the figure, as fractions of its width and of its height.

    The bands between the boxes of everything drawn (axes as shrunk by their aspect, texts,
    legends), along x and along y, the canvas' edges included.
    """
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    boxes = [ax.get_window_extent(renderer) for ax in fig.axes if is_panel(ax)]
    boxes += [_box(artist, renderer) for _, _, artist in _texts(fig)]
    out = []
    for lo_attr, hi_attr, size in (("x0", "x1", fig.bbox.width), ("y0", "y1", fig.bbox.height)):
        spans = sorted(
            (max(0.0, getattr(b, lo_attr)), min(size, getattr(b, hi_attr))) for b in boxes
        )
        gap, reach = 0.0, 0.0
        for lo, hi in spans:
            gap = max(gap, lo - reach)
            reach = max(reach, hi)
        out.append(max(gap, size - reach) / size)
    return out[0], out[1]
