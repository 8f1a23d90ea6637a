"""Write and read logs (Parquet or CSV, chosen by the file's suffix) through pandas/pyarrow.

Reading is bounded and strict (see :mod:`impact_balance.scenario.reader` for the limits):

- the file is opened once and must be a regular file (a FIFO or a device is refused at once);
- the file's size, row count, column count and value count are checked before it is read
  (a Parquet file's from its metadata; a CSV file is read up to the first row past the limit);
- only the columns the checker reads are read (``time``, the base, ``q_``/``v_``, ``zmp_``,
  ``force_``, ``com_``, ``comd_``); any other column is skipped unread. A Parquet column the
  checker reads may hold at most :data:`MAX_LOG_COLUMN_BYTES_PER_ROW` bytes a row once
  uncompressed (checked from the footer, before reading), so a small file cannot unpack into
  gigabytes;
- every column the checker reads (``time``, the base pose and velocity, each ``q_``/``v_``
  joint column) must hold finite numbers: text, a boolean, an empty cell, NaN or infinity is
  named with its column and row (and the line of a CSV file);
- the optional columns (ZMP, forces, reference CoM) must be numbers; an empty cell there means
  "not measured at this sample";
- a CSV file whose last line has no line break may have been cut while written: a last line
  with missing fields is left out, with a warning; a complete one is kept, with a warning that
  its last value may be cut.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import BinaryIO

import numpy as np
import pandas as pd

from impact_balance.analysis.result import Diagnostic
from impact_balance.exceptions import ScenarioError, short_repr
from impact_balance.files import open_regular
from impact_balance.logs.schema import LOG_VERSION, LogColumns
from impact_balance.scenario.reader import (
    MAX_LOG_BYTES,
    MAX_LOG_COLUMNS,
    MAX_LOG_ROWS,
    MAX_LOG_VALUES,
)

__all__ = [
    "MAX_LOG_COLUMN_BYTES_PER_ROW",
    "MAX_LOG_COLUMN_SLACK",
    "SUFFIXES",
    "check_log_columns",
    "check_log_path",
    "read_log",
    "write_log",
]

#: Supported file types.
SUFFIXES = (".parquet", ".csv")
#: Largest uncompressed size of a column the checker reads, bytes per row (a float64 is 8; a
#: column of short text, refused later with its row named, fits too).
MAX_LOG_COLUMN_BYTES_PER_ROW = 64
#: Uncompressed bytes a read column may hold beyond its rows' share (page headers, a few texts).
MAX_LOG_COLUMN_SLACK = 1 << 20
#: Prefixes of the optional numeric columns (an empty cell: not measured at that sample).
_OPTIONAL = ("zmp_", "force_", "com_", "comd_")


def check_log_path(path: str | Path, field: str = "--log") -> str:
    """The suffix of a log file name (``.parquet`` or ``.csv``).

    Commands call it before a long run, so a bad name fails at once.

    Args:
        path: The log file's name.
        field: The option or argument named in the error.

    Returns:
        The suffix, in lower case.

    Raises:
        ScenarioError: The suffix is neither ``.parquet`` nor ``.csv``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ScenarioError(
            field,
            str(path)[:80],
            f"a log is a .parquet or .csv file, not {suffix or 'no suffix'!r}",
        )
    return suffix


def write_log(
    frame: pd.DataFrame, path: str | Path, metadata: dict[str, str] | None = None
) -> Path:
    """Write ``frame`` (columns of :mod:`.schema`) to ``path``.

    Args:
        frame: The log.
        path: The file; its suffix chooses the format.
        metadata: Key-value pairs a Parquet file keeps beside the schema's version.

    Returns:
        The path written.
    """
    path = Path(path)
    suffix = check_log_path(path, "--log")
    missing = [c for c in LogColumns().required if c not in frame.columns]
    if missing:
        raise ScenarioError("log", ", ".join(missing), "missing required columns")
    path.parent.mkdir(parents=True, exist_ok=True)
    if suffix == ".csv":
        frame.to_csv(path, index=False)
    else:
        import pyarrow as pa
        import pyarrow.parquet as pq

        table = pa.Table.from_pandas(frame, preserve_index=False)
        meta = dict(table.schema.metadata or {})
        meta[b"impact_balance_log_version"] = str(LOG_VERSION).encode()
        for key, value in (metadata or {}).items():
            meta[f"impact_balance_{key}".encode()] = str(value).encode()
        pq.write_table(table.replace_schema_metadata(meta), path)
    return path


