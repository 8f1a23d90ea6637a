"""The output folder of a sweep: a manifest, one Parquet part per chunk, checked like a database.

```
OUT/manifest.json               what the sweep is (the plan's digest, points, chunks, columns)
OUT/manifest-parts.jsonl        one line per part written: chunk, file, rows, checksum
OUT/parts/part-000000.parquet   rows of chunk 0 ... (metadata: digest, chunk, rows, checksum)
OUT/rejected/                   parts a resume found bad, moved aside (never deleted)
```

A part is written to a hidden temporary file and renamed, then recorded in the manifest of
parts. A folder is never trusted by its file names: :func:`check_folder` opens every part and
checks that it is readable to the end, that it belongs to this sweep (the digest in its
metadata), that it holds the chunk its name says, the row count of that chunk, the points of
that chunk, and the checksum of its values (against its metadata and against the manifest).
Before a part is read, its footer is checked: its columns must be this sweep's and its sizes
(file, uncompressed values) within :data:`MAX_PART_ROW_BYTES` a row. A part recorded
in the manifest of parts must have the checksum recorded (a part written just before a kill may
be unrecorded); a folder whose ``manifest-parts.jsonl`` is gone is damaged: none of its parts
is vouched for, a resume computes them again. The manifest itself is checked against the sweep
it records (``spec``): ``n_points``, ``chunk_size``, ``n_chunks`` and the number of
``dimensions`` are recomputed from it, not trusted; a resume rewrites a damaged manifest from
the sweep file. The manifest, the manifest of parts and the parts must be regular files, read
with a bound (:data:`MAX_MANIFEST_BYTES`, :data:`MAX_LEDGER_BYTES`): a FIFO is refused, never
waited on.

The checksums protect against damage and accidental edits (a cut file, a flipped value, a
part copied from another folder); they do not protect against a forger, who can recompute
them.

A part that fails is named in one line with what is wrong:

- ``damaged``: cut short, emptied, edited (checksum), the wrong rows, or not the part recorded;
- ``foreign``: from another sweep (another digest), or not written by impact-balance;
- ``renamed``: holds another chunk than its name says;
- ``extra``: a chunk beyond the sweep, or a file that is not a part;
- ``missing``: recorded in the manifest, but the file is gone (or the manifest of parts is gone).

A resume (:func:`~impact_balance.sweep.runner.run_sweep`) moves every bad part to ``rejected/``
and computes its chunk again: rows are never duplicated, never silently skipped, and a resumed
folder holds the same rows as an uninterrupted run. ``--summary`` reads the good parts only and
names the others; ``impact-balance sweep --verify DIR`` checks a folder.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import re
from collections.abc import Callable, Iterator
from contextlib import ExitStack
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pyarrow as pa
import pyarrow.compute as pc
import pyarrow.parquet as pq

from impact_balance.exceptions import EnvironmentFailure, SweepError, short_repr
from impact_balance.files import open_regular, read_regular
from impact_balance.ranges import MAX_SWEEP_POINTS
from impact_balance.sweep.columns import RESULT_COLUMNS
from impact_balance.sweep.plan import PLAN_VERSION, SweepPlan, chunk_size_of
from impact_balance.sweep.spec import SweepSpec

__all__ = [
    "LEDGER",
    "MANIFEST",
    "MAX_LEDGER_BYTES",
    "MAX_MANIFEST_BYTES",
    "MAX_PART_ROW_BYTES",
    "PARTS",
    "REJECTED",
    "FolderCheck",
    "PartProblem",
    "PartRecord",
    "ProblemKind",
    "ResultStore",
    "check_folder",
    "load_results",
    "read_manifest",
    "read_results",
    "table_checksum",
]

#: What is wrong with a part (see the module docstring).
ProblemKind = Literal["damaged", "foreign", "renamed", "extra", "missing"]

MANIFEST = "manifest.json"
LEDGER = "manifest-parts.jsonl"
PARTS = "parts"
REJECTED = "rejected"
#: Largest manifest and manifest of parts read (bytes).
MAX_MANIFEST_BYTES = 32 * 1024 * 1024
MAX_LEDGER_BYTES = 64 * 1024 * 1024
#: Largest size of a part a row (bytes, on disk and uncompressed), from its footer, plus 1 MiB.
MAX_PART_ROW_BYTES = 64 * 1024
_PART_ALLOWANCE = 1024 * 1024
_PART = re.compile(r"^part-(\d{6})\.parquet$")
_TMP = re.compile(r"^\.part-\d{6}\.parquet\.\d+\.tmp$")
#: Keys of a part's Parquet metadata.
META_DIGEST, META_CHUNK, META_ROWS, META_CHECKSUM = (
    b"impact_balance.sweep",
    b"impact_balance.chunk",
    b"impact_balance.rows",
    b"impact_balance.checksum",
)


def _part_name(chunk: int) -> str:
    return f"part-{chunk:06d}.parquet"


# -- checksum --------------------------------------------------------------------------------
def _type_name(t: pa.DataType) -> str:
    """A type's name without the child field's name (``list<item>`` and ``list<element>`` agree)."""
    if pa.types.is_list(t) or pa.types.is_large_list(t):
        return f"list<{_type_name(t.value_type)}>"
    return "string" if pa.types.is_large_string(t) else str(t)


def _hash_array(h: Any, arr: pa.Array) -> None:
    h.update(np.packbits(arr.is_valid().to_numpy(zero_copy_only=False)).tobytes())
    t = arr.type
    if pa.types.is_list(t) or pa.types.is_large_list(t):
        h.update(
            pc.list_value_length(arr)
            .fill_null(0)
            .to_numpy(zero_copy_only=False)
            .astype("<i8")
            .tobytes()
        )
        _hash_array(h, pc.list_flatten(arr))
    elif pa.types.is_string(t) or pa.types.is_large_string(t):
        values = arr.fill_null("").to_pylist()
        h.update(np.asarray([len(v) for v in values], dtype="<i8").tobytes())
        h.update("".join(values).encode("utf-8", "surrogatepass"))
    else:
        values = arr.fill_null(pa.scalar(0).cast(t) if not pa.types.is_boolean(t) else False)
        data = values.to_numpy(zero_copy_only=False)
        h.update(np.ascontiguousarray(data, dtype=data.dtype.newbyteorder("<")).tobytes())


def table_checksum(table: pa.Table) -> str:
    """``sha256:...`` of a table's column names, types, validity and values.

    The checksum is not of the file's encoding: the same rows read back from Parquet give the
    same checksum.
    """
    h = hashlib.sha256(f"rows={table.num_rows}".encode())
    for fld, column in zip(table.schema, table.columns, strict=True):
        h.update(b"\x00" + fld.name.encode() + b"\x00" + _type_name(fld.type).encode() + b"\x00")
        _hash_array(h, column.combine_chunks())
    return "sha256:" + h.hexdigest()


# -- the folder ------------------------------------------------------------------------------
@dataclass(frozen=True)
class PartRecord:
    """A good part: its chunk, file (relative to the folder), row count and checksum."""

    chunk: int
    file: str
    rows: int
    checksum: str

    def to_dict(self) -> dict[str, Any]:
        """The record as a line of the manifest of parts."""
        return {
            "chunk": self.chunk,
            "file": self.file,
            "rows": self.rows,
            "checksum": self.checksum,
        }


@dataclass(frozen=True)
class PartProblem:
    """A part that cannot be used, and why (see the module docstring for the kinds).

    Attributes:
        file: Its path relative to the folder (``parts/part-000003.parquet``).
        kind: "damaged", "foreign", "renamed", "extra" or "missing".
        reason: What is wrong, in words.
        chunk: The chunk its name (or the manifest) gives, None for a file that is not a part.
    """

    file: str
    kind: ProblemKind
    reason: str
    chunk: int | None = None

    def line(self) -> str:
        """The problem in one line: file, kind, reason."""
        return f"{self.file}: {self.kind}: {self.reason}"

    def to_dict(self) -> dict[str, Any]:
        """The problem as JSON values."""
        return {"file": self.file, "kind": self.kind, "reason": self.reason, "chunk": self.chunk}


@dataclass
class FolderCheck:
    """What :func:`check_folder` found.

    Attributes:
        root: The folder.
        manifest: Its manifest.
        good: The good parts by chunk.
        problems: The bad parts, each with its reason.
        tables: The good parts' rows by chunk (when asked for).
    """

    root: Path
    manifest: dict[str, Any]
    good: dict[int, PartRecord] = field(default_factory=dict)
    problems: list[PartProblem] = field(default_factory=list)
    tables: dict[int, pa.Table] = field(default_factory=dict)

    @property
    def n_chunks(self) -> int:
        """Number of chunks of the sweep."""
        return int(self.manifest["n_chunks"])

    @property
    def missing(self) -> list[int]:
        """Chunks without a good part (to compute)."""
        return [c for c in range(self.n_chunks) if c not in self.good]

    @property
    def ok(self) -> bool:
        """No bad part (the folder may still be incomplete)."""
        return not self.problems

    @property
    def rows(self) -> int:
        """Rows in the good parts."""
        return sum(r.rows for r in self.good.values())

    def to_dict(self) -> dict[str, Any]:
        """The check as JSON values (``sweep --verify --json``)."""
        return {
            "out": str(self.root),
            "digest": self.manifest.get("digest"),
            "n_points": self.manifest.get("n_points"),
            "n_chunks": self.n_chunks,
            "good_parts": len(self.good),
            "rows": self.rows,
            "missing_chunks": len(self.missing),
            "complete": self.ok and not self.missing,
            "ok": self.ok,
            "problems": [p.to_dict() for p in self.problems],
        }


def _rows_of(manifest: dict[str, Any], chunk: int) -> tuple[int, int]:
    size, n = int(manifest["chunk_size"]), int(manifest["n_points"])
    start = chunk * size
    return start, min(n, start + size)


def _read_regular(path: Path, limit: int) -> bytes:
    """The bytes of ``path``, by the package's one file-reading rule.

    See :func:`impact_balance.files.read_regular`.

    Raises:
        OSError: Cannot be opened or read, not a regular file, or larger than ``limit``.
    """
    return read_regular(path, limit=limit)


def _read_ledger(root: Path) -> dict[int, dict[str, Any]] | None:
    """The manifest of parts: the last record of each chunk (a line cut by a kill is skipped).

    Returns:
        The records by chunk, or None when the file is gone.
    """
    records: dict[int, dict[str, Any]] = {}
    try:
        data = _read_regular(root / LEDGER, MAX_LEDGER_BYTES)
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise SweepError(
            "DIR", str(root), f"cannot read {LEDGER} ({exc.strerror or type(exc).__name__})"
        ) from None
    for line in data.decode("utf-8", errors="replace").splitlines():
        try:
            rec = json.loads(line)
            chunk = rec["chunk"]
            if (
                isinstance(chunk, int)
                and not isinstance(chunk, bool)
                and isinstance(rec.get("checksum"), str)
            ):
                records[chunk] = rec
        except (ValueError, TypeError, KeyError, RecursionError):
            continue
    return records


def _expected_columns(manifest: dict[str, Any]) -> list[str]:
    names = [str(d["name"]) for d in manifest["dimensions"]]
    return ["point", "chunk", *names, *(name for name, _, _ in RESULT_COLUMNS)]


def _footer_problem(parquet: pq.ParquetFile, manifest: dict[str, Any], rows: int) -> str | None:
    """What the footer of a part shows wrong (columns, sizes), before anything is read."""
    names = parquet.schema_arrow.names
    expected = _expected_columns(manifest)
    if names != expected:
        odd = sorted(set(names) ^ set(expected))
        which = f" ({', '.join(short_repr(n, 40) for n in odd[:3])})" if odd else " (order)"
        return f"its columns are not this sweep's{which}"
    types = {f.name: _type_name(f.type) for f in parquet.schema_arrow}
    for name, typ, _ in RESULT_COLUMNS:
        if types[name] != _type_name(typ):
            return f"its column {name} is {types[name]}, not {_type_name(typ)}"
    bound = _PART_ALLOWANCE + rows * MAX_PART_ROW_BYTES
    meta = parquet.metadata
    size = sum(meta.row_group(i).total_byte_size for i in range(meta.num_row_groups))
    if size > bound:
        return f"its values take {size} bytes uncompressed, more than {rows} rows can"
    return None


def _check_part(
    path: Path,
    manifest: dict[str, Any],
    ledger: dict[int, dict[str, Any]] | None,
    keep: dict[int, pa.Table] | None,
) -> PartRecord | PartProblem:
    """One part checked against the manifest and the ledger (its file closed on return)."""
    with ExitStack() as stack:
        return _check_part_in(path, manifest, ledger, keep, stack)


def _check_part_in(
    path: Path,
    manifest: dict[str, Any],
    ledger: dict[int, dict[str, Any]] | None,
    keep: dict[int, pa.Table] | None,
    stack: ExitStack,
) -> PartRecord | PartProblem:
    rel = f"{PARTS}/{path.name}"
    match = _PART.match(path.name)
    if match is None:
        return PartProblem(rel, "extra", "not a part file name (part-NNNNNN.parquet)")
    named = int(match.group(1))
    n_chunks = int(manifest["n_chunks"])
    if path.is_symlink() or not path.is_file():
        return PartProblem(rel, "extra", "not a regular file", named)
    if named >= n_chunks:
        return PartProblem(
            rel, "extra", f"chunk {named} is beyond this sweep's {n_chunks} chunks", named
        )
    start, stop = _rows_of(manifest, named)
    if path.stat().st_size > _PART_ALLOWANCE + (stop - start) * MAX_PART_ROW_BYTES:
        return PartProblem(rel, "damaged", f"larger than {stop - start} rows can be", named)
    try:
        # Read through the descriptor the file-reading rule checked (a regular file, opened
        # without blocking): a FIFO swapped in after the checks above is never waited on.
        limit = _PART_ALLOWANCE + (stop - start) * MAX_PART_ROW_BYTES
        handle = stack.enter_context(open_regular(path, limit=limit, what=rel))
        parquet = pq.ParquetFile(handle, pre_buffer=False)  # no reader thread (in read_log)
        meta = parquet.schema_arrow.metadata or {}
        stored_rows = parquet.metadata.num_rows
        footer = _footer_problem(parquet, manifest, stop - start)
    except Exception:
        return PartProblem(
            rel, "damaged", "not a readable Parquet file (cut short, emptied or overwritten)", named
        )
    digest = meta.get(META_DIGEST)
    if digest is None:
        return PartProblem(
            rel, "foreign", "not a part of an impact-balance sweep (no sweep metadata)", named
        )
    if digest.decode(errors="replace") != manifest["digest"]:
        return PartProblem(
            rel,
            "foreign",
            f"a part of another sweep (digest {digest.decode(errors='replace')[:16]}; "
            f"this folder's is {manifest['digest']})",
            named,
        )
    try:
        chunk, rows, checksum = (
            int(meta[META_CHUNK]),
            int(meta[META_ROWS]),
            meta[META_CHECKSUM].decode(),
        )
    except (KeyError, ValueError, UnicodeDecodeError):
        return PartProblem(
            rel,
            "damaged",
            "its sweep metadata is incomplete (no chunk, row count or checksum)",
            named,
        )
    if chunk != named:
        return PartProblem(
            rel, "renamed", f"holds chunk {chunk}, but its name says chunk {named}", named
        )
    if rows != stop - start or stored_rows != stop - start:
        return PartProblem(
            rel, "damaged", f"{stored_rows} rows where chunk {chunk} has {stop - start}", named
        )
    if footer is not None:
        return PartProblem(rel, "damaged", footer, named)
    if ledger is None:
        return PartProblem(rel, "damaged", f"not vouched for: {LEDGER} is gone", named)
    table = _checked_values(parquet, chunk, start, stop, checksum)
    if isinstance(table, str):
        return PartProblem(rel, "damaged", table, named)
    recorded = ledger.get(chunk)
    if recorded is not None and recorded.get("checksum") != checksum:
        return PartProblem(
            rel, "damaged", "not the part recorded in the manifest (another checksum)", named
        )
    if keep is not None:
        keep[chunk] = table
    return PartRecord(chunk, rel, rows, checksum)


def _checked_values(
    parquet: pq.ParquetFile, chunk: int, start: int, stop: int, checksum: str
) -> pa.Table | str:
    """A part's rows, read once its footer passed; or what is wrong with its values."""
    try:
        table = parquet.read(use_threads=False)
    except Exception:
        return "cannot be read to the end (cut short or overwritten)"
    table = table.replace_schema_metadata(None)
    if table_checksum(table) != checksum:
        return "its values are not those written (checksum mismatch: edited or corrupted)"
    try:
        points_ok = (
            table["point"].to_numpy().tolist() == list(range(start, stop))
            and pc.all(pc.equal(table["chunk"], chunk)).as_py() is not False
        )
    except (KeyError, pa.ArrowInvalid):
        points_ok = False
    if not points_ok:
        return f"its rows are not the points {start}..{stop - 1} of chunk {chunk}"
    return table


