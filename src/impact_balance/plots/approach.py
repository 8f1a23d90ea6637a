"""The figure of one governed approach to an unknown wall (``impact-balance approach --plots``).

Left: the reference speed, the governor's cap, the speed commanded and the point's measured
approach speed against time, the contact marked. Right: the CoM velocity through the approach
and the impact over the CoM velocity area (and the area shrunk by the scenario's ZMP margin).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from impact_balance.analysis.analyze import Analysis
from impact_balance.geometry.polygon import Polygon
from impact_balance.plots.balance import OUTCOME_COLORS
from impact_balance.plots.style import (
    AREA_COLOR,
    FONT_SMALL,
    draw_polygon,
    new_figure,
    set_limits,
)

__all__ = ["plot_approach"]


def plot_approach(trial: Any, analysis: Analysis, margin_area: Polygon | None = None) -> Figure:
    """The figure of one governed approach (see the module docstring).

    Args:
        trial: A :class:`~impact_balance.sim.studies.wall.WallTrial` (a layer above the
            figures: read by its attributes, not imported).
        analysis: The scenario's analysis (its CoM velocity area, m/s).
        margin_area: The CoM velocity area the governor used, when it differs (a ZMP margin).

    Returns:
        The figure.
    """
    fig = new_figure(11.0, 4.8)
    left, right = fig.subplots(1, 2, width_ratios=[1.3, 1.0])
    s = trial.series
    t = np.asarray(s["time"], dtype=float)
    start = trial.result.disturbance_time
    t0 = t[0] if len(t) else 0.0

    def line(key: str, **kw: Any) -> None:
        y = np.array([np.nan if x is None else x for x in s[key]], dtype=float)
        if np.isfinite(y).any():
            left.plot(t - t0, y, **kw)

    line("reference", color="0.5", ls="--", lw=1.2, label="reference")
    line("cap", color="#009E73", lw=1.5, label=f"cap ({trial.options.governor} governor)")
    line("commanded", color="#0072B2", lw=1.0, label="commanded")
    line("measured", color="black", lw=1.0, alpha=0.8, label="measured approach speed")
    if start is not None:
        left.axvline(start - t0, color=OUTCOME_COLORS["fell"], lw=0.8, ls=":", label="contact")
    top = max([trial.options.reference, trial.speed_at_contact or 0.0]) * 1.25
    left.set_ylim(-0.1 * top, top)
    left.set_xlabel("time from the start of the approach (s)")
    left.set_ylabel("approach speed (m/s)")
    left.grid(alpha=0.3)
    speed = "-" if trial.speed_at_contact is None else f"{trial.speed_at_contact:.3f} m/s"
    cap = "-" if trial.cap_at_contact is None else f"{trial.cap_at_contact:.3f} m/s"
    left.set_title(f"speed at contact {speed}, cap {cap}", fontsize=9)
    left.legend(loc="upper right", fontsize=FONT_SMALL)

    area = analysis.areas.com_velocity_area
    draw_polygon(right, area, color=AREA_COLOR, label="CoM velocity area")
    handles = [Line2D([], [], color=AREA_COLOR, lw=6, alpha=0.5, label="CoM velocity area")]
    if margin_area is not None and not margin_area.is_empty:
        draw_polygon(right, margin_area, color=AREA_COLOR, fill=False, ls="--", lw=1.0, edge="0.35")
        handles.append(Line2D([], [], color="0.35", ls="--", lw=1.0, label="with the ZMP margin"))
    series = trial.result.series
    path = np.zeros((0, 2))
    if len(series.get("time", ())):
        keep = series["time"] >= t0
        path = series["com_velocity"][keep][:, :2]
        color = OUTCOME_COLORS[trial.result.outcome]
        right.plot(path[:, 0], path[:, 1], color=color, lw=1.0)
        handles.append(
            Line2D(
                [],
                [],
                color=color,
                lw=1.0,
                label=f"CoM velocity ({trial.result.outcome.replace('_', ' ')})",
            )
        )
        if trial.result.impact is not None:
            before, after = (
                trial.result.impact.com_velocity_before,
                trial.result.impact.com_velocity_after,
            )
            right.plot(
                [before[0], after[0]], [before[1], after[1]], "o-", color="#D55E00", ms=3, lw=1.2
            )
            handles.append(
                Line2D([], [], color="#D55E00", marker="o", ms=3, label="across the impact")
            )
    set_limits(right, [area.vertices, path], min_ratio=0.5)
    right.set_aspect("equal")
    right.set_xlabel("CoM velocity x (m/s)")
    right.set_ylabel("CoM velocity y (m/s)")
    right.grid(alpha=0.3)
    right.set_title("CoM velocity through the approach and the impact", fontsize=9)
    right.legend(handles=handles, loc="upper left", fontsize=FONT_SMALL)
    o = trial.options
    fig.suptitle(
        f"{analysis.scenario.name}: approach at {o.reference:g} m/s reference, "
        f"wall {100 * o.wall_distance:g} cm away, {o.governor} governor: "
        f"{trial.result.outcome.replace('_', ' ')}",
        fontsize=10,
    )
    return fig
