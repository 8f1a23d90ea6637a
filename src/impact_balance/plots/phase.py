"""LIPM phase portrait with the stable standing region (paper Fig. lipm-pplane)."""

from __future__ import annotations

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from impact_balance.analysis.analyze import Analysis
from impact_balance.balance.lipm import PhasePortrait, phase_portrait
from impact_balance.plots.style import (
    COM_COLOR,
    FONT_SMALL,
    FONT_TITLE,
    IMPACT_COLOR,
    new_figure,
)

__all__ = ["analysis_phase_portrait", "plot_phase_portrait"]


def analysis_phase_portrait(analysis: Analysis, axis: int = 0) -> PhasePortrait:
    """Sagittal (``axis=0``) or lateral (``axis=1``) phase portrait of an analysis' stance.

    The ZMP range is the chord of the ZMP support area through the CoM projection along that
    axis, relative to the CoM (so that c = 0 is the current CoM); the pendulum height is the
    CoM height above the ZMP plane.

    Raises:
        ValueError: when the ZMP support area does not contain the CoM projection along the axis.
    """
    areas = analysis.areas
    com = areas.com
    zmp = areas.zmp_area
    if zmp.is_empty:
        raise ValueError("empty ZMP support area: no phase portrait")
    G, h = zmp.halfplanes
    d = np.zeros(2)
    d[axis] = 1.0
    # { com_xy + t d : G (com_xy + t d) <= h }
    slack = h - G @ com[:2]
    rate = G @ d
    lo, hi = -np.inf, np.inf
    for s, r in zip(slack, rate, strict=True):
        if abs(r) < 1e-12:
            if s < -1e-9:
                raise ValueError(
                    "the CoM projection is outside the ZMP support area along this axis"
                )
            continue
        if r > 0:
            hi = min(hi, s / r)
        else:
            lo = max(lo, s / r)
    if not (np.isfinite(lo) and np.isfinite(hi)) or lo > hi + 1e-12:
        raise ValueError(
            "the ZMP support area has no bounded chord through the CoM along this axis"
        )
    return phase_portrait(float(com[2] - areas.plane_height), (float(lo), float(hi)), areas.gravity)


