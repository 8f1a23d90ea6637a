"""Trials written as they finish: one JSON line per trial, so that a crash or Ctrl-C keeps what ran.

A journal is a JSON-lines file. Its first line is a header holding the ``digest`` of everything
that decides a trial's outcome (scenario, controller and its gains, thresholds, trial options,
the package version); each further line is one finished trial: the same ``digest``, its ``key``
(what was tried: a commanded speed, a push), its ``entry`` (the trial's summary and a short
trajectory) and a ``checksum`` (SHA-256 of the line's other fields as canonical JSON). Running
the same command again finds the journal by its digest, reuses the trials it holds and runs only
the others.

A trial line is reused only when it is whole and its own: a line that does not parse (a last
line cut by a crash, garbage), whose digest is another's (a foreign journal, even behind a
damaged header), whose checksum does not match (damage, an accidental edit) or whose entry is
not a trial this version writes (an unknown outcome) is named in :attr:`TrialJournal.problems`
and its trial is run again. A readable header of another digest refuses the whole file.

The checksums protect against damage and accidental edits, not against a forger who recomputes
them. The file must be a regular file of at most :data:`MAX_JOURNAL_BYTES` bytes: a FIFO, a
device or a larger file is refused, never waited on or read without bound.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
import stat
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from impact_balance.files import FileTooLargeError, NotRegularFileError, read_regular

__all__ = [
    "MAX_JOURNAL_BYTES",
    "TrialJournal",
    "check_trial_entry",
    "default_journal_path",
    "journal_digest",
]

#: Folder of the default journals (relative to the current directory).
JOURNAL_FOLDER = "impact-balance-trials"
#: Largest journal read back (bytes); a larger file is refused.
MAX_JOURNAL_BYTES = 256 * 1024 * 1024
#: Problems named one by one; the others are counted.
_NAMED_PROBLEMS = 10
#: A line that does not parse.
_NOT_JSON = object()


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


def _checksum(record: dict[str, Any]) -> str:
    """SHA-256 (hex) of ``record`` without its ``checksum``, as canonical JSON."""
    body = {k: v for k, v in record.items() if k != "checksum"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()


def _refuse_constant(constant: str) -> Any:
    raise ValueError(f"not JSON: {constant}")


def _read_regular(path: Path, limit: int) -> bytes:
    """The bytes of ``path``, by the package's one file-reading rule.

    See :func:`impact_balance.files.read_regular`.

    Raises:
        SimulationError: Not a regular file, or larger than ``limit`` (``--journal`` named).
        OSError: The file cannot be opened or read.
    """
    from impact_balance.exceptions import SimulationError

    try:
        return read_regular(path, limit=limit)
    except NotRegularFileError:
        raise SimulationError("--journal", str(path), "not a regular file") from None
    except FileTooLargeError:
        raise SimulationError(
            "--journal", str(path), f"larger than {limit} bytes; choose another file"
        ) from None


def check_trial_entry(entry: Any) -> str | None:
    """Why ``entry`` is not a trial entry this version writes, or None when it is one.

    A trial entry is an object with a ``summary`` object whose ``outcome`` is one of
    :data:`impact_balance.sim.trials.outcomes.OUTCOMES`, and a ``trajectory`` object.
    """
    from impact_balance.exceptions import short_repr
    from impact_balance.sim.trials.outcomes import OUTCOMES

    if not isinstance(entry, dict) or not isinstance(entry.get("summary"), dict):
        return "no trial summary"
    outcome = entry["summary"].get("outcome")
    if not isinstance(outcome, str) or outcome not in OUTCOMES:
        return f"unknown outcome {short_repr(outcome)}"
    if not isinstance(entry.get("trajectory"), dict):
        return "no trajectory"
    return None


@dataclass
class TrialJournal:
    """An append-only journal of finished trials (see the module docstring).

    Attributes:
        path: The JSON-lines file (None: keep nothing on disk).
        digest: What the trials depend on.
        header: Extra header fields (written once, informative).
        entries: The trials read back, by key.
        skipped_lines: Lines that were not reused (cut, damaged, foreign, edited, unknown).
        problems: One line per line not reused: its number and why (at most ten, then a count).
    """

    path: Path | None
    digest: str
    header: dict[str, Any] = field(default_factory=dict)
    entries: dict[str, dict[str, Any]] = field(default_factory=dict)
    skipped_lines: int = 0
    problems: list[str] = field(default_factory=list)
    _handle: Any = field(default=None, init=False, repr=False)

    @classmethod
    def open(
        cls,
        path: str | Path | None,
        digest: str,
        header: dict[str, Any] | None = None,
        check: Callable[[Any], str | None] = check_trial_entry,
    ) -> TrialJournal:
        """Open (or create) the journal at ``path``; a file of another digest is refused.

        Args:
            path: The JSON-lines file, or None for a journal kept in memory only.
            digest: What the trials depend on (:func:`journal_digest`).
            header: Extra header fields, written when the file is created.
            check: Why an entry read back is not reusable (None: it is);
                :func:`check_trial_entry` by default.

        Raises:
            SimulationError: The file holds another digest's trials (a readable header), is
                not a regular file, or is too large (bad input, exit 2).
            EnvironmentFailure: The file cannot be read or written (exit 1).
        """
        journal = cls(None if path is None else Path(path), digest, dict(header or {}))
        if journal.path is None:
            return journal
        cut = False
        try:
            if journal.path.exists() or journal.path.is_symlink():
                cut = journal._read(check)
            else:
                journal.path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(
                journal.path,
                os.O_WRONLY | os.O_APPEND | os.O_CREAT | os.O_NONBLOCK | os.O_CLOEXEC,
                0o666,
            )
            if not stat.S_ISREG(os.fstat(fd).st_mode):  # swapped in since the read
                os.close(fd)
                raise OSError(errno.EINVAL, "not a regular file")
            journal._handle = os.fdopen(fd, "a", encoding="utf-8")
            if cut:  # end a cut last line, so that the next line starts clean
                journal._handle.write("\n")
            if os.fstat(fd).st_size == 0:
                record = {"journal": "impact-balance trials", "digest": digest, **journal.header}
                journal._write({**record, "checksum": _checksum(record)})
        except OSError as exc:
            journal.close()
            raise journal._failure(exc) from None
        return journal

    def _failure(self, exc: OSError) -> Exception:
        from impact_balance.exceptions import EnvironmentFailure

        reason = exc.strerror or os.strerror(exc.errno or 0) or type(exc).__name__
        return EnvironmentFailure("--journal", str(self.path), reason)

    def _problem(self, number: int, why: str) -> None:
        self.skipped_lines += 1
        if len(self.problems) < _NAMED_PROBLEMS:
            self.problems.append(f"line {number}: {why}; its trial runs again")
        elif len(self.problems) == _NAMED_PROBLEMS:
            self.problems.append("more lines not reused (see skipped_lines)")

    def _header(self, record: Any) -> None:
        from impact_balance.exceptions import SimulationError

        if not isinstance(record, dict) or "journal" not in record:
            self._problem(1, "not a journal header (damaged); each trial line is checked alone")
            return
        if record.get("digest") != self.digest:
            raise SimulationError(
                "--journal",
                str(self.path),
                "holds the trials of another scenario or of "
                "other options (digest differs); choose another file",
            )
        try:
            intact = record.get("checksum") == _checksum(record)
        except (ValueError, TypeError, RecursionError):  # not canonical JSON
            intact = False
        if not intact:
            self.skipped_lines += 1
            self.problems.append("line 1: header checksum does not match (damaged or edited)")

    def _line(
        self, number: int, record: dict[str, Any], check: Callable[[Any], str | None]
    ) -> None:
        if set(record) != {"digest", "key", "entry", "checksum"}:
            self._problem(number, "not a trial line (damaged, or written by an older version)")
        elif record["digest"] != self.digest:
            self._problem(number, "the trial of another scenario or options (digest differs)")
        elif record["checksum"] != _checksum(record):
            self._problem(number, "checksum does not match (damaged or edited)")
        elif (why := check(record["entry"])) is not None:
            self._problem(number, f"not a trial entry ({why})")
        else:
            self.entries[_key(record["key"])] = record["entry"]

    def _read(self, check: Callable[[Any], str | None]) -> bool:
        """Read the trials back; True when the last line is cut (no newline)."""
        assert self.path is not None
        data = _read_regular(self.path, MAX_JOURNAL_BYTES)
        for index, raw in enumerate(data.splitlines()):
            number = index + 1
            if not raw.strip():
                continue
            try:
                record = json.loads(raw.decode("utf-8"), parse_constant=_refuse_constant)
            except (ValueError, RecursionError):
                record = _NOT_JSON
            if index == 0:
                self._header(record)
            elif record is _NOT_JSON:
                self._problem(number, "not JSON (damaged or cut)")
            elif not isinstance(record, dict):
                self._problem(number, "not a JSON object (damaged)")
            else:
                try:
                    self._line(number, record, check)
                except (ValueError, TypeError, RecursionError):  # not canonical JSON
                    self._problem(number, "not a trial line (damaged)")
        return bool(data) and not data.endswith(b"\n")

    def _write(self, record: dict[str, Any]) -> None:
        if self._handle is None:
            return
        try:
            self._handle.write(json.dumps(record, allow_nan=False) + "\n")
            self._handle.flush()
            os.fsync(self._handle.fileno())
        except OSError as exc:
            raise self._failure(exc) from None

    def get(self, key: Any) -> dict[str, Any] | None:
        """The stored entry of a trial, or None."""
        return self.entries.get(_key(key))

    def add(self, key: Any, entry: dict[str, Any]) -> None:
        """Record a finished trial (written and flushed at once).

        Raises:
            EnvironmentFailure: The line cannot be written (a full disk: ``--journal`` named).
        """
        self.entries[_key(key)] = entry
        record = {"digest": self.digest, "key": key, "entry": entry}
        self._write({**record, "checksum": _checksum(record)})

    def close(self) -> None:
        """Close the journal's file (idempotent; a failing close is ignored)."""
        if self._handle is not None:
            handle, self._handle = self._handle, None
            try:
                handle.close()
            except OSError:
                pass
