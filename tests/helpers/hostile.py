"""Hostile values for the fuzz tests, and mutations of parsed YAML mappings."""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

from hypothesis import strategies as st

__all__ = [
    "HOSTILE_NUMBERS",
    "HOSTILE_STRINGS",
    "apply_mutation",
    "hostile_values",
    "mapping_paths",
    "nested",
]

HOSTILE_NUMBERS = [
    math.nan,
    math.inf,
    -math.inf,
    1e300,
    -1e300,
    1e160,
    -1e160,
    1e-300,
    0.0,
    -0.0,
    -1.0,
    1e6,
    1e7,
    10**400,
    -(10**30),
    2**63,
]
HOSTILE_STRINGS = [
    "",
    " ",
    "x" * 300,
    "a/" * 200,
    "../../../../etc/passwd",
    "/dev/zero",
    "\u00e9\u4e2d\U0001f600",
    "nan",
    "1e999",
    "~",
    "left_sole_link" * 30,
    "C:\\\\Windows",
]


def nested(depth: int) -> Any:
    """1.0 inside ``depth`` lists."""
    value: object = 1.0
    for _ in range(depth):
        value = [value]
    return value


hostile_values = st.one_of(
    st.sampled_from(HOSTILE_NUMBERS),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**20), max_value=10**20),
    st.sampled_from(HOSTILE_STRINGS),
    st.text(max_size=40),
    st.none(),
    st.booleans(),
    st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), max_size=5),
    st.dictionaries(st.text(max_size=8), st.integers(), max_size=3),
    st.integers(min_value=1, max_value=80).map(nested),
)


def mapping_paths(node: Any, prefix: tuple[Any, ...] = ()) -> Iterator[tuple[tuple[Any, ...], Any]]:
    """Every (path, value) in a parsed scenario, mappings and lists included."""
    yield prefix, node
    if isinstance(node, dict):
        for k, v in node.items():
            yield from mapping_paths(v, (*prefix, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from mapping_paths(v, (*prefix, i))


def apply_mutation(data: Any, path: tuple[Any, ...], op: str, value: Any) -> Any:
    """``data`` with the item at ``path`` set, deleted, wrapped in a list or given a new key."""
    if not path:
        return value if op == "set" else data
    parent = data
    for part in path[:-1]:
        parent = parent[part]
    key = path[-1]
    if op == "set":
        parent[key] = value
    elif op == "delete":
        del parent[key]
    elif op == "wrap":
        parent[key] = [parent[key]]
    elif op == "unknown_key" and isinstance(parent[key], dict):
        parent[key][str(value)[:50] or "k"] = 1
    return data
