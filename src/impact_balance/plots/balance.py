"""Figures of the balance trials (paper Exp. 1 and 2) and of a checked log.

- :func:`plot_validation`: every impact trial's outcome against the measured approach speed
  (the commanded one beside it), with the predicted maxima of both criteria.
- :func:`plot_impact_trajectories`: the CoM velocity of every impact trial over the CoM
  velocity area.
- :func:`plot_push_trajectories`: the ZMP (or the CoM velocity) after every push over its
  area, with the before-trial predictions.
- :func:`plot_log_margins`: the CoM velocity margin and the ZMP margin of a checked log over
  time.

Outcomes have one colour everywhere (:data:`OUTCOME_COLORS`); falls are drawn first, so the
trials that did not fall stay visible on top of them.

The trial results come from :mod:`impact_balance.sim`, a layer above the figures: they are
read by their attributes (``Any``), not imported.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Any, Literal

import numpy as np
import numpy.typing as npt
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

from impact_balance.analysis.analyze import Analysis
from impact_balance.geometry.polygon import Polygon
from impact_balance.plots.style import (
    AREA_COLOR,
    FALL_COLOR,
    FONT_SMALL,
    OK_COLOR,
    ZMP_COLOR,
    draw_polygon,
    new_figure,
    set_limits,
    trim_height,
)

__all__ = [
    "OUTCOME_COLORS",
    "PushView",
    "plot_impact_trajectories",
    "plot_log_margins",
    "plot_push_trajectories",
    "plot_validation",
]

#: Colour of each trial outcome.
OUTCOME_COLORS = {
    "balanced": OK_COLOR,
    "contact_broken": "#E69F00",
    "fell": FALL_COLOR,
    "aborted": "0.6",
}
_ORDER = {
    "fell": 0,
    "aborted": 1,
    "contact_broken": 2,
    "balanced": 3,
}  # drawing order: falls underneath

#: What a push figure shows: the CoM velocity over the CoM velocity area, or the ZMP over the
#: ZMP support area.
PushView = Literal["com_velocity", "zmp"]


def _outcome_handles(outcomes: Iterable[str]) -> list[Line2D]:
    """Legend entries of the outcomes present, in the order of :data:`OUTCOME_COLORS`."""
    seen = set(outcomes)
    present = [o for o in OUTCOME_COLORS if o in seen]
    return [
        Line2D([], [], color=OUTCOME_COLORS[o], lw=1.5, label=o.replace("_", " ")) for o in present
    ]


def plot_validation(result: Any) -> Figure:
    """Each impact trial's outcome against its measured and commanded approach speeds.

    The measured speed is filled, the commanded one open; the CoM and ZMP criteria's maximum
    contact velocity (composite) are lines, solid without margin, dashed with it.

    Args:
        result: The impact trials of ``validate`` (``impact_balance.sim.trials``).

    Returns:
        The figure.
    """
    fig = new_figure(8.0, 3.8)
    ax = fig.add_subplot()
    rows = {"balanced": 0, "contact_broken": 1, "fell": 2, "aborted": 3}
    speeds: list[float] = []
    for t in result.trials:
        y = rows[t.outcome]
        color = OUTCOME_COLORS[t.outcome]
        ax.plot([t.speed], [y + 0.18], "o", mfc="none", mec=color, ms=6, zorder=3)
        speeds.append(t.speed)
        if t.measured is not None:
            ax.plot([t.speed, t.measured], [y + 0.18, y], color=color, lw=0.6, alpha=0.6, zorder=2)
            ax.plot([t.measured], [y], "o", color=color, ms=6, zorder=4)
            speeds.append(t.measured)
    top = max([*speeds, 0.1])
    lines = []
    for crit, color, name in (
        ("com_criterion", "#0072B2", "CoM criterion"),
        ("zmp_criterion", "#009E73", "ZMP criterion"),
    ):
        for values, ls, note in (
            (result.predicted, "-", "no margin"),
            (result.predicted_with_margin, "--", f"ZMP margin {1000 * result.zmp_margin:g} mm"),
        ):
            value = values[crit]["composite"]
            if value is None:
                continue
            if value <= 1.3 * top:
                ax.axvline(value, color=color, ls=ls, lw=1.2, zorder=1)
            lines.append(
                Line2D(
                    [],
                    [],
                    color=color,
                    ls=ls,
                    label=f"{name} ({note}): {value:.3f} m/s"
                    + ("" if value <= 1.3 * top else " (off scale)"),
                )
            )
    b = result.bracket()
    handles = [
        Line2D([], [], marker="o", color="0.3", ls="none", label="measured at first contact"),
        Line2D([], [], marker="o", mfc="none", mec="0.3", ls="none", label="commanded"),
        *lines,
    ]
    ax.set_yticks(list(rows.values()), [k.replace("_", " ") for k in rows])
    ax.set_ylim(-0.5, 3.6)
    ax.set_xlim(0, 1.35 * top)
    ax.set_xlabel("approach speed (m/s)")
    rigid = ", joints held through the impact" if result.rigid_impact else ""
    bracket = f"stood {_speed(b['survived'])} m/s, fell {_speed(b['fell'])} m/s (measured)"
    ax.set_title(
        f"{result.scenario}: impact trials ({result.joints} joints{rigid})\n{bracket}", fontsize=10
    )
    ax.grid(alpha=0.3)
    fig.legend(handles=handles, loc="outside right center", fontsize=FONT_SMALL, frameon=False)
    return fig


def _speed(value: float | None) -> str:
    """A speed with three decimals, ``-`` for none."""
    return "-" if value is None else f"{value:.3f}"


def _area_with_margin(
    ax: Axes, area: Polygon, margin_area: Polygon | None, color: str, label: str, margin: float
) -> list[Line2D]:
    """Draw an area and, with a margin, the area shrunk by it; their legend entries."""
    draw_polygon(ax, area, color=color, label=label)
    handles = [Line2D([], [], color=color, lw=6, alpha=0.5, label=label)]
    if margin_area is not None and margin > 0 and not margin_area.is_empty:
        draw_polygon(ax, margin_area, color=color, fill=False, ls="--", lw=1.0, edge="0.35")
        handles.append(
            Line2D(
                [],
                [],
                color="0.35",
                ls="--",
                lw=1.0,
                label=f"with the ZMP margin ({1000 * margin:g} mm)",
            )
        )
    return handles


_MARKERS = "os^vDP*Xph<>"


def plot_impact_trajectories(result: Any, analysis: Analysis) -> Figure:
    """The CoM velocity of every impact trial over the CoM velocity area.

    Each line runs from just before the contact to 1.5 s after, and ends with a marker that
    the legend names by its measured speed.

    Args:
        result: The impact trials of ``validate`` (``impact_balance.sim.trials``).
        analysis: The scenario's analysis (its CoM velocity area, m/s).

    Returns:
        The figure.
    """
    areas = analysis.areas
    area = areas.com_velocity_area
    shrunk = areas.com_velocity_area_inset(result.zmp_margin) if result.zmp_margin > 0 else None
    fig = new_figure(6.4, 6.4)
    ax = fig.add_subplot()
    handles = _area_with_margin(
        ax, area, shrunk, AREA_COLOR, "CoM velocity area", result.zmp_margin
    )
    paths: list[npt.NDArray[np.float64]] = []
    trial_handles: list[Line2D] = []
    ranked = sorted(
        (t for t in result.trials if t.trajectory.get("com_velocity")),
        key=lambda t: t.measured or 0.0,
    )
    marker = {id(t): _MARKERS[k % len(_MARKERS)] for k, t in enumerate(ranked)}
    for t in sorted(ranked, key=lambda t: _ORDER[t.outcome]):
        path = np.array(
            [p for p in t.trajectory["com_velocity"] if p is not None], dtype=float
        ).reshape(-1, 2)
        if not len(path):
            continue
        color = OUTCOME_COLORS[t.outcome]
        ax.plot(path[:, 0], path[:, 1], color=color, lw=0.9, alpha=0.8)
        ax.plot(path[-1:, 0], path[-1:, 1], marker[id(t)], color=color, ms=5)
        paths.append(path)
    for t in ranked:
        speed = "no contact" if t.measured is None else f"{t.measured:.3f} m/s"
        trial_handles.append(
            Line2D(
                [],
                [],
                marker=marker[id(t)],
                color=OUTCOME_COLORS[t.outcome],
                ls="none",
                label=f"{speed}: {t.outcome.replace('_', ' ')}",
            )
        )
    set_limits(ax, [area.vertices, *paths], min_ratio=0.5)
    ax.set_aspect("equal")
    ax.set_xlabel("CoM velocity x (m/s)")
    ax.set_ylabel("CoM velocity y (m/s)")
    ax.set_title(
        f"{result.scenario}: CoM velocity through each impact\n(from the contact to 1.5 s after; "
        f"markers at the end, by measured approach speed)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    fig.legend(
        handles=handles + trial_handles,
        loc="outside lower center",
        ncols=3,
        fontsize=FONT_SMALL,
        frameon=False,
    )
    trim_height(fig, [ax])
    return fig


def plot_push_trajectories(result: Any, kind: PushView = "com_velocity") -> Figure:
    """After every push, the CoM velocity or the ZMP over its area, coloured by outcome.

    Crosses mark each push's before-trial prediction (the post-push CoM velocity, or the
    quasi-static ZMP while it acts). The directions and impulses are written under the figure.

    Args:
        result: The pushes of ``push-test`` (``impact_balance.sim.trials``).
        kind: ``"com_velocity"`` (m/s, over the CoM velocity area) or ``"zmp"`` (m, over the
            ZMP support area).

    Returns:
        The figure.
    """
    areas = result.setup.analysis.areas
    margin = result.zmp_margin
    if kind == "zmp":
        area, color, label, unit, quantity = (
            areas.zmp_area,
            ZMP_COLOR,
            "ZMP support area",
            "m",
            "ZMP",
        )
        shrunk = areas.zmp_area.inset(margin) if margin > 0 else None
    else:
        area, color, label, unit, quantity = (
            areas.com_velocity_area,
            AREA_COLOR,
            "CoM velocity area",
            "m/s",
            "CoM velocity",
        )
        shrunk = areas.com_velocity_area_inset(margin) if margin > 0 else None
    fig = new_figure(6.4, 6.6)
    ax = fig.add_subplot()
    handles = _area_with_margin(ax, area, shrunk, color, label, margin)
    paths: list[npt.NDArray[np.float64]] = []
    predicted: list[npt.NDArray[np.float64]] = []
    for o in sorted(result.outcomes, key=lambda o: _ORDER[o.outcome]):
        c = OUTCOME_COLORS[o.outcome]
        path = np.array(
            [p if p is not None else [np.nan, np.nan] for p in o.trajectory.get(kind, [])],
            dtype=float,
        ).reshape(-1, 2)
        if len(path):
            beyond = o.strict_fail and not o.fell  # came to rest, but not on its stance
            ax.plot(path[:, 0], path[:, 1], color=c, lw=0.7, alpha=0.75, ls="--" if beyond else "-")
            paths.append(path)
        guess = o.prediction.zmp if kind == "zmp" else o.prediction.com_velocity
        ax.plot([guess[0]], [guess[1]], "x", color=c, ms=4, mew=1.0, alpha=0.9, zorder=4)
        predicted.append(np.asarray(guess, dtype=float).reshape(1, 2))
    view = [area.vertices, *paths]
    if kind == "com_velocity":
        view += predicted
    set_limits(ax, view, min_ratio=0.5)
    notes = [_directions_note(result)]
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    outside = [p[0] for p in predicted if not (x0 <= p[0, 0] <= x1 and y0 <= p[0, 1] <= y1)]
    if outside:
        far = np.linalg.norm(np.array(outside) - areas.com[:2], axis=1)
        notes.append(
            f"{len(outside)} predictions lie off the view, "
            f"{far.min():.2f} to {far.max():.2f} m from the CoM"
        )
    ax.set_aspect("equal")
    ax.set_xlabel(f"{quantity} x ({unit})")
    ax.set_ylabel(f"{quantity} y ({unit})")
    what = "ZMP during and after each push" if kind == "zmp" else "CoM velocity after each push"
    fig.suptitle(
        f"{result.scenario}: {what}\n({len(result.outcomes)} pushes, "
        f"{result.setup.controller} controller, "
        f"{1000 * result.outcomes[0].push.duration:.0f} ms)",
        fontsize=9,
    )
    ax.grid(alpha=0.3)
    handles += _outcome_handles(o.outcome for o in result.outcomes)
    if any(o.strict_fail and not o.fell for o in result.outcomes):
        handles.append(
            Line2D([], [], color="0.3", ls="--", lw=0.7, label="a contact beyond the strict bounds")
        )
    handles.append(
        Line2D([], [], marker="x", color="0.3", ls="none", label="predicted before the trial")
    )
    legend = fig.legend(
        handles=handles,
        loc="outside lower center",
        ncols=3,
        fontsize=FONT_SMALL,
        frameon=False,
        title="\n".join(notes),
        title_fontsize=FONT_SMALL,
    )
    legend.get_title().set_color("0.3")
    trim_height(fig, [ax])
    return fig


def _directions_note(result: Any) -> str:
    """The pushes' directions (from world x) and impulse ranges, a few directions a line."""
    by: dict[float, list[float]] = {}
    for o in result.outcomes:
        by.setdefault(round(float(np.rad2deg(o.push.direction)), 1), []).append(o.push.magnitude)
    parts = [f"{d:g}°: {min(m):.0f}–{max(m):.0f}" for d, m in sorted(by.items())]
    lines = [", ".join(parts[i : i + 4]) for i in range(0, len(parts), 4)][:4]
    more = " ..." if len(parts) > 16 else ""
    return "push direction from world x: impulse (N s)\n" + "\n".join(lines) + more


