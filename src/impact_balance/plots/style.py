"""The style shared by the figures: colours, resolution, figure creation, polygons, limits, text.

Every figure is made by :func:`new_figure` (an Agg canvas, no pyplot), so that the figure
modules touch no global state; the colours keep one meaning across figures.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine
from matplotlib.patches import Polygon as PolygonPatch
from matplotlib.typing import ColorType, LineStyleType

from impact_balance.geometry.polygon import Polygon

if TYPE_CHECKING:
    from impact_balance.analysis.analyze import Analysis

__all__ = [
    "AREA_COLOR",
    "AREA_EDGE",
    "CAPPED_COLOR",
    "COM_COLOR",
    "COM_CRITERION_COLOR",
    "CONTACT_COLOR",
    "DIGITS",
    "DPI",
    "FALL_COLOR",
    "FONT_MIN",
    "FONT_SMALL",
    "FONT_SUPTITLE",
    "FONT_TITLE",
    "IMPACT_COLOR",
    "LOG_RATIO",
    "OK_COLOR",
    "PALETTE",
    "REFERENCE_COLOR",
    "ZMP_COLOR",
    "ZMP_CRITERION_COLOR",
    "area_view_points",
    "centre_message",
    "draw_polygon",
    "fmt_speed",
    "hull",
    "needs_log_scale",
    "new_figure",
    "scenario_title",
    "set_limits",
    "text_box",
    "trim_height",
]

#: A colour-blind-safe palette (Okabe and Ito, 2008): blue, orange, bluish green, reddish
#: purple, sky blue, vermillion, yellow, black. Series of one figure take its colours in order.
PALETTE = (
    "#0072B2",
    "#E69F00",
    "#009E73",
    "#CC79A7",
    "#56B4E9",
    "#D55E00",
    "#F0E442",
    "#000000",
)
#: The ZMP support area (bluish green).
ZMP_COLOR = "#009E73"
#: The CoM velocity area (sky blue, the paper's cyan) and its boundary (blue).
AREA_COLOR = "#56B4E9"
AREA_EDGE = "#0072B2"
#: The CoM, its projection and its velocity.
COM_COLOR = "black"
#: The impact: its point, its force and its impulse set (vermillion).
IMPACT_COLOR = "#D55E00"
#: A balanced outcome (blue).
OK_COLOR = "#0072B2"
#: A fall, or what makes the robot fall (vermillion).
FALL_COLOR = "#D55E00"
#: The contact rectangles (brown: dark, apart from the palette's hues).
CONTACT_COLOR = "#8c564b"
#: The CoM criterion and the ZMP criterion, wherever the two are compared.
COM_CRITERION_COLOR = "#0072B2"
ZMP_CRITERION_COLOR = "#E69F00"
#: A reference (an intended velocity) and its capped value.
REFERENCE_COLOR = "#E69F00"
CAPPED_COLOR = "#0072B2"

#: Resolution of the written figures, dots per inch.
DPI = 120
#: Font sizes at the saved size, points: figure title, panel title, legends and notes. No text
#: of a figure is smaller than :data:`FONT_MIN`.
FONT_SUPTITLE = 12.0
FONT_TITLE = 10.5
FONT_SMALL = 8.5
FONT_MIN = 8.0
#: Significant digits of a number written on a figure (speeds, ratios).
DIGITS = 3
#: Two values of one axis further apart than this ratio are drawn on a log scale (the smaller
#: would be a sliver under 5 % of a linear axis).
LOG_RATIO = 20.0


def new_figure(width: float, height: float) -> Figure:
    """A figure on an Agg canvas that does not go through pyplot.

    No global state is touched (no ``matplotlib.use``, no pyplot figure manager), so these
    functions are safe in scripts, tests and notebooks alike; ``fig.savefig`` renders with Agg.
    """
    fig = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    # A wider margin than the default (3 pt): a legend anchored outside its axes otherwise
    # ends on the canvas' edge, where its frame is cut.
    engine = fig.get_layout_engine()
    if isinstance(engine, ConstrainedLayoutEngine):
        engine.set(w_pad=0.06, h_pad=0.06)
    FigureCanvasAgg(fig)
    return fig


def needs_log_scale(values: Iterable[float]) -> bool:
    """Whether ``values`` (drawn on one axis) need a log scale.

    They do when their positive finite values span more than :data:`LOG_RATIO`: the smallest
    would be invisible on a linear axis.
    """
    v = np.asarray([float(x) for x in values], dtype=float)
    v = v[np.isfinite(v) & (v > 0)]
    return bool(v.size >= 2 and v.max() > LOG_RATIO * v.min())


def fmt_speed(value: float | None, digits: int = DIGITS) -> str:
    """An approach speed in m/s, ``unbounded`` for infinity."""
    if value is None or not math.isfinite(value):
        return "unbounded"
    return f"{value:.{digits}g} m/s"


def draw_polygon(
    ax: Axes,
    polygon: Polygon,
    *,
    color: ColorType,
    alpha: float = 0.35,
    label: str | None = None,
    edge: ColorType | None = None,
    lw: float = 1.5,
    ls: LineStyleType = "-",
    zorder: float = 1.0,
    fill: bool = True,
) -> None:
    """Draw a (possibly degenerate) convex polygon: filled polygon, thick segment, or point.

    Args:
        ax: The axes.
        polygon: The polygon, in the axes' data coordinates.
        color: The fill colour.
        alpha: The fill's opacity.
        label: The legend entry.
        edge: The boundary's colour (default: ``color``).
        lw: The boundary's width, points.
        ls: The boundary's line style.
        zorder: The drawing order.
        fill: Fill the polygon (else its boundary only).
    """
    v = np.asarray(polygon.vertices, dtype=float).reshape(-1, 2)
    edge = edge or color
    if len(v) == 0:
        return
    if len(v) == 1:
        ax.plot(v[:, 0], v[:, 1], "o", color=edge, ms=6, label=label, zorder=zorder + 0.5)
    elif len(v) == 2:
        ax.plot(
            v[:, 0],
            v[:, 1],
            "-",
            color=edge,
            lw=max(3.0, 2 * lw),
            solid_capstyle="round",
            label=label,
            zorder=zorder + 0.5,
        )
    else:
        ax.add_patch(
            PolygonPatch(
                v,
                closed=True,
                facecolor=color if fill else "none",
                alpha=alpha if fill else 1.0,
                edgecolor="none",
                zorder=zorder,
            )
        )
        ax.add_patch(
            PolygonPatch(
                v,
                closed=True,
                facecolor="none",
                edgecolor=edge,
                lw=lw,
                ls=ls,
                zorder=zorder + 0.1,
                label=label,
            )
        )


def hull(points: npt.ArrayLike) -> Polygon:
    """Convex hull of planar points as a :class:`Polygon` (point or segment when degenerate)."""
    return Polygon.from_points(np.asarray(points, dtype=float).reshape(-1, 2))


def set_limits(
    ax: Axes,
    points: Iterable[npt.ArrayLike],
    margin: float = 0.12,
    min_span: float = 0.05,
    min_ratio: float = 0.0,
) -> None:
    """Fit the axis limits to ``points`` (arrays of (k, 2)), with a relative margin.

    Args:
        ax: The axes.
        points: Arrays of points (k, 2); non-finite points are left out.
        margin: The margin on each side, a fraction of the span.
        min_span: The smallest span, data units.
        min_ratio: Keeps each span at least that fraction of the other, so that flat data
            (a segment) does not give an unreadable sliver of an axes under an equal aspect.
    """
    pts = [np.asarray(p, dtype=float).reshape(-1, 2) for p in points]
    pts = [p[np.all(np.isfinite(p), axis=1)] for p in pts if len(p)]
    pts = [p for p in pts if len(p)]
    if not pts:
        return
    allp = np.vstack(pts)
    lo, hi = allp.min(axis=0), allp.max(axis=0)
    span = np.maximum(hi - lo, min_span)
    span = np.maximum(span, min_ratio * span.max())
    centre = 0.5 * (lo + hi)
    half = 0.5 * span * (1 + 2 * margin)
    ax.set_xlim(centre[0] - half[0], centre[0] + half[0])
    ax.set_ylim(centre[1] - half[1], centre[1] + half[1])


def text_box(
    ax: Axes,
    text: str,
    loc: str = "upper left",
    fontsize: float = FONT_SMALL,
    edgecolor: str = "0.6",
) -> None:
    """A boxed note inside the axes."""
    x, ha = (0.02, "left") if "left" in loc else (0.98, "right")
    y, va = (0.98, "top") if "upper" in loc else (0.02, "bottom")
    ax.text(
        x,
        y,
        text,
        transform=ax.transAxes,
        ha=ha,
        va=va,
        fontsize=fontsize,
        zorder=10,
        bbox={
            "boxstyle": "round,pad=0.4",
            "facecolor": "white",
            "edgecolor": edgecolor,
            "alpha": 0.9,
            "lw": 2 if edgecolor != "0.6" else 1,
        },
    )


def centre_message(
    ax: Axes, text: str, color: str = FALL_COLOR, y: float = 0.5, fontsize: float = 13
) -> None:
    """A large message across the axes (e.g. "cannot balance"), at height ``y`` (axes fraction)."""
    put = getattr(ax, "text2D", ax.text)  # 3D axes place 2D text with text2D
    put(
        0.5,
        y,
        text,
        transform=ax.transAxes,
        ha="center",
        va="center",
        fontsize=fontsize,
        color=color,
        zorder=11,
        bbox={
            "boxstyle": "round,pad=0.5",
            "facecolor": "white",
            "edgecolor": color,
            "alpha": 0.9,
        },
    )


def scenario_title(analysis: Analysis) -> str:
    """Scenario name and robot for figure titles."""
    name = analysis.scenario.name or "scenario"
    return f"{name} ({analysis.stance.robot.name})"


def area_view_points(polygon: Polygon, extra: Sequence[npt.ArrayLike] = ()) -> list[npt.ArrayLike]:
    """Points that the view must contain: the polygon if bounded, plus ``extra``."""
    out = list(extra)
    if polygon.bounded and not polygon.is_empty:
        out.append(polygon.vertices)
    return out


def trim_height(fig: Figure, axes: Sequence[Axes], passes: int = 2, width: bool = False) -> None:
    """Shrink the figure to what its equal-aspect ``axes`` (one row) use.

    Constrained layout gives each axes a cell; an equal aspect then shrinks the axes inside it
    and leaves blank bands above and below (or beside) it. The height is reduced by the
    smallest band; with ``width``, the width by the side bands of every axes.
    """
    for _ in range(passes):
        fig.canvas.draw()
        spare_h = min(
            ax.get_position(original=True).height - ax.get_position(original=False).height
            for ax in axes
        )
        spare_w = sum(
            ax.get_position(original=True).width - ax.get_position(original=False).width
            for ax in axes
        )
        w_in, h_in = fig.get_figwidth(), fig.get_figheight()
        cut_h = spare_h * h_in if spare_h * h_in >= 0.05 else 0.0
        cut_w = spare_w * w_in if width and spare_w * w_in >= 0.05 else 0.0
        # Never narrower than a title: an axes keeps its title's width.
        renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
        room = min(
            (ax.get_window_extent().width - ax.title.get_window_extent(renderer).width) / fig.dpi
            for ax in axes
        )
        cut_w = min(cut_w, max(room, 0.0) * len(axes))
        if not cut_h and not cut_w:
            return
        fig.set_size_inches(w_in - 0.9 * cut_w, h_in - cut_h + (0.02 if cut_h else 0.0))
