"""The impulse set and the CoM velocity jump set of an impact (paper Fig. impulse_set)."""

from __future__ import annotations

from typing import Literal, cast

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from mpl_toolkits.mplot3d.axes3d import Axes3D
from scipy.spatial import ConvexHull, QhullError

from impact_balance.analysis.analyze import Analysis
from impact_balance.impact.model import ImpactModel
from impact_balance.plots.placement import place_inside
from impact_balance.plots.style import (
    DIGITS,
    FONT_SMALL,
    FONT_SUPTITLE,
    FONT_TITLE,
    IMPACT_COLOR,
    centre_message,
    draw_polygon,
    hull,
    new_figure,
    scenario_title,
    set_limits,
)

__all__ = ["SetSpeed", "impulse_set_speed", "plot_impulse_set"]

#: Which approach speed the sets are drawn at: the maximum contact velocity, the reference
#: approach speed, 1 m/s, or none (no impact).
SetSpeed = Literal["v_max", "reference", "unit speed", "no impact"]

FloatArray = npt.NDArray[np.float64]


def impulse_set_speed(analysis: Analysis) -> tuple[float, SetSpeed]:
    """Approach speed (m/s) at which to show the sets, and a label saying which one it is.

    The maximum contact velocity when finite and positive; otherwise the reference approach
    speed; otherwise 1 m/s (the sets scale linearly with the speed).

    Args:
        analysis: The analysis.

    Returns:
        The speed (m/s, 0 without an impact) and which one it is.
    """
    im = analysis.impact
    if im is None:
        return 0.0, "no impact"
    if im.com.is_finite and im.max_contact_velocity > 0:
        return im.max_contact_velocity, "v_max"
    ref = im.model.spec.reference_velocity
    if ref is not None and im.model.approach_speed(ref) > 0:
        return im.model.approach_speed(ref), "reference"
    return 1.0, "unit speed"


def _faces(vertices: FloatArray) -> list[FloatArray]:
    """Faces of the impulse polytope: qhull facets, or the structural faces if it is flat."""
    try:
        h = ConvexHull(vertices)
        return [vertices[s] for s in h.simplices]
    except (QhullError, ValueError):
        # Flat (c_lo == c_hi, or mu == 0): the two rings coincide or collapse; draw the rings.
        return [vertices[0::2], vertices[1::2]]


def _draw_impulse_polytope(ax: Axes3D, model: ImpactModel, speed: float) -> None:
    """The impulse set at ``speed`` (m/s, N s in world axes) with the friction cone's edges."""
    verts = model.impulse_vertices(speed)
    n = model.cone.shape[1]
    hi, lo = verts[0::2], verts[1::2]
    faces = _faces(verts)
    ax.add_collection3d(
        Poly3DCollection(faces, facecolor=IMPACT_COLOR, edgecolor="none", alpha=0.18)
    )
    # Structural edges: the two restitution rings and the edges joining them along the
    # generators.
    for ring, ls in ((hi, "-"), (lo, "--")):
        closed = np.vstack([ring, ring[:1]])
        ax.plot(*closed.T, ls, color="#9E3D00", lw=1.0)
    for i in range(n):
        ax.plot(*np.vstack([hi[i], lo[i]]).T, "-", color="#9E3D00", lw=0.6, alpha=0.7)
    c_lo, c_hi = model.spec.restitution
    ax.scatter(
        *hi.T,
        color=IMPACT_COLOR,
        s=22,
        depthshade=False,
        label=f"vertices on the plane c_r = {c_hi:g}",
    )
    ax.scatter(
        *lo.T,
        facecolor="white",
        edgecolor=IMPACT_COLOR,
        s=22,
        depthshade=False,
        label=f"vertices on the plane c_r = {c_lo:g}",
    )
    # Friction-cone generators from the origin, long enough to pass through the set.
    K = model.cone
    reach = np.linalg.norm(verts, axis=1).max() if len(verts) else 1.0
    length = 1.2 * reach / max(float(np.linalg.norm(K, axis=0).min()), 1e-12)
    for i in range(n):
        seg = np.vstack([np.zeros(3), length * K[:, i]])
        ax.plot(
            *seg.T, "-", color="0.45", lw=0.8, label="friction-cone generators" if i == 0 else None
        )
    ax.scatter([0], [0], [0], color="black", s=25, label="origin (zero impulse)")
    pts = np.vstack([verts, np.zeros((1, 3)), length * K.T])
    lo_, hi_ = pts.min(axis=0), pts.max(axis=0)
    centre, half = 0.5 * (lo_ + hi_), 0.5 * float((hi_ - lo_).max()) * 1.05
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    # Zoomed out a little: constrained layout does not see 3D axis labels, which the full
    # box would push out of the figure.
    ax.set_box_aspect((1, 1, 1), zoom=0.78)
    # Horizontal labels, padded off the ticks: labels rotated along the axes read upside
    # down from some view directions.
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_rotate_label(False)
    # Padded well off the tick labels (checked on the rendered figure by the tests).
    ax.set_xlabel(r"$\iota_x$ (N s)", labelpad=20)
    ax.set_ylabel(r"$\iota_y$ (N s)", labelpad=20)
    ax.set_zlabel(r"$\iota_z$ (N s)", labelpad=22)
    # Look from between the impulse direction and the normal of the planes of restitution
    # (W^T n), slightly from above, snapped to the nearest diagonal of the x-y axes: the two
    # rings show as ellipses, and neither horizontal axis is seen end-on (its ticks and its
    # label would pile up).
    nrm = model.normal
    plane = model.W.T @ nrm
    look = nrm + plane / max(float(np.linalg.norm(plane)), 1e-12)
    azim = (
        float(np.degrees(np.arctan2(look[1], look[0])))
        if np.linalg.norm(look[:2]) > 1e-6
        else -60.0
    )
    azim = 45.0 + 90.0 * round((azim - 45.0) / 90.0)
    for axis in (ax.xaxis, ax.yaxis, ax.zaxis):
        axis.set_major_locator(MaxNLocator(5))
    ax.view_init(elev=30, azim=azim)
    ax.legend(loc="upper left", bbox_to_anchor=(0.0, 1.0), fontsize=FONT_SMALL)


