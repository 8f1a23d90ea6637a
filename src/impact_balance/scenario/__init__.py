"""Scenario files: one YAML file describes one situation (robot, stance, contacts, impact).

Files are validated with pydantic; every problem becomes a :class:`ScenarioError` naming the
field and the bad value. A scenario may ``extends:`` another (a bundled name or a path):
mappings are merged recursively, everything else is replaced.

- :mod:`.fields`: value types and bounds (vectors, ranges with units, the strict base model).
- :mod:`.schema`: the pydantic models (:class:`Scenario` and its parts) and stance building.
- :mod:`.specs`: library specs built from scenario values, cached by content.
- :mod:`.errors`: pydantic's errors to one ``ScenarioError`` naming the field.
- :mod:`.validate`: a mapping to a :class:`Scenario` (:meth:`Scenario.from_mapping`).
- :mod:`.bundled`: the scenarios shipped in ``impact_balance/scenarios/`` and name lookup.
- :mod:`.load`: files, ``extends:`` chains and :func:`load_scenario`.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Also re-exported: the helpers sweep/, gui/, analysis.py and tests import from here
# (ExtendsResolver, with_source, field_name, merge_mappings, read_mapping). Imported on first use
# (PEP 562):
# listing the bundled scenarios needs only .bundled, not pydantic and pinocchio.
_EXPORTS: dict[str, str] = {
    "bundled_scenarios": ".bundled",
    "scenario_path": ".bundled",
    "ExtendsResolver": ".load",
    "FileReader": ".load",
    "merge_mappings": ".load",
    "read_mapping": ".load",
    "load_scenario": ".load",
    "BasePose": ".schema",
    "ContactConfig": ".schema",
    "ImpactConfig": ".schema",
    "Offset": ".schema",
    "QPConfig": ".schema",
    "RobotFiles": ".schema",
    "Scenario": ".schema",
    "with_source": ".schema",
    "field_name": ".errors",
    "scenario_from_dict": ".validate",
}


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(module, __name__), name)
    globals()[name] = value
    return value


if TYPE_CHECKING:
    from impact_balance.scenario.bundled import bundled_scenarios, scenario_path
    from impact_balance.scenario.errors import field_name
    from impact_balance.scenario.load import (
        ExtendsResolver,
        FileReader,
        load_scenario,
        merge_mappings,
        read_mapping,
    )
    from impact_balance.scenario.schema import (
        BasePose,
        ContactConfig,
        ImpactConfig,
        Offset,
        QPConfig,
        RobotFiles,
        Scenario,
        with_source,
    )
    from impact_balance.scenario.validate import scenario_from_dict

__all__ = [
    "BasePose",
    "ContactConfig",
    "ExtendsResolver",
    "FileReader",
    "ImpactConfig",
    "Offset",
    "QPConfig",
    "RobotFiles",
    "Scenario",
    "bundled_scenarios",
    "field_name",
    "load_scenario",
    "merge_mappings",
    "read_mapping",
    "scenario_from_dict",
    "scenario_path",
    "with_source",
]
