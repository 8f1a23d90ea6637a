"""The ZMP support area and the CoM velocity area with the post-impact sets.

The figure is the paper's Fig. solving-opt.
"""

from __future__ import annotations

import math
import textwrap

import numpy as np
import numpy.typing as npt
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from impact_balance.analysis.analyze import Analysis
from impact_balance.analysis.result import ImpactAnswer
from impact_balance.geometry.polygon import Polygon
from impact_balance.plots.placement import place_inside
from impact_balance.plots.style import (
    AREA_COLOR,
    AREA_EDGE,
    COM_COLOR,
    CONTACT_COLOR,
    DIGITS,
    FALL_COLOR,
    FONT_SMALL,
    FONT_SUPTITLE,
    FONT_TITLE,
    ZMP_COLOR,
    area_view_points,
    centre_message,
    draw_polygon,
    fmt_speed,
    hull,
    new_figure,
    scenario_title,
    set_limits,
    trim_height,
)

__all__ = ["draw_com_velocity_area", "draw_zmp_area", "plot_areas", "short_reason"]

FloatArray = npt.NDArray[np.float64]


def short_reason(analysis: Analysis) -> str | None:
    """Why the robot cannot balance, in a few words for a title (None when it can)."""
    reason = analysis.cannot_balance_reason
    if reason is None:
        return None
    if reason.kind == "torque_limits":
        scaled = [j for j in reason.binding_joints if j.min_scale is not None]
        if scaled:
            return f"torque limits ({scaled[0].joint} x{scaled[0].min_scale:.2g})"
        if reason.uniform_scale is not None:
            return f"torque limits (all x{reason.uniform_scale:.2g})"
        return "torque limits"
    if reason.kind == "friction":
        return "friction" + (
            f" (needs μ ≥ {reason.min_friction:.2g})" if reason.min_friction is not None else ""
        )
    if reason.kind == "com_outside":
        return "CoM outside the static-equilibrium region"
    return reason.kind.replace("_", " ")


def _headroom(ax: Axes, fraction: float = 0.3) -> None:
    """Raise the top of the view by ``fraction`` of its height: room for a message above."""
    y0, y1 = ax.get_ylim()
    ax.set_ylim(y0, y1 + fraction * (y1 - y0))


def _cannot_balance(ax: Axes, analysis: Analysis, what: str) -> None:
    """The message "cannot balance" high in ``ax``, with the reason in a few words."""
    why = short_reason(analysis)
    # High in the axes: the CoM projection and the contacts stay visible below it.
    centre_message(
        ax,
        f"cannot balance: empty {what}" + (f"\nbecause of the {why}" if why else ""),
        y=0.9,
        fontsize=11,
    )


def draw_zmp_area(ax: Axes, analysis: Analysis) -> None:
    """ZMP support area, the contact rectangles projected on the plane and the CoM projection."""
    areas = analysis.areas
    zmp = areas.zmp_area
    view: list[FloatArray] = []
    for i, contact in enumerate(analysis.stance.contacts):
        corners = contact.corners()[:, :2]
        view.append(corners)
        draw_polygon(
            ax,
            hull(corners),
            color=CONTACT_COLOR,
            lw=1.4,
            ls="--",
            zorder=2,
            fill=False,
            label="contact rectangles (projected)" if i == 0 else None,
        )
    if zmp.is_empty:
        _cannot_balance(ax, analysis, "ZMP support area")
    else:
        if zmp.bounded:
            label = f"ZMP support area ({zmp.area * 1e4:.0f} cm$^2$)"
        else:
            label = "ZMP support area, unbounded (clipped)"
        draw_polygon(ax, zmp, color=ZMP_COLOR, alpha=0.45, lw=2, label=label, zorder=1)
    com = areas.com[:2]
    ax.plot(*com, "o", color=COM_COLOR, ms=7, mfc="white", mew=2, label="CoM projection", zorder=5)
    view.append(com)
    set_limits(ax, area_view_points(zmp, view), margin=0.15, min_ratio=0.3)
    if zmp.is_empty:
        _headroom(ax)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.xaxis.set_major_locator(MaxNLocator(5))  # a narrow panel crowds the default ticks
    ax.set_title(f"ZMP support area (plane z = {areas.plane_height:g} m)", fontsize=FONT_TITLE)
    ax.grid(True, alpha=0.3)
    # Placed by plot_areas (place_inside): in a corner clear of the area, the view widened
    # when no corner is.
    ax.legend(fontsize=FONT_SMALL, framealpha=0.9)


