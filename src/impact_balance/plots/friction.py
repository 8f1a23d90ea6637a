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

from impact_balance.analysis.analyze import Analysis
from impact_balance.analysis.result import ImpactAnswer
from impact_balance.plots.impulse import impulse_set_speed
from impact_balance.plots.style import (
    AREA_COLOR,
    COM_COLOR,
    area_view_points,
    draw_polygon,
    fmt_speed,
    hull,
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
    fig = new_figure(12, 6.2)
    ax, bar = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.1, 1]})
    _draw_sets(ax, runs)
    _draw_bars(bar, runs)
    base = runs[0][0]
    names = list(dict.fromkeys(r.scenario.name or "scenario" for r, _ in runs))
    stem = ", ".join(names) if len(names) <= 4 else f"{len(names)} scenarios"
    fig.suptitle(
        f"Impact friction comparison ({stem}; robot {base.stance.robot.name})", fontsize=12
    )
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
            edge="teal",
            lw=2,
            label="CoM velocity area",
            zorder=1,
        )
    view = list(area_view_points(area))
    cmap = colormaps["plasma"]
    colors = [cmap(0.05 + 0.75 * i / max(len(runs) - 1, 1)) for i in range(len(runs))]
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
            label += f" (set at {speed:.3g} m/s)"
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
        "Post-impact CoM velocity sets at each maximum (stars: limiting vertices)", fontsize=10
    )
    ax.grid(True, alpha=0.3)
    # Below the axes: inside, it would cover the area's boundary.
    ax.legend(
        loc="upper center",
        bbox_to_anchor=(0.5, 0.0),
        borderaxespad=4.8,
        fontsize=8,
        framealpha=0.9,
        ncol=2,
    )


def _draw_bars(bar: Axes, runs: list[_Run]) -> None:
    """Right panel: v_max against mu, both criteria (bars with their values written on them)."""
    mus = [im.model.spec.friction for _, im in runs]
    com = np.array([im.max_contact_velocity for _, im in runs], dtype=np.float64)
    zmp = np.array([im.zmp_max_contact_velocity for _, im in runs], dtype=np.float64)
    x = np.arange(len(runs))
    width = 0.38
    finite = np.concatenate([com[np.isfinite(com)], zmp[np.isfinite(zmp)]])
    top = float(finite.max()) if finite.size else 1.0
    top = top if top > 0 else 1.0
    series: tuple[tuple[npt.NDArray[np.float64], float, str, str], ...] = (
        (com, -width / 2, "tab:blue", "CoM velocity criterion"),
        (zmp, width / 2, "tab:orange", "ZMP criterion"),
    )
    for values, dx, color, name in series:
        shown = np.where(np.isfinite(values), values, 1.1 * top)
        bars = bar.bar(x + dx, shown, width, color=color, label=name)
        for rect, v in zip(bars, values, strict=True):
            if not np.isfinite(v):
                rect.set_hatch("//")  # no limit: drawn above the largest finite value
            text = f"{v:.3g}" if np.isfinite(v) else "unbounded"
            bar.text(
                rect.get_x() + rect.get_width() / 2,
                rect.get_height() + 0.01 * top,
                text,
                ha="center",
                va="bottom",
                fontsize=8,
            )
    bar.set_xticks(x, [f"{m:g}" for m in mus])
    bar.set_xlabel("impact friction coefficient μ (-)")
    bar.set_ylabel("maximum approach speed (m/s)")
    bar.set_ylim(0, 1.25 * top)
    bar.set_title("Maximum contact velocity vs impact friction", fontsize=10)
    bar.grid(True, axis="y", alpha=0.3)
    bar.legend(loc="upper right", fontsize=8)
