"""The GUI's 2D view, as SVG: the CoM velocity area with the post-impact sets, and the ZMP area.

SVG text is built directly (no figure library): cheap enough to rebuild on every update, and
drawn crisply by the browser at any size.
Top panel: the CoM velocity area (m/s), the pre-impact CoM velocity, the post-impact CoM
velocity set at the maximum contact velocity, and the set at the reference velocity (red
when the robot would fall, green otherwise). Bottom panel: the ZMP support area (m), the
contact rectangles projected on its plane, the CoM projection and, when computed, the CoM's
reach around it.
"""

from __future__ import annotations

import html
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from impact_balance.analysis.result import Analysis, ImpactAnswer
from impact_balance.geometry.polygon import Polygon
from impact_balance.gui.session import Summary, format_speed

if TYPE_CHECKING:
    from impact_balance.balance.reach import ComReach

__all__ = ["PANEL_COLORS", "svg_view"]

PANEL_COLORS = {
    "area": "#7fd3e6",
    "area_edge": "#1b8a9e",
    "zmp": "#8fbc8f",
    "zmp_edge": "#2e6b2e",
    "contact": "#8c564b",
    "at_max": "#1f3c88",
    "falls": "#d62728",
    "safe": "#2ca02c",
    "com": "#111111",
    "limit": "#f2b705",
    "grid": "#e3e3e3",
    "axis": "#888888",
    "com_reach": "#9467bd",
}


def _nice_step(span: float, target: int = 5) -> float:
    """A round tick step (1, 2, 2.5 or 5 times a power of ten) giving about ``target`` ticks."""
    raw = max(span, 1e-12) / target
    base = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if raw <= m * base:
            return m * base
    return 10.0 * base


def _fmt_tick(v: float, step: float) -> str:
    """Tick value ``v`` with the digits its ``step`` needs ("0", never "-0.0")."""
    digits = max(
        0,
        -math.floor(math.log10(step))
        + (1 if step / 10 ** math.floor(math.log10(step)) == 2.5 else 0),
    )
    s = f"{v:.{digits}f}"
    return "0" if s.strip("-0.") == "" else s


#: A point of a plot, world (x, y) (m or m/s).
_Point = Sequence[float] | npt.NDArray[np.float64]


