"""A scenario mapping to a :class:`~.schema.Scenario`: pydantic's errors become one
:class:`~impact_balance.exceptions.ScenarioError` naming the field, the value and the valid keys.
"""

from __future__ import annotations

import typing
from typing import Any

from pydantic import BaseModel, ValidationError

from impact_balance.exceptions import ScenarioError, UnknownKeyError
from impact_balance.scenario.reader import check_structure
from impact_balance.scenario.schema import Scenario

__all__ = ["scenario_from_dict"]


def field_name(loc: tuple) -> str:
    out = ""
    for part in loc:
        if isinstance(part, int):
            out += f"[{part}]"
        elif part in ("function-after", "function-before") or "[" in str(part):
            continue
        else:
            out += f".{part}" if out else str(part)
    return out or "scenario"


def scenario_from_dict(raw: dict, source: str | None = None, check_size: bool = True) -> Scenario:
    """Validate a scenario mapping; raises :class:`ScenarioError` on the first bad field.

    ``check_size=False`` skips the nesting and expanded-size check of
    :func:`~impact_balance.scenario.reader.check_structure`, for a mapping the library built from
    input that already passed it (a sweep's points: its base scenario and its file were
    checked once, when the sweep was planned).
    """
    if check_size:
        check_structure(raw, source)
    try:
        return Scenario.model_validate({**raw, "source": source})
    except ValidationError as exc:
        errors = exc.errors()
        # A typo shows up as an unknown key AND a missing one: report the typo.
        err = next((e for e in errors if e["type"] == "extra_forbidden"), errors[0])
        loc = tuple(p for p in err["loc"] if p not in ("str", "RobotFiles"))
        reason = err["msg"].removeprefix("Value error, ")
        value = err.get("input")
        if err["type"] == "extra_forbidden" and loc:
            raise UnknownKeyError(
                field_name(loc), str(loc[-1]), value, _keys_at(loc[:-1]), source
            ) from None
        elif err["type"] == "missing":
            if loc and isinstance(loc[-1], int):  # a short list/tuple: report the whole list
                value, reason, loc = (
                    _lookup(raw, loc[:-1]),
                    f"too few items (item {loc[-1]} is missing)",
                    loc[:-1],
                )
            else:
                value, reason = None, "missing required key"
        raise ScenarioError(field_name(loc), value, reason, source) from None
    except ScenarioError as exc:
        raise ScenarioError(exc.field, exc.value, exc.reason, source) from None


def _model_in(annotation: Any) -> type[BaseModel] | None:
    """The pydantic model inside an annotation (``X | None``, ``list[X]``, ``str | X``), if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return annotation
    for arg in typing.get_args(annotation):
        found = _model_in(arg)
        if found is not None:
            return found
    return None


def _keys_at(loc: tuple) -> list[str]:
    """The keys the schema accepts in the mapping at ``loc`` (for "did you mean")."""
    model: type[BaseModel] | None = Scenario
    for part in loc:
        if isinstance(part, int) or model is None:
            continue
        info = model.model_fields.get(part)
        model = _model_in(info.annotation) if info is not None else None
    if model is None:
        return []
    return [name for name, info in model.model_fields.items() if not info.exclude]


def _lookup(raw: Any, loc: tuple) -> Any:
    for part in loc:
        try:
            raw = raw[part]
        except (KeyError, IndexError, TypeError):
            return None
    return raw