def _draw_jump_set(ax: Axes, model: ImpactModel, speed: float) -> None:
    """The CoM velocity jump set at ``speed`` (m/s), in the world's x-y plane."""
    jumps = model.com_velocity_jumps(speed)[:, :2]
    draw_polygon(
        ax,
        hull(jumps),
        color=IMPACT_COLOR,
        alpha=0.25,
        edge="#9E3D00",
        lw=1.8,
        label="CoM velocity jump set (convex hull)",
        zorder=2,
    )
    c_lo, c_hi = model.spec.restitution
    ax.plot(
        *jumps[0::2].T, "o", color=IMPACT_COLOR, ms=4.5, label=f"vertices, c_r = {c_hi:g}", zorder=4
    )
    ax.plot(
        *jumps[1::2].T,
        "o",
        mfc="white",
        mec=IMPACT_COLOR,
        ms=4.5,
        label=f"vertices, c_r = {c_lo:g}",
        zorder=4,
    )
    ax.plot(0, 0, "+", color="black", ms=12, mew=2, label="no jump", zorder=5)
    # Fitted to the set and the origin (the figure's size follows the view's shape).
    set_limits(ax, [jumps, np.zeros((1, 2))], margin=0.12, min_span=0.02, min_ratio=0.35)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel(r"$\Delta\dot c_x$ (m/s)")
    ax.set_ylabel(r"$\Delta\dot c_y$ (m/s)")
    ax.grid(True, alpha=0.3)
    # Placed by plot_impulse_set in a corner clear of the set (place_inside).
    ax.legend(fontsize=FONT_SMALL, framealpha=0.9)


def plot_impulse_set(analysis: Analysis, approach_speed: float | None = None) -> Figure:
    """3D impulse set with the friction cone (left) and the planar CoM velocity jump set (right).

    Args:
        analysis: The analysis; without an impact both panels say so.
        approach_speed: m/s; default: the maximum contact velocity (see
            :func:`impulse_set_speed`).

    Returns:
        The figure.
    """
    fig = new_figure(11, 5.4)
    grid = fig.add_gridspec(1, 2, width_ratios=[1.15, 1])
    ax3 = cast(Axes3D, fig.add_subplot(grid[0], projection="3d"))
    ax2 = fig.add_subplot(grid[1])
    title = scenario_title(analysis)
    im = analysis.impact
    if im is None:
        for ax in (ax3, ax2):
            centre_message(ax, "no impact in this scenario", color="0.3")
        ax3.set_title("Impulse set")
        ax3.set_xlabel(r"$\iota_x$ (N s)")
        ax3.set_ylabel(r"$\iota_y$ (N s)")
        ax3.set_zlabel(r"$\iota_z$ (N s)")
        ax2.set_title("CoM velocity jump set")
        ax2.set_xlabel(r"$\Delta\dot c_x$ (m/s)")
        ax2.set_ylabel(r"$\Delta\dot c_y$ (m/s)")
        fig.suptitle(f"Impulse set: {title}")
        return fig
    which: SetSpeed | Literal["given"]
    if approach_speed is None:
        speed, which = impulse_set_speed(analysis)
    else:
        speed, which = float(approach_speed), "given"
    model = im.model
    n = model.cone.shape[1]
    _draw_impulse_polytope(ax3, model, speed)
    ax3.set_title(
        f"Impulse set: {2 * n} vertices\nfriction cone with N = {n} edges "
        f"(μ = {model.spec.friction:g})",
        fontsize=FONT_TITLE,
    )
    _draw_jump_set(ax2, model, speed)
    ax2.set_title(f"CoM velocity jump set (xy), mass {model.mass:.1f} kg", fontsize=FONT_TITLE)
    tags: dict[str, str] = {
        "v_max": "the maximum contact velocity",
        "reference": "the reference approach speed",
        "unit speed": "unit approach speed",
        "given": "the given approach speed",
    }
    tag = tags[which]
    fig.suptitle(f"Impulse set at {tag} {speed:.{DIGITS}g} m/s: {title}", fontsize=FONT_SUPTITLE)

    def relayout() -> None:
        # The 3D panel square, the jump set's panel as wide as its view at the same height.
        (x0, x1), (y0, y1) = ax2.get_xlim(), ax2.get_ylim()
        wide = float(np.clip(abs(x1 - x0) / max(abs(y1 - y0), 1e-12), 0.6, 2.4))
        height = 5.4
        grid.set_width_ratios([1.15, wide])
        fig.set_size_inches(height * (1.15 + wide) * 0.8 + 0.6, height)

    relayout()
    place_inside(ax2, [ax2.get_legend()], relayout=relayout)
    return fig