@dataclass
class _Panel:
    """An equal-aspect plot box: world (x, y) to SVG pixels.

    Items are queued with their points, and drawn by :meth:`render` once the limits are known.
    """

    x0: float
    y0: float
    width: float
    height: float
    points: list[npt.NDArray[np.float64]] = field(default_factory=list)
    ops: list[Callable[[], str]] = field(default_factory=list)
    min_span: float = 0.2
    scale: float = field(default=1.0, init=False)
    cx: float = field(default=0.0, init=False)
    cy: float = field(default=0.0, init=False)

    def fit(self) -> None:
        """Fit the limits to the finite queued points, at least ``min_span`` wide, 15 % margin."""
        pts = (
            np.vstack([np.asarray(p, dtype=float).reshape(-1, 2) for p in self.points])
            if self.points
            else np.zeros((1, 2))
        )
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if len(pts) == 0:
            pts = np.zeros((1, 2))
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        centre = 0.5 * (lo + hi)
        span = np.maximum(hi - lo, self.min_span) * 1.15
        self.scale = min(self.width / span[0], self.height / span[1])
        self.cx, self.cy = centre

    def px(self, p: _Point) -> tuple[float, float]:
        """SVG pixels of world point ``p`` (y up in the world, down in SVG)."""
        return (
            self.x0 + 0.5 * self.width + (p[0] - self.cx) * self.scale,
            self.y0 + 0.5 * self.height - (p[1] - self.cy) * self.scale,
        )

    def world_bounds(self) -> tuple[float, float, float, float]:
        """World limits of the box: (xmin, xmax, ymin, ymax)."""
        hw, hh = 0.5 * self.width / self.scale, 0.5 * self.height / self.scale
        return self.cx - hw, self.cx + hw, self.cy - hh, self.cy + hh

    def polygon(
        self,
        vertices: npt.ArrayLike,
        fill: str,
        edge: str,
        opacity: float = 0.4,
        width: float = 1.5,
        dash: str | None = None,
        fill_none: bool = False,
    ) -> None:
        """Queue a (possibly degenerate) convex polygon; its vertices count for the limits."""
        v = np.asarray(vertices, dtype=float).reshape(-1, 2)
        if len(v) == 0:
            return
        if len(v) == 1:
            self.dot(v[0], edge, 3.5)
            return
        self.points.append(v)
        self.ops.append(lambda: self._polygon(v, fill, edge, opacity, width, dash, fill_none))

    def _polygon(
        self,
        v: npt.NDArray[np.float64],
        fill: str,
        edge: str,
        opacity: float,
        width: float,
        dash: str | None,
        fill_none: bool,
    ) -> str:
        pts = " ".join(f"{x:.1f},{y:.1f}" for x, y in (self.px(p) for p in v))
        dash_attr = f' stroke-dasharray="{dash}"' if dash else ""
        fill_attr = "none" if fill_none else fill
        tag = "polygon" if len(v) >= 3 else "polyline"
        return (
            f'<{tag} points="{pts}" fill="{fill_attr}" fill-opacity="{opacity}" stroke="{edge}" '
            f'stroke-width="{width}"{dash_attr} stroke-linejoin="round"/>'
        )

    def dot(
        self,
        p: npt.ArrayLike,
        color: str,
        r: float = 4.0,
        fill: str | None = None,
        width: float = 1.5,
    ) -> None:
        """Queue a dot of radius ``r`` px at world point ``p``."""
        point = np.asarray(p, dtype=float)[:2]
        self.points.append(point)

        def draw() -> str:
            x, y = self.px(point)
            return (
                f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r}" fill="{fill or color}" '
                f'stroke="{color}" stroke-width="{width}"/>'
            )

        self.ops.append(draw)

    def _ticks(self, axis: int, lo: float, hi: float, step: float) -> list[str]:
        """Grid lines and tick values every ``step`` from ``lo`` to ``hi`` on ``axis`` (0: x)."""
        out = []
        k = math.ceil(lo / step)
        while k * step <= hi:
            v = k * step
            stroke = PANEL_COLORS["grid"] if k else PANEL_COLORS["axis"]
            if axis == 0:
                x, _ = self.px((v, 0.0))
                out.append(
                    f'<line x1="{x:.1f}" y1="{self.y0}" x2="{x:.1f}" '
                    f'y2="{self.y0 + self.height}" stroke="{stroke}" stroke-width="1"/>'
                )
                out.append(
                    f'<text x="{x:.1f}" y="{self.y0 + self.height + 12}" font-size="10" '
                    f'text-anchor="middle" fill="#555">{_fmt_tick(v, step)}</text>'
                )
            else:
                _, y = self.px((0.0, v))
                out.append(
                    f'<line x1="{self.x0}" y1="{y:.1f}" x2="{self.x0 + self.width}" '
                    f'y2="{y:.1f}" stroke="{stroke}" stroke-width="1"/>'
                )
                out.append(
                    f'<text x="{self.x0 - 4}" y="{y + 3:.1f}" font-size="10" text-anchor="end" '
                    f'fill="#555">{_fmt_tick(v, step)}</text>'
                )
            k += 1
        return out

    def axes(self, unit: tuple[str, str]) -> str:
        """Frame, grid, tick values, and the axis labels ``unit`` = (x label, y label)."""
        xmin, xmax, ymin, ymax = self.world_bounds()
        step = _nice_step(max(xmax - xmin, ymax - ymin), 6)
        out = [
            f'<rect x="{self.x0}" y="{self.y0}" width="{self.width}" height="{self.height}" '
            f'fill="white" stroke="{PANEL_COLORS["axis"]}"/>'
        ]
        out += self._ticks(0, xmin, xmax, step)
        out += self._ticks(1, ymin, ymax, step)
        xlabel, ylabel = unit
        out.append(
            f'<text x="{self.x0 + self.width / 2:.1f}" y="{self.y0 + self.height + 26}" '
            f'font-size="11" text-anchor="middle" fill="#333">{html.escape(xlabel)}</text>'
        )
        # The y label, turned along the axis, left of the tick values.
        cx, cy = self.x0 - 40, self.y0 + self.height / 2
        out.append(
            f'<text x="{cx:.1f}" y="{cy:.1f}" font-size="11" text-anchor="middle" fill="#333" '
            f'transform="rotate(-90 {cx:.1f} {cy:.1f})">{html.escape(ylabel)}</text>'
        )
        return "\n".join(out)

    def render(self, unit: tuple[str, str]) -> str:
        """Fit the limits to every queued point, then draw the axes and the queued items."""
        self.fit()
        clip = f"clip{int(self.x0)}_{int(self.y0)}"
        return (
            f'<clipPath id="{clip}"><rect x="{self.x0}" y="{self.y0}" width="{self.width}" '
            f'height="{self.height}"/></clipPath>'
            + self.axes(unit)
            + f'<g clip-path="url(#{clip})">'
            + "\n".join(op() for op in self.ops)
            + "</g>"
        )