def check_folder(
    root: str | Path, keep_tables: bool = False, manifest: dict[str, Any] | None = None
) -> FolderCheck:
    """Check every part of a sweep folder (see the module docstring); never raises for a bad part.

    Args:
        root: The folder.
        keep_tables: Keep the good parts' rows (:attr:`FolderCheck.tables`).
        manifest: The manifest to check the parts against (a resume gives its plan's);
            default: the folder's own, checked by :func:`read_manifest`.

    Raises:
        SweepError: ``root`` is not a sweep folder (no manifest, or an unreadable or damaged
            one), or its manifest of parts cannot be read.
    """
    root = Path(root)
    manifest = read_manifest(root) if manifest is None else manifest
    check = FolderCheck(root, manifest)
    ledger = _read_ledger(root)
    if ledger is None:
        check.problems.append(
            PartProblem(LEDGER, "missing", "the manifest of parts is gone: no part is vouched for")
        )
    parts = root / PARTS
    try:
        entries = sorted(parts.iterdir()) if parts.is_dir() else []
    except OSError as exc:
        raise SweepError(
            "DIR", str(root), f"cannot list {PARTS}/ ({exc.strerror or type(exc).__name__})"
        ) from None
    keep = check.tables if keep_tables else None
    for path in entries:
        if _TMP.match(path.name):  # a write cut short by a kill: never a part
            continue
        if not _PART.match(path.name):
            check.problems.append(
                PartProblem(
                    f"{PARTS}/{path.name}", "extra", "not a part file name (part-NNNNNN.parquet)"
                )
            )
            continue
        found = _check_part(path, manifest, ledger, keep)
        if isinstance(found, PartRecord):
            check.good[found.chunk] = found
        else:
            check.problems.append(found)
    named = {p.chunk for p in check.problems if p.chunk is not None}
    for chunk, rec in sorted((ledger or {}).items()):
        if chunk not in check.good and chunk not in named and 0 <= chunk < check.n_chunks:
            check.problems.append(
                PartProblem(
                    str(rec.get("file") or f"{PARTS}/{_part_name(chunk)}"),
                    "missing",
                    "recorded in the manifest, but the file is gone",
                    chunk,
                )
            )
    return check


