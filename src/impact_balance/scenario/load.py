"""Loading scenario files: bundled names or paths, ``extends:`` chains, validation.

A scenario may ``extends:`` another (a bundled name or a path): mappings are merged
recursively, everything else is replaced. Files are read through
:func:`impact_balance.input_limits.read_yaml` (size limits, parse cache keyed by content).
"""

from __future__ import annotations

import typing
from pathlib import Path

from ..exceptions import ScenarioError, UnknownScenarioError
from ..input_limits import MAX_EXTENDS, check_path_text, read_yaml
from .bundled import _is_file, scenario_path
from .schema import Scenario
from .validate import scenario_from_dict

__all__ = ["ExtendsResolver", "load_scenario"]

#: ``extends`` resolver: (the value, the file that extends) -> the file to read.
ExtendsResolver = typing.Callable[[str, Path], Path]


def _merge(base: dict, override: dict) -> dict:
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = _merge(out[key], value)
        else:
            out[key] = value
    return out


def _read(path: Path, seen: tuple[Path, ...] = (), resolve_path: ExtendsResolver | None = None) -> dict:
    if path.resolve() in seen:
        raise ScenarioError("extends", str(path), "circular extends")
    if len(seen) >= MAX_EXTENDS:
        raise ScenarioError("extends", str(path), f"a chain of more than {MAX_EXTENDS} extends")
    raw = read_yaml(path)
    if raw is None:
        raise ScenarioError("scenario", str(path), "the file is empty")
    if not isinstance(raw, dict):
        raise ScenarioError("scenario", str(path), f"must be a YAML mapping of keys, got {type(raw).__name__}")
    parent = raw.pop("extends", None)
    if parent is not None:
        if not isinstance(parent, str):
            raise ScenarioError("extends", parent, "must be a bundled scenario name or a file path", str(path))
        check_path_text("extends", parent, str(path))
        candidate = path.parent / parent
        try:
            if resolve_path is not None:
                parent_path = resolve_path(parent, path)
            else:
                parent_path = candidate if _is_file(candidate) else scenario_path(parent)
        except UnknownScenarioError as exc:
            raise UnknownScenarioError("extends", parent, exc.valid, str(path)) from None
        except ScenarioError as exc:
            raise ScenarioError("extends", parent, exc.reason, str(path)) from None
        raw = _merge(_read(parent_path, seen + (path.resolve(),), resolve_path), raw)
    return raw


def load_scenario(name_or_path: str | Path, resolve_path: ExtendsResolver | None = None) -> Scenario:
    """Load and validate a scenario file (or a bundled scenario by name).

    Args:
        resolve_path: Optional rule for ``extends:`` (value, path of the file that extends) ->
            path to read, raising :class:`ScenarioError` to refuse. The GUI passes its
            workspace's rule; without it, a path relative to the file or a bundled name.
    """
    path = scenario_path(name_or_path)
    raw = _read(path, (), resolve_path)
    raw.setdefault("name", path.stem)
    return scenario_from_dict(raw, str(path))
