"""Markdown output: rates with their Wilson intervals, numbers, tables."""

from __future__ import annotations

from collections.abc import Sequence

from impact_balance.sim.studies.scores import wilson

__all__ = ["DASH", "called_safe", "fixed", "rate", "table"]

#: What a cell shows when there is nothing to show.
DASH = "–"


def rate(count: int, total: int) -> str:
    """``count / total`` in percent with its 95 % Wilson interval: ``13 % [8, 21] (12/92)``."""
    interval = wilson(count, total)
    if interval is None:
        return f"{DASH} (0/0)"
    low, high = interval
    return f"{100 * count / total:.0f} % [{100 * low:.0f}, {100 * high:.0f}] ({count}/{total})"


def called_safe(count: int, total: int, empty: str = DASH) -> str:
    """The share of standing trials called safe, without an interval: ``21 % (80/376)``."""
    if total == 0:
        return empty
    return f"{100 * count / total:.0f} % ({count}/{total})"


def fixed(value: float | None, digits: int = 3) -> str:
    """``value`` with ``digits`` decimals, or a dash when it is None."""
    return DASH if value is None else f"{value:.{digits}f}"


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A markdown table (``|`` in a header cell is escaped)."""
    lines = ["| " + " | ".join(cell.replace("|", "\\|") for cell in header) + " |"]
    lines.append("|" + "---|" * len(header))
    lines.extend("| " + " | ".join(row) + " |" for row in rows)
    return "\n".join(lines)
