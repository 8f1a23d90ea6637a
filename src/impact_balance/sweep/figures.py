"""Figures of a sweep: a curve for one varying dimension, a heat map for two.

The maximum contact velocity of the CoM criterion is drawn (the ZMP criterion as a second
curve on the one-dimensional plot). Limiting cases are marked: the best and the worst point,
the points that could not be evaluated (grey crosses), and where the limiting edge of the CoM
velocity area changes (dotted lines on a curve, contour lines on a grid heat map): on each
side of such a line a different constraint of the area limits the impact.

With more than two varying dimensions the heat map shows the first two (in the order of the
results) and, in each cell, the minimum over the others (the worst case), as its title says.
"""

from __future__ import annotations

import re
import textwrap
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.figure import Figure

from impact_balance.plots.style import (
    COM_CRITERION_COLOR,
    DPI,
    FALL_COLOR,
    OK_COLOR,
    ZMP_CRITERION_COLOR,
    needs_log_scale,
    new_figure,
)
from impact_balance.sweep.columns import EVALUATED, Status
from impact_balance.sweep.summary import load_frame

__all__ = ["TURN_DEG", "VALUED", "axis_label", "save_sweep_figures", "sweep_figures"]

FloatArray = npt.NDArray[np.float64]


def _varying(manifest: dict[str, Any], df: pd.DataFrame) -> list[str]:
    """The numeric dimensions that take more than one value."""
    dims = []
    for d in manifest["dimensions"]:
        col = df[d["name"]]
        if pd.api.types.is_numeric_dtype(col) and col.nunique() > 1:
            dims.append(d["name"])
    return dims


def _values(df: pd.DataFrame) -> FloatArray:
    """Maximum contact velocity for plotting: NaN without one to show (unbounded stays inf).

    A point already falling, or a stance that cannot balance, has a "maximum" of 0 in the
    results, which is no contact velocity at all: it is drawn with its own marker, not as 0 m/s.
    """
    v: FloatArray = df["max_contact_velocity"].to_numpy(dtype=float).copy()
    v[~df["status"].isin(VALUED).to_numpy()] = np.nan
    return v


def _mark_statuses(ax: Axes, df: pd.DataFrame, x: str, y: str | None) -> None:
    """Markers for the points without a maximum: falling, cannot balance, not evaluated."""
    for status, (marker, color, text) in _MARKS.items():
        rows = df[df["status"] == status]
        if len(rows):
            ys = rows[y] if y is not None else np.zeros(len(rows))
            ax.plot(
                rows[x],
                ys,
                marker,
                color=color,
                mfc="none" if y is None else color,
                mec="w" if y else color,
                ms=7,
                ls="",
                label=f"{text}: {len(rows)}",
            )
    bad = df[~df["status"].isin(EVALUATED)]
    if len(bad):
        ys = bad[y] if y is not None else np.zeros(len(bad))
        ax.plot(
            bad[x],
            ys,
            "x",
            color="0.5",
            ms=5,
            ls="",
            label=f"not evaluated (invalid, unreachable, error): {len(bad)}",
        )


#: Two limiting edges whose outward normals differ by more than this (deg) are different cases.
TURN_DEG = 10.0


def _turns(a: FloatArray, b: FloatArray) -> npt.NDArray[np.bool_]:
    """Where the limiting-edge direction changes between neighbours (both evaluated)."""
    diff = np.abs((a - b + 180.0) % 360.0 - 180.0)
    turns: npt.NDArray[np.bool_] = np.isfinite(a) & np.isfinite(b) & (diff > TURN_DEG)
    return turns


def _cell_edges(v: FloatArray) -> FloatArray:
    """The edges of the cells centred on the sorted values ``v``."""
    mid = 0.5 * (v[1:] + v[:-1])
    first = v[0] - (mid[0] - v[0]) if len(v) > 1 else v[0] - 0.5
    last = v[-1] + (v[-1] - mid[-1]) if len(v) > 1 else v[-1] + 0.5
    return np.concatenate([[first], mid, [last]])


def _draw_turns(ax: Axes, xs: FloatArray, ys: FloatArray, E: FloatArray) -> None:
    """White dotted lines between grid cells limited by different edges of the area."""
    bx, by = _cell_edges(xs), _cell_edges(ys)
    segments = []
    for i, j in zip(*np.nonzero(_turns(E[:, 1:], E[:, :-1])), strict=True):  # along x
        segments.append([(bx[j + 1], by[i]), (bx[j + 1], by[i + 1])])
    for i, j in zip(*np.nonzero(_turns(E[1:, :], E[:-1, :])), strict=True):  # along y
        segments.append([(bx[j], by[i + 1]), (bx[j + 1], by[i + 1])])
    if segments:
        from matplotlib.collections import LineCollection

        ax.add_collection(
            LineCollection(
                segments,
                colors="w",
                linewidths=1.0,
                linestyles=":",
                label=f"limiting edge turns > {TURN_DEG:g} deg",
            )
        )


