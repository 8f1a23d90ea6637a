"""Trials written as they finish: one JSON line per trial, so that a crash or Ctrl-C keeps what ran.

A journal is a JSON-lines file. Its first line is a header holding the ``digest`` of everything
that decides a trial's outcome (scenario, controller and its gains, thresholds, trial options,
the package version); each further line is one finished trial: its ``key`` (what was tried: a
commanded speed, a push) and its ``entry`` (the trial's summary and a short trajectory). Running
the same command again finds the journal by its digest, reuses the trials it holds and runs only
the others. A last line cut by a crash is ignored (and reported); a journal of another digest is
never mixed in: the command starts a new one.
"""

from __future__ import annotations

import hashlib
import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

__all__ = ["TrialJournal", "default_journal_path", "journal_digest"]

#: Folder of the default journals (relative to the current directory).
JOURNAL_FOLDER = "impact-balance-trials"


def journal_digest(parts: dict[str, Any]) -> str:
    """SHA-256 (hex) of ``parts`` as canonical JSON (sorted keys)."""
    text = json.dumps(parts, sort_keys=True, separators=(",", ":"), default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def default_journal_path(command: str, scenario: str, digest: str) -> Path:
    """The journal's default path, in ``impact-balance-trials/`` of the current directory.

    ``impact-balance-trials/<command>_<scenario>_<digest[:12]>.jsonl`` in the current directory.
    """
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in (scenario or "scenario"))[
        :80
    ]
    return Path(JOURNAL_FOLDER) / f"{command}_{safe}_{digest[:12]}.jsonl"


def _key(key: Any) -> str:
    return json.dumps(key, sort_keys=True)


@dataclass
class TrialJournal:
    """An append-only journal of finished trials (see the module docstring).

    Attributes:
        path: The JSON-lines file (None: keep nothing on disk).
        digest: What the trials depend on.
        header: Extra header fields (written once, informative).
        entries: The trials read back, by key.
        skipped_lines: Lines that could not be read (a cut last line).
    """

    path: Path | None
    digest: str
    header: dict[str, Any] = field(default_factory=dict)
    entries: dict[str, dict[str, Any]] = field(default_factory=dict)
    skipped_lines: int = 0
    _handle: Any = field(default=None, init=False, repr=False)

    @classmethod
    def open(
        cls, path: str | Path | None, digest: str, header: dict[str, Any] | None = None
    ) -> TrialJournal:
        """Open (or create) the journal at ``path``; a file of another digest is refused."""
        from impact_balance.exceptions import SimulationError

        journal = cls(None if path is None else Path(path), digest, dict(header or {}))
        if journal.path is None:
            return journal
        if journal.path.exists():
            journal._read()
        else:
            journal.path.parent.mkdir(parents=True, exist_ok=True)
        try:
            journal._handle = open(journal.path, "a", encoding="utf-8")
        except OSError as exc:
            raise SimulationError(
                "--journal", str(journal.path), f"cannot write it ({exc.strerror})"
            ) from None
        if journal.path.stat().st_size == 0:
            journal._write({"journal": "impact-balance trials", "digest": digest, **journal.header})
        return journal

    def _read(self) -> None:
        from impact_balance.exceptions import SimulationError

        assert self.path is not None
        with open(self.path, encoding="utf-8", errors="replace") as fh:
            text = fh.read()
        lines = text.splitlines()
        for number, line in enumerate(lines):
            try:
                record = json.loads(line)
            except json.JSONDecodeError:
                self.skipped_lines += bool(line.strip())
                continue
            if number == 0:
                if record.get("digest") != self.digest:
                    raise SimulationError(
                        "--journal",
                        str(self.path),
                        "holds the trials of another scenario or of "
                        "other options (digest differs); choose another file",
                    )
                continue
            if isinstance(record, dict) and "key" in record and "entry" in record:
                self.entries[_key(record["key"])] = record["entry"]
            elif line.strip():
                self.skipped_lines += 1
        if text and not text.endswith("\n"):
            # A cut last line: end it, so that the next line starts clean.
            with open(self.path, "a", encoding="utf-8") as fh:
                fh.write("\n")

    def _write(self, record: dict[str, Any]) -> None:
        if self._handle is None:
            return
        self._handle.write(json.dumps(record, allow_nan=False) + "\n")
        self._handle.flush()
        os.fsync(self._handle.fileno())

    def get(self, key: Any) -> dict[str, Any] | None:
        """The stored entry of a trial, or None."""
        return self.entries.get(_key(key))

    def add(self, key: Any, entry: dict[str, Any]) -> None:
        """Record a finished trial (written and flushed at once)."""
        self.entries[_key(key)] = entry
        self._write({"key": key, "entry": entry})

    def close(self) -> None:
        """Close the journal's file (idempotent)."""
        if self._handle is not None:
            self._handle.close()
            self._handle = None