# -- writing ---------------------------------------------------------------------------------
@dataclass
class ResultStore:
    """The parts of one plan in ``root`` (see the module docstring).

    :meth:`prepare` checks a folder without changing anything; :meth:`create` makes it (or
    readies it for a resume: bad parts moved to ``rejected/``); :meth:`write` adds a part.
    """

    root: Path
    plan: SweepPlan
    check: FolderCheck | None = None
    repair: str | None = None
    _good: set[int] = field(default_factory=set)

    @classmethod
    def prepare(cls, root: str | Path, plan: SweepPlan) -> ResultStore:
        """Check that ``root`` is new, empty, or a folder of the same sweep (its parts checked).

        Raises:
            SweepError: a file, a folder of another sweep, a folder that is not a sweep's.
        """
        root = Path(root)
        if root.exists() and not root.is_dir():
            raise SweepError("--out", str(root), "exists and is not a folder: choose another --out")
        store = cls(root, plan)
        if (root / MANIFEST).exists() or (root / MANIFEST).is_symlink():
            old = _manifest_data(root)
            if old.get("digest") != plan.digest:
                raise SweepError(
                    "--out",
                    str(root),
                    f"holds the results of a different sweep (digest {old.get('digest')}, "
                    f"this one is {plan.digest}): choose another --out, or delete the folder "
                    "to start again",
                )
            want = json.loads(json.dumps(store.manifest()))
            store.repair = _plan_damage(old) or next(
                (
                    f"{k} is {short_repr(old[k])}, the sweep file has {short_repr(want[k])}"
                    for k in ("n_points", "chunk_size", "n_chunks", "dimensions")
                    if old[k] != want[k]
                ),
                None,
            )
            store.check = check_folder(root, manifest=want)
        elif root.exists() and any(root.iterdir()):
            raise SweepError(
                "--out",
                str(root),
                "exists and is not a sweep folder (no manifest.json): choose another --out",
            )
        return store

    @classmethod
    def open(
        cls, root: str | Path, plan: SweepPlan, notify: Callable[[str], None] | None = None
    ) -> ResultStore:
        """:meth:`prepare` then :meth:`create`."""
        store = cls.prepare(root, plan)
        store.create(notify)
        return store

    @property
    def problems(self) -> list[PartProblem]:
        """The bad parts the check found (moved aside by :meth:`create`)."""
        return list(self.check.problems) if self.check is not None else []

    def create(self, notify: Callable[[str], None] | None = None) -> None:
        """Make the folder and its manifest, or ready it for a resume.

        On a resume every bad part is moved to ``rejected/`` and the manifest of parts lists
        the good ones.

        Args:
            notify: Gets one line per bad part.
        """
        with _writing(self.root, f"{PARTS}/"):
            (self.root / PARTS).mkdir(parents=True, exist_ok=True)
            for stale in (self.root / PARTS).iterdir():  # writes cut short by a kill
                if _TMP.match(stale.name):
                    stale.unlink(missing_ok=True)
        if self.repair is not None and notify is not None:
            notify(f"{MANIFEST}: damaged: {self.repair}; rewritten from the sweep file")
        if self.repair is not None or not (self.root / MANIFEST).is_file():
            with _writing(self.root, MANIFEST):
                _atomic_write_text(self.root / MANIFEST, json.dumps(self.manifest(), indent=1))
        good: dict[int, PartRecord] = dict(self.check.good) if self.check is not None else {}
        for problem in self.problems:
            with _writing(self.root, f"{REJECTED}/"):
                moved = _reject(self.root, problem)
            if notify is not None:
                again = (
                    f"; chunk {problem.chunk} is computed again"
                    if problem.chunk is not None
                    and problem.chunk < self.plan.n_chunks
                    and problem.chunk not in good
                    else ""
                )
                notify(f"{problem.line()}{f': moved to {moved}' if moved else ''}{again}")
        lines = "".join(json.dumps(good[c].to_dict()) + "\n" for c in sorted(good))
        with _writing(self.root, LEDGER):
            _atomic_write_text(self.root / LEDGER, lines)
        self._good = set(good)

    def manifest(self) -> dict[str, Any]:
        """The folder's ``manifest.json``: what the sweep is."""
        plan = self.plan
        return {
            "format": "impact-balance sweep",
            "version": PLAN_VERSION,
            "digest": plan.digest,
            "source": plan.spec.source,
            "description": plan.spec.description,
            "base_source": plan.base_source,
            "n_points": plan.n_points,
            "chunk_size": plan.chunk_size,
            "n_chunks": plan.n_chunks,
            "sampling": plan.spec.sampling.method,
            "dimensions": [
                {"name": d.name, "axis": d.axis, "kind": d.kind, "stance": d.stance}
                for d in plan.dims
            ],
            "spec": plan.spec.digest_data(),
        }

    def finished(self) -> set[int]:
        """Chunks with a good part (checked when the store was prepared)."""
        return set(self._good)

    def write(self, chunk: int, table: pa.Table) -> Path:
        """Write one chunk's rows, then record them in the manifest of parts.

        The part is written to a temporary file and renamed (atomic).

        Args:
            chunk: The chunk.
            table: Its rows.

        Returns:
            The part's path.

        Raises:
            EnvironmentFailure: The part or its record cannot be written (``--out`` and the
                file named: a full disk).
        """
        path = self.root / PARTS / _part_name(chunk)
        data = table.replace_schema_metadata(None)
        checksum = table_checksum(data)
        meta = {
            META_DIGEST: self.plan.digest.encode(),
            META_CHUNK: str(chunk).encode(),
            META_ROWS: str(table.num_rows).encode(),
            META_CHECKSUM: checksum.encode(),
        }
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        with _writing(self.root, f"{PARTS}/{path.name}"):
            try:
                pq.write_table(data.replace_schema_metadata(meta), tmp)
            except BaseException:
                tmp.unlink(missing_ok=True)  # a part cut by a full disk: never left behind
                raise
            os.replace(tmp, path)
        record = PartRecord(chunk, f"{PARTS}/{path.name}", table.num_rows, checksum)
        with _writing(self.root, LEDGER), open(self.root / LEDGER, "a", encoding="utf-8") as f:
            f.write(json.dumps(record.to_dict()) + "\n")
        return path


