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
from impact_balance.plots.style import (
    AREA_COLOR,
    COM_COLOR,
    CONTACT_COLOR,
    FALL_COLOR,
    ZMP_COLOR,
    area_view_points,
    centre_message,
    draw_polygon,
    fmt_speed,
    hull,
    new_figure,
    scenario_title,
    set_limits,
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
    ax.set_title(f"ZMP support area (plane z = {areas.plane_height:g} m)")
    ax.grid(True, alpha=0.3)
    # Below the axes: a legend inside would cover the area's boundary.
    ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        borderaxespad=4.8,
        fontsize=8,
        framealpha=0.9,
        ncol=2,
    )


def draw_com_velocity_area(
    ax: Axes, analysis: Analysis, n_steps: int = 5, side: Axes | None = None
) -> None:
    """CoM velocity area, pre-impact CoM velocity and post-impact sets for increasing speeds.

    The legend and the note (maxima, impact parameters, why the robot cannot balance) go in
    ``side``, an axes without frame beside ``ax`` (default: right of ``ax``, outside it).

    Args:
        ax: The axes of the CoM velocity plane (m/s, world x and y).
        analysis: The analysis drawn.
        n_steps: Post-impact sets drawn, at ``k / n_steps`` of the maximum approach speed.
        side: The axes of the legend and the note.
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
            ax, area, color=AREA_COLOR, alpha=0.4, lw=2, edge="teal", label=label, zorder=1
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
    # Outside the axes, in the side column (the legend above, this note below): nothing
    # covers the area's boundary, whatever its shape.
    _note(ax, side, lines, alarm=falling or reason is not None)
    set_limits(ax, area_view_points(area, view), margin=0.12, min_ratio=0.5)
    if area.is_empty:
        _headroom(ax)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(r"$\dot c_x$ (m/s)")
    ax.set_ylabel(r"$\dot c_y$ (m/s)")
    ax.xaxis.set_major_locator(MaxNLocator(6))
    ax.set_title("CoM velocity area and post-impact CoM velocities")
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
        lab = f"at the reference {v_ref:.3g} m/s: falls"
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
    """The post-impact sets at ``k / n_steps * top`` (m/s), k = 1..n_steps, the last one bold."""
    model, limit = im.model, im.com
    cmap = colormaps["Blues"]
    for k in range(1, n_steps + 1):
        s = top * k / n_steps
        pts = model.post_impact_com_velocities(c0, s)
        view.append(pts)
        last = k == n_steps
        if last and limit.is_finite:
            lab = f"post-impact set at v_max = {s:.3g} m/s"
        else:
            lab = f"post-impact set at {s:.3g} m/s"
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
        color="gold",
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
            color="gold",
            lw=4,
            alpha=0.8,
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
    """The note at the bottom of ``side`` (or right of ``ax``), framed in red on an alarm."""
    where = side if side is not None else ax
    x0 = 0.0 if side is not None else 1.03
    where.text(
        x0,
        0.0,
        "\n".join(lines),
        transform=where.transAxes,
        ha="left",
        va="bottom",
        fontsize=8,
        zorder=10,
        bbox={
            "boxstyle": "round,pad=0.4",
            "facecolor": "white",
            "edgecolor": FALL_COLOR if alarm else "0.6",
            "lw": 2 if alarm else 1,
        },
    )


def _velocity_legend(ax: Axes, side: Axes | None) -> None:
    """The legend of ``ax`` at the top of ``side`` (or right of ``ax``)."""
    handles, labels = ax.get_legend_handles_labels()
    if side is not None:
        side.legend(
            handles,
            labels,
            loc="upper left",
            bbox_to_anchor=(0.0, 1.0),
            borderaxespad=0.0,
            fontsize=7.5,
            framealpha=0.9,
        )
    else:
        ax.legend(loc="upper left", bbox_to_anchor=(1.03, 1.0), fontsize=7.5, framealpha=0.9)


def plot_areas(analysis: Analysis, n_steps: int = 5) -> Figure:
    """ZMP support area (left) and CoM velocity area with the post-impact sets (right).

    The post-impact CoM velocity sets are drawn for the approach speeds ``k / n_steps * v_max``,
    k = 1..n_steps (paper Fig. solving-opt), the one at v_max highlighted with its limiting
    vertex; when the reference approach speed exceeds v_max, the set at the reference speed is
    drawn in red. Without an impact only the areas are drawn.
    """
    if n_steps < 1 or not math.isfinite(n_steps):
        raise ValueError("n_steps must be >= 1")
    fig = new_figure(15, 6.2)
    # A third column holds the right panel's legend and note: constrained layout then keeps
    # them inside the canvas (a legend anchored outside an axes reached the edge).
    left, right, side = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1, 1.25, 0.5]})
    side.set_axis_off()
    draw_zmp_area(left, analysis)
    draw_com_velocity_area(right, analysis, n_steps, side=side)
    # Height from the data: both axes have an equal aspect, so a flat area in a fixed-height
    # figure leaves bands of blank space above and below it.
    # Panels as wide as their data at a common height: fixed ratios left a blank band beside
    # a narrow (tall) area.
    ratio = max(
        _aspect(left), _aspect(right), 0.75 if analysis.cannot_balance_reason is not None else 0.0
    )
    height = float(np.clip(4.2 * ratio + 2.6, 4.0, 9.0))
    axes_height = height - 2.2  # titles, tick labels and the legend below the left panel
    widths = [
        axes_height / _aspect(left),
        axes_height / _aspect(right),
        3.0,
    ]  # inches; 3 for the legend
    left.get_gridspec().set_width_ratios(widths)
    fig.set_size_inches(float(np.clip(sum(widths) + 1.8, 10.0, 20.0)), height)
    why = short_reason(analysis)
    verdict = f"cannot balance because of the {why}" if why else analysis.verdict
    fig.suptitle(f"Balance areas: {scenario_title(analysis)} - {verdict}", fontsize=12)
    return fig


def _aspect(ax: Axes) -> float:
    """Height / width of the axes' data limits."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    return abs(y1 - y0) / max(abs(x1 - x0), 1e-12)
