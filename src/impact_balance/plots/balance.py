"""Figures of the balance trials (paper Exp. 1 and 2) and of a checked log.

- :func:`plot_zmp_trajectories`: measured ZMP trajectories over the ZMP support area.
- :func:`plot_com_velocity_trajectories`: measured CoM velocity trajectories over the CoM velocity area.
- :func:`plot_validation`: outcome of every trial against the commanded approach speed, with the
  predictions of both criteria and both inertia models.
- :func:`plot_log_margins`: the CoM velocity margin and the ZMP margin of a checked log over time.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from ..polygon import Polygon
from ._common import AREA_COLOR, FALL_COLOR, OK_COLOR, ZMP_COLOR, draw_polygon, new_figure, set_limits

__all__ = ["plot_zmp_trajectories", "plot_com_velocity_trajectories", "plot_validation", "plot_log_margins"]


def _legend(ax, area_label: str, area_color: str) -> None:
    ax.legend(handles=[
        Line2D([], [], color=area_color, lw=6, alpha=0.5, label=area_label),
        Line2D([], [], color=OK_COLOR, label="did not fall"),
        Line2D([], [], color=FALL_COLOR, label="fell"),
    ], loc="best", fontsize=8)


def _trajectories_over(area: Polygon, area_label: str, area_color: str, trajectories: Sequence[np.ndarray],
                       fell: Sequence[bool], quantity: str, unit: str, title: str, mark_ends: bool) -> Figure:
    """Trajectories (each k x 2, world) over an area, coloured by outcome (the two figures of Exp. 2)."""
    fig = new_figure(5.5, 5.0)
    ax = fig.add_subplot()
    draw_polygon(ax, area, color=area_color, label=area_label)
    for path, f in zip(trajectories, fell):
        ax.plot(path[:, 0], path[:, 1], color=FALL_COLOR if f else OK_COLOR, lw=0.8, alpha=0.7)
        if mark_ends:
            ax.plot(path[-1:, 0], path[-1:, 1], "o", ms=2, color=FALL_COLOR if f else OK_COLOR)
    set_limits(ax, [area.vertices, *[p[np.all(np.isfinite(p), axis=1)] for p in trajectories]], min_ratio=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel(f"{quantity}x ({unit})")
    ax.set_ylabel(f"{quantity}y ({unit})")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3)
    _legend(ax, area_label, area_color)
    return fig


def plot_zmp_trajectories(area: Polygon, trajectories: Sequence[np.ndarray], fell: Sequence[bool],
                          title: str = "") -> Figure:
    """Measured ZMP trajectories (each k x 2, m, world) over the ZMP support area."""
    return _trajectories_over(area, "ZMP support area", ZMP_COLOR, trajectories, fell, "", "m",
                              title or "ZMP over the ZMP support area", mark_ends=False)


def plot_com_velocity_trajectories(area: Polygon, trajectories: Sequence[np.ndarray], fell: Sequence[bool],
                                   title: str = "") -> Figure:
    """Measured CoM velocity trajectories (each k x 2, m/s, world) over the CoM velocity area."""
    return _trajectories_over(area, "CoM velocity area", AREA_COLOR, trajectories, fell, "CoM velocity ", "m/s",
                              title or "CoM velocity over the CoM velocity area", mark_ends=True)


def plot_validation(speeds: Sequence[float], fell: Sequence[bool], predicted: dict, title: str = "") -> Figure:
    """Each trial's outcome against its commanded approach speed, with the predicted maxima."""
    fig = new_figure(7.0, 3.2)
    ax = fig.add_subplot()
    s = np.asarray(speeds, dtype=float)
    f = np.asarray(fell, dtype=bool)
    ax.scatter(s[~f], np.zeros((~f).sum()), color=OK_COLOR, label="did not fall", zorder=3)
    ax.scatter(s[f], np.ones(f.sum()), color=FALL_COLOR, marker="x", label="fell", zorder=3)
    styles = {("com_criterion", "composite"): ("tab:blue", "-"), ("com_criterion", "joint_space"): ("tab:blue", ":"),
              ("zmp_criterion", "composite"): ("tab:green", "-"), ("zmp_criterion", "joint_space"): ("tab:green", ":")}
    top = max([*s.tolist(), 0.1])
    for (crit, inertia), (color, ls) in styles.items():
        value = predicted.get(crit, {}).get(inertia)
        if value is None:
            continue
        shown = min(value, 1.5 * top)
        ax.axvline(shown, color=color, ls=ls, lw=1.2,
                   label=f"{crit.replace('_', ' ')}, {inertia}: {value:.3g} m/s" + (" (off scale)" if value > shown else ""))
    ax.set_yticks([0, 1], ["survived", "fell"])
    ax.set_ylim(-0.5, 1.5)
    ax.set_xlim(0, 1.55 * top)
    ax.set_xlabel("commanded approach speed (m/s)")
    ax.set_title(title or "Fall threshold: trials and predictions", fontsize=10)
    ax.legend(fontsize=7, loc="center right")
    ax.grid(alpha=0.3)
    return fig


def plot_log_margins(time: np.ndarray, com_velocity_margin: np.ndarray, zmp_margin: np.ndarray | None,
                     title: str = "") -> Figure:
    """CoM velocity margin (m/s) and ZMP margin (m) against time; below zero is outside the area."""
    fig = new_figure(7.0, 4.0)
    axes = fig.subplots(2 if zmp_margin is not None else 1, 1, sharex=True, squeeze=False)[:, 0]
    axes[0].plot(time, np.where(np.isfinite(com_velocity_margin), com_velocity_margin, np.nan), color=OK_COLOR)
    axes[0].axhline(0, color=FALL_COLOR, lw=0.8)
    axes[0].set_ylabel("CoM velocity margin (m/s)")
    if zmp_margin is not None:
        axes[1].plot(time, np.where(np.isfinite(zmp_margin), zmp_margin, np.nan), color="tab:green")
        axes[1].axhline(0, color=FALL_COLOR, lw=0.8)
        axes[1].set_ylabel("ZMP margin (m)")
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(title or "Margins (negative: outside the area)", fontsize=10)
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig
