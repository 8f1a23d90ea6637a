"""Reading a held-out set's records (``studies/held_out_results_N/``) back, typed."""

from __future__ import annotations

import csv
import json
from pathlib import Path
from typing import Any

__all__ = ["flag", "number", "read_csv", "read_json"]


def read_csv(records_dir: Path, name: str) -> list[dict[str, str]]:
    """The rows of ``records_dir/name`` (empty when the file is absent)."""
    path = records_dir / name
    if not path.is_file():
        return []
    with path.open(newline="") as handle:
        return list(csv.DictReader(handle))


def read_json(records_dir: Path, name: str) -> Any:
    """The document ``records_dir/name`` (None when the file is absent)."""
    path = records_dir / name
    return json.loads(path.read_text()) if path.is_file() else None


def number(cell: str | None) -> float | None:
    """A CSV cell as a float (None when empty or absent)."""
    return None if cell is None or cell == "" else float(cell)


def flag(cell: str | None) -> bool:
    """A 0/1 (or True/False) CSV cell as a bool (an empty cell is False)."""
    return cell not in (None, "", "0", "False", "false")