def _size_limits(shown: str, rows: int, columns: int) -> int:
    """The rows a log of ``columns`` columns may have; refuses too many columns."""
    if columns > MAX_LOG_COLUMNS:
        raise ScenarioError("LOG", shown, f"{columns} columns: a log has at most {MAX_LOG_COLUMNS}")
    allowed = min(MAX_LOG_ROWS, MAX_LOG_VALUES // max(columns, 1))
    if rows > allowed:
        raise ScenarioError(
            "LOG",
            shown,
            f"{rows:,} rows of {columns} columns: a log has at most {MAX_LOG_ROWS:,} "
            f"rows and {MAX_LOG_VALUES:,} values (split it)",
        )
    return allowed


def _used(name: object) -> bool:
    """Whether the checker reads column ``name`` (the others are never read)."""
    text = str(name)
    return text in LogColumns().required or text.startswith(("q_", "v_", *_OPTIONAL))


def _read_parquet(f: BinaryIO, shown: str) -> pd.DataFrame:
    import pyarrow.parquet as pq

    parquet = pq.ParquetFile(f, pre_buffer=False)
    meta = parquet.metadata  # counts and sizes from the footer: no column is read yet
    _size_limits(shown, meta.num_rows, meta.num_columns)
    used = [name for name in parquet.schema_arrow.names if _used(name)]
    sizes: dict[str, int] = {}
    for group in range(meta.num_row_groups):
        row_group = meta.row_group(group)
        for j in range(row_group.num_columns):
            column = row_group.column(j)
            name = column.path_in_schema.split(".")[0]
            sizes[name] = sizes.get(name, 0) + column.total_uncompressed_size
    allowed = MAX_LOG_COLUMN_BYTES_PER_ROW * meta.num_rows + MAX_LOG_COLUMN_SLACK
    for name in used:
        if sizes.get(name, 0) > allowed:
            raise ScenarioError(
                "LOG",
                shown,
                f"column {name}: {sizes[name]:,} bytes once uncompressed for {meta.num_rows:,} "
                f"rows (at most {MAX_LOG_COLUMN_BYTES_PER_ROW} a row): not a column of numbers",
            )
    # Read and convert on this thread: Arrow's reader and conversion threads can still run at
    # interpreter exit and abort the process there (apache/arrow#34314).
    return parquet.read(columns=used, use_threads=False).to_pandas(use_threads=False)


def _last_line(f: BinaryIO) -> tuple[bool, str]:
    """(ends with a line break, the last line's text)."""
    size = os.fstat(f.fileno()).st_size
    f.seek(max(0, size - 65536))
    tail = f.read(65536)
    ends = tail.endswith(b"\n")
    last = tail.rstrip(b"\r\n").rsplit(b"\n", 1)[-1]
    return ends, last.decode("utf-8", errors="replace")


def _read_csv(f: BinaryIO, shown: str, warnings: list[Diagnostic] | None) -> pd.DataFrame:
    header = f.readline(1 << 20)
    columns = header.count(b",") + 1 if header.strip() else 0
    allowed = _size_limits(shown, 0, columns)
    f.seek(0)
    frame = pd.read_csv(f, nrows=allowed + 1, usecols=_used)
    _size_limits(shown, len(frame), columns)
    ends, last = _last_line(f)
    if not ends and len(frame):
        fields = last.count(",") + 1
        line = len(frame) + 1
        if fields < columns:
            frame = frame.iloc[:-1]
            note = (
                f"the last line ({line}) has {fields} of {columns} fields and no "
                "line break: the file was cut while written; that line is left out"
            )
        else:
            note = (
                "the file does not end with a line break: its last line "
                f"({line}) may have been cut while written (its last value may be short)"
            )
        if warnings is not None:
            warnings.append(Diagnostic("log_cut", "LOG", note))
    return frame


def read_log(path: str | Path, warnings: list[Diagnostic] | None = None) -> pd.DataFrame:
    """Read a log within the limits (only the columns the checker uses).

    The file is opened once (:func:`impact_balance.files.open_regular`: a regular file, never a
    FIFO or a device, at most :data:`~impact_balance.scenario.reader.MAX_LOG_BYTES`) and
    parsed through that descriptor. A Parquet file's row, column and uncompressed sizes are
    checked from its footer before any column is read; unused columns are never read.

    Args:
        path: A ``.parquet`` or ``.csv`` file.
        warnings: If given, receives the caveats (a CSV file cut in its last line).

    Returns:
        The log, one row per sample: the columns the checker reads (time, base, joints, ZMP,
        forces, CoM), in the file's order.

    Raises:
        ScenarioError: The file is missing, not a regular file, too large (in bytes, rows,
            columns or uncompressed bytes of a column), lacks a required column (named) or
            holds a value the checker cannot use (named with its column and row).
    """
    path = Path(path)
    suffix = check_log_path(path, "LOG")
    shown = str(path)[:80]
    try:
        f = open_regular(path, limit=MAX_LOG_BYTES, what="LOG")
    except ScenarioError as exc:
        raise ScenarioError("LOG", shown, exc.reason) from None
    with f:
        try:
            frame = _read_csv(f, shown, warnings) if suffix == ".csv" else _read_parquet(f, shown)
        except ScenarioError:
            raise
        except MemoryError:
            raise
        except Exception as exc:  # pandas/pyarrow raise many types for a malformed file
            raise ScenarioError(
                "LOG", shown, f"cannot read as {suffix[1:]}: {type(exc).__name__}"
            ) from None
    missing = [c for c in LogColumns().required if c not in frame.columns]
    if missing:
        raise ScenarioError("LOG", shown, f"missing required columns: {', '.join(missing)}")
    check_log_columns(frame, shown, line_offset=2 if suffix == ".csv" else None)
    return frame


def _where(row: int, line_offset: int | None) -> str:
    return f"row {row + 1}" + (f" (line {row + line_offset})" if line_offset is not None else "")


def check_log_columns(
    frame: pd.DataFrame, source: str = "LOG", line_offset: int | None = None
) -> None:
    """Refuse a value the checker cannot use, naming its column and row (see the module docstring).

    ``line_offset``: for a CSV file, the file line of row 0 (the header is line 1).
    """
    cols = LogColumns()
    required = set(cols.required) | {c for c in frame.columns if str(c).startswith(("q_", "v_"))}
    for name in frame.columns:
        name_s = str(name)
        needed = name in required
        if not needed and not name_s.startswith(_OPTIONAL):
            continue
        column = frame[name]
        if pd.api.types.is_bool_dtype(column):
            raise ScenarioError("LOG", source, f"column {name_s}: true/false values, not numbers")
        if not pd.api.types.is_numeric_dtype(column):
            numbers = pd.to_numeric(column, errors="coerce")
            bad = numbers.isna() & column.notna()
            if bad.any():
                row = int(np.flatnonzero(bad.to_numpy())[0])
                value = short_repr(column.iloc[row], 30)
                raise ScenarioError(
                    "LOG",
                    source,
                    f"column {name_s}, {_where(row, line_offset)}: {value} is not a number",
                )
            column = numbers
        if needed:
            values = column.to_numpy(dtype=float)
            bad_rows = np.flatnonzero(~np.isfinite(values))
            if bad_rows.size:
                row = int(bad_rows[0])
                what = "empty (or NaN)" if np.isnan(values[row]) else "infinite"
                more = f"; {bad_rows.size} such rows" if bad_rows.size > 1 else ""
                raise ScenarioError(
                    "LOG",
                    source,
                    f"column {name_s}, {_where(row, line_offset)}: {what}, not a finite "
                    f"number{more}",
                )