def plot_log_margins(
    time: npt.ArrayLike,
    com_velocity_margin: npt.ArrayLike,
    zmp_margin: npt.ArrayLike | None,
    title: str = "",
) -> Figure:
    """CoM velocity margin (m/s) and ZMP margin (m) against time; below zero is outside the area.

    Args:
        time: Sample times (s).
        com_velocity_margin: The CoM velocity margin of each sample (m/s).
        zmp_margin: The ZMP margin of each sample (m), None without a logged ZMP.
        title: The figure's title.

    Returns:
        The figure.
    """
    fig = new_figure(7.0, 4.0)
    axes = fig.subplots(2 if zmp_margin is not None else 1, 1, sharex=True, squeeze=False)[:, 0]
    axes[0].plot(
        time,
        np.where(np.isfinite(com_velocity_margin), com_velocity_margin, np.nan),
        color=OK_COLOR,
    )
    axes[0].axhline(0, color=FALL_COLOR, lw=0.8)
    axes[0].set_ylabel("CoM velocity margin (m/s)")
    if zmp_margin is not None:
        axes[1].plot(time, np.where(np.isfinite(zmp_margin), zmp_margin, np.nan), color="#009E73")
        axes[1].axhline(0, color=FALL_COLOR, lw=0.8)
        axes[1].set_ylabel("ZMP margin (m)")
    axes[-1].set_xlabel("time (s)")
    axes[0].set_title(title or "Margins (negative: outside the area)", fontsize=10)
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig
