"""Numbers as JSON values: a finite float, or ``null`` for an undefined or infinite result."""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import SupportsFloat

__all__ = ["json_number", "json_numbers"]


def json_number(value: SupportsFloat | None) -> float | None:
    """``value`` as a float, or None when it is None, NaN or infinite.

    Args:
        value: A number (Python or numpy), or None.

    Returns:
        ``float(value)`` when finite, else None.

    A result that is undefined (the ZMP of a robot off the ground) or unbounded (a maximum
    contact velocity that no approach speed reaches) is ``null`` in JSON, never ``NaN`` or
    ``Infinity``, which strict JSON parsers refuse.
    """
    if value is None:
        return None
    number = float(value)
    return number if math.isfinite(number) else None


def json_numbers(values: Iterable[SupportsFloat | None]) -> list[float | None]:
    """Each value through :func:`json_number`.

    Args:
        values: Numbers or None.

    Returns:
        The list of their JSON values.
    """
    return [json_number(v) for v in values]
