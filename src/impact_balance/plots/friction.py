"""Post-impact sets and maximum contact velocities for several impact frictions.

The figure is the paper's Fig. miu-compare.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import numpy.typing as npt
from matplotlib import colormaps
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.typing import ColorType

from impact_balance.analysis.analyze import Analysis
from impact_balance.analysis.result import ImpactAnswer
from impact_balance.plots.impulse import impulse_set_speed
from impact_balance.plots.placement import place_inside
from impact_balance.plots.style import (
    AREA_COLOR,
    AREA_EDGE,
    COM_COLOR,
    COM_CRITERION_COLOR,
    DIGITS,
    FONT_SMALL,
    FONT_SUPTITLE,
    FONT_TITLE,
    PALETTE,
    ZMP_CRITERION_COLOR,
    area_view_points,
    draw_polygon,
    fmt_speed,
    hull,
    needs_log_scale,
    new_figure,
    set_limits,
)

__all__ = ["plot_friction_comparison"]

#: An analysis with its impact answer.
_Run = tuple[Analysis, ImpactAnswer]


def _same_area(a: Analysis, b: Analysis) -> bool:
    """The two analyses have the same CoM velocity area (to 1e-9 m/s)."""
    va, vb = a.areas.com_velocity_area.vertices, b.areas.com_velocity_area.vertices
    return va.shape == vb.shape and bool(np.allclose(va, vb, atol=1e-9))


def plot_friction_comparison(analyses: Sequence[Analysis]) -> Figure:
    """Post-impact CoM velocity sets at each analysis' own maximum, one colour per friction.

    Left: the sets on the (common) CoM velocity area, legend ``μ = 0.1: v_max = ... m/s``; an
    analysis whose area differs from the first one also gets its area outlined in its colour.
    Right: the maximum approach speed against mu for the CoM and the ZMP criteria.

    Args:
        analyses: The analyses compared; those without an impact are left out.

    Returns:
        The figure.

    Raises:
        ValueError: when no analysis has an impact.
    """
    runs = sorted(
        ((a, a.impact) for a in analyses if a.impact is not None),
        key=lambda run: run[1].model.spec.friction,
    )
    if not runs:
        raise ValueError("plot_friction_comparison needs at least one analysis with an impact")
    fig = new_figure(11, 5.6)
    ax, bar = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1]})
    _draw_sets(ax, runs)
    _draw_bars(bar, runs)
    base = runs[0][0]
    names = list(dict.fromkeys(r.scenario.name or "scenario" for r, _ in runs))
    stem = ", ".join(names) if len(names) <= 4 else f"{len(names)} scenarios"
    fig.suptitle(
        f"Impact friction comparison ({stem}; robot {base.stance.robot.name})",
        fontsize=FONT_SUPTITLE,
    )
    place_inside(ax, [ax.get_legend()])
    place_inside(bar, [bar.get_legend()])
    return fig


def _draw_sets(ax: Axes, runs: list[_Run]) -> None:
    """Left panel: each run's post-impact set at its maximum, on the CoM velocity area (m/s)."""
    base = runs[0][0]
    area = base.areas.com_velocity_area
    if not area.is_empty:
        draw_polygon(
            ax,
            area,
            color=AREA_COLOR,
            alpha=0.4,
            edge=AREA_EDGE,
            lw=2,
            label="CoM velocity area",
            zorder=1,
        )
    view = list(area_view_points(area))
    # Palette colours after the area's blue (one per friction, up to seven; then a colormap).
    colors: list[ColorType] = list(PALETTE[1 : len(runs) + 1])
    if len(runs) > len(PALETTE) - 1:
        colors = [colormaps["viridis"](i / (len(runs) - 1)) for i in range(len(runs))]
    for (run, im), color in zip(runs, colors, strict=True):
        mu = im.model.spec.friction
        c0 = run.com_velocity[:2]
        if not _same_area(run, base) and not run.areas.com_velocity_area.is_empty:
            draw_polygon(
                ax,
                run.areas.com_velocity_area,
                color=color,
                fill=False,
                lw=1.2,
                ls=":",
                zorder=1.5,
                label=f"μ = {mu:g}: its own CoM velocity area",
            )
            view += area_view_points(run.areas.com_velocity_area)
        speed, which = impulse_set_speed(run)
        pts = im.model.post_impact_com_velocities(c0, speed)
        view.append(pts)
        label = f"μ = {mu:g}: v_max = {fmt_speed(im.max_contact_velocity)}"
        if which != "v_max":
            label += f" (set at {speed:.{DIGITS}g} m/s)"
        draw_polygon(
            ax, hull(pts), color=color, alpha=0.35, edge=color, lw=2, label=label, zorder=3
        )
        lim = im.com
        if lim.is_finite and lim.limiting_vertex is not None:
            ax.plot(*pts[lim.limiting_vertex], "*", color=color, mec="black", ms=13, zorder=5)
        view.append(c0)
    c0s = np.array([r.com_velocity[:2] for r, _ in runs])
    ax.plot(*c0s.T, "o", color=COM_COLOR, ms=7, label="pre-impact CoM velocity", zorder=6)
    set_limits(ax, view, margin=0.1, min_ratio=0.5)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(r"$\dot c_x$ (m/s)")
    ax.set_ylabel(r"$\dot c_y$ (m/s)")
    ax.set_title(
        "Post-impact CoM velocity sets at each maximum\n(stars: limiting vertices)",
        fontsize=FONT_TITLE,
    )
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=FONT_SMALL, framealpha=0.9)  # placed clear of the data (place_inside)


