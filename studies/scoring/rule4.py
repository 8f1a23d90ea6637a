"""Rule 4: the records' predictions equal the protocol's tables, to the last printed digit.

The protocol (``docs/studies/held-out-protocol-N.md``) prints, before any trial, per stance:
the boundary impulse per push direction (N s, 0° to 315° by 45°), the CoM's reach (m, every
other azimuth of the records' 16) with the CoM height held, the paper's criterion at margin 0
(m/s) and, when it has that table, the held-stance model at 10 mm (m/s). Each is recomputed
from the records and printed as the protocol prints it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from scoring.markdown import table
from scoring.records import number

__all__ = ["Check", "check", "check_table", "protocol_tables"]


@dataclass(frozen=True)
class Check:
    """One printed prediction: the stance, what, the protocol's text and the records'."""

    stance: str
    what: str
    protocol: str
    records: str

    @property
    def equal(self) -> bool:
        """Whether the records print as the protocol does."""
        return self.protocol == self.records


def protocol_tables(text: str) -> list[tuple[list[str], list[list[str]]]]:
    """Every markdown table of ``text`` whose first column is ``stance``: (header, rows)."""
    tables = []
    lines = text.splitlines()
    for i, line in enumerate(lines[:-1]):
        if not line.startswith("| stance |") or not lines[i + 1].startswith("|---"):
            continue
        header = [cell.strip() for cell in line.strip().strip("|").split("|")]
        rows = []
        for row in lines[i + 2 :]:
            if not row.startswith("|"):
                break
            rows.append([cell.strip().strip("`") for cell in row.strip().strip("|").split("|")])
        tables.append((header, rows))
    return tables


def _column(header: list[str], pattern: str) -> int | None:
    for index, name in enumerate(header):
        if re.fullmatch(pattern, name):
            return index
    return None


def _impulses(pushes: Sequence[dict[str, str]], stance: str) -> str:
    """The boundary impulse per direction, from the push with the largest relative impulse."""
    best: dict[int, tuple[float, float]] = {}
    for row in pushes:
        if row["stance"] != stance:
            continue
        direction, relative = round(float(row["direction_deg"])), float(row["relative"])
        if direction not in best or relative > best[direction][0]:
            best[direction] = (relative, float(row["impulse_Ns"]) / relative)
    return " ".join(f"{best[d][1]:.1f}" for d in sorted(best))


def _reach(reach: Sequence[dict[str, str]], stance: str) -> tuple[str, str]:
    rows = sorted(
        (r for r in reach if r["stance"] == stance), key=lambda r: float(r["azimuth_deg"])
    )
    radii = " ".join(f"{float(r['radius_m']):.4f}" for r in rows[::2])
    return radii, (f"{float(rows[0]['height_m']):.3f}" if rows else "")


def _impact_value(impacts: Sequence[dict[str, str]], stance: str, column: str) -> str:
    values = {
        f"{v:.3f}"
        for r in impacts
        if r["stance"] == stance
        if (v := number(r.get(column))) is not None
    }
    return " / ".join(sorted(values))


def check(
    protocol: str,
    pushes: Sequence[dict[str, str]],
    impacts: Sequence[dict[str, str]],
    reach: Sequence[dict[str, str]],
) -> list[Check]:
    """Every prediction the protocol prints, against the records (see the module)."""
    checks = []
    for header, rows in protocol_tables(protocol):
        impulse = _column(header, r"boundary impulse.*")
        radius, height = _column(header, r"CoM reach.*"), _column(header, r"CoM height held.*")
        paper = _column(header, r"CoM criterion, margin 0")
        held = _column(header, r"held-stance model, 10 mm")
        for row in rows:
            stance = row[0]
            if impulse is not None and pushes:
                checks.append(
                    Check(stance, "boundary impulse", row[impulse], _impulses(pushes, stance))
                )
            if radius is not None and height is not None and reach:
                radii, held_height = _reach(reach, stance)
                checks.append(Check(stance, "CoM reach", row[radius], radii))
                checks.append(Check(stance, "CoM height", row[height], held_height))
            if paper is not None and impacts:
                value = _impact_value(impacts, stance, "predicted_paper_0mm_mps")
                checks.append(Check(stance, "paper, margin 0", row[paper], value))
            if held is not None and impacts:
                value = _impact_value(impacts, stance, "predicted_held_stance_mps")
                checks.append(Check(stance, "held-stance model, 10 mm", row[held], value))
    return checks


def check_table(checks: Sequence[Check]) -> str:
    """The checks as a table, then how many differ."""
    header = ["stance", "prediction", "protocol", "records", "equal"]
    rows = [
        [c.stance, c.what, c.protocol, c.records, "yes" if c.equal else "**no**"] for c in checks
    ]
    differ = sum(not c.equal for c in checks)
    verdict = "holds" if differ == 0 else "does not hold"
    return table(header, rows) + f"\n\nRule 4 {verdict}: {differ} of {len(checks)} differ."
