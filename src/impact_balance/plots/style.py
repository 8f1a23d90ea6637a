"""Shared helpers of the figure modules: figure creation, polygon drawing, limits, text."""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Polygon as PolygonPatch

from impact_balance.geometry.polygon import Polygon

#: Colours used consistently across the figures.
ZMP_COLOR = "#8fbc8f"  # ZMP support area
AREA_COLOR = "#7fd3e6"  # CoM velocity area (cyan, as in the paper)
COM_COLOR = "black"
IMPACT_COLOR = "tab:red"
OK_COLOR = "tab:blue"
FALL_COLOR = "tab:red"
CONTACT_COLOR = "tab:brown"

DPI = 120


def new_figure(width: float, height: float) -> Figure:
    """A figure on an Agg canvas that does not go through pyplot.

    No global state is touched (no ``matplotlib.use``, no pyplot figure manager), so these
    functions are safe in scripts, tests and notebooks alike; ``fig.savefig`` renders with Agg.
    """
    fig = Figure(figsize=(width, height), layout="constrained")
    # A wider margin than the default (3 pt): a legend anchored outside its axes otherwise
    # ends on the canvas' edge, where its frame is cut.
    fig.get_layout_engine().set(w_pad=0.06, h_pad=0.06)
    FigureCanvasAgg(fig)
    return fig


def fmt_speed(value: float, digits: int = 3) -> str:
    """An approach speed in m/s, ``unbounded`` for infinity."""
    if value is None or not math.isfinite(value):
        return "unbounded"
    return f"{value:.{digits}g} m/s"


def draw_polygon(
    ax: Axes,
    polygon: Polygon,
    *,
    color: str,
    alpha: float = 0.35,
    label: str | None = None,
    edge: str | None = None,
    lw: float = 1.5,
    ls: str = "-",
    zorder: float = 1.0,
    fill: bool = True,
) -> None:
    """Draw a (possibly degenerate) convex polygon: filled polygon, thick segment, or point."""
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


def hull(points: np.ndarray) -> Polygon:
    """Convex hull of planar points as a :class:`Polygon` (point or segment when degenerate)."""
    return Polygon.from_points(np.asarray(points, dtype=float).reshape(-1, 2))


def set_limits(
    ax: Axes,
    points: Iterable[np.ndarray],
    margin: float = 0.12,
    min_span: float = 0.05,
    min_ratio: float = 0.0,
) -> None:
    """Fit the axis limits to ``points`` (arrays of (k, 2)), with a relative margin.

    ``min_ratio`` keeps each span at least that fraction of the other, so that flat data
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
    ax: Axes, text: str, loc: str = "upper left", fontsize: float = 9, edgecolor: str = "0.6"
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
        bbox=dict(
            boxstyle="round,pad=0.4",
            facecolor="white",
            edgecolor=edgecolor,
            alpha=0.9,
            lw=2 if edgecolor != "0.6" else 1,
        ),
    )


def centre_message(
    ax: Axes, text: str, color: str = "tab:red", y: float = 0.5, fontsize: float = 13
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
        bbox=dict(boxstyle="round,pad=0.5", facecolor="white", edgecolor=color, alpha=0.9),
    )


def scenario_title(analysis) -> str:
    """Scenario name and robot for figure titles."""
    name = analysis.scenario.name or "scenario"
    return f"{name} ({analysis.stance.robot.name})"


def area_view_points(polygon: Polygon, extra: Sequence[np.ndarray] = ()) -> list[np.ndarray]:
    """Points that the view must contain: the polygon if bounded, plus ``extra``."""
    out = list(extra)
    if polygon.bounded and not polygon.is_empty:
        out.append(polygon.vertices)
    return out


def trim_height(fig: Figure, axes: Sequence[Axes], passes: int = 2) -> None:
    """Shrink the figure's height to what its equal-aspect ``axes`` (one row) use.

    Constrained layout gives each axes a cell; an equal aspect then shrinks the axes inside it
    and leaves blank bands above and below. The height is reduced by the smallest band.
    """
    for _ in range(passes):
        fig.canvas.draw()
        spare = min(
            ax.get_position(original=True).height - ax.get_position(original=False).height
            for ax in axes
        )
        if spare * fig.get_figheight() < 0.05:
            return
        fig.set_figheight(fig.get_figheight() * (1.0 - spare) + 0.02)
