"""Top and side views of a stance: robot stick figure, contacts, CoM, ZMP area and impact."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from impact_balance.analysis.analyze import Analysis
from impact_balance.analysis.result import ImpactAnswer
from impact_balance.plots.style import (
    CAPPED_COLOR,
    COM_COLOR,
    CONTACT_COLOR,
    DIGITS,
    FONT_SMALL,
    FONT_SUPTITLE,
    FONT_TITLE,
    IMPACT_COLOR,
    REFERENCE_COLOR,
    ZMP_COLOR,
    draw_polygon,
    hull,
    new_figure,
    scenario_title,
    set_limits,
)

__all__ = ["NORMAL_LENGTH", "VELOCITY_SCALE", "joint_positions", "plot_stance"]

FloatArray = npt.NDArray[np.float64]

#: Length of the contact and impact normal arrows, m.
NORMAL_LENGTH = 0.15
#: Drawing scale of velocity arrows, m per (m/s).
VELOCITY_SCALE = 0.3


def joint_positions(analysis: Analysis) -> tuple[FloatArray, list[tuple[int, int]]]:
    """World positions of the joint origins and the parent links.

    Uses the stance's pinocchio data, already at the stance configuration (``data.oMi``).

    Args:
        analysis: The analysis whose stance is drawn.

    Returns:
        The positions (njoints x 3, m, world; row 0 the universe) and the (joint, parent)
        pairs of the links between joints.
    """
    stance = analysis.stance
    model, data = stance.model, stance.data
    pos = np.array([np.asarray(data.oMi[j].translation, dtype=float) for j in range(model.njoints)])
    links = [
        (j, int(model.parents[j])) for j in range(1, model.njoints) if int(model.parents[j]) > 0
    ]
    return pos, links


def _frame_joint(analysis: Analysis, frame: str) -> int | None:
    """The joint that moves ``frame`` (None if the robot has no such frame)."""
    stance = analysis.stance
    try:
        f = stance.model.frames[stance.robot.frame_id(frame)]
    except Exception:
        return None
    return int(f.parentJoint if hasattr(f, "parentJoint") else f.parent)  # pinocchio 3 / 2


def _arrow(
    ax: Axes,
    start: FloatArray,
    delta: FloatArray,
    color: str,
    label: str | None,
    width: float = 0.012,
    zorder: float = 7,
    ls: str = "-",
    hollow: bool = False,
) -> bool:
    """Arrow from ``start`` by ``delta`` (data units); nothing if it is too short to see.

    A ``hollow`` arrow is its outline only (another arrow drawn inside it stays visible).
    """
    if float(np.linalg.norm(delta)) < 1e-4:
        return False
    ax.arrow(
        start[0],
        start[1],
        delta[0],
        delta[1],
        width=width * 0.35 * (2.0 if hollow else 1.0),
        head_width=width * 2.2,
        head_length=width * 2.5,
        length_includes_head=True,
        facecolor="none" if hollow else color,
        edgecolor=color,
        lw=1.5 if hollow else 1.0,
        zorder=zorder,
        label=label,
        ls=ls,
    )
    return True


@dataclass
class _View:
    """One view of the stance: its axes, the world axes it shows, the points it must contain."""

    ax: Axes
    analysis: Analysis
    i: int
    k: int
    view: list[FloatArray] = field(default_factory=list)

    @property
    def top(self) -> bool:
        """The view from above (x-y)."""
        return (self.i, self.k) == (0, 1)


def _draw_view(ax: Axes, analysis: Analysis, axes: tuple[int, int], robot: bool) -> None:
    """One view (world axes ``axes``, m): robot, ZMP support area, contacts, CoM and impact."""
    v = _View(ax, analysis, *axes)
    if robot:
        _draw_robot(v)
    _draw_zmp_area(v)
    _draw_contacts(v)
    _draw_com(v)
    if analysis.impact is not None:
        _draw_impact(v, analysis.impact)
    i, k = axes
    set_limits(ax, v.view, margin=0.08, min_span=0.3)
    ax.set_aspect("equal", adjustable="box")
    names = "xyz"
    ax.set_xlabel(f"{names[i]} (m)")
    ax.set_ylabel(f"{names[k]} (m)")
    ax.grid(True, alpha=0.3)


def _draw_robot(v: _View) -> None:
    """A stick figure of the joint origins, with sticks to the contact and impact points."""
    ax, analysis, i, k = v.ax, v.analysis, v.i, v.k
    pos, links = joint_positions(analysis)
    for n, (j, p) in enumerate(links):
        seg = pos[[p, j]][:, [i, k]]
        ax.plot(
            *seg.T,
            "-",
            color="0.55",
            lw=2.0,
            solid_capstyle="round",
            zorder=2,
            label="robot (joint origins)" if n == 0 else None,
        )
    ax.plot(*pos[1:, [i, k]].T, "o", color="0.35", ms=3, zorder=2.1)
    v.view.append(pos[1:, [i, k]])
    # Sticks from the last joint to the contact and impact points.
    ends = [(c.spec.frame, c.position) for c in analysis.stance.contacts]
    if analysis.impact is not None:
        ends.append((analysis.impact.model.spec.frame, analysis.impact.model.point))
    for frame, point in ends:
        joint = _frame_joint(analysis, frame)
        if joint:
            ax.plot(
                *np.vstack([pos[joint], point])[:, [i, k]].T, ":", color="0.55", lw=1.5, zorder=2
            )


def _draw_zmp_area(v: _View) -> None:
    """The ZMP support area on its plane (a segment in a side view), and the plane."""
    ax, areas, i, top = v.ax, v.analysis.areas, v.i, v.top
    h = areas.plane_height
    zmp = areas.zmp_area
    if not zmp.is_empty:
        if top:
            draw_polygon(
                ax, zmp, color=ZMP_COLOR, alpha=0.4, lw=1.5, label="ZMP support area", zorder=1
            )
        else:
            xs = zmp.vertices[:, 0] if i == 0 else zmp.vertices[:, 1]
            ax.plot(
                [xs.min(), xs.max()],
                [h, h],
                "-",
                color=ZMP_COLOR,
                lw=7,
                alpha=0.8,
                solid_capstyle="butt",
                label="ZMP support area",
                zorder=1,
            )
        if zmp.bounded:
            v.view.append(
                np.column_stack([zmp.vertices[:, 0], zmp.vertices[:, 1]])
                if top
                else np.array([[zmp.vertices[:, 0].min(), h], [zmp.vertices[:, 0].max(), h]])
            )
    if not top:
        ax.axhline(h, color="0.3", lw=0.8, ls="--", zorder=0.5, label=f"ZMP plane z = {h:g} m")


def _draw_contacts(v: _View) -> None:
    """The contact rectangles and their normals.

    A normal seen end-on (a flat foot from above) would be an arrow of no length: it is drawn
    as the usual symbol of a vector towards the viewer.
    """
    ax, i, k, top = v.ax, v.i, v.k, v.top
    labelled = False
    for n, c in enumerate(v.analysis.stance.contacts):
        corners = c.corners()[:, [i, k]]
        v.view.append(corners)
        draw_polygon(
            ax,
            hull(corners),
            color=CONTACT_COLOR,
            alpha=0.3,
            lw=1.5,
            zorder=1.5,
            label="contact rectangles" if n == 0 else None,
        )
        seen = c.normal[[i, k]]
        if float(np.linalg.norm(seen)) < 0.35:  # within ~20 deg of the line of sight
            out = float(c.normal[3 - i - k]) * (1.0 if top else -1.0) > 0  # towards the viewer?
            ax.plot(
                *c.position[[i, k]],
                marker=r"$\odot$" if out else r"$\otimes$",
                ms=15,
                color=CONTACT_COLOR,
                ls="",
                zorder=7,
                label=None if labelled else "contact normals (⊙ towards you)",
            )
        else:
            _arrow(
                ax,
                c.position[[i, k]],
                NORMAL_LENGTH * seen,
                CONTACT_COLOR,
                None if labelled else "contact normals (⊙ towards you)",
                width=0.008,
            )
        labelled = True
        v.view.append((c.position + NORMAL_LENGTH * c.normal)[None, [i, k]])


def _draw_com(v: _View) -> None:
    """The CoM, and in a side view its projection on the ZMP plane."""
    ax, areas, i, k = v.ax, v.analysis.areas, v.i, v.k
    h = areas.plane_height
    com = areas.com
    ax.plot(*com[[i, k]], "o", color=COM_COLOR, ms=9, mfc="yellow", mew=2, zorder=9, label="CoM")
    if not v.top:
        ax.plot([com[i], com[i]], [com[2], h], "--", color=COM_COLOR, lw=1, zorder=8)
        ax.plot(com[i], h, "x", color=COM_COLOR, ms=9, mew=2, zorder=9, label="CoM projection")
    v.view.append(com[None, [i, k]])


def _draw_impact(v: _View, im: ImpactAnswer) -> None:
    """The impact point and normal, the reference velocity and the velocity capped at v_max."""
    ax, i, k = v.ax, v.i, v.k
    p = im.model.point
    ax.plot(*p[[i, k]], "o", color=IMPACT_COLOR, ms=8, zorder=9, label="impact point")
    v.view.append(p[None, [i, k]])
    _arrow(
        ax,
        p[[i, k]],
        NORMAL_LENGTH * im.model.normal[[i, k]],
        IMPACT_COLOR,
        "impact normal (impulse on the robot)",
        width=0.01,
    )
    v.view.append((p + NORMAL_LENGTH * im.model.normal)[None, [i, k]])
    reference = im.model.spec.reference_velocity
    if reference is None:
        return
    ref = np.asarray(reference, dtype=float)
    capped = im.contact_velocity
    is_capped = capped is not None and not np.allclose(capped, ref)
    # The reference as a wide hollow arrow, the capped velocity as a thin solid one inside it:
    # when the two nearly coincide, both stay visible.
    _arrow(
        ax,
        p[[i, k]],
        VELOCITY_SCALE * ref[[i, k]],
        REFERENCE_COLOR,
        f"reference velocity {np.linalg.norm(ref):.{DIGITS}g} m/s"
        f" (arrows: {VELOCITY_SCALE:g} m per m/s)",
        width=0.016,
        zorder=7,
        hollow=is_capped,
    )
    v.view.append((p + VELOCITY_SCALE * ref)[None, [i, k]])
    if is_capped and capped is not None:
        _arrow(
            ax,
            p[[i, k]],
            VELOCITY_SCALE * capped[[i, k]],
            CAPPED_COLOR,
            f"capped at v_max: {np.linalg.norm(capped):.{DIGITS}g} m/s",
            width=0.006,
            zorder=7.5,
        )


def _aspect_width(ax: Axes) -> float:
    """Width / height of the axes' data limits."""
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    return abs(x1 - x0) / max(abs(y1 - y0), 1e-12)


