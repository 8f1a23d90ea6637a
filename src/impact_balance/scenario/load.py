"""Loading scenario files: bundled names or paths, ``extends:`` chains, validation.

A scenario may ``extends:`` another (a bundled name or a path): mappings are merged
recursively, everything else is replaced. Each file is read once, through
:func:`impact_balance.scenario.reader.read_text` (one open, a regular file only, size limits) or
the caller's reader, and those bytes are parsed (a cache keyed by content); the validated
:class:`Scenario` is cached too, keyed by the digests of the bytes of every file of its
``extends`` chain, so loading an unchanged file again costs its reads only, and a file rewritten
while it is loaded can never map its new bytes to the old scenario.
"""

from __future__ import annotations

import hashlib
import threading
import typing
from collections import OrderedDict
from pathlib import Path
from typing import Any

from impact_balance.exceptions import ScenarioError, UnknownScenarioError
from impact_balance.scenario.bundled import _exists, _is_file, scenario_path
from impact_balance.scenario.reader import (
    MAX_EXTENDS,
    _copy_tree,
    _parse_cached,
    check_path_text,
    read_text,
)
from impact_balance.scenario.schema import Scenario
from impact_balance.scenario.validate import scenario_from_dict

__all__ = ["ExtendsResolver", "FileReader", "load_scenario"]

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
        if _is_file(candidate) or (candidate.suffix in (".yaml", ".yml") and _exists(candidate)):
            return candidate  # a FIFO or a device is refused by the reader, naming what it is
        return scenario_path(parent)
    except UnknownScenarioError as exc:
        raise UnknownScenarioError("extends", parent, exc.valid, str(path)) from None
    except ScenarioError as exc:
        raise ScenarioError("extends", parent, exc.reason, str(path)) from None


#: Reads a scenario file's text (the GUI's reads through its workspace folder, without links).
FileReader = typing.Callable[[Path], str]


def _raw_mapping(raw: Any, path: Path) -> dict[str, Any]:
    if raw is None:
        raise ScenarioError("scenario", str(path), "the file is empty")
    if not isinstance(raw, dict):
        raise ScenarioError(
            "scenario", str(path), f"must be a YAML mapping of keys, got {type(raw).__name__}"
        )
    return raw


def _read_chain(
    path: Path,
    seen: tuple[Path, ...],
    resolve_path: ExtendsResolver | None,
    read_file: FileReader,
) -> list[tuple[Path, str, dict[str, Any]]]:
    """Each file of ``path``'s ``extends`` chain, read once: (path, text, parsed tree).

    The trees are the parse cache's own (not copied): callers must not change them.
    """
    chain: list[tuple[Path, str, dict[str, Any]]] = []
    while True:
        if path.resolve() in seen:
            raise ScenarioError("extends", str(path), "circular extends")
        if len(seen) >= MAX_EXTENDS:
            raise ScenarioError("extends", str(path), f"a chain of more than {MAX_EXTENDS} extends")
        text = read_file(path)
        raw = _raw_mapping(_parse_cached(text, str(path)), path)
        chain.append((path, text, raw))
        parent = raw.get("extends")
        if parent is None:
            return chain
        seen = (*seen, path.resolve())
        path = _parent(path, parent, resolve_path)


def _merge_chain(chain: list[tuple[Path, str, dict[str, Any]]]) -> dict[str, Any]:
    """The merged mapping of a chain read by :func:`_read_chain` (fresh containers)."""
    mapping: dict[str, Any] = {}
    for _, _, raw in reversed(chain):
        own = _copy_tree(raw)
        own.pop("extends", None)
        mapping = merge_mappings(mapping, own) if mapping else own
    return mapping


def read_mapping(
    path: Path,
    seen: tuple[Path, ...] = (),
    resolve_path: ExtendsResolver | None = None,
    read_file: FileReader | None = None,
) -> dict[str, Any]:
    """The mapping of a scenario file with its ``extends`` chain merged (each file read once)."""
    return _merge_chain(_read_chain(path, seen, resolve_path, read_file or read_text))


def _chain_key(
    path: Path, chain: list[tuple[Path, str, dict[str, Any]]], resolve_path: ExtendsResolver | None
) -> tuple[Any, ...]:
    """The cache key of a chain: its files' names and the digests of the very bytes parsed."""
    digests = tuple(
        (str(p), hashlib.sha256(text.encode("utf-8")).hexdigest()) for p, text, _ in chain
    )
    return (str(path), resolve_path, digests)


#: Validated scenarios by their chain's digests (and the extends rule): most recent last.
_LOADED: OrderedDict[tuple[Any, ...], Scenario] = OrderedDict()
_LOADED_SIZE = 64
_LOADED_LOCK = threading.Lock()


def load_scenario(
    name_or_path: str | Path,
    resolve_path: ExtendsResolver | None = None,
    read_file: FileReader | None = None,
) -> Scenario:
    """Load and validate a scenario file (or a bundled scenario by name).

    Every file of the ``extends`` chain is read once; the result is cached by the digests of
    the very bytes parsed (and the files' names): an edited file gives a new scenario, an
    unchanged one is not parsed or validated again (scenarios are immutable).

    Args:
        name_or_path: A scenario file, or the name of a bundled scenario (with ``read_file``:
            the path that reader is given).
        resolve_path: Optional rule for ``extends:`` (value, path of the file that extends) ->
            path to read, raising :class:`ScenarioError` to refuse. The GUI passes its
            workspace's rule; without it, a path relative to the file or a bundled name.
        read_file: Optional rule for reading a file's text (path -> text, raising
            :class:`ScenarioError` to refuse). The GUI passes its workspace's reader (through
            the checked folder, no link); without it,
            :func:`~impact_balance.scenario.reader.read_text`.
    """
    if read_file is None:
        path = scenario_path(name_or_path)
    else:  # the reader's own path: it decides what exists
        check_path_text("scenario", str(name_or_path))
        path = Path(name_or_path)
    chain = _read_chain(path, (), resolve_path, read_file or read_text)
    key = _chain_key(path, chain, resolve_path)
    with _LOADED_LOCK:
        hit = _LOADED.get(key)
        if hit is not None:
            _LOADED.move_to_end(key)
            return hit
    raw = _merge_chain(chain)
    raw.setdefault("name", path.stem)
    scenario = scenario_from_dict(raw, str(path))
    with _LOADED_LOCK:
        _LOADED[key] = scenario
        while len(_LOADED) > _LOADED_SIZE:
            _LOADED.popitem(last=False)
    return scenario
