"""Read a sweep folder back: counts by status, the best and the worst points.

"Best" and "worst" rank the evaluated points by the maximum contact velocity of the CoM
criterion (an unbounded maximum ranks first); points that could not be evaluated (invalid,
unreachable, error) are counted but not ranked.

The folder is checked first (:func:`~impact_balance.sweep.store.check_folder`): only good parts
are read; a bad part is named in ``problems`` (and the summary is not ``complete``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from impact_balance.json_values import json_number
from impact_balance.sweep.evaluate import STATUSES
from impact_balance.sweep.store import FolderCheck, load_results

__all__ = ["EVALUATED", "format_summary", "load_frame", "summarize"]

#: Statuses of points that were evaluated (the others are rows with a message).
EVALUATED = ("ok", "unbounded", "already_falling", "cannot_balance")

_SHOWN = (
    "status",
    "verdict",
    "max_contact_velocity",
    "zmp_max_contact_velocity",
    "limiting_vertex",
    "limiting_edge",
)


def load_frame(
    root: str | Path, check: list[FolderCheck] | None = None
) -> tuple[dict[str, Any], pd.DataFrame]:
    """The manifest and the rows of the good parts (a pandas DataFrame sorted by point, without
    the configurations ``q``); ``check``, if given, receives the folder's check.
    """
    found, table = load_results(root)
    if check is not None:
        check.append(found)
    if "q" in table.column_names:
        table = table.drop_columns(["q"])  # one array per row: heavy in pandas, not summarized
    frame = table.to_pandas() if table.num_columns else pd.DataFrame()
    return found.manifest, frame


def _clean(value: Any) -> Any:
    """A JSON-safe value: NaN, inf and pandas' missing values become None."""
    if value is None:
        return None
    if isinstance(value, (np.integer,)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return json_number(value)
    if value is pd.NA:
        return None
    return value


def _records(df: pd.DataFrame, columns: list[str]) -> list[dict[str, Any]]:
    return [{c: _clean(row[c]) for c in columns} for _, row in df[columns].iterrows()]


def summarize(root: str | Path, top: int = 5) -> dict[str, Any]:
    """Summary of a sweep folder (JSON-ready: no NaN or infinity, ``null`` instead).

    Returns:
        ``out``, ``description``, ``n_points``, ``rows`` (finished), ``complete``,
        ``status_counts``, ``max_contact_velocity`` {``min``, ``median``, ``max``, ``unbounded``}
        over the evaluated points, and ``best`` / ``worst``: the ``top`` points with their axis
        values, point index and results (``max_contact_velocity`` null when unbounded).
    """
    checks: list[FolderCheck] = []
    manifest, df = load_frame(root, checks)
    check = checks[0]
    dims = [d["name"] for d in manifest["dimensions"]]
    out: dict[str, Any] = {
        "out": str(root),
        "description": manifest.get("description"),
        "digest": manifest["digest"],
        "n_points": manifest["n_points"],
        "rows": len(df),
        "complete": len(df) == manifest["n_points"] and check.ok,
        "problems": [p.line() for p in check.problems],
        "dimensions": dims,
        "status_counts": {
            s: int((df["status"] == s).sum())
            for s in STATUSES
            if len(df) and (df["status"] == s).any()
        },
    }
    evaluated = df[df["status"].isin(EVALUATED)] if len(df) else df
    columns = ["point", *dims, *_SHOWN]
    if len(evaluated):
        v = evaluated["max_contact_velocity"].to_numpy(dtype=float)
        finite = v[np.isfinite(v)]
        out["max_contact_velocity"] = {
            "min": _clean(v.min()),
            "median": _clean(float(np.median(finite))) if len(finite) else None,
            "max": _clean(v.max()),
            "unbounded": int((~np.isfinite(v)).sum()),
        }
        # Stable sorts on (value, point): ties keep the point order, so the answer is deterministic.
        ranked = evaluated.assign(_v=v).sort_values(["_v", "point"], kind="stable")
        out["worst"] = _records(ranked.head(top), columns)
        best = evaluated.assign(_v=-v).sort_values(["_v", "point"], kind="stable")
        out["best"] = _records(best.head(top), columns)
    else:
        out["max_contact_velocity"] = None
        out["best"] = out["worst"] = []
    failed = df[~df["status"].isin(EVALUATED)] if len(df) else df
    out["failed_examples"] = (
        _records(failed.head(3), ["point", *dims, "status", "message"]) if len(failed) else []
    )
    return out


def _fmt(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.4g}"
    return str(value)


def format_summary(summary: dict[str, Any]) -> str:
    """The summary as text."""
    problems = summary.get("problems") or []
    lines = [
        f"sweep {summary['out']}: {summary['rows']} of {summary['n_points']} points"
        + ("" if summary["complete"] else " (incomplete: run the same command to resume)")
    ]
    if problems:
        lines.append(
            f"  {len(problems)} bad part(s) left out (named on stderr and by `sweep --verify`; a resume "
            "moves them to rejected/ and computes them again)"
        )
    if summary.get("description"):
        lines.append(f"  {summary['description']}")
    lines.append("  status: " + ", ".join(f"{k} {v}" for k, v in summary["status_counts"].items()))
    stats = summary.get("max_contact_velocity")
    if stats:
        lines.append(
            f"  max contact velocity (CoM criterion), m/s: min {_fmt(stats['min'])}, median {_fmt(stats['median'])}, "
            f"max {_fmt(stats['max']) if stats['max'] is not None else 'unbounded'} ({stats['unbounded']} unbounded)"
        )
    dims = summary["dimensions"]
    header = ["point", *dims, "max v (m/s)", "ZMP (m/s)", "verdict", "vertex", "edge"]
    for title in ("best", "worst"):
        rows = summary.get(title) or []
        if not rows:
            continue
        lines.append(f"  {title}:")
        table = [header] + [
            [
                _fmt(r["point"]),
                *(_fmt(r[d]) for d in dims),
                _fmt(r["max_contact_velocity"])
                if r["max_contact_velocity"] is not None
                else "unbounded",
                _fmt(r["zmp_max_contact_velocity"])
                if r["zmp_max_contact_velocity"] is not None
                else "unbounded",
                _fmt(r["verdict"]),
                _fmt(r["limiting_vertex"]),
                _fmt(r["limiting_edge"]),
            ]
            for r in rows
        ]
        widths = [max(len(row[i]) for row in table) for i in range(len(header))]
        for row in table:
            lines.append("    " + "  ".join(cell.rjust(w) for cell, w in zip(row, widths)))
    for r in summary.get("failed_examples") or []:
        lines.append(f"  e.g. point {r['point']} {r['status']}: {r['message']}")
    return "\n".join(lines)