#: Scenario keys (the last name of a key path): words and unit for an axis label.
_KEYS: dict[str, tuple[str, str]] = {
    "friction": ("friction coefficient", "-"),
    "restitution": ("restitution coefficient", "-"),
    "cone_edges": ("friction cone edges", "count"),
    "reference_velocity": ("reference velocity", "m/s"),
    "com_velocity": ("pre-impact CoM velocity", "m/s"),
    "duration": ("impact duration", "s"),
    "peak_factor": ("peak factor", "-"),
    "plane_height": ("ZMP plane height", "m"),
    "gravity": ("gravity", "m/s²"),
    "size": ("size", "m"),
    "position": ("position", "m"),
    "rpy": ("roll-pitch-yaw", "rad"),
    "normal": ("normal", "-"),
}
_XYZ = "xyz"
_PART = re.compile(r"([A-Za-z_]+)(?:\[(\d+)\])?")


def axis_label(name: str, frame: str | None = None) -> str:
    """A sweep dimension as an axis label for people, with its unit and, below, its key path.

    ``impact.friction`` -> "impact friction coefficient (-)"; ``impact.restitution[1]`` ->
    "impact restitution coefficient, upper bound (-)"; ``posture.y`` -> "target y of the
    impact frame by IK, world (m)"; ``joints.NAME`` -> "joint NAME (rad)".
    """
    if name.startswith("posture."):
        words, unit = (
            f"target {name.split('.', 1)[1]} of {frame or 'the impact frame'} by IK, world",
            "m",
        )
    elif name.endswith((".azimuth", ".elevation")):
        words, unit = f"{name.rsplit('.', 2)[-2]} {name.rsplit('.', 1)[1]}", "deg"
    elif name.startswith("joints."):
        words, unit = f"joint {name.split('.', 1)[1]}", "rad or m"
    else:
        parts = name.split(".")
        last = _PART.fullmatch(parts[-1])
        key, index = (last.group(1), last.group(2)) if last else (parts[-1], None)
        words, unit = _KEYS.get(key, (key.replace("_", " "), "scenario units"))
        owners = []
        for part in parts[:-1]:
            m = _PART.fullmatch(part)
            owners.append(
                f"{m.group(1).rstrip('s')} {m.group(2)}"
                if m and m.group(2)
                else part.replace("_", " ")
            )
        words = " ".join([*owners, words])
        if index is not None:
            if key == "restitution":
                words += ", " + ("lower" if index == "0" else "upper") + " bound"
            elif key == "size":
                words += " " + ("length (x)" if index == "0" else "width (y)")
            elif int(index) < 3:
                words += " " + _XYZ[int(index)]
            else:
                words += f" [{index}]"
    return f"{words} ({unit})\n{name}"


#: Statuses drawn with a value; the other evaluated ones have markers of their own.
VALUED: tuple[Status, ...] = ("ok", "unbounded")
#: Marker, colour and legend text of the points that have no maximum to show.
_MARKS: dict[Status, tuple[str, str, str]] = {
    "already_falling": ("v", FALL_COLOR, "falling before the impact (no maximum)"),
    "cannot_balance": ("s", "black", "cannot balance (no maximum)"),
}


def _curve(df: pd.DataFrame, x: str, title: str, frame: str | None = None) -> Figure:
    """The maximum contact velocity against one varying dimension."""
    fig = new_figure(6.4, 4.6)
    ax = fig.add_subplot()
    df = df.sort_values([x, "point"], kind="stable")
    xs = df[x].to_numpy(dtype=float)
    v = _values(df)
    z = df["zmp_max_contact_velocity"].to_numpy(dtype=float).copy()
    z[np.isnan(v)] = np.nan
    ax.plot(
        xs,
        np.where(np.isfinite(v), v, np.nan),
        "-o",
        ms=3,
        color=COM_CRITERION_COLOR,
        label="CoM criterion",
    )
    ax.plot(
        xs,
        np.where(np.isfinite(z), z, np.nan),
        "--",
        color=ZMP_CRITERION_COLOR,
        label="ZMP criterion",
    )
    ok = np.isfinite(v)
    if ok.any():
        best, worst = (
            int(np.nanargmax(np.where(ok, v, -np.inf))),
            int(np.nanargmin(np.where(ok, v, np.inf))),
        )
        ax.plot(
            xs[best],
            v[best],
            "*",
            ms=14,
            color=OK_COLOR,
            label=f"highest maximum {v[best]:.3g} m/s",
        )
        ax.plot(
            xs[worst],
            v[worst],
            "X",
            ms=10,
            color=FALL_COLOR,
            label=f"lowest maximum {v[worst]:.3g} m/s",
        )
    _mark_statuses(ax, df, x, None)
    directions = df["limiting_direction"].to_numpy(dtype=float)
    changes = np.flatnonzero(_turns(directions[1:], directions[:-1]))
    for i, k in enumerate(changes):
        ax.axvline(
            0.5 * (xs[k] + xs[k + 1]),
            ls=":",
            color="k",
            lw=0.8,
            label="limiting edge changes" if i == 0 else None,
        )
    ax.set_xlabel(axis_label(x, frame))
    if needs_log_scale(np.concatenate([v, z])):  # the ZMP criterion's maxima: a hundredth
        ax.set_yscale("log")
        ax.set_ylabel("maximum contact velocity (m/s, log scale)")
    else:
        ax.set_ylabel("maximum contact velocity (m/s)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    fig.legend(
        loc="outside lower center", ncol=2, fontsize=8
    )  # below: inside, it covered the curve
    return fig


