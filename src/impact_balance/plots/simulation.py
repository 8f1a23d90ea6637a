"""Figures of a simulated impact trial (``impact-balance simulate --plots DIR``)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator

from ._common import IMPACT_COLOR, draw_polygon, hull, new_figure, text_box

__all__ = ["plot_jump_on_sets", "plot_time_series"]

_MODEL_COLORS = {"composite": "tab:blue", "joint_space": "tab:orange"}


def plot_jump_on_sets(result, title: str) -> Figure:
    """The measured CoM velocity jump on the predicted jump sets of both inertia models.

    Left: both sets at the measured approach speed and restitution. Right: zoom on the
    ``joint_space`` set, usually much smaller, with the measured jump.
    """
    fig = new_figure(10.0, 4.6)
    axes = fig.subplots(1, 2)
    jump = np.asarray(result.com_velocity_jump_measured)
    for ax, names in zip(axes, (("composite", "joint_space"), ("joint_space",))):
        zoom = len(names) == 1
        points = [jump[None, :], np.zeros((1, 2))]
        if zoom:  # keep the measured jump in view unless it is far beyond the set
            extent = float(np.linalg.norm(result.predicted[names[0]].com_velocity_jumps, axis=1).max())
            points = points[1:] if np.linalg.norm(jump) > 5.0 * extent else points
        for name in names:
            p = result.predicted[name]
            draw_polygon(ax, hull(p.com_velocity_jumps), color=_MODEL_COLORS[name], alpha=0.3,
                         label=f"{name} (distance {p.distance:.4f} m/s)")
            points.append(p.com_velocity_jumps)
        pts = np.vstack(points)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.15 * max(float((hi - lo).max()), 1e-6)
        if not zoom or ((jump >= lo - pad) & (jump <= hi + pad)).all():
            ax.plot(*jump, marker="*", ms=13, color=IMPACT_COLOR, ls="", label="measured", zorder=5)
        else:
            text_box(ax, f"measured jump off this scale: ({jump[0]:+.4f}, {jump[1]:+.4f}) m/s", loc="lower left",
                     fontsize=8)
        ax.plot(0, 0, marker="+", color="k", ms=9, ls="")
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.xaxis.set_major_locator(MaxNLocator(5))
        ax.set_xlabel("CoM velocity jump x (m/s)")
        ax.set_ylabel("CoM velocity jump y (m/s)")
        ax.grid(alpha=0.3)
        ax.legend(loc="best", fontsize=8)
    axes[0].set_title("predicted jump sets and the measured jump", fontsize=10)
    axes[1].set_title("zoom: joint_space", fontsize=10)
    fig.suptitle(title, fontsize=11)
    return fig


def plot_time_series(result, title: str) -> Figure:
    """Contact forces (norm, N) and CoM velocity (x, y, m/s) against time, the impact shaded."""
    record = result.record
    fig = new_figure(9.0, 6.0)
    ax_f, ax_v = fig.subplots(2, 1, sharex=True)
    t = record.time
    for name, force in record.forces.items():
        ax_f.plot(t, np.linalg.norm(force, axis=1), label=name, color=IMPACT_COLOR if name == "impact" else None)
    ax_f.set_ylabel("contact force |f| (N)")
    ax_f.legend(fontsize=8, loc="upper left")
    for k, axis in enumerate("xy"):
        ax_v.plot(t, record.com_velocity[:, k], label=f"CoM velocity {axis}")
    ax_v.set_ylabel("CoM velocity (m/s)")
    ax_v.set_xlabel("time (s)")
    ax_v.legend(fontsize=8, loc="upper left")
    t0, t1 = result.impact_time
    for ax in (ax_f, ax_v):
        ax.axvspan(t0, t1, color=IMPACT_COLOR, alpha=0.15)
        ax.grid(alpha=0.3)
    text_box(ax_v, f"jump measured: ({result.com_velocity_jump_measured[0]:+.4f}, "
                   f"{result.com_velocity_jump_measured[1]:+.4f}) m/s", loc="lower left")
    fig.suptitle(title, fontsize=11)
    return fig
