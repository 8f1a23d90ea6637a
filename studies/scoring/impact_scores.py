"""The impact searches' table, the rigid impacts' ratios, the premise and the approaches.

The impact table has one column per prediction the records carry (m/s; a column with no value
in any row is left out), each with the strict failure over it: the default's (its reach when
recorded), the held-stance model's, the held-stance model with its angular momentum, any other
``predicted_<name>_mps`` column, then the paper's criterion at margin 0.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from scoring.markdown import DASH, fixed, table
from scoring.records import flag, number

__all__ = [
    "Prediction",
    "approach_table",
    "impact_table",
    "predictions",
    "premise_table",
    "ratio_summary",
]

#: The band of strict failure over prediction the impact targets ask for.
RATIO_BAND = (0.9, 1.3)
#: Columns of ``impacts.csv`` that are not a prediction of their own.
NOT_PREDICTIONS = ("predicted_default_mps", "predicted_paper_0mm_mps")


@dataclass(frozen=True)
class Prediction:
    """A prediction column of ``impacts.csv``: its column, its label, its ratio's label."""

    column: str
    label: str
    ratio_label: str


def _default_speed(row: dict[str, str]) -> float | None:
    reach = number(row.get("predicted_within_reach_mps"))
    return reach if reach is not None else number(row.get("predicted_default_mps"))


def predictions(rows: Sequence[dict[str, str]]) -> list[Prediction]:
    """The prediction columns of the records that hold a value, in the table's order."""
    columns = list(rows[0]) if rows else []
    named = {
        "predicted_within_reach_mps": Prediction(
            "predicted_within_reach_mps",
            "default prediction (within reach)",
            "ratio strict / default",
        ),
        "predicted_held_stance_mps": Prediction(
            "predicted_held_stance_mps", "held-stance prediction", "ratio strict / held stance"
        ),
        "predicted_held_stance_with_L_mps": Prediction(
            "predicted_held_stance_with_L_mps", "held stance with L", "ratio strict / with L"
        ),
    }
    found = [named["predicted_within_reach_mps"]]
    found += [named[c] for c in named if c in columns and c != "predicted_within_reach_mps"]
    for column in columns:
        if column.startswith("predicted_") and column.endswith("_mps"):
            if column not in named and column not in NOT_PREDICTIONS:
                name = column.removeprefix("predicted_").removesuffix("_mps")
                found.append(Prediction(column, f"{name} prediction", f"ratio strict / {name}"))
    return [p for p in found if any(_speed(row, p) is not None for row in rows)]


def _speed(row: dict[str, str], prediction: Prediction) -> float | None:
    if prediction.column == "predicted_within_reach_mps":
        return _default_speed(row)
    return number(row.get(prediction.column))


def _ratio(strict: float | None, speed: float | None) -> str:
    return DASH if strict is None or speed is None else f"{strict / speed:.2f}"


def impact_table(rows: Sequence[dict[str, str]]) -> str:
    """One row per impact search: the measured speeds, each prediction and its ratio (m/s)."""
    found = predictions(rows)
    header = ["stance", "model", "strict failure (m/s)", "fell (m/s)", "survived (m/s)"]
    for prediction in found:
        header += [prediction.label, prediction.ratio_label]
    header += ["paper, margin 0", "first contact break (m/s)", "aborted"]
    lines = []
    for row in rows:
        strict = number(row["strict_failed_mps"])
        cells = [row["stance"], "rigid" if row["impact_model"] == "rigid" else "rotor inertia"]
        cells += [fixed(strict), fixed(number(row["fell_mps"])), fixed(number(row["survived_mps"]))]
        for prediction in found:
            speed = _speed(row, prediction)
            fell_back = prediction.column == "predicted_held_stance_mps" and flag(
                row.get("held_stance_fell_back")
            )
            cells += [fixed(speed) + (" (fell back)" if fell_back else ""), _ratio(strict, speed)]
        first_break = number(row["first_contact_break_mps"])
        cells.append(fixed(number(row["predicted_paper_0mm_mps"])))
        cells.append(
            DASH if not first_break else f"{row['first_contact_break']} from {first_break:.3f}"
        )
        cells.append(row["aborted"])
        lines.append(cells)
    return table(header, lines)