def draw_com_velocity_area(
    ax: Axes, analysis: Analysis, n_steps: int = 5, side: Axes | None = None
) -> None:
    """CoM velocity area, pre-impact CoM velocity and post-impact sets for increasing speeds.

    The legend and the note (maxima, impact parameters, why the robot cannot balance) are
    inside ``ax``, or in ``side`` if given (an axes without frame beside ``ax``);
    :func:`plot_areas` moves them to corners of ``ax`` clear of the data
    (:func:`~impact_balance.plots.placement.place_inside`).

    Args:
        ax: The axes of the CoM velocity plane (m/s, world x and y).
        analysis: The analysis drawn.
        n_steps: Post-impact sets drawn, at ``k / n_steps`` of the maximum approach speed.
        side: The axes of the legend and the note (default: ``ax``).
    """
    areas = analysis.areas
    area = areas.com_velocity_area
    c0 = np.asarray(analysis.com_velocity[:2], dtype=float)
    view: list[FloatArray] = [c0]
    lines = []
    if area.is_empty:
        _cannot_balance(ax, analysis, "CoM velocity area")
    else:
        label = f"CoM velocity area ({len(area.vertices)} vertices)"
        if not area.bounded:
            label += ", unbounded (clipped)"
        draw_polygon(
            ax, area, color=AREA_COLOR, alpha=0.35, lw=2, edge=AREA_EDGE, label=label, zorder=1
        )
    ax.plot(*c0, "o", color=COM_COLOR, ms=7, label="pre-impact CoM velocity", zorder=6)

    im = analysis.impact
    if im is not None:
        v_ref = _draw_post_impact_sets(ax, im, area, c0, n_steps, view)
        lines += _impact_note(im, v_ref)
    else:
        lines.append("no impact in this scenario")
    falling = not area.is_empty and not analysis.com_velocity_inside
    if falling:
        lines.insert(0, "FALLING: the pre-impact CoM velocity\nis outside the area (v_max = 0)")
    reason = analysis.cannot_balance_reason
    if reason is not None:
        lines[:0] = ["CANNOT BALANCE, why:", *textwrap.wrap(str(reason), 46), ""]
    lines.append(f"ω = {areas.omega:.3f} 1/s")
    _note(ax, side, lines, alarm=falling or reason is not None)
    set_limits(ax, area_view_points(area, view), margin=0.12, min_ratio=0.5)
    if area.is_empty:
        _headroom(ax)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(r"$\dot c_x$ (m/s)")
    ax.set_ylabel(r"$\dot c_y$ (m/s)")
    ax.xaxis.set_major_locator(MaxNLocator(6))
    ax.set_title("CoM velocity area and post-impact CoM velocities", fontsize=FONT_TITLE)
    ax.grid(True, alpha=0.3)
    _velocity_legend(ax, side)


