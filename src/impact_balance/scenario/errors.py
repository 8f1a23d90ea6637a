"""Pydantic's validation errors as one :class:`~impact_balance.exceptions.ScenarioError`.

The first error of a mapping becomes one error naming the field (a dotted path such as
``contacts[0].friction``), the bad value and the reason; an unknown key becomes an
:class:`~impact_balance.exceptions.UnknownKeyError` listing the keys the schema accepts there.
"""

from __future__ import annotations

import typing
from collections.abc import Mapping
from typing import Any

from pydantic import BaseModel, ValidationError

from impact_balance.exceptions import ScenarioError, UnknownKeyError

__all__ = ["field_name", "scenario_error"]


def field_name(loc: tuple[Any, ...]) -> str:
    """The dotted field path of a pydantic error location.

    Args:
        loc: Pydantic's location: keys and list indices, with its validator tags.

    Returns:
        The path, e.g. ``contacts[0].friction`` (``scenario`` for the top level).
    """
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-after", "function-before") or "[" in str(part):
            continue
        else:
            out += f".{part}" if out else str(part)
    return out or "scenario"


def scenario_error(
    exc: ValidationError, raw: Mapping[str, Any], model: type[BaseModel], source: str | None
) -> ScenarioError:
    """The first error of ``exc`` as one :class:`ScenarioError`.

    A typo shows up as an unknown key AND a missing one: the unknown key is reported.

    Args:
        exc: Pydantic's error for ``raw``.
        raw: The mapping that was validated.
        model: The model it was validated against (for the keys it accepts).
        source: The file it came from, if any.

    Returns:
        The error to raise: an :class:`UnknownKeyError` for an unknown key, else a
        :class:`ScenarioError` naming the field, the value and the reason.
    """
    errors = exc.errors()
    err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
    loc = tuple(p for p in err["loc"] if p not in ("str", "RobotFiles"))
    reason = err["msg"].removeprefix("Value error, ")
    value = err.get("input")
    if err["type"] == "extra_forbidden" and loc:
        return UnknownKeyError(
            field_name(loc), str(loc[-1]), value, _keys_at(model, loc[:-1]), source
        )
    if err["type"] == "missing":
        if loc and isinstance(loc[-1], int):  # a short list/tuple: report the whole list
            value, reason, loc = (
                _lookup(raw, loc[:-1]),
                f"too few items (item {loc[-1]} is missing)",
                loc[:-1],
            )
        else:
            value, reason = None, "missing required key"
    return ScenarioError(field_name(loc), value, reason, source)


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model inside an annotation (``X | None``, ``list[X]``, ``str | X``), if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


def _keys_at(root: type[BaseModel], loc: tuple[Any, ...]) -> list[str]:
    """The keys the schema accepts in the mapping at ``loc`` (for "did you mean")."""
    model: type[BaseModel] | None = root
    for part in loc:
        if isinstance(part, int) or model is None:
            continue
        info = model.model_fields.get(part)
        model = _model_in(info.annotation) if info is not None else None
    if model is None:
        return []
    return [name for name, info in model.model_fields.items() if not info.exclude]


def _lookup(raw: Any, loc: tuple[Any, ...]) -> Any:
    """The value at ``loc`` in ``raw``, None when it is not there."""
    for part in loc:
        try:
            raw = raw[part]
        except (KeyError, IndexError, TypeError):
            return None
    return raw