def _draw_bars(bar: Axes, runs: list[_Run]) -> None:
    """Right panel: v_max against mu, both criteria (bars with their values written on them).

    The axis is logarithmic when the values span more than :data:`LOG_RATIO` (the ZMP
    criterion's maxima are often a hundredth of the CoM criterion's).
    """
    mus = [im.model.spec.friction for _, im in runs]
    com = np.array([im.max_contact_velocity for _, im in runs], dtype=np.float64)
    zmp = np.array([im.zmp_max_contact_velocity for _, im in runs], dtype=np.float64)
    x = np.arange(len(runs))
    width = 0.38
    finite = np.concatenate([com[np.isfinite(com)], zmp[np.isfinite(zmp)]])
    positive = finite[finite > 0]
    top = float(positive.max()) if positive.size else 1.0
    log = needs_log_scale(finite)
    bottom = float(positive.min()) / 3.0 if log else 0.0
    series: tuple[tuple[npt.NDArray[np.float64], float, str, str], ...] = (
        (com, -width / 2, COM_CRITERION_COLOR, "CoM velocity criterion"),
        (zmp, width / 2, ZMP_CRITERION_COLOR, "ZMP criterion"),
    )
    unbounded = 1.6 * top if log else 1.1 * top  # where a bar without a limit ends
    for values, dx, color, name in series:
        shown = np.where(np.isfinite(values), values, unbounded)
        shown = np.maximum(shown, bottom)  # a zero on a log axis: a bar of no height
        bars = bar.bar(x + dx, shown - bottom, width, bottom=bottom, color=color, label=name)
        for rect, v, h in zip(bars, values, shown, strict=True):
            if not np.isfinite(v):
                rect.set_hatch("//")  # no limit: drawn above the largest finite value
            text = f"{v:.{DIGITS}g}" if np.isfinite(v) else "unbounded"
            bar.annotate(
                text,
                (rect.get_x() + rect.get_width() / 2, h),
                xytext=(0, 2),
                textcoords="offset points",
                ha="center",
                va="bottom",
                fontsize=FONT_SMALL,
            )
    bar.set_xticks(x, [f"{m:g}" for m in mus])
    bar.set_xlabel("impact friction coefficient μ (-)")
    if log:
        bar.set_yscale("log")
        bar.set_ylim(bottom, top * 2.5)
        bar.set_ylabel("maximum approach speed (m/s, log scale)")
    else:
        bar.set_ylim(0, 1.2 * top)
        bar.set_ylabel("maximum approach speed (m/s)")
    bar.set_title("Maximum contact velocity vs impact friction", fontsize=FONT_TITLE)
    bar.grid(True, axis="y", alpha=0.3)
    bar.legend(fontsize=FONT_SMALL, framealpha=0.9)
