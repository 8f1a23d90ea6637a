"""The output folder of a sweep: a manifest and one Parquet part file per finished chunk.

```
OUT/manifest.json               what the sweep is (the plan's digest, points, chunks, columns)
OUT/parts/part-000000.parquet   rows of chunk 0 ... (a Parquet dataset: read the folder)
```

A part is written to a hidden temporary file and renamed, so a part file is either complete
or absent: after Ctrl-C, a crash or a kill, the chunks with a part file are done and the same
command computes only the others. A manifest with another digest means the folder holds a
different sweep: it is refused rather than mixed.
"""

from __future__ import annotations

import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from ..exceptions import SweepError
from .plan import PLAN_VERSION, SweepPlan

__all__ = ["ResultStore", "read_manifest", "read_results", "MANIFEST", "PARTS"]

MANIFEST = "manifest.json"
PARTS = "parts"
_PART = re.compile(r"^part-(\d{6})\.parquet$")


def _part_name(chunk: int) -> str:
    return f"part-{chunk:06d}.parquet"


@dataclass
class ResultStore:
    """Writes the parts of one plan into ``root`` (see the module docstring)."""

    root: Path
    plan: SweepPlan

    @classmethod
    def open(cls, root: str | Path, plan: SweepPlan) -> "ResultStore":
        """Create the folder, or reopen it to resume the same sweep.

        Raises:
            SweepError: the folder holds another sweep's results, or is not a sweep folder.
        """
        root = Path(root)
        manifest = root / MANIFEST
        if manifest.is_file():
            old = read_manifest(root)
            if old.get("digest") != plan.digest:
                raise SweepError("--out", str(root), f"holds the results of a different sweep (digest {old.get('digest')}, "
                                 f"this one is {plan.digest}): choose another --out, or delete the folder to start again")
        elif root.exists() and any(root.iterdir()):
            raise SweepError("--out", str(root), "exists and is not a sweep folder (no manifest.json): choose another --out")
        (root / PARTS).mkdir(parents=True, exist_ok=True)
        for stale in (root / PARTS).glob(".part-*.tmp"):  # a write cut short by a kill
            stale.unlink(missing_ok=True)
        store = cls(root, plan)
        if not manifest.is_file():
            _atomic_write_text(manifest, json.dumps(store.manifest(), indent=1))
        return store

    def manifest(self) -> dict[str, Any]:
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
            "dimensions": [{"name": d.name, "axis": d.axis, "kind": d.kind, "stance": d.stance} for d in plan.dims],
            "spec": plan.spec.digest_data(),
        }

    def finished(self) -> set[int]:
        """Chunks with a complete part file."""
        return finished_chunks(self.root)

    def write(self, chunk: int, table: pa.Table) -> Path:
        """Write one chunk's rows at once (temporary file, then an atomic rename)."""
        path = self.root / PARTS / _part_name(chunk)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        pq.write_table(table, tmp)
        os.replace(tmp, path)
        return path


def finished_chunks(root: str | Path) -> set[int]:
    parts = Path(root) / PARTS
    if not parts.is_dir():
        return set()
    return {int(m.group(1)) for p in parts.iterdir() if (m := _PART.match(p.name))}


def _atomic_write_text(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    os.replace(tmp, path)


def read_manifest(root: str | Path) -> dict[str, Any]:
    """The manifest of a sweep folder.

    Raises:
        SweepError: no manifest, or not readable.
    """
    path = Path(root) / MANIFEST
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise SweepError("DIR", str(root), "is not a sweep folder (no manifest.json)") from None
    except (OSError, ValueError) as exc:
        raise SweepError("DIR", str(root), f"cannot read manifest.json ({exc.__class__.__name__})") from None
    if not isinstance(data, dict) or data.get("format") != "impact-balance sweep":
        raise SweepError("DIR", str(root), "manifest.json is not an impact-balance sweep manifest")
    return data


def read_results(root: str | Path) -> pa.Table:
    """All finished rows of a sweep folder, sorted by point (an empty table if none)."""
    read_manifest(root)
    parts = sorted((Path(root) / PARTS).glob("part-*.parquet"))
    if not parts:
        return pa.table({})
    table = pq.ParquetDataset([str(p) for p in parts]).read()
    return table.sort_by("point")