def _heatmap(
    df: pd.DataFrame, x: str, y: str, others: list[str], title: str, frame: str | None = None
) -> Figure:
    """The maximum contact velocity over two dimensions (the worst case over the others)."""
    fig = new_figure(6.8, 6.2)
    ax = fig.add_subplot()
    df = df.assign(_v=_values(df))
    # Worst case over the other dimensions (NaN, i.e. not evaluated, only if every point is).
    cell = df.groupby([x, y], sort=True)["_v"].min() if others else df.set_index([x, y])["_v"]
    # The limiting edge of the worst case of each cell, by the direction of its outward normal
    # (edge indices are not comparable across stances; directions are).
    worst = (
        df.loc[df.assign(_w=df["_v"].fillna(np.inf)).groupby([x, y], sort=True)["_w"].idxmin()]
        if others
        else df
    )
    edge = worst.set_index([x, y])["limiting_direction"]
    xs, ys = np.unique(df[x].to_numpy(dtype=float)), np.unique(df[y].to_numpy(dtype=float))
    grid = len(cell) == len(xs) * len(ys)
    finite = np.isfinite(df["_v"].to_numpy())
    vmax = float(np.nanmax(np.where(finite, df["_v"], np.nan))) if finite.any() else 1.0
    mesh: ScalarMappable
    if grid:
        V = cell.unstack(level=0).reindex(index=ys, columns=xs).to_numpy(dtype=float)
        shown = np.where(np.isinf(V), vmax, V)
        mesh = ax.pcolormesh(
            xs,
            ys,
            np.ma.masked_invalid(shown),
            shading="nearest",
            cmap="viridis",
            vmin=0.0,
            vmax=vmax,
        )
        E = edge.unstack(level=0).reindex(index=ys, columns=xs).to_numpy(dtype=float)
        _draw_turns(ax, xs, ys, E)
        ax.set_facecolor("0.88")  # cells without a maximum (masked) show this grey
    else:
        pts = df[np.isfinite(df["_v"])]
        mesh = ax.scatter(pts[x], pts[y], c=pts["_v"], cmap="viridis", vmin=0.0, vmax=vmax, s=12)
    _mark_statuses(ax, df, x, y)
    fig.colorbar(
        mesh,
        ax=ax,
        label="maximum contact velocity (m/s)" + (" (min over other axes)" if others else ""),
    )
    ok = df[np.isfinite(df["_v"])]
    if len(ok):
        b, w = ok.loc[ok["_v"].idxmax()], ok.loc[ok["_v"].idxmin()]
        ax.plot(
            b[x],
            b[y],
            "*",
            ms=16,
            mfc=OK_COLOR,
            mec="w",
            label=f"highest maximum {b['_v']:.3g} m/s",
        )
        ax.plot(
            w[x],
            w[y],
            "X",
            ms=11,
            mfc=FALL_COLOR,
            mec="w",
            label=f"lowest maximum {w['_v']:.3g} m/s",
        )
    ax.set_xlabel(axis_label(x, frame))
    ax.set_ylabel(axis_label(y, frame))
    ax.set_title(title, fontsize=9)
    # Below the map: inside, it covered cells. Grey: the white dotted turn lines show on it.
    fig.legend(loc="outside lower center", ncol=2, fontsize=8, facecolor="0.85")
    return fig


def sweep_figures(root: str | Path) -> list[tuple[str, Figure]]:
    """(name, Figure) pairs for a sweep folder: a curve or a heat map (empty without data)."""
    manifest, df = load_frame(root)
    if not len(df):
        return []
    dims = _varying(manifest, df)
    title = (manifest.get("description") or "").strip()
    title = textwrap.fill(title, 90)
    frame = next(
        (
            a.get("frame")
            for a in manifest.get("spec", {}).get("axes", [])
            if isinstance(a, dict) and "tolerance" in a and a.get("frame")
        ),
        None,
    )  # the posture axis' frame
    if len(dims) == 1:
        return [(f"curve_{dims[0]}", _curve(df, dims[0], title, frame))]
    if len(dims) >= 2:
        return [
            (f"heatmap_{dims[0]}_{dims[1]}", _heatmap(df, dims[0], dims[1], dims[2:], title, frame))
        ]
    return []


def save_sweep_figures(
    root: str | Path, out_dir: str | Path | None = None, dpi: int = DPI
) -> list[Path]:
    """Write the figures of a sweep folder as PNG files (default ``ROOT/figures``)."""
    out = Path(out_dir) if out_dir is not None else Path(root) / "figures"
    written = []
    for name, fig in sweep_figures(root):
        out.mkdir(parents=True, exist_ok=True)
        path = out / (re.sub(r"[^A-Za-z0-9._-]+", "_", name).strip("._") + ".png")
        fig.savefig(path, dpi=dpi)
        written.append(path)
    return written
