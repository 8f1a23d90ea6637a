"""The GUI's 2D view, as SVG: the CoM velocity area with the post-impact sets, and the ZMP area.

SVG text is built directly (no figure library): it costs well under a millisecond, which
keeps a full update within the GUI's budget, and the browser draws it crisply at any size.
Top panel: the CoM velocity area (m/s), the pre-impact CoM velocity, the post-impact CoM
velocity set at the maximum contact velocity, and the set at the reference velocity (red
when the robot would fall, green otherwise). Bottom panel: the ZMP support area (m), the
contact rectangles projected on its plane and the CoM projection.
"""

from __future__ import annotations

import html
import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from impact_balance.analysis.analyze import Analysis
from impact_balance.geometry.polygon import Polygon
from impact_balance.gui.session import Summary, format_speed

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
}


def _nice_step(span: float, target: int = 5) -> float:
    raw = max(span, 1e-12) / target
    base = 10.0 ** math.floor(math.log10(raw))
    for m in (1.0, 2.0, 2.5, 5.0, 10.0):
        if raw <= m * base:
            return m * base
    return 10.0 * base


def _fmt_tick(v: float, step: float) -> str:
    digits = max(
        0,
        -int(math.floor(math.log10(step)))
        + (1 if step / 10 ** math.floor(math.log10(step)) == 2.5 else 0),
    )
    s = f"{v:.{digits}f}"
    return "0" if s.strip("-0.") == "" else s


@dataclass
class _Panel:
    """An equal-aspect plot box: world (x, y) to SVG pixels."""

    x0: float
    y0: float
    width: float
    height: float
    points: list[np.ndarray] = field(default_factory=list)
    ops: list = field(default_factory=list)  # drawing deferred until the limits are known
    min_span: float = 0.2

    def fit(self) -> None:
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

    def px(self, p: Sequence[float]) -> tuple[float, float]:
        return (
            self.x0 + 0.5 * self.width + (p[0] - self.cx) * self.scale,
            self.y0 + 0.5 * self.height - (p[1] - self.cy) * self.scale,
        )

    def world_bounds(self) -> tuple[float, float, float, float]:
        hw, hh = 0.5 * self.width / self.scale, 0.5 * self.height / self.scale
        return self.cx - hw, self.cx + hw, self.cy - hh, self.cy + hh

    def polygon(
        self,
        vertices: np.ndarray,
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
        v: np.ndarray,
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
        p: Sequence[float],
        color: str,
        r: float = 4.0,
        fill: str | None = None,
        width: float = 1.5,
    ) -> None:
        """Queue a dot of radius ``r`` px at world point ``p``."""
        p = np.asarray(p, dtype=float)[:2]
        self.points.append(p)

        def draw() -> str:
            x, y = self.px(p)
            return f'<circle cx="{x:.1f}" cy="{y:.1f}" r="{r}" fill="{fill or color}" stroke="{color}" stroke-width="{width}"/>'

        self.ops.append(draw)

    def axes(self, unit: tuple[str, str]) -> str:
        """Frame, grid, tick values, and the axis labels ``unit`` = (x label, y label) with units."""
        xmin, xmax, ymin, ymax = self.world_bounds()
        step = _nice_step(max(xmax - xmin, ymax - ymin), 6)
        out = [
            f'<rect x="{self.x0}" y="{self.y0}" width="{self.width}" height="{self.height}" fill="white" stroke="{PANEL_COLORS["axis"]}"/>'
        ]
        for axis, (lo, hi) in enumerate(((xmin, xmax), (ymin, ymax))):
            k = math.ceil(lo / step)
            while k * step <= hi:
                v = k * step
                if axis == 0:
                    x, _ = self.px((v, 0.0))
                    out.append(
                        f'<line x1="{x:.1f}" y1="{self.y0}" x2="{x:.1f}" y2="{self.y0 + self.height}" '
                        f'stroke="{PANEL_COLORS["grid"] if k else PANEL_COLORS["axis"]}" stroke-width="1"/>'
                    )
                    out.append(
                        f'<text x="{x:.1f}" y="{self.y0 + self.height + 12}" font-size="10" text-anchor="middle" '
                        f'fill="#555">{_fmt_tick(v, step)}</text>'
                    )
                else:
                    _, y = self.px((0.0, v))
                    out.append(
                        f'<line x1="{self.x0}" y1="{y:.1f}" x2="{self.x0 + self.width}" y2="{y:.1f}" '
                        f'stroke="{PANEL_COLORS["grid"] if k else PANEL_COLORS["axis"]}" stroke-width="1"/>'
                    )
                    out.append(
                        f'<text x="{self.x0 - 4}" y="{y + 3:.1f}" font-size="10" text-anchor="end" '
                        f'fill="#555">{_fmt_tick(v, step)}</text>'
                    )
                k += 1
        xlabel, ylabel = unit
        out.append(
            f'<text x="{self.x0 + self.width / 2:.1f}" y="{self.y0 + self.height + 26}" font-size="11" '
            f'text-anchor="middle" fill="#333">{html.escape(xlabel)}</text>'
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
            f'<clipPath id="{clip}"><rect x="{self.x0}" y="{self.y0}" width="{self.width}" height="{self.height}"/></clipPath>'
            + self.axes(unit)
            + f'<g clip-path="url(#{clip})">'
            + "\n".join(op() for op in self.ops)
            + "</g>"
        )


