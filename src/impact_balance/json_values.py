"""Numbers as JSON values: a finite float, or ``null`` for an undefined or infinite result."""

from __future__ import annotations

import math
from collections.abc import Iterable

__all__ = ["json_number", "json_numbers"]


def json_number(value: float | None) -> float | None:
    """``value`` as a float, or None when it is None, NaN or infinite.

    A result that is undefined (the ZMP of a robot off the ground) or unbounded (a maximum
    contact velocity that no approach speed reaches) is ``null`` in JSON, never ``NaN`` or
    ``Infinity``, which strict JSON parsers refuse.
    """
    if value is None:
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def json_numbers(values: Iterable[float | None]) -> list[float | None]:
    """Each value through :func:`json_number`."""
    return [json_number(v) for v in values]