@contextlib.contextmanager
def _writing(root: Path, what: str) -> Iterator[None]:
    """An error of the machine while writing ``what`` in ``root``: ``--out`` and the file named.

    Raises:
        EnvironmentFailure: For any ``OSError`` (a full disk, a folder made read-only), exit 1.
    """
    try:
        yield
    except OSError as exc:
        reason = (
            exc.strerror
            or (os.strerror(exc.errno) if exc.errno else None)
            or " ".join(str(exc).split())[:160]
            or type(exc).__name__
        )
        raise EnvironmentFailure("--out", str(root), f"cannot write {what}: {reason}") from None


def _reject(root: Path, problem: PartProblem) -> str | None:
    """Move a bad part to ``rejected/`` (a free name).

    Returns:
        Its new path relative to ``root``, None if it is gone.
    """
    source = root / problem.file
    if not (source.exists() or source.is_symlink()) or problem.kind == "missing":
        return None
    folder = root / REJECTED
    folder.mkdir(exist_ok=True)
    target = folder / source.name
    k = 1
    while target.exists() or target.is_symlink():
        target = folder / f"{source.name}.{k}"
        k += 1
    os.replace(source, target)
    return f"{REJECTED}/{target.name}"


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


# -- reading ---------------------------------------------------------------------------------
def _manifest_data(root: str | Path) -> dict[str, Any]:
    """The manifest's JSON object, read with a bound; its format and keys checked, not its plan.

    Raises:
        SweepError: no manifest, not readable, not a sweep manifest.
    """
    path = Path(root) / MANIFEST
    try:
        data = json.loads(_read_regular(path, MAX_MANIFEST_BYTES).decode("utf-8"))
    except FileNotFoundError:
        raise SweepError("DIR", str(root), "is not a sweep folder (no manifest.json)") from None
    except NotADirectoryError:
        raise SweepError("DIR", str(root), "is not a folder") from None
    except OSError as exc:
        raise SweepError(
            "DIR", str(root), f"cannot read manifest.json ({exc.strerror or type(exc).__name__})"
        ) from None
    except (ValueError, RecursionError) as exc:
        raise SweepError(
            "DIR", str(root), f"cannot read manifest.json ({exc.__class__.__name__})"
        ) from None
    keys = ("digest", "n_points", "chunk_size", "n_chunks", "dimensions", "spec")
    if (
        not isinstance(data, dict)
        or data.get("format") != "impact-balance sweep"
        or not all(k in data for k in keys)
    ):
        raise SweepError("DIR", str(root), "manifest.json is not an impact-balance sweep manifest")
    return data


