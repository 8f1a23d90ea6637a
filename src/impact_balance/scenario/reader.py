"""Bounded reading of scenario input: file size, nesting depth, expanded size, name length.

A scenario file comes from the user, and through the GUI from anyone who can upload one, so
reading it must finish quickly in bounded memory whatever it contains:

- **size**: a file is read only up to :data:`MAX_BYTES` (1 MB; bundled files are ~2 KB);
- **depth**: mappings and lists nest at most :data:`MAX_DEPTH` levels (the schema needs 4).
  The YAML composer recurses once per level, so the limit is checked while composing, before
  Python's recursion limit could be reached;
- **expanded size**: YAML anchors and aliases (``&a`` / ``*a``) share one node, so a 400-byte
  file can stand for 10^9 values (a "billion laughs" alias bomb). The composed node graph is
  counted as if every alias were expanded, without expanding it, and refused beyond
  :data:`MAX_VALUES`; an alias inside its own anchor (a cycle) is refused;
- **keys**: a key appears at most once in a mapping (a repeated key is refused with its line,
  never silently replaced by the last value), and a mapping has at most :data:`MAX_KEYS` keys
  (more than any scenario or sweep can have); both are checked while composing, so a file of
  60,000 keys is refused at key :data:`MAX_KEYS`, before the rest is parsed;
- **names**: a file name or ``extends`` longer than :data:`MAX_NAME_CHARS` characters per path
  component (the usual file-system limit) or :data:`MAX_PATH_CHARS` in all is refused before
  the operating system is asked.

Logs (``check-log``) are bounded too, before they are read: a file of at most
:data:`MAX_LOG_BYTES`, at most :data:`MAX_LOG_ROWS` rows, :data:`MAX_LOG_COLUMNS` columns and
:data:`MAX_LOG_VALUES` values (rows x columns, 400 MB as float64). A Parquet log's counts come
from its metadata; a CSV log is read up to the first row past the limit.

Files are read through :func:`impact_balance.files.read_bounded` (one open, a regular file
only, a byte bound), and the bytes read are the bytes parsed.

Every refusal is a :class:`~impact_balance.exceptions.ScenarioError` naming the file and the
limit. Mappings given directly (the GUI, the library) get the same depth and size checks
(:func:`check_structure`).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

import yaml

from impact_balance.exceptions import ScenarioError
from impact_balance.files import read_bounded

__all__ = [
    "MAX_BYTES",
    "MAX_DEPTH",
    "MAX_EXTENDS",
    "MAX_KEYS",
    "MAX_LOG_BYTES",
    "MAX_LOG_COLUMNS",
    "MAX_LOG_ROWS",
    "MAX_LOG_VALUES",
    "MAX_NAME_CHARS",
    "MAX_PATH_CHARS",
    "MAX_VALUES",
    "check_path_text",
    "check_structure",
    "decode_text",
    "parse_yaml",
    "read_text",
    "read_yaml",
]

#: Largest scenario file read, bytes.
MAX_BYTES = 1_000_000
#: Deepest nesting of mappings and lists (the scenario schema needs 4: impact.offset.position[i]).
MAX_DEPTH = 32
#: Most values (scalars, mappings, lists) after expanding every alias.
MAX_VALUES = 100_000
#: Most keys in one mapping (a scenario has about 20 top-level keys, a 100-joint robot 100 joints).
MAX_KEYS = 1_000
#: Longest file-name component, characters (the usual file-system limit).
MAX_NAME_CHARS = 255
#: Longest path, characters (Linux PATH_MAX is 4096 bytes).
MAX_PATH_CHARS = 4096
#: Longest chain of ``extends``.
MAX_EXTENDS = 16
#: Largest log file, bytes.
MAX_LOG_BYTES = 1_000_000_000
#: Most samples (rows) in a log (1000 s at 1 kHz).
MAX_LOG_ROWS = 1_000_000
#: Most columns in a log (a 100-joint robot has 217).
MAX_LOG_COLUMNS = 2_000
#: Most values (rows x columns) in a log: 400 MB once read as float64.
MAX_LOG_VALUES = 50_000_000


class _LimitError(yaml.YAMLError):  # type: ignore[misc]  # PyYAML ships no type stubs
    def __init__(self, problem: str, mark: yaml.Mark | None = None):
        super().__init__(problem)
        self.problem = problem
        self.problem_mark = mark


def _node_children(node: yaml.Node) -> Iterable[yaml.Node]:
    """The child nodes of a YAML node (keys and values of a mapping)."""
    if isinstance(node, yaml.SequenceNode):
        children: list[yaml.Node] = node.value
        return children
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    return ()


def _object_children(obj: Any) -> Iterable[Any]:
    if isinstance(obj, dict):
        return [x for pair in obj.items() for x in pair]
    if isinstance(obj, (list, tuple)):
        return obj
    return ()


def _count(
    root: Any, children: Callable[[Any], Iterable[Any]], leaf: Callable[[Any], bool]
) -> tuple[int, int]:
    """Expanded size and depth of a graph whose shared nodes stand for copies (iterative).

    Raises ``ValueError`` on a cycle or when the size exceeds :data:`MAX_VALUES`.
    """
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[Any, bool]] = [(root, False)]
    while stack:
        node, finished = stack.pop()
        key = id(node)
        if finished:
            kids = children(node)
            size[key] = 1 + sum(size[id(k)] for k in kids)
            depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
            on_path.discard(key)
            if size[key] > MAX_VALUES:
                raise ValueError(
                    f"expands to more than {MAX_VALUES} values (anchors and aliases included)"
                )
            continue
        if key in size:
            continue
        if key in on_path:
            raise ValueError("an alias refers to a mapping or list that contains it (a cycle)")
        if leaf(node):
            size[key], depth[key] = 1, 0
            continue
        on_path.add(key)
        stack.append((node, True))
        stack.extend((k, False) for k in children(node) if id(k) not in size)
    return size[id(root)], depth[id(root)]


class _BoundedLoader(yaml.SafeLoader):  # type: ignore[misc]  # PyYAML ships no type stubs
    """PyYAML's safe loader with a nesting limit while composing and an expanded-size limit."""

    def __init__(self, stream: str):
        super().__init__(stream)
        self._depth = 0
        self._nodes = 0
        #: Keys seen so far in each mapping being composed: id(node) -> {key: line}.
        self._keys: dict[int, dict[tuple[str, str], int]] = {}

    def compose_node(self, parent: yaml.Node | None, index: object) -> yaml.Node:
        """PyYAML's node composition, with the nesting, node-count and key limits."""
        self._depth += 1
        self._nodes += 1
        try:
            if self._depth > MAX_DEPTH:
                raise _LimitError(
                    f"nested deeper than {MAX_DEPTH} levels", self.peek_event().start_mark
                )
            if self._nodes > MAX_VALUES:
                raise _LimitError(f"more than {MAX_VALUES} values", self.peek_event().start_mark)
            node: yaml.Node = super().compose_node(parent, index)
        finally:
            self._depth -= 1
        if isinstance(parent, yaml.MappingNode) and index is None:  # ``node`` is a key
            self._check_key(parent, node)
        return node

    def _check_key(self, mapping: yaml.MappingNode, key: yaml.Node) -> None:
        """Refuse a key seen before in ``mapping``, or one key too many."""
        seen = self._keys.setdefault(id(mapping), {})
        if len(seen) >= MAX_KEYS:
            raise _LimitError(f"a mapping with more than {MAX_KEYS} keys", key.start_mark)
        if not isinstance(key, yaml.ScalarNode) or key.tag == "tag:yaml.org,2002:merge":
            return
        line = key.start_mark.line + 1
        first = seen.get((key.tag, key.value))
        seen[(key.tag, key.value)] = line if first is None else first
        if first is not None:
            raise _LimitError(
                f"duplicate key {key.value[:80]!r} at line {line} (first at line {first}): "
                "a key may appear once in a mapping",
                key.start_mark,
            )

    def compose_document(self) -> yaml.Node:
        """PyYAML's document composition, with the expanded-size limit."""
        node: yaml.Node = super().compose_document()
        self._keys.clear()
        try:
            _count(node, _node_children, lambda n: isinstance(n, yaml.ScalarNode))
        except ValueError as exc:
            raise _LimitError(str(exc), node.start_mark) from None
        return node


