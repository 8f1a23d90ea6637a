"""Helpers shared by the simulation commands: strict JSON, a progress bar on stderr."""

from __future__ import annotations

import json
import math
import sys
from typing import Any

import numpy as np

__all__ = ["strict_json", "progress_bar"]


def _clean(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return float(obj) if math.isfinite(obj) else None
    return obj


def strict_json(obj: Any) -> str:
    """One strict JSON document: NaN and infinities become null."""
    return json.dumps(_clean(obj), allow_nan=False)


def progress_bar(desc: str, total: int | None = None):
    """A tqdm bar on stderr (disabled when stderr is not a terminal and not forced)."""
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, file=sys.stderr, unit="trial", leave=False, dynamic_ncols=True)
