"""The records of a held-out run: its JSON outputs to compact CSV files.

A run directory holds, per stance, the outputs of the commands of the protocol (``--json``):
``push_<stance>_<body>.json`` (``push-test``), ``val_<stance>_<mode>.json`` (``validate``,
``mode`` ``rigid`` with ``--rigid-impact`` or ``free``) and ``approach<kind>_<stance>_ref<NN>.json``
(``approach``; ``kind`` empty for the default governor, ``held`` for the held-stance model, any
other word for another governor). The records are one row per push, per impact search, per
governed approach and per reach azimuth. Prediction keys the records do not name are carried
through: every boolean ``*_safe`` key of a push (a column of that name, 0 or 1) and every
``predicted.<name>.max_contact_velocity`` (and one level deeper, ``predicted_<name>_<sub>_mps``)
or number ``predicted.<name>`` of a search (``predicted_<name>_mps``).
"""

from __future__ import annotations

import csv
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

__all__ = [
    "RecordsError",
    "approach_rows",
    "com_reach_rows",
    "impact_rows",
    "push_rows",
    "write_csv",
]

#: Search predictions with a name of their own in ``impacts.csv``: key path -> column.
NAMED_PREDICTIONS = {
    ("com_reach",): "predicted_within_reach_mps",
    ("held_stance",): "predicted_held_stance_mps",
    ("held_stance", "angular_momentum"): "predicted_held_stance_with_L_mps",
}
#: Governors of the approach files by their name's prefix (``approach<kind>_``).
GOVERNORS = {"approach": "default", "approachheld": "held_stance"}


class RecordsError(ValueError):
    """A run output that cannot be read as a record (its file and what is wrong)."""

    def __init__(self, path: Path, problem: str) -> None:
        super().__init__(f"{path}: {problem}")
        self.path = path
        self.problem = problem


def _load(path: Path) -> dict[str, Any]:
    try:
        document = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise RecordsError(path, f"not a JSON document ({error})") from error
    if not isinstance(document, dict):
        raise RecordsError(path, "not a JSON object")
    return document


def _outputs(run_dir: Path, prefix: str) -> Iterator[tuple[str, Path]]:
    """``(name without prefix and .json, path)`` of ``<prefix>*.json``, sorted by file name."""
    for path in sorted(run_dir.glob(f"{prefix}*.json")):
        yield path.name[len(prefix) : -len(".json")], path


def _candidate_flags(push: dict[str, Any]) -> dict[str, int]:
    """Every boolean ``*_safe`` key of a push but ``com_criterion_safe`` (the default's)."""
    return {
        key: int(value)
        for key, value in push.items()
        if key.endswith("_safe") and key != "com_criterion_safe" and isinstance(value, bool)
    }


def _rounded(value: float | None) -> float | str:
    """``value`` to 6 decimals, or an empty cell when it is None."""
    return "" if value is None else round(value, 6)


def _angular_momentum_margin(push: dict[str, Any]) -> float:
    """The paper's margin with the angular momentum term alone (m/s, no push duration, no reach).

    At full precision: it is scored against 0, where a rounded margin could change sides.
    """
    effective = push.get("effective_com_velocity_margin")
    margin = float(push["com_velocity_margin"])
    return margin if effective is None else min(margin, float(effective))


def _push_row(
    stance: str, body: str, document: dict[str, Any], push: dict[str, Any], commit: str
) -> dict[str, Any]:
    omega, margin = document["omega"], document["zmp_margin"]
    return {
        "stance": stance,
        "body": body,
        "direction_deg": round(push["direction_deg"]),
        "relative": push["relative"],
        "impulse_Ns": round(push["magnitude"], 4),
        "omega": round(omega, 6),
        "zmp_margin": margin,
        "default_margin_mps": round(push["predicted_com_velocity_margin"], 6),
        "paper_margin_mps": round(push["com_velocity_margin"] + omega * margin, 6),
        "default_safe": int(push["com_criterion_safe"]),
        "com_reach_margin_mps": _rounded(push.get("com_reach_margin")),
        "commit": commit,
        "finite_push_factor": round(push.get("finite_push_factor") or 1.0, 6),
        "outcome": push["outcome"],
        "fell": int(push["fell"]),
        "strict_fail": int(push["strict_fail"]),
        "strict_reason": push["strict_reason"] or "",
        "angular_momentum_margin_mps": _angular_momentum_margin(push),
        **_candidate_flags(push),
    }


def push_rows(run_dir: Path, commit: str = "") -> list[dict[str, Any]]:
    """One row per push of every ``push_<stance>_<body>.json``, in file-name order.

    Args:
        run_dir: The run's output directory.
        commit: The frozen commit the run was made from (the ``commit`` column).

    Returns:
        The rows of ``pushes.csv``: the impulse (N s), omega (1/s), the margins (m/s: the
        default's before its reach, the paper's at margin 0, the angular momentum term's alone),
        the default's call, the outcome, and the carried ``*_safe`` calls.

    Raises:
        RecordsError: A file is not a ``push-test --json`` document.
    """
    rows: list[dict[str, Any]] = []
    for name, path in _outputs(run_dir, "push_"):
        stance, _, body = name.rpartition("_")
        document = _load(path)
        try:
            rows.extend(
                _push_row(stance, body, document, push, commit) for push in document["pushes"]
            )
        except (KeyError, TypeError) as error:
            raise RecordsError(path, f"no push-test record ({error!r} missing)") from error
    return rows