def ratio_summary(rows: Sequence[dict[str, str]]) -> str:
    """At the rigid impact, the strict failure over each prediction: within, below, above.

    Each ratio is counted as the impact table prints it (two decimals): 0.897 is 0.90, within.
    """
    rigid = [row for row in rows if row["impact_model"] == "rigid"]
    header = [
        "",
        f"within [{RATIO_BAND[0]}, {RATIO_BAND[1]}]",
        f"optimistic (below {RATIO_BAND[0]})",
        "below 1.0 (above the failure)",
        f"conservative (above {RATIO_BAND[1]})",
        "range",
    ]
    lines = []
    for prediction in predictions(rows):
        ratios = []
        for row in rigid:
            strict, speed = number(row["strict_failed_mps"]), _speed(row, prediction)
            if strict is not None and speed:
                ratios.append(round(strict / speed, 2))  # as printed
        within = sum(RATIO_BAND[0] <= r <= RATIO_BAND[1] for r in ratios)
        span = f"{min(ratios):.2f} to {max(ratios):.2f}" if ratios else DASH
        lines.append(
            [
                prediction.label,
                f"{within} of {len(rigid)}",
                str(sum(r < RATIO_BAND[0] for r in ratios)),
                str(sum(r < 1.0 for r in ratios)),
                str(sum(r > RATIO_BAND[1] for r in ratios)),
                span,
            ]
        )
    return table(header, lines)


def premise_table(premise: dict[str, dict[str, Any]]) -> str:
    """The capture's premise per stance (``premise.json``): s(j_m), strict failure, B."""
    header = [
        "stance",
        "measured jump reaches (m/s)",
        "strict failure (m/s)",
        "B",
        "premise holds",
        "trials",
    ]
    lines = [
        [
            name,
            fixed(entry["jump_reaches"]),
            fixed(entry["strict"]),
            fixed(entry["B"], 2),
            "yes" if entry["premise"] else "no",
            str(entry["trials"]),
        ]
        for name, entry in premise.items()
    ]
    return table(header, lines)


def _span(values: Sequence[float]) -> str:
    return f"{min(values):.3f} to {max(values):.3f}" if values else DASH


def approach_table(rows: Sequence[dict[str, str]]) -> str:
    """Per governor, stance and reference speed: the outcomes, caps and speed ratios."""
    groups: dict[tuple[str, float], list[dict[str, str]]] = {}
    for row in rows:
        governor = row.get("governor") or "default"
        prefix = "" if governor == "default" else governor.replace("_", " ") + ": "
        groups.setdefault((prefix + row["stance"], float(row["reference"])), []).append(row)
    header = [
        "stance",
        "reference (m/s)",
        "trials",
        "outcomes",
        "strict failures",
        "cap at contact (m/s)",
        "speed / min(reference, cap)",
    ]
    lines = []
    for (stance, reference), trials in sorted(groups.items()):
        outcomes = Counter(
            t["outcome"]
            + (f" (`{t['reason']}`)" if t["outcome"] == "aborted" and t["reason"] else "")
            for t in trials
        )
        caps = [c for t in trials if (c := number(t["cap_at_contact"])) is not None]
        ratios = [
            speed / min(reference, cap)
            for t in trials
            if (cap := number(t["cap_at_contact"])) is not None
            and (speed := number(t["speed_at_contact"])) is not None
        ]
        lines.append(
            [
                stance,
                f"{reference}",
                str(len(trials)),
                ", ".join(f"{k} {v}" for k, v in outcomes.items()),
                str(sum(flag(t["strict_fail"]) for t in trials)),
                _span(caps),
                _span(ratios),
            ]
        )
    return table(header, lines)
