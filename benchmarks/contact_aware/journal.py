"""The journalled trials: every trial is written to a journal under ``--out`` as it finishes (a
crash or one failing trial loses nothing else; the same command resumes), and a wall trial's
summary without its long trajectory fields."""

from __future__ import annotations

import sys
import traceback
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from impact_balance.sim.studies.journal import TrialJournal, journal_digest
from impact_balance.sim.studies.wall import APPROACH_VERSION
from impact_balance.sim.trials.balance_trial import TRIAL_VERSION

__all__ = ["journalled", "open_journal", "slim"]


def journalled(
    journal: TrialJournal, keys: Iterable[dict], run: Callable[[dict], dict], label: str
) -> tuple[list, int]:
    """``[(key, entry)]`` for every key: the journal's entry, else ``run(key)``'s, journalled at
    once.

    A key whose run raises is printed and left out (a rerun tries it again). Returns the pairs
    and the number of failures."""
    pairs, failed = [], 0
    for key in keys:
        entry = journal.get(key)
        if entry is None:
            try:
                entry = run(key)
            except Exception:
                failed += 1
                print(
                    f"  FAILED {label} {key}:\n{traceback.format_exc()}",
                    file=sys.stderr,
                    flush=True,
                )
                continue
            journal.add(key, entry)
        pairs.append((key, entry))
    return pairs, failed


def open_journal(out: Path, command: str, name: str, parts: dict[str, Any]) -> TrialJournal:
    """The journal of ``command`` on scenario ``name`` under ``out/journals``; ``parts``: what
    else decides the trials' outcome (a rerun with other parts starts another journal)."""
    digest = journal_digest(
        {
            "trial_version": TRIAL_VERSION,
            "approach_version": APPROACH_VERSION,
            "benchmark": "contact_aware_governor",
            "command": command,
            "scenario": name,
            **parts,
        }
    )
    return TrialJournal.open(out / "journals" / f"{command}_{name}_{digest[:12]}.jsonl", digest)


def slim(trial_dict: dict) -> dict:
    """A wall trial's summary (``WallTrial.to_dict()``) without its long trajectory fields: the
    approach's numbers, and from the trial the margin at the end (m/s), the slip (m) and the
    impact's measurements."""
    trial = trial_dict["trial"]
    out = {k: v for k, v in trial_dict.items() if k != "trial"}
    out["margin_raw"] = trial["com_velocity_margin_at_end"]
    out["max_slip"] = trial["max_slip"]
    impact = trial.get("impact") or {}
    for k in ("com_velocity_after", "com_velocity_jump", "sustained_impulses", "impulse"):
        out[k] = impact.get(k)
    return out