def _predictions(predicted: dict[str, Any]) -> dict[str, Any]:
    """Every ``max_contact_velocity`` under ``predicted`` (two levels), by its column name.

    A number directly under ``predicted`` (but ``default``) is a speed too.
    """
    columns: dict[str, Any] = dict.fromkeys(NAMED_PREDICTIONS.values(), "")
    for key, value in predicted.items():
        if isinstance(value, (int, float)) and not isinstance(value, bool) and key != "default":
            columns[f"predicted_{key}_mps"] = value  # a speed of its own beside the default's
        if not isinstance(value, dict):
            continue
        paths: list[tuple[tuple[str, ...], dict[str, Any]]] = [((key,), value)]
        paths += [((key, sub), inner) for sub, inner in value.items() if isinstance(inner, dict)]
        for path, entry in paths:
            if "max_contact_velocity" not in entry:
                continue
            column = NAMED_PREDICTIONS.get(path, "predicted_" + "_".join(path) + "_mps")
            speed = entry["max_contact_velocity"]
            columns[column] = "" if speed is None else speed
    return columns


def _impact_row(stance: str, mode: str, document: dict[str, Any]) -> dict[str, Any]:
    empirical, predicted = document["empirical"], document["predicted"]
    first_break = empirical.get("first_contact_break") or {}
    held = predicted.get("held_stance") or {}
    predictions = _predictions(predicted)
    row = {
        "stance": stance,
        "impact_model": mode,
        "survived_mps": empirical.get("survived"),
        "fell_mps": empirical.get("fell"),
        "strict_failed_mps": empirical.get("strict_failed"),
        "first_contact_break_mps": first_break.get("measured") or "",
        "first_contact_break": (
            f"{first_break.get('contact')} {first_break.get('kind')}" if first_break else ""
        ),
        "predicted_default_mps": predicted["default"],
        "predicted_within_reach_mps": predictions.pop("predicted_within_reach_mps"),
        "predicted_paper_0mm_mps": predicted["com_criterion"]["composite"],
        "predicted_held_stance_mps": predictions.pop("predicted_held_stance_mps"),
        "held_stance_fell_back": int(held["fell_back"]) if "fell_back" in held else "",
        "predicted_held_stance_with_L_mps": predictions.pop("predicted_held_stance_with_L_mps"),
        "trials": len(document["trials"]),
        "aborted": sum(1 for trial in document["trials"] if trial.get("outcome") == "aborted"),
    }
    return {**row, **predictions}


def impact_rows(run_dir: Path) -> list[dict[str, Any]]:
    """One row per ``val_<stance>_<mode>.json`` (an impact search), by stance and mode.

    ``valpaper_<stance>_<mode>.json`` is the same search run without the held-stance model (a
    stance whose held-stance QP has no answer): its held-stance predictions are left empty.

    Returns:
        The rows of ``impacts.csv``: the measured speeds (m/s: survived, fell, failed strictly,
        first contact break and which), every prediction (m/s; empty when not recorded), the
        trials and the aborted ones.

    Raises:
        RecordsError: A file is not a ``validate --json`` document.
    """
    rows = []
    outputs = sorted(
        [*_outputs(run_dir, "val_"), *_outputs(run_dir, "valpaper_")],
        key=lambda output: output[0].rpartition("_")[::2],
    )
    for name, path in outputs:
        stance, _, mode = name.rpartition("_")
        try:
            rows.append(_impact_row(stance, mode, _load(path)))
        except (KeyError, TypeError) as error:
            raise RecordsError(path, f"no validate record ({error!r} missing)") from error
    return rows


def approach_rows(run_dir: Path) -> list[dict[str, Any]]:
    """One row per governed approach of every ``approach<kind>_<stance>_ref<NN>.json``.

    Returns:
        The rows of ``approaches.csv``: the governor, the reference speed and the wall's
        distance, the cap and the speed at contact (m/s), the outcome.

    Raises:
        RecordsError: A file is not an ``approach --json`` document.
    """
    rows: list[dict[str, Any]] = []
    for path in sorted(run_dir.glob("approach*_*.json")):
        kind, _, rest = path.name[: -len(".json")].partition("_")
        stance = re.sub(r"_ref\d+$", "", rest)
        governor = GOVERNORS.get(kind, kind.removeprefix("approach"))
        try:
            rows.extend(
                {
                    "stance": stance,
                    "governor": governor,
                    "reference": trial["reference"],
                    "wall_distance": trial["wall_distance"],
                    "cap_at_contact": trial["cap_at_contact"],
                    "speed_at_contact": trial["speed_at_contact"],
                    "outcome": trial["outcome"],
                    "strict_fail": int(trial["strict_fail"]),
                    "reason": trial.get("reason") or "",
                }
                for trial in _load(path)["trials"]
            )
        except (KeyError, TypeError) as error:
            raise RecordsError(path, f"no approach record ({error!r} missing)") from error
    return rows


def com_reach_rows(run_dir: Path) -> list[dict[str, Any]]:
    """The CoM's reach of each stance (from its first push file): azimuth (deg), radius (m)."""
    rows: list[dict[str, Any]] = []
    seen = set()
    for name, path in _outputs(run_dir, "push_"):
        stance = name.rpartition("_")[0]
        if stance in seen:
            continue
        seen.add(stance)
        reach = _load(path).get("com_reach")
        if not reach:
            continue
        rows.extend(
            {"stance": stance, "azimuth_deg": a, "radius_m": r, "height_m": reach["height"]}
            for a, r in zip(reach["azimuths_deg"], reach["radii"], strict=True)
        )
    return rows


def write_csv(path: Path, rows: list[dict[str, Any]]) -> int:
    """Write ``rows`` to ``path`` (the union of their keys, in first-seen order); their count."""
    fields: dict[str, None] = {}
    for row in rows:
        fields.update(dict.fromkeys(row))
    with path.open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(fields))
        writer.writeheader()
        writer.writerows(rows)
    return len(rows)