def _plan_damage(data: dict[str, Any]) -> str | None:
    """What in a manifest disagrees with the sweep it records (``spec``), or None.

    ``n_points``, ``chunk_size``, ``n_chunks`` and the number of ``dimensions`` are recomputed
    from the recorded sweep file.
    """
    ints = [data[k] for k in ("n_points", "chunk_size", "n_chunks")]
    if not all(isinstance(v, int) and not isinstance(v, bool) and v >= 0 for v in ints):
        return "its point and chunk counts are not counts"
    try:
        spec = SweepSpec.model_validate(data["spec"])
    except Exception:  # pydantic's ValidationError, or a value its validators refuse
        return "the sweep it records (spec) is not a sweep file's"
    n_points = spec.point_count()
    if n_points is None or n_points > MAX_SWEEP_POINTS:
        return "the sweep it records (spec) has no bounded point count"
    chunk = chunk_size_of(spec)
    expected = {"n_points": n_points, "chunk_size": chunk, "n_chunks": math.ceil(n_points / chunk)}
    for key, value in expected.items():
        if data[key] != value:
            return f"{key} is {short_repr(data[key])}, its sweep has {value}"
    dims, n_dims = data["dimensions"], len(spec.dimension_sizes())
    if not isinstance(dims, list) or not all(
        isinstance(d, dict) and isinstance(d.get("name"), str) for d in dims
    ):
        return "dimensions is not a list of named dimensions"
    if len(dims) != n_dims or len({d["name"] for d in dims}) != n_dims:
        return f"{len(dims)} dimensions (distinct names), its sweep has {n_dims}"
    return None


