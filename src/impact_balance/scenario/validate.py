"""A scenario mapping to a :class:`~.schema.Scenario`.

Pydantic's errors become one :class:`~impact_balance.exceptions.ScenarioError` naming the field, the
value and the valid keys.
"""

from __future__ import annotations

from typing import Any

from impact_balance.scenario.errors import field_name
from impact_balance.scenario.schema import Scenario

__all__ = ["field_name", "scenario_from_dict"]


def scenario_from_dict(
    raw: dict[str, Any], source: str | None = None, check_size: bool = True
) -> Scenario:
    """Validate a scenario mapping (see :meth:`Scenario.from_mapping`).

    Args:
        raw: The mapping, as read from a file (its ``extends:`` chain merged).
        source: The file it came from, if any (named in errors).
        check_size: ``False`` skips the nesting and expanded-size check of
            :func:`~impact_balance.scenario.reader.check_structure`, for a mapping the library
            built from input that already passed it (a sweep's points).

    Returns:
        The validated scenario.

    Raises:
        ScenarioError: The first bad field (an :class:`UnknownKeyError` for an unknown key).
    """
    return Scenario.from_mapping(raw, source, check_size)