#: One legend row: (kind, colour, text), kind "fill", "dash" or "dot" (see :func:`_legend`).
_LegendRow = tuple[str, str, str]


def _hull(points: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Vertices of the convex hull of planar ``points``."""
    return Polygon.from_points(np.asarray(points, dtype=float).reshape(-1, 2)).vertices


def _text(
    x: float,
    y: float,
    s: str,
    size: int = 11,
    color: str = "#222",
    weight: str = "normal",
    anchor: str = "start",
) -> str:
    """An SVG ``<text>`` at (``x``, ``y``) px; ``s`` is escaped."""
    return (
        f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" fill="{color}" font-weight="{weight}" '
        f'text-anchor="{anchor}">{html.escape(s)}</text>'
    )


def _legend(x: float, y: float, items: list[_LegendRow]) -> tuple[str, float]:
    """Legend rows (kind, colour, text); kind: "fill", "dash", "dot". Returns SVG and the next y."""
    out = []
    for kind, color, label in items:
        if kind == "fill":
            out.append(
                f'<rect x="{x}" y="{y - 8}" width="14" height="9" fill="{color}" '
                f'fill-opacity="0.5" stroke="{color}"/>'
            )
        elif kind == "dash":
            out.append(
                f'<line x1="{x}" y1="{y - 4}" x2="{x + 14}" y2="{y - 4}" stroke="{color}" '
                f'stroke-width="2" stroke-dasharray="4 2"/>'
            )
        else:
            out.append(f'<circle cx="{x + 7}" cy="{y - 4}" r="4" fill="{color}"/>')
        out.append(_text(x + 20, y, label, 10))
        y += 14
    return "\n".join(out), y


@dataclass(frozen=True)
class _Layout:
    """Where the 2D view's parts go, SVG pixels.

    The view's width, the room left of the plots (tick values and the turned y label), the
    padding, and the size of one plot box.
    """

    width: int
    margin_left: int = 62
    pad: int = 8

    @property
    def plot_w(self) -> int:
        """Width of a plot box, px."""
        return self.width - self.margin_left - self.pad

    @property
    def plot_h(self) -> int:
        """Height of a plot box, px."""
        return int(0.85 * self.plot_w)


def _header(summary: Summary, layout: _Layout, y: float) -> list[str]:
    """The verdict (left) and the maximum contact velocities (right) on the line at ``y``."""
    color = PANEL_COLORS["safe"] if summary.headline == "balanced" else PANEL_COLORS["falls"]
    parts = [_text(layout.pad, y, summary.headline.upper(), 14, color, "bold")]
    if summary.max_contact_velocity is not None:
        parts.append(
            _text(
                layout.width - layout.pad,
                y,
                f"v_max {format_speed(summary.max_contact_velocity)} (CoM), "
                f"{format_speed(summary.zmp_max_contact_velocity)} (ZMP)",
                11,
                anchor="end",
            )
        )
    return parts


def _cannot_balance(layout: _Layout, y: float) -> str:
    """The words "cannot balance" across the plot box whose top is at ``y``."""
    return _text(
        layout.margin_left + layout.plot_w / 2,
        y + layout.plot_h / 2,
        "cannot balance",
        18,
        PANEL_COLORS["falls"],
        "bold",
        "middle",
    )


def _post_impact_sets(
    top: _Panel, impact: ImpactAnswer, summary: Summary, c0: npt.NDArray[np.float64]
) -> list[_LegendRow]:
    """Queue on ``top`` the post-impact CoM velocity sets (m/s) of ``impact`` from ``c0``.

    The set at the maximum contact velocity (or at the reference's when the maximum is
    unbounded), the set at the reference velocity (red when the robot falls, green otherwise)
    and the limiting vertex. Returns their legend rows.
    """
    legend: list[_LegendRow] = []
    model, limit = impact.model, impact.com
    s = impact.evaluation_speed()
    at_max = model.post_impact_com_velocities(c0, s)
    if s > 0:
        top.polygon(_hull(at_max), PANEL_COLORS["at_max"], PANEL_COLORS["at_max"], 0.25, 2)
        word = "maximum" if limit.is_finite else "reference"
        legend.append(
            ("fill", PANEL_COLORS["at_max"], f"post-impact set at the {word} {s:.3f} m/s")
        )
    reference = summary.reference_speed
    if reference is not None and limit.is_finite and reference > 0:
        at_ref = model.post_impact_com_velocities(c0, reference)
        ref_color = PANEL_COLORS["falls"] if summary.falls_at_reference else PANEL_COLORS["safe"]
        top.polygon(_hull(at_ref), ref_color, ref_color, 0.12, 1.8, dash="5 3")
        verdict = "falls" if summary.falls_at_reference else "does not fall"
        legend.append(("dash", ref_color, f"at the reference {reference:.3f} m/s: {verdict}"))
    if limit.is_finite and limit.limiting_vertex is not None and s > 0:
        top.dot(at_max[limit.limiting_vertex], "#000", 5, PANEL_COLORS["limit"], 1.0)
        legend.append(("dot", PANEL_COLORS["limit"], f"limiting vertex #{limit.limiting_vertex}"))
    return legend


def _com_velocity_panel(
    analysis: Analysis, summary: Summary, layout: _Layout, y: float
) -> tuple[list[str], float]:
    """The top panel from ``y`` (px) down, and the next free y.

    Its title, the CoM velocity area (m/s), the pre-impact CoM velocity, the post-impact sets,
    and its legend.
    """
    parts = [
        _text(
            layout.pad,
            y + 12,
            "CoM velocity area and post-impact CoM velocities",
            12,
            weight="bold",
        )
    ]
    y += 20
    top = _Panel(layout.margin_left, y, layout.plot_w, layout.plot_h, min_span=0.3)
    area = analysis.areas.com_velocity_area
    c0 = np.asarray(analysis.com_velocity, dtype=float)[:2]
    legend: list[_LegendRow] = []
    if not area.is_empty:
        top.polygon(area.vertices, PANEL_COLORS["area"], PANEL_COLORS["area_edge"], 0.45, 2)
        clipped = "" if area.bounded else ", clipped"
        legend.append(
            ("fill", PANEL_COLORS["area"], f"CoM velocity area ({area.area:.3f} m²/s²){clipped}")
        )
    if analysis.impact is not None:
        legend += _post_impact_sets(top, analysis.impact, summary, c0)
    top.dot(c0, PANEL_COLORS["com"], 4)
    legend.append(
        ("dot", PANEL_COLORS["com"], f"pre-impact CoM velocity ({c0[0]:.2f}, {c0[1]:.2f}) m/s")
    )
    parts.append(top.render(("ċx, CoM velocity x (m/s)", "ċy, CoM velocity y (m/s)")))
    if area.is_empty:
        parts.append(_cannot_balance(layout, y))
    y += layout.plot_h + 40
    svg, y = _legend(layout.margin_left, y, legend)
    parts.append(svg)
    return parts, y


def _zmp_panel(
    analysis: Analysis, layout: _Layout, y: float, reach: ComReach | None = None
) -> tuple[list[str], float]:
    """The bottom panel from ``y`` (px) down, and the next free y.

    Its title, the ZMP support area (m), the contact rectangles projected on its plane, the
    CoM's reach (when given), the CoM projection, and its legend.
    """
    areas = analysis.areas
    shrunk = f", shrunk by {areas.zmp_margin * 100:g} cm" if areas.zmp_margin > 0 else ""
    parts = [
        _text(
            layout.pad,
            y + 12,
            f"ZMP support area (plane z = {areas.plane_height:g} m{shrunk})",
            12,
            weight="bold",
        )
    ]
    y += 20
    bottom = _Panel(layout.margin_left, y, layout.plot_w, layout.plot_h, min_span=0.3)
    zmp = areas.zmp_area
    legend: list[_LegendRow] = []
    for contact in analysis.stance.contacts:
        if contact.is_point:  # a point foot: a dot
            bottom.dot(contact.position[:2], PANEL_COLORS["contact"], 3.0)
            continue
        corners = contact.corners()[:, :2]
        bottom.polygon(
            _hull(corners), "none", PANEL_COLORS["contact"], 0.0, 1.4, dash="4 2", fill_none=True
        )
    if analysis.stance.contacts:
        legend.append(("dash", PANEL_COLORS["contact"], "contact rectangles (projected)"))
    if not zmp.is_empty:
        bottom.polygon(zmp.vertices, PANEL_COLORS["zmp"], PANEL_COLORS["zmp_edge"], 0.5, 2)
        clipped = "" if zmp.bounded else ", clipped"
        legend.append(
            ("fill", PANEL_COLORS["zmp"], f"ZMP support area ({zmp.area * 1e4:.0f} cm²){clipped}")
        )
    com = np.asarray(areas.com, dtype=float)[:2]
    if reach is not None:
        bottom.polygon(
            reach.polygon(com),
            "none",
            PANEL_COLORS["com_reach"],
            0.0,
            1.6,
            dash="2 2",
            fill_none=True,
        )
        radii = reach.radii
        legend.append(
            (
                "dash",
                PANEL_COLORS["com_reach"],
                f"CoM reach at constant height ({1000 * radii.min():.0f} to "
                f"{1000 * radii.max():.0f} mm)",
            )
        )
    bottom.dot(com, PANEL_COLORS["com"], 4, "white", 2)
    legend.append(("dot", PANEL_COLORS["com"], f"CoM projection ({com[0]:.3f}, {com[1]:.3f}) m"))
    parts.append(bottom.render(("x (m)", "y (m)")))
    if zmp.is_empty:
        parts.append(_cannot_balance(layout, y))
    y += layout.plot_h + 40
    svg, y = _legend(layout.margin_left, y, legend)
    parts.append(svg)
    return parts, y


def svg_view(analysis: Analysis, width: int = 420, reach: ComReach | None = None) -> str:
    """The 2D view of ``analysis`` as an ``<svg>`` element (scales to its container's width).

    Args:
        analysis: The analysis to draw.
        width: Width of the drawing's view box, px (the height follows).
        reach: The CoM's reach of the analysis's stance, drawn around the CoM projection in
            the ZMP panel (:meth:`~impact_balance.balance.reach.ComReach.polygon`); None: not.

    Returns:
        An HTML ``<div>`` holding the ``<svg>``; text from the scenario is escaped.
    """
    summary = Summary.of(analysis)
    layout = _Layout(width)
    parts = _header(summary, layout, 18)
    top, y = _com_velocity_panel(analysis, summary, layout, 18 + 14)
    bottom, y = _zmp_panel(analysis, layout, y + 6, reach)
    height = int(y + 4)
    # Inside a box that keeps clear of the panel's scroll bar, which would cover the right
    # edge of the drawing (the maxima and the x labels).
    return (
        f'<div style="box-sizing: border-box; width: 100%; padding-right: 16px">'
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width} {height}" width="100%" '
        f'style="font-family: sans-serif; background: white; display: block">'
        + "\n".join(parts + top + bottom)
        + "</svg></div>"
    )