def _draw_trajectories(
    ax: Axes, portrait: PhasePortrait, xlim: tuple[float, float], ylim: tuple[float, float]
) -> None:
    """The portrait's LIPM trajectories, each with an arrow a third of the way in the view."""
    for k, traj in enumerate(portrait.trajectories):
        traj = np.asarray(traj, dtype=float)
        if len(traj) < 2:
            continue
        ax.plot(
            traj[:, 0],
            traj[:, 1],
            "-",
            color="0.45",
            lw=0.8,
            label="LIPM trajectories, saturated ZMP feedback" if k == 0 else None,
        )
        inside = np.flatnonzero(
            (traj[:, 0] > xlim[0]) & (traj[:, 0] < xlim[1]) & (np.abs(traj[:, 1]) < ylim[1])
        )
        if len(inside) > 4:
            i = inside[len(inside) // 3]
            ax.annotate(
                "",
                xy=traj[i + 1],
                xytext=traj[i],
                arrowprops={"arrowstyle": "->", "color": "0.35", "lw": 0.9},
            )


def _draw_velocities(
    ax: Axes, pre: float | None, post: tuple[float, float] | None, post_label: str
) -> None:
    """A CoM velocity (a point) and a range of them (a segment) at c = 0, m/s."""
    if post is not None:
        ax.plot(
            [0.0, 0.0],
            sorted(post),
            "-",
            color=IMPACT_COLOR,
            lw=5,
            alpha=0.8,
            solid_capstyle="butt",
            zorder=4,
            label=f"{post_label}: {min(post):+.4f} to {max(post):+.4f} m/s",
        )
    if pre is not None:
        ax.plot(
            [0.0],
            [pre],
            "o",
            color=COM_COLOR,
            mfc="white",
            mew=2,
            ms=8,
            zorder=6,
            label=f"pre-impact CoM velocity {pre:+.4f} m/s",
        )


def plot_phase_portrait(
    portrait: PhasePortrait,
    title: str | None = None,
    pre_impact: float | None = None,
    post_impact: tuple[float, float] | None = None,
    post_label: str = "post-impact CoM velocities",
) -> Figure:
    """LIPM phase portrait (c in m, cd in m/s) with the stable standing region shaded.

    The region lies between the lines c + cd / omega = z_lo and z_hi; its intersection with
    c = 0 gives the CoM velocity bounds, marked and annotated.

    Args:
        portrait: The phase portrait.
        title: The title (default: the portrait's height, ZMP range and omega).
        pre_impact: A CoM velocity at c = 0 to mark (m/s), e.g. the stance's pre-impact one.
        post_impact: A range of CoM velocities at c = 0 to draw as a segment (m/s, lowest and
            highest), e.g. the post-impact ones at the maximum contact velocity.
        post_label: The legend entry of ``post_impact``.
    """
    w = portrait.omega
    z_lo, z_hi = portrait.zmp_range
    v_lo, v_hi = portrait.com_velocity_bounds
    width = max(z_hi - z_lo, 1e-3)
    vmax = max(abs(v_lo), abs(v_hi), w * width / 2, 1e-3)
    xlim = (min(z_lo, 0.0) - 1.2 * width, max(z_hi, 0.0) + 1.2 * width)
    ylim = (-2.0 * vmax, 2.0 * vmax)

    fig = new_figure(8.5, 7.2)
    ax = fig.subplots()
    c = np.linspace(*xlim, 200)
    ax.fill_between(
        c,
        w * (z_lo - c),
        w * (z_hi - c),
        color="#b5e3b5",
        alpha=0.6,
        lw=0,
        label=r"stable standing region: $z_{lo} \leq c + \dot c/\omega \leq z_{hi}$",
    )
    ax.plot(c, w * (z_lo - c), "-", color="darkgreen", lw=1.5)
    ax.plot(c, w * (z_hi - c), "-", color="darkgreen", lw=1.5)
    for z, name in ((z_lo, "lo"), (z_hi, "hi")):
        # Label each boundary line where it crosses the top or bottom of the view.
        cd = 0.8 * ylim[1] if name == "lo" else 0.8 * ylim[0]
        cx = z - cd / w
        if xlim[0] < cx < xlim[1]:
            # Written towards the middle of the view, so that it never runs out of the axes.
            right_half = cx > 0.5 * (xlim[0] + xlim[1])
            ax.annotate(
                rf"$c + \dot c/\omega = {z:+.3g}$ m",
                (cx, cd),
                xytext=(-6 if right_half else 6, 0),
                textcoords="offset points",
                fontsize=FONT_SMALL,
                color="darkgreen",
                va="center",
                ha="right" if right_half else "left",
            )
    _draw_trajectories(ax, portrait, xlim, ylim)
    ax.axvline(0.0, color="#009E73", lw=1.2, ls="--", label="c = 0 (CoM at the reference)")
    ax.axhline(0.0, color="0.6", lw=0.6)
    # The values go in the legend, outside the axes: a label beside the points was crossed by
    # the trajectories that converge there.
    ax.plot(
        [0.0, 0.0],
        [v_lo, v_hi],
        "D",
        color="#0072B2",
        ms=7,
        zorder=5,
        label=f"CoM velocity bounds at c = 0: {v_lo:+.4f} and {v_hi:+.4f} m/s",
    )
    _draw_velocities(ax, pre_impact, post_impact, post_label)
    ax.set_xlim(*xlim)
    ax.set_ylim(*ylim)
    ax.set_xlabel("CoM position c (m)")
    ax.set_ylabel(r"CoM velocity $\dot c$ (m/s)")
    ax.grid(True, alpha=0.3)
    # Below the axes: inside, the trajectories run under it wherever it goes.
    fig.legend(loc="outside lower center", ncol=2, fontsize=FONT_SMALL, framealpha=0.9)
    gravity = w * w * portrait.com_height  # omega = sqrt(g / h)
    ax.set_title(
        title
        or (
            f"LIPM phase portrait: CoM height {portrait.com_height:.3g} m, "
            f"ZMP in [{z_lo:.3g}, {z_hi:.3g}] m,\nω = {w:.4f} 1/s with g = {gravity:.4g} m/s²"
        ),
        fontsize=FONT_TITLE,
    )
    return fig
