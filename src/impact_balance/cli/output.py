"""What the commands write: strict JSON documents on stdout, progress bars on stderr.

Under ``--json`` stdout is exactly one JSON document that any parser reads: non-finite numbers
are ``null`` where they are produced (an unbounded maximum, for example), and
:func:`print_json` refuses NaN and Infinity (``allow_nan=False``) rather than print them.
"""

from __future__ import annotations

import json
import math
import sys
from typing import TYPE_CHECKING, Any

from impact_balance.exceptions import ImpactBalanceError

if TYPE_CHECKING:
    from tqdm import tqdm

__all__ = ["NonFiniteOutputError", "print_json", "progress_bar"]


class NonFiniteOutputError(ImpactBalanceError):
    """A result to print holds NaN or an infinity where a number is expected.

    A bug, reported as one line naming the field rather than printed as invalid JSON.

    Attributes:
        field: Dotted path of the value in the document.
    """

    def __init__(self, field: str):
        self.field = field
        super().__init__(
            f"{field}: the result is not a finite number (please report this scenario)"
        )


def _non_finite_path(obj: Any, path: str = "") -> str | None:
    """Where the first non-finite float of a JSON value is (``a.b[2]``), or None."""
    stack = [(obj, path)]
    while stack:
        node, where = stack.pop()
        if isinstance(node, float) and not math.isfinite(node):
            return where or "(document)"
        if isinstance(node, dict):
            stack.extend((v, f"{where}.{k}" if where else str(k)) for k, v in node.items())
        elif isinstance(node, (list, tuple)):
            stack.extend((v, f"{where}[{i}]") for i, v in enumerate(node))
    return None


def _plain(obj: Any) -> Any:
    """Numpy arrays and scalars as plain lists and numbers (json knows neither)."""
    import numpy as np  # here: `impact-balance scenarios` imports this module and needs no numpy

    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, np.generic):
        return obj.item()
    raise TypeError(f"{type(obj).__name__} is not JSON serializable")


def print_json(document: Any) -> None:
    """Print one strict JSON document (no NaN/Infinity) on stdout."""
    try:
        text = json.dumps(document, allow_nan=False, default=_plain)
    except ValueError:
        raise NonFiniteOutputError(_non_finite_path(document) or "(document)") from None
    print(text)


def progress_bar(desc: str, total: int | None = None, unit: str = "trial") -> tqdm[Any]:
    """A tqdm progress bar on stderr (stdout stays for the answer)."""
    from tqdm import tqdm

    # disable=None: drawn on a terminal only, so logs and pipes get no carriage-return noise.
    return tqdm(
        total=total,
        desc=desc,
        file=sys.stderr,
        unit=unit,
        leave=False,
        dynamic_ncols=True,
        disable=None,
    )
