"""The value types of the scenario schema: vectors, bounded numbers, and the strict base model.

Every bound names its range and unit in the message pydantic raises; the physical ranges
themselves live in :mod:`impact_balance.constants` (shared with lipm.py).
"""

from __future__ import annotations

import math
from typing import Annotated, Any

import numpy as np
from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict

from impact_balance.constants import MAX_ANGLE, MAX_FRICTION, MAX_POSITION, MAX_SPEED

__all__ = ["Angles", "Flag", "Friction", "Integer", "Number", "Position", "Vec2", "Vec3"]


def _not_bool_or_text(v: Any, what: str) -> Any:
    if isinstance(v, (bool, np.bool_)):
        raise ValueError(f"must be {what}, not a boolean ({v})")
    if isinstance(v, (str, bytes)):
        raise ValueError(f"must be {what}, not text (write it without quotes)")
    return v


def _number(v: Any) -> Any:
    return _not_bool_or_text(v, "a number")


def _integer(v: Any) -> Any:
    return _not_bool_or_text(v, "an integer")


def _flag(v: Any) -> Any:
    if isinstance(v, np.bool_):
        return bool(v)
    if not isinstance(v, bool):
        raise ValueError("must be true or false")
    return v


# Strict types: YAML's `True`, `yes` or `'0.7'` is not read as a number, nor 1 as a boolean
# (pydantic's lax mode would convert them silently); ints stay numbers.
#: A number (int or float; a bool or a string is refused).
Number = Annotated[float, BeforeValidator(_number)]
#: An integer (a bool or a string is refused).
Integer = Annotated[int, BeforeValidator(_integer)]
#: true or false (a number or a string is refused).
Flag = Annotated[bool, BeforeValidator(_flag)]

Vec2 = tuple[Number, Number]
Vec3 = tuple[Number, Number, Number]


def _interval(lo: float, hi: float, lo_open: bool = False, hi_open: bool = False) -> str:
    return f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"


def _scalar(
    lo: float, hi: float, unit: str = "", lo_open: bool = False, hi_open: bool = False
) -> AfterValidator:
    """A validator keeping a number within [lo, hi] (or open ends), naming the range."""
    text = _interval(lo, hi, lo_open, hi_open) + (f" {unit}" if unit else "")

    def check(v: float) -> float:
        if not ((lo < v if lo_open else lo <= v) and (v < hi if hi_open else v <= hi)):
            raise ValueError(f"must be in {text}")
        return v

    return AfterValidator(check)


def _coordinates(limit: float, unit: str) -> AfterValidator:
    """A validator keeping every coordinate of a vector within [-limit, limit]."""

    def check(v: tuple[float, ...]) -> tuple[float, ...]:
        if any(abs(x) > limit for x in v):
            raise ValueError(f"each coordinate must be in [{-limit:g}, {limit:g}] {unit}")
        return v

    return AfterValidator(check)


def _speed(v: tuple[float, ...]) -> tuple[float, ...]:
    """``v`` if its norm is at most :data:`~impact_balance.constants.MAX_SPEED` m/s."""
    if math.hypot(*v) > MAX_SPEED:
        raise ValueError(f"the speed must be at most {MAX_SPEED:g} m/s")
    return v


Position = Annotated[Vec3, _coordinates(MAX_POSITION, "m")]
Angles = Annotated[Vec3, _coordinates(MAX_ANGLE, "rad")]
Friction = Annotated[Number, _scalar(0.0, MAX_FRICTION, lo_open=True)]


class _Model(BaseModel):
    # allow_inf_nan=False: NaN and infinities are refused in every float field.
    model_config = ConfigDict(extra="forbid", frozen=True, strict=False, allow_inf_nan=False)


def _finite(values: Any, what: str = "value") -> Any:
    for v in np.atleast_1d(np.asarray(values, dtype=float)):
        if not math.isfinite(v):
            raise ValueError(f"{what} must be finite")
    return values