def read_manifest(root: str | Path) -> dict[str, Any]:
    """The manifest of a sweep folder, checked against the sweep it records.

    Raises:
        SweepError: no manifest, not readable (not a regular file, too large), not a sweep
            manifest, or damaged (its counts or dimensions are not those of its sweep).
    """
    data = _manifest_data(root)
    why = _plan_damage(data)
    if why is not None:
        raise SweepError("DIR", str(root), f"manifest.json is damaged: {why}")
    return data


def load_results(root: str | Path) -> tuple[FolderCheck, pa.Table]:
    """The folder's check and the rows of its good parts, sorted by point (empty if none)."""
    check = check_folder(root, keep_tables=True)
    tables = [check.tables[c] for c in sorted(check.tables)]
    check.tables = {}
    if not tables:
        return check, pa.table({})
    table = pa.concat_tables(tables).sort_by("point")
    return check, table.replace_schema_metadata(
        {META_DIGEST: str(check.manifest["digest"]).encode()}
    )


def read_results(root: str | Path, strict: bool = True) -> pa.Table:
    """All rows of a sweep folder's good parts, sorted by point.

    Args:
        root: The sweep folder.
        strict: Raise :class:`SweepError` naming the first bad part when a part is bad
            (otherwise the good parts only are returned).
    """
    check, table = load_results(root)
    if strict and check.problems:
        more = f" (and {len(check.problems) - 1} more)" if len(check.problems) > 1 else ""
        raise SweepError(
            "DIR",
            str(root),
            f"{check.problems[0].line()}{more}; `impact-balance sweep --verify DIR` "
            "lists them, a resume recomputes them",
        )
    return table