def _draw_post_impact_sets(
    ax: Axes,
    im: ImpactAnswer,
    area: Polygon,
    c0: FloatArray,
    n_steps: int,
    view: list[FloatArray],
) -> float | None:
    """The post-impact sets, the limiting vertex and edge, and the set at a falling reference.

    Args:
        ax: The axes of the CoM velocity plane.
        im: The impact answer.
        area: The CoM velocity area (m/s).
        c0: The pre-impact CoM velocity (m/s, world x and y).
        n_steps: Sets drawn, at ``k / n_steps`` of the maximum (or of the reference speed).
        view: Receives the points the view must contain.

    Returns:
        The reference approach speed (m/s, at least 0), None without a reference velocity.
    """
    model = im.model
    limit = im.com
    vmax = limit.max_contact_velocity
    ref = model.spec.reference_velocity
    v_ref = max(0.0, model.approach_speed(ref)) if ref is not None else None
    # The series k / n * v_max (or of the reference speed when there is no limit).
    top = vmax if limit.is_finite else v_ref
    if top is not None and top > 0:
        _draw_speed_series(ax, im, c0, top, n_steps, view)
        if limit.is_finite and limit.limiting_vertex is not None:
            _draw_limiting(ax, im, area, c0)
    if v_ref is not None and limit.is_finite and v_ref > vmax + 1e-12:
        pts = model.post_impact_com_velocities(c0, v_ref)
        view.append(pts)
        # An outline on top of the v_max set (no fill): when the reference is close to
        # v_max the two sets nearly coincide, and a filled red set would hide the other.
        above = 100.0 * (v_ref / vmax - 1.0) if vmax > 0 else math.inf
        lab = f"at the reference {v_ref:.{DIGITS}g} m/s: falls"
        if above < 10.0:
            lab += f"\n(only {above:.1f} % above v_max: nearly the same set)"
        draw_polygon(
            ax,
            hull(pts),
            color=FALL_COLOR,
            fill=False,
            edge=FALL_COLOR,
            lw=1.3,
            ls=(0, (4, 2)),
            label=lab,
            zorder=6,
        )
    return v_ref


def _draw_speed_series(
    ax: Axes,
    im: ImpactAnswer,
    c0: FloatArray,
    top: float,
    n_steps: int,
    view: list[FloatArray],
) -> None:
    """The post-impact sets at ``k / n_steps * top`` (m/s), k = 1..n_steps, the last one bold.

    One legend entry for the lighter sets (their speeds as fractions of the last one's).
    """
    model, limit = im.model, im.com
    cmap = colormaps["Blues"]
    name = "v_max" if limit.is_finite else "the reference"
    fractions = ", ".join(f"{k / n_steps:.2g}" for k in range(1, n_steps))
    for k in range(1, n_steps + 1):
        s = top * k / n_steps
        pts = model.post_impact_com_velocities(c0, s)
        view.append(pts)
        last = k == n_steps
        lab: str | None = None
        if last:
            at = "v_max = " if limit.is_finite else ""
            lab = f"post-impact set at {at}{s:.{DIGITS}g} m/s"
        elif k == 1:
            lab = f"post-impact sets at {fractions} x {name} (light to dark)"
        color = cmap(0.35 + 0.6 * k / n_steps)
        draw_polygon(
            ax,
            hull(pts),
            color=color,
            alpha=0.25 if not last else 0.45,
            edge="navy" if last else color,
            lw=2.5 if last else 1.0,
            label=lab,
            zorder=3 + 0.1 * k,
        )


def _draw_limiting(ax: Axes, im: ImpactAnswer, area: Polygon, c0: FloatArray) -> None:
    """The vertex of the post-impact set at v_max on the boundary, and the edge it reaches."""
    limit = im.com
    if limit.limiting_vertex is None:
        return
    p = im.model.post_impact_com_velocities(c0, limit.max_contact_velocity)[limit.limiting_vertex]
    ax.plot(
        *p,
        marker="*",
        color="#F0E442",
        mec="black",
        ms=16,
        zorder=8,
        label=f"limiting vertex #{limit.limiting_vertex} (on the boundary)",
    )
    if limit.limiting_edge is not None and len(area.vertices) >= 3:
        k = limit.limiting_edge
        e = area.vertices[[k, (k + 1) % len(area.vertices)]]
        ax.plot(
            e[:, 0],
            e[:, 1],
            "-",
            color="#F0E442",
            lw=4,
            alpha=0.9,
            zorder=2.5,
            label="limiting edge of the area",
        )


def _impact_note(im: ImpactAnswer, v_ref: float | None) -> list[str]:
    """The lines of the note about the impact: the maxima and the impact's parameters."""
    model, limit = im.model, im.com
    lines = ["maximum approach speed:"]
    lines.append(f"  CoM criterion: {fmt_speed(limit.max_contact_velocity)}")
    lines.append(f"  ZMP criterion: {fmt_speed(im.zmp_max_contact_velocity)}")
    if v_ref is not None:
        lines.append(f"  reference: {v_ref:.3g} m/s")
    lines.append(f"impact friction μ = {model.spec.friction:g}")
    lines.append(f"restitution [{model.spec.restitution[0]:g}, {model.spec.restitution[1]:g}]")
    if limit.status == "unbounded":
        lines.append("no approach speed can leave the area")
    return lines


