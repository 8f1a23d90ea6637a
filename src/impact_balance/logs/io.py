"""Write and read logs (Parquet or CSV, chosen by the file's suffix) through pandas/pyarrow."""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from ..exceptions import ScenarioError
from .schema import LOG_VERSION, LogColumns

__all__ = ["write_log", "read_log", "check_log_path", "SUFFIXES"]

#: Supported file types.
SUFFIXES = (".parquet", ".csv")


def check_log_path(path: str | Path, field: str = "--log") -> str:
    """The suffix of a log file name (``.parquet`` or ``.csv``); :class:`ScenarioError` naming
    ``field`` otherwise. Commands call it before a long run, so a bad name fails at once."""
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in SUFFIXES:
        raise ScenarioError(field, str(path)[:80], f"a log is a .parquet or .csv file, not {suffix or 'no suffix'!r}")
    return suffix


def write_log(frame: pd.DataFrame, path: str | Path, metadata: dict[str, str] | None = None) -> Path:
    """Write ``frame`` (columns of :mod:`.schema`) to ``path``; Parquet files keep ``metadata`` and the version."""
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


def read_log(path: str | Path) -> pd.DataFrame:
    """Read a log; refuse a file without the required columns, naming them."""
    path = Path(path)
    suffix = check_log_path(path, "LOG")
    if not path.is_file():
        raise ScenarioError("LOG", str(path)[:80], "no such file")
    try:
        frame = pd.read_csv(path) if suffix == ".csv" else pd.read_parquet(path)
    except Exception as exc:  # pandas/pyarrow raise many types for a malformed file
        raise ScenarioError("LOG", str(path)[:80], f"cannot read as {suffix[1:]}: {type(exc).__name__}") from None
    missing = [c for c in LogColumns().required if c not in frame.columns]
    if missing:
        raise ScenarioError("LOG", str(path)[:80], f"missing required columns: {', '.join(missing)}")
    return frame
