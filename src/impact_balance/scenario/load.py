"""Loading scenario files: bundled names or paths, ``extends:`` chains, validation.

A scenario may ``extends:`` another (a bundled name or a path): mappings are merged
recursively, everything else is replaced. Files are read through
:func:`impact_balance.scenario.reader.read_text` (size limits) and parsed with a cache keyed by
content; the validated :class:`Scenario` is cached too, keyed by the text of every file of its
``extends`` chain, so loading an unchanged file again costs its reads only.
"""

from __future__ import annotations

import threading
import typing
from collections import OrderedDict
from pathlib import Path
from typing import Any

from impact_balance.exceptions import ScenarioError, UnknownScenarioError
from impact_balance.scenario.bundled import _is_file, scenario_path
from impact_balance.scenario.reader import (
    MAX_EXTENDS,
    _parse_cached,
    check_path_text,
    parse_yaml,
    read_text,
)
from impact_balance.scenario.schema import Scenario
from impact_balance.scenario.validate import scenario_from_dict

__all__ = ["ExtendsResolver", "load_scenario"]

#: ``extends`` resolver: (the value, the file that extends) -> the file to read.
ExtendsResolver = typing.Callable[[str, Path], Path]


def merge_mappings(base: dict[str, Any], override: dict[str, Any]) -> dict[str, Any]:
    """``override`` merged into ``base``: mappings recursively, everything else replaced."""
    out = dict(base)
    for key, value in override.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            out[key] = merge_mappings(out[key], value)
        else:
            out[key] = value
    return out


def _parent(path: Path, parent: typing.Any, resolve_path: ExtendsResolver | None) -> Path:
    """The file that ``path``'s ``extends: parent`` names."""
    if not isinstance(parent, str):
        raise ScenarioError(
            "extends", parent, "must be a bundled scenario name or a file path", str(path)
        )
    check_path_text("extends", parent, str(path))
    candidate = path.parent / parent
    try:
        if resolve_path is not None:
            return resolve_path(parent, path)
        return candidate if _is_file(candidate) else scenario_path(parent)
    except UnknownScenarioError as exc:
        raise UnknownScenarioError("extends", parent, exc.valid, str(path)) from None
    except ScenarioError as exc:
        raise ScenarioError("extends", parent, exc.reason, str(path)) from None


def read_mapping(
    path: Path, seen: tuple[Path, ...] = (), resolve_path: ExtendsResolver | None = None
) -> dict[str, Any]:
    if path.resolve() in seen:
        raise ScenarioError("extends", str(path), "circular extends")
    if len(seen) >= MAX_EXTENDS:
        raise ScenarioError("extends", str(path), f"a chain of more than {MAX_EXTENDS} extends")
    raw = parse_yaml(read_text(path), str(path))
    if raw is None:
        raise ScenarioError("scenario", str(path), "the file is empty")
    if not isinstance(raw, dict):
        raise ScenarioError(
            "scenario", str(path), f"must be a YAML mapping of keys, got {type(raw).__name__}"
        )
    mapping: dict[str, Any] = raw
    parent = mapping.pop("extends", None)
    if parent is not None:
        parent_path = _parent(path, parent, resolve_path)
        parent_raw = read_mapping(parent_path, (*seen, path.resolve()), resolve_path)
        mapping = merge_mappings(parent_raw, mapping)
    return mapping


def _chain_key(path: Path | None, resolve_path: ExtendsResolver | None) -> tuple[Any, ...] | None:
    """The texts of the files of ``path``'s ``extends`` chain, or None on a problem.

    :func:`read_mapping` then reports the problem. Reads the parse cache without copying it.
    """
    texts: list[tuple[str, str]] = []
    try:
        while path is not None and len(texts) <= MAX_EXTENDS:  # a cycle ends at the cap
            text = read_text(path)
            texts.append((str(path), text))
            raw = _parse_cached(text, str(path))
            if not isinstance(raw, dict):
                return None
            parent = raw.get("extends")
            path = None if parent is None else _parent(path, parent, resolve_path)
    except (ScenarioError, OSError, ValueError):
        return None
    return (resolve_path, tuple(texts)) if path is None else None


#: Validated scenarios by the texts of their chain (and the extends rule): most recent last.
_LOADED: OrderedDict[tuple[Any, ...], Scenario] = OrderedDict()
_LOADED_SIZE = 64
_LOADED_LOCK = threading.Lock()


def load_scenario(
    name_or_path: str | Path, resolve_path: ExtendsResolver | None = None
) -> Scenario:
    """Load and validate a scenario file (or a bundled scenario by name).

    The result is cached by the content of every file of the ``extends`` chain: an edited file
    is read again, an unchanged one is not parsed or validated again (scenarios are immutable).

    Args:
        name_or_path: A scenario file, or the name of a bundled scenario.
        resolve_path: Optional rule for ``extends:`` (value, path of the file that extends) ->
            path to read, raising :class:`ScenarioError` to refuse. The GUI passes its
            workspace's rule; without it, a path relative to the file or a bundled name.
    """
    path = scenario_path(name_or_path)
    key = _chain_key(path, resolve_path)
    if key is not None:
        key = (str(path), *key)
        with _LOADED_LOCK:
            hit = _LOADED.get(key)
            if hit is not None:
                _LOADED.move_to_end(key)
                return hit
    raw = read_mapping(path, (), resolve_path)
    raw.setdefault("name", path.stem)
    scenario = scenario_from_dict(raw, str(path))
    if key is not None:
        with _LOADED_LOCK:
            _LOADED[key] = scenario
            while len(_LOADED) > _LOADED_SIZE:
                _LOADED.popitem(last=False)
    return scenario