def _hull(points: np.ndarray) -> np.ndarray:
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
    return (
        f'<text x="{x:.1f}" y="{y:.1f}" font-size="{size}" fill="{color}" font-weight="{weight}" '
        f'text-anchor="{anchor}">{html.escape(s)}</text>'
    )


def _legend(x: float, y: float, items: list[tuple[str, str, str]]) -> tuple[str, float]:
    """Legend rows (kind, colour, text); kind: "fill", "dash", "dot". Returns SVG and the next y."""
    out = []
    for kind, color, label in items:
        if kind == "fill":
            out.append(
                f'<rect x="{x}" y="{y - 8}" width="14" height="9" fill="{color}" fill-opacity="0.5" stroke="{color}"/>'
            )
        elif kind == "dash":
            out.append(
                f'<line x1="{x}" y1="{y - 4}" x2="{x + 14}" y2="{y - 4}" stroke="{color}" stroke-width="2" stroke-dasharray="4 2"/>'
            )
        else:
            out.append(f'<circle cx="{x + 7}" cy="{y - 4}" r="4" fill="{color}"/>')
        out.append(_text(x + 20, y, label, 10))
        y += 14
    return "\n".join(out), y


def svg_view(analysis: Analysis, width: int = 420) -> str:
    """The 2D view of ``analysis`` as an ``<svg>`` element (scales to its container's width)."""
    summary = Summary.of(analysis)
    areas = analysis.areas
    margin_left, pad = 62, 8  # room for the tick values and the turned y label
    plot_w = width - margin_left - pad
    plot_h = int(0.85 * plot_w)
    parts: list[str] = []
    y = 18
    color = PANEL_COLORS["safe"] if summary.headline == "balanced" else PANEL_COLORS["falls"]
    parts.append(_text(pad, y, summary.headline.upper(), 14, color, "bold"))
    if summary.max_contact_velocity is not None:
        parts.append(
            _text(
                width - pad,
                y,
                f"v_max {format_speed(summary.max_contact_velocity)} (CoM), "
                f"{format_speed(summary.zmp_max_contact_velocity)} (ZMP)",
                11,
                anchor="end",
            )
        )
    y += 14

    # -- CoM velocity area ----------------------------------------------------------------
    parts.append(
        _text(pad, y + 12, "CoM velocity area and post-impact CoM velocities", 12, weight="bold")
    )
    y += 20
    top = _Panel(margin_left, y, plot_w, plot_h, min_span=0.3)
    area = areas.com_velocity_area
    c0 = np.asarray(analysis.com_velocity, dtype=float)[:2]
    legend: list[tuple[str, str, str]] = []
    if not area.is_empty:
        top.polygon(area.vertices, PANEL_COLORS["area"], PANEL_COLORS["area_edge"], 0.45, 2)
        legend.append(
            (
                "fill",
                PANEL_COLORS["area"],
                f"CoM velocity area ({area.area:.3f} m²/s²)"
                + ("" if area.bounded else ", clipped"),
            )
        )
    im = analysis.impact
    if im is not None:
        model, limit = im.model, im.com
        s = im.evaluation_speed()
        at_max = model.post_impact_com_velocities(c0, s)
        if s > 0:
            top.polygon(_hull(at_max), PANEL_COLORS["at_max"], PANEL_COLORS["at_max"], 0.25, 2)
            word = "maximum" if limit.is_finite else "reference"
            legend.append(
                ("fill", PANEL_COLORS["at_max"], f"post-impact set at the {word} {s:.3f} m/s")
            )
        if summary.reference_speed is not None and limit.is_finite and summary.reference_speed > 0:
            at_ref = model.post_impact_com_velocities(c0, summary.reference_speed)
            ref_color = (
                PANEL_COLORS["falls"] if summary.falls_at_reference else PANEL_COLORS["safe"]
            )
            top.polygon(_hull(at_ref), ref_color, ref_color, 0.12, 1.8, dash="5 3")
            verdict = "falls" if summary.falls_at_reference else "does not fall"
            legend.append(
                (
                    "dash",
                    ref_color,
                    f"at the reference {summary.reference_speed:.3f} m/s: {verdict}",
                )
            )
        if limit.is_finite and limit.limiting_vertex is not None and s > 0:
            top.dot(at_max[limit.limiting_vertex], "#000", 5, PANEL_COLORS["limit"], 1.0)
            legend.append(
                ("dot", PANEL_COLORS["limit"], f"limiting vertex #{limit.limiting_vertex}")
            )
    top.dot(c0, PANEL_COLORS["com"], 4)
    legend.append(
        ("dot", PANEL_COLORS["com"], f"pre-impact CoM velocity ({c0[0]:.2f}, {c0[1]:.2f}) m/s")
    )
    parts.append(top.render(("ċx, CoM velocity x (m/s)", "ċy, CoM velocity y (m/s)")))
    if area.is_empty:
        parts.append(
            _text(
                margin_left + plot_w / 2,
                y + plot_h / 2,
                "cannot balance",
                18,
                PANEL_COLORS["falls"],
                "bold",
                "middle",
            )
        )
    y += plot_h + 40
    svg, y = _legend(margin_left, y, legend)
    parts.append(svg)

    # -- ZMP support area -----------------------------------------------------------------
    y += 6
    shrunk = f", shrunk by {areas.zmp_margin * 100:g} cm" if areas.zmp_margin > 0 else ""
    parts.append(
        _text(
            pad,
            y + 12,
            f"ZMP support area (plane z = {areas.plane_height:g} m{shrunk})",
            12,
            weight="bold",
        )
    )
    y += 20
    bottom = _Panel(margin_left, y, plot_w, plot_h, min_span=0.3)
    zmp = areas.zmp_area
    legend = []
    for contact in analysis.stance.contacts:
        corners = contact.corners()[:, :2]
        bottom.polygon(
            _hull(corners), "none", PANEL_COLORS["contact"], 0.0, 1.4, dash="4 2", fill_none=True
        )
    if analysis.stance.contacts:
        legend.append(("dash", PANEL_COLORS["contact"], "contact rectangles (projected)"))
    if not zmp.is_empty:
        bottom.polygon(zmp.vertices, PANEL_COLORS["zmp"], PANEL_COLORS["zmp_edge"], 0.5, 2)
        legend.append(
            (
                "fill",
                PANEL_COLORS["zmp"],
                f"ZMP support area ({zmp.area * 1e4:.0f} cm²)"
                + ("" if zmp.bounded else ", clipped"),
            )
        )
    com = np.asarray(areas.com, dtype=float)[:2]
    bottom.dot(com, PANEL_COLORS["com"], 4, "white", 2)
    legend.append(("dot", PANEL_COLORS["com"], f"CoM projection ({com[0]:.3f}, {com[1]:.3f}) m"))
    parts.append(bottom.render(("x (m)", "y (m)")))
    if zmp.is_empty:
        parts.append(
            _text(
                margin_left + plot_w / 2,
                y + plot_h / 2,
                "cannot balance",
                18,
                PANEL_COLORS["falls"],
                "bold",
                "middle",
            )
        )
    y += plot_h + 40
    svg, y = _legend(margin_left, y, legend)
    parts.append(svg)
    height = int(y + 4)
    # Inside a box that keeps clear of the panel's scroll bar (which otherwise covers the right
    # edge of the drawing: the maxima and the x labels were cut at a 1500 px wide window).
    return (
        f'<div style="box-sizing: border-box; width: 100%; padding-right: 16px">'
        f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {width} {height}" width="100%" '
        f'style="font-family: sans-serif; background: white; display: block">'
        + "\n".join(parts)
        + "</svg></div>"
    )