def plot_stance(analysis: Analysis, robot: bool = True) -> Figure:
    """Top view (x-y) and side view (x-z) of the stance.

    Shows the contact rectangles with their normals, the CoM and its projection, the ZMP
    support area on its plane, the impact point with the impact normal and the reference
    velocity (and the velocity capped at v_max), and, with ``robot``, a stick figure of the
    joint origins. Velocity arrows are drawn at 0.3 m per m/s, normals 0.15 m long.

    Args:
        analysis: The analysis whose stance is drawn.
        robot: Draw the stick figure.

    Returns:
        The figure.
    """
    fig = new_figure(13, 7)
    top, side = fig.subplots(1, 2)
    _draw_view(top, analysis, (0, 1), robot)
    top.set_title("Top view (x-y)", fontsize=FONT_TITLE)
    _draw_view(side, analysis, (0, 2), robot)
    side.set_title("Side view (x-z)", fontsize=FONT_TITLE)
    # Each panel as wide as its data at a common height (both have an equal aspect), and
    # the figure as wide as both: fixed ratios left a wide blank gap between the views.
    widths = [_aspect_width(ax) for ax in (top, side)]
    top.get_gridspec().set_width_ratios(widths)
    axes_height = min(4.9, 13.4 / sum(widths))  # inches; lower for wide views, within 15 in
    fig.set_size_inches(max(8.0, axes_height * sum(widths) + 1.6), axes_height + 2.3)
    handles, labels = side.get_legend_handles_labels()
    th, tl = top.get_legend_handles_labels()
    for hnd, lab in zip(th, tl, strict=True):
        if lab not in labels:
            handles.append(hnd)
            labels.append(lab)
    ncol = max(2, min(4, int(fig.get_figwidth() / 3.3)))  # as many columns as the width holds
    fig.legend(
        handles, labels, loc="outside lower center", ncol=ncol, fontsize=FONT_SMALL, framealpha=0.9
    )
    fig.suptitle(
        f"Stance: {scenario_title(analysis)}, mass {analysis.stance.mass:.1f} kg",
        fontsize=FONT_SUPTITLE,
    )
    return fig
