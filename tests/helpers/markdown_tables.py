"""Markdown tables of a document, for comparing a script's printed tables with a study's."""

from __future__ import annotations

__all__ = ["cells", "markdown_tables"]


def cells(line: str) -> list[str]:
    """The cells of a markdown table line (an escaped ``\\|`` stays inside its cell)."""
    parts = line.strip().removeprefix("|").removesuffix("|").replace("\\|", "\0").split("|")
    return [part.strip().replace("\0", "\\|") for part in parts]


def markdown_tables(text: str) -> list[tuple[list[str], list[list[str]]]]:
    """Every table of ``text``: its header's cells and its rows' cells."""
    lines = text.splitlines()
    tables = []
    for i in range(len(lines) - 1):
        if lines[i].startswith("|") and lines[i + 1].startswith("|---"):
            if i > 0 and lines[i - 1].startswith("|"):
                continue
            rows = []
            for line in lines[i + 2 :]:
                if not line.startswith("|"):
                    break
                rows.append(cells(line))
            tables.append((cells(lines[i]), rows))
    return tables