def _note(ax: Axes, side: Axes | None, lines: list[str], alarm: bool) -> None:
    """The note (a framed text) in ``side`` or ``ax``, framed in red on an alarm."""
    where = side if side is not None else ax
    where.text(
        0.015,
        0.015,
        "\n".join(lines),
        transform=where.transAxes,
        ha="left",
        va="bottom",
        fontsize=FONT_SMALL,
        multialignment="left",
        zorder=10,
        gid="note",
        bbox={
            "boxstyle": "round,pad=0.4",
            "facecolor": "white",
            "edgecolor": FALL_COLOR if alarm else "0.6",
            "lw": 2 if alarm else 1,
        },
    )


def _velocity_legend(ax: Axes, side: Axes | None) -> None:
    """The legend of ``ax``, in ``side`` or in ``ax``."""
    handles, labels = ax.get_legend_handles_labels()
    (side if side is not None else ax).legend(
        handles, labels, fontsize=FONT_SMALL, framealpha=0.9, loc="upper left"
    )


def _size(fig: Figure, left: Axes, right: Axes, cannot_balance: bool) -> None:
    """Panels as wide as their data at a common height (both have an equal aspect)."""
    ratio = max(_aspect(left), _aspect(right), 0.75 if cannot_balance else 0.0)
    height = float(np.clip(4.4 * ratio + 2.4, 4.5, 9.5))
    axes_height = height - 2.3  # the titles, the tick labels and the legend below
    widths = [axes_height / _aspect(left), axes_height / _aspect(right)]  # inches
    grid = left.get_gridspec()
    assert grid is not None
    grid.set_width_ratios(widths)
    fig.set_size_inches(float(np.clip(sum(widths) + 1.6, 9.0, 18.0)), height)


def plot_areas(analysis: Analysis, n_steps: int = 5) -> Figure:
    """ZMP support area (left) and CoM velocity area with the post-impact sets (right).

    The post-impact CoM velocity sets are drawn for the approach speeds ``k / n_steps * v_max``,
    k = 1..n_steps (paper Fig. solving-opt), the one at v_max highlighted with its limiting
    vertex; when the reference approach speed exceeds v_max, the set at the reference speed is
    drawn in red. Without an impact only the areas are drawn. Each legend and the note (the
    maxima, the impact's parameters) sit inside their panel, in a corner clear of the data.
    """
    if n_steps < 1 or not math.isfinite(n_steps):
        raise ValueError("n_steps must be >= 1")
    fig = new_figure(12, 6.0)
    left, right = fig.subplots(1, 2)
    draw_zmp_area(left, analysis)
    draw_com_velocity_area(right, analysis, n_steps)
    why = short_reason(analysis)
    verdict = f"cannot balance because of the {why}" if why else analysis.verdict
    fig.suptitle(f"Balance areas: {scenario_title(analysis)} - {verdict}", fontsize=FONT_SUPTITLE)
    cannot = analysis.cannot_balance_reason is not None

    def relayout() -> None:
        _size(fig, left, right, cannot)
        trim_height(fig, [left, right], passes=3, width=True)

    # The velocity panel's legend under both panels (too long for a corner of the panel);
    # the ZMP panel's legend and the note inside their panels, clear of the data.
    handles, labels = right.get_legend_handles_labels()
    right.get_legend().remove()
    ncol = 3 if len(labels) > 4 else 2
    fig.legend(
        handles, labels, loc="outside lower center", ncol=ncol, fontsize=FONT_SMALL, framealpha=0.9
    )
    relayout()
    place_inside(left, [left.get_legend()], relayout=relayout)
    place_inside(right, [t for t in right.texts if t.get_gid() == "note"], relayout=relayout)
    return fig


def _aspect(ax: Axes) -> float:
    """Height / width of the axes' data limits."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    return abs(y1 - y0) / max(abs(x1 - x0), 1e-12)
