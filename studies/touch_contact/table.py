"""The touch-contact study's table: results.jsonl beside the held-out records (markdown).

For every stance: the record's strict fall bracket (``studies/held_out_results_N/impacts.csv``,
rigid rows) and this tree's, without and with ``--touch-contact``, and the default prediction
(within reach) with the ratio strict / prediction. From the repository root:
``python studies/touch_contact/table.py``.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

HERE = Path(__file__).parent
ROOT = HERE.parents[1]


def _records() -> dict[str, dict[str, str]]:
    rows = {}
    for n in (7, 8, 9, 10, 11):
        path = ROOT / f"studies/held_out_results_{n}/impacts.csv"
        for row in csv.DictReader(path.open()):
            if row["impact_model"] == "rigid":
                rows[row["stance"]] = {**row, "set": str(n)}
    return rows


def _f(x: float | str | None, digits: int = 3) -> str:
    if x in (None, ""):
        return "–"
    return f"{float(x):.{digits}f}"


def main() -> None:
    """Print the table."""
    records = _records()
    runs: dict[tuple[str, bool], dict] = {}
    for line in (HERE / "results.jsonl").read_text().splitlines():
        row = json.loads(line)
        runs[(Path(row["stance"]).stem, row["touch_contact"])] = row
    print(
        "| set | stance | record: strict failure | this tree: strict stood / failed | "
        "with `--touch-contact` | same bracket | default prediction (within reach) | "
        "ratio strict / prediction (record; this tree; with) |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for stance in dict.fromkeys(s for s, _ in runs):
        off, on = runs.get((stance, False)), runs.get((stance, True))
        rec = records[stance]
        predicted = float(rec["predicted_within_reach_mps"])
        # The record's default prediction is this tree's (else the row is marked).
        now = (off or on or {}).get("predicted_default")
        moved = now is not None and abs(float(rec["predicted_default_mps"]) - now) > 1e-6
        same = "–"
        if off and on:
            keys = ("survived", "fell", "strict_failed", "strict_stood")
            same = (
                "yes"
                if all(
                    (off[k] is None and on[k] is None)
                    or (off[k] is not None and on[k] is not None and abs(off[k] - on[k]) < 1e-9)
                    for k in keys
                )
                else "**no**"
            )

        def pair(r: dict | None) -> str:
            return "–" if r is None else f"{_f(r['strict_stood'])} / {_f(r['strict_failed'])}"

        def ratio(x: float | str | None, predicted: float = predicted) -> str:
            return "–" if x in (None, "") else f"{float(x) / predicted:.2f}"

        print(
            f"| {rec['set']} | {stance} | {_f(rec['strict_failed_mps'])} | {pair(off)} | "
            f"{pair(on)} | {same} | {predicted:.3f}{' (moved)' if moved else ''} | "
            f"{ratio(rec['strict_failed_mps'])}; "
            f"{ratio(off and off['strict_failed'])}; {ratio(on and on['strict_failed'])} |"
        )


if __name__ == "__main__":
    main()
