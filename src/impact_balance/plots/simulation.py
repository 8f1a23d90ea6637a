"""Figures of a simulated impact trial (``impact-balance simulate --plots DIR``)."""

from __future__ import annotations

from typing import Any

import numpy as np
import numpy.typing as npt
from matplotlib.artist import Artist
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from impact_balance.plots.style import (
    IMPACT_COLOR,
    draw_polygon,
    hull,
    new_figure,
    text_box,
    trim_height,
)

__all__ = ["plot_jump_on_sets", "plot_time_series"]

# The trial results come from :mod:`impact_balance.sim`, a layer above the figures: they are
# read by their attributes (``Any``), not imported.

_MODEL_COLORS = {"composite": "#0072B2", "joint_space": "#E69F00"}


def plot_jump_on_sets(result: Any, title: str) -> Figure:
    """The measured CoM velocity jump on the predicted jump sets of both inertia models.

    Left: both sets at the measured approach speed and restitution. Right: zoom on the
    ``joint_space`` set, usually much smaller, with the measured jump.

    Args:
        result: An impact trial's result (``impact_balance.sim.trials``): its measured jump
            (m/s, world x and y), restitution and the predicted sets by inertia model.
        title: The figure's title.

    Returns:
        The figure.
    """
    fig = new_figure(10.0, 4.6)
    axes = fig.subplots(1, 2)
    jump = np.asarray(result.com_velocity_jump_measured)
    flat: set[str] = set()
    for ax, names in zip(axes, (("composite", "joint_space"), ("joint_space",)), strict=True):
        zoom = len(names) == 1
        points = [jump[None, :], np.zeros((1, 2))]
        if zoom:  # keep the measured jump in view unless it is far beyond the set
            extent = float(
                np.linalg.norm(result.predicted[names[0]].com_velocity_jumps, axis=1).max()
            )
            points = points[1:] if np.linalg.norm(jump) > 5.0 * extent else points
        for name in names:
            p = result.predicted[name]
            label = f"{name} (distance {p.distance:.4f} m/s)"
            if _flat(p.com_velocity_jumps):
                flat.add(name)
                label += " (flat: see below)"
            draw_polygon(
                ax, hull(p.com_velocity_jumps), color=_MODEL_COLORS[name], alpha=0.3, label=label
            )
            points.append(p.com_velocity_jumps)
        pts = np.vstack(points)
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        pad = 0.15 * max(float((hi - lo).max()), 1e-6)
        if not zoom or ((jump >= lo - pad) & (jump <= hi + pad)).all():
            ax.plot(*jump, marker="*", ms=13, color=IMPACT_COLOR, ls="", label="measured", zorder=5)
        else:
            text_box(
                ax,
                f"measured jump off this scale: ({jump[0]:+.4f}, {jump[1]:+.4f}) m/s",
                loc="lower left",
                fontsize=8,
            )
        ax.plot(0, 0, marker="+", color="k", ms=9, ls="")
        ax.set_xlim(lo[0] - pad, hi[0] + pad)
        ax.set_ylim(lo[1] - pad, hi[1] + pad)
        ax.set_aspect("equal", adjustable="box")
        ax.xaxis.set_major_locator(MaxNLocator(5))
        ax.set_xlabel("CoM velocity jump x (m/s)")
        ax.set_ylabel("CoM velocity jump y (m/s)")
        ax.grid(alpha=0.3)
    axes[0].set_title("predicted jump sets and the measured jump", fontsize=10)
    axes[1].set_title("zoom: joint_space", fontsize=10)
    # One legend below both panels: inside, it covered the sets or the measured jump.
    entries: dict[str, Artist] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if flat:  # why a set is a line, as the legend's last row
        entries[
            f"{' and '.join(sorted(flat))} is flat: at the single measured restitution (e = "
            f"{result.restitution_measured:.2f}) every impulse of the set lies on one plane, "
            "n·Wι = (1 + e) v,\n"
            "and seen from above (x-y) that plane is nearly edge-on, so the set shows as a line"
        ] = Line2D([], [], ls="")
    fig.legend(
        list(entries.values()),
        list(entries),
        loc="outside lower center",
        ncol=3 if not flat else 1,
        fontsize=8,
    )
    fig.suptitle(title, fontsize=11)
    # Height from the data (both panels have an equal aspect): a fixed height left blank
    # bands above and below flat panels.
    trim_height(fig, axes)
    return fig


def _flat(points: npt.ArrayLike) -> bool:
    """Whether a planar point set is (nearly) a segment: thinner than 3 % of its length."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(pts) < 3:
        return True
    centred = pts - pts.mean(axis=0)
    s = np.linalg.svd(centred, compute_uv=False)
    return bool(s[0] == 0.0 or s[1] / s[0] < 0.03)


def plot_time_series(result: Any, title: str) -> Figure:
    """Contact forces (norm, N) and CoM velocity (x, y, m/s) against time, the impact shaded.

    One legend below both panels (inside, it covered the force transient). With ``rigid``
    joints the robot floats without gravity, so its feet carry no force: a note says so.

    Args:
        result: An impact trial's result (``impact_balance.sim.trials``): its record (time,
            forces by contact, CoM velocity), impact window and joints.
        title: The figure's title.

    Returns:
        The figure.
    """
    record = result.record
    fig = new_figure(9.0, 6.4)
    ax_f, ax_v = fig.subplots(2, 1, sharex=True)
    t = record.time
    others = iter(("#0072B2", "#E69F00", "#8c564b", "0.45", "#56B4E9", "#F0E442"))
    for name, force in record.forces.items():
        label = "impact point" if name == "impact" else f"contact {name}"
        ax_f.plot(
            t,
            np.linalg.norm(force, axis=1),
            label=label,
            color=IMPACT_COLOR if name == "impact" else next(others, None),
        )
    ax_f.set_ylabel("contact force |f| (N)")
    for k, (axis, color) in enumerate(
        zip("xy", ("#009E73", "#CC79A7"), strict=True)
    ):  # not the forces' colours:
        ax_v.plot(
            t, record.com_velocity[:, k], label=f"CoM velocity {axis}", color=color
        )  # one legend
    ax_v.set_ylabel("CoM velocity (m/s)")
    ax_v.set_xlabel("time (s)")
    t0, t1 = result.impact_time
    for ax in (ax_f, ax_v):
        ax.axvspan(
            t0,
            t1,
            color=IMPACT_COLOR,
            alpha=0.15,
            gid="background",
            label=f"impact window {1e3 * (t1 - t0):.0f} ms (impulse and jump measured over it)",
        )
        ax.grid(alpha=0.3)
    handles, labels = ax_f.get_legend_handles_labels()
    h2, l2 = ax_v.get_legend_handles_labels()
    handles += h2[:-1]  # the impact window once
    labels += l2[:-1]
    if result.joints == "rigid" and any(name != "impact" for name in record.forces):
        # Say why the sole forces are zero, in the legend (a note in the axes would cover data).
        handles.append(Line2D([], [], ls=""))
        labels.append(
            "rigid joints: the robot floats, gravity off (the paper's rigid\n"
            "impact model), so the contacts carry no force"
        )
    jump = result.com_velocity_jump_measured
    handles.append(Line2D([], [], ls=""))
    labels.append(f"jump measured: ({jump[0]:+.4f}, {jump[1]:+.4f}) m/s")
    fig.legend(handles, labels, loc="outside lower center", ncol=2, fontsize=8, framealpha=0.9)
    fig.suptitle(title, fontsize=11)
    return fig