# YAML 1.2 floats: PyYAML follows YAML 1.1, where ``5e-05`` or ``1e3`` (no dot) is a string. The
# schema is strict (a string is not a number), so the reader knows them as the numbers they are.
_BoundedLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$"),
    list("-+0123456789."),
)


def parse_yaml(text: str, source: str = "scenario") -> Any:
    """Parse YAML text within the limits; :class:`ScenarioError` on ``scenario`` naming ``source``.

    Cached by content (PyYAML's pure-Python parser is most of the cost of loading a scenario).
    The cached tree is never handed out: callers get a fresh copy of its dicts and lists
    (scalars are immutable). Refusals are not cached.
    """
    return _copy_tree(_parse_cached(text, source))


def _copy_tree(node: Any) -> Any:
    """Copy of a parsed YAML tree's containers (faster than copy.deepcopy for plain data)."""
    if isinstance(node, dict):
        return {k: _copy_tree(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_copy_tree(v) for v in node]
    return node


@functools.lru_cache(maxsize=64)
def _parse_cached(text: str, source: str) -> Any:
    if len(text) > MAX_BYTES:
        raise ScenarioError(
            "scenario", source, f"larger than {MAX_BYTES // 1000} kB, the limit for a scenario file"
        )
    loader = None
    try:
        # PyYAML checks the characters when the loader is made (a control character or a NUL
        # byte raises ReaderError there): inside the try, like every other YAML error.
        loader = _BoundedLoader(text)
        return loader.get_single_data()
    except _LimitError as exc:
        raise ScenarioError("scenario", source, f"refused: {exc.problem}") from None
    except yaml.reader.ReaderError as exc:
        line = text.count("\n", 0, exc.position) + 1
        what = "a NUL byte" if exc.character == 0 else f"the control character {exc.character:#04x}"
        raise ScenarioError(
            "scenario",
            source,
            f"not valid YAML: {what} at line {line} (YAML allows printable text only)",
        ) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or "syntax error"
        raise ScenarioError("scenario", source, f"not valid YAML: {problem}{where}") from None
    finally:
        if loader is not None:
            loader.dispose()


def decode_text(data: bytes, source: str) -> str:
    """``data`` as UTF-8 text (:class:`ScenarioError` naming ``source`` otherwise)."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise ScenarioError("scenario", source, "cannot read: not UTF-8 text") from None


def read_text(path: Path) -> str:
    """A scenario file's text, read once within the size limit (:class:`ScenarioError` otherwise).

    Read through :func:`~impact_balance.files.read_bounded`: a FIFO, a device or a folder is
    refused without waiting, a file over :data:`MAX_BYTES` is refused.
    """
    check_path_text("scenario", str(path))
    data = read_bounded(path, limit=MAX_BYTES, what="scenario")
    return decode_text(data, str(path))


def read_yaml(path: Path) -> Any:
    """Read and parse a scenario file within the limits (:class:`ScenarioError` otherwise)."""
    return parse_yaml(read_text(path), str(path))


def check_structure(raw: Any, source: str | None = None) -> None:
    """Refuse a mapping too deep, too large or containing itself.

    Too deep: nested deeper than :data:`MAX_DEPTH`; too large: more than :data:`MAX_VALUES`
    values once shared parts are counted as copies.
    """
    try:
        _, depth = _count(raw, _object_children, lambda x: not isinstance(x, (dict, list, tuple)))
    except ValueError as exc:
        raise ScenarioError("scenario", "...", str(exc), source) from None
    if depth > MAX_DEPTH:
        raise ScenarioError("scenario", "...", f"nested deeper than {MAX_DEPTH} levels", source)


def check_path_text(field: str, text: str, source: str | None = None) -> None:
    """Refuse a file name the operating system would reject with an error of its own."""
    if "\x00" in text:
        raise ScenarioError(field, text, "a file name cannot contain a NUL character", source)
    if len(text) > MAX_PATH_CHARS:
        reason = f"too long for a path ({len(text)} characters, at most {MAX_PATH_CHARS})"
        raise ScenarioError(field, text, reason, source)
    longest = max((len(part) for part in text.replace("\\", "/").split("/")), default=0)
    if longest > MAX_NAME_CHARS:
        reason = (
            f"a file or scenario name has at most {MAX_NAME_CHARS} characters "
            f"(this one has {longest})"
        )
        raise ScenarioError(field, text, reason, source)
