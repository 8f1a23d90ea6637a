"""Scenario key paths: ``impact.offset.position[1]``, ``contacts[2].friction``, ``joints.NAME``.

A path is a dotted list of mapping keys with ``[i]`` list indices. It is checked once against
the base scenario (every key must exist, every index must be in range; ``joints`` accepts any
joint of the robot), then applied to each point by copying only the containers on the path,
so that applying a point costs microseconds and never mutates the base.
"""

from __future__ import annotations

import re
from collections.abc import Mapping, Sequence
from typing import Any

from impact_balance.exceptions import SweepError, UnknownPathError

__all__ = ["STANCE_FREE_ROOTS", "check_path", "format_path", "get_path", "parse_path", "set_path"]

Token = str | int

#: Top-level keys that do not change the stance (hence the areas): only the impact part and
#: the pre-impact CoM velocity are recomputed when only these vary.
STANCE_FREE_ROOTS = frozenset({"impact", "com_velocity", "name", "description"})

#: Top-level keys an axis may not vary (not numbers, or no meaning in a sweep).
_NOT_AXES = frozenset({"name", "description", "source"})

_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_\-]*)|\[(\d+)\]")


def parse_path(path: str, field: str = "path") -> tuple[Token, ...]:
    """``"contacts[2].friction"`` -> ``("contacts", 2, "friction")``.

    Raises:
        SweepError: the text is not a path.
    """
    tokens: list[Token] = []
    pos = 0
    text = str(path).strip()
    while pos < len(text):
        if tokens and text[pos] == ".":
            pos += 1
        m = _TOKEN.match(text, pos)
        if m is None or (m.group(1) is not None and tokens and text[pos - 1] != "."):
            raise SweepError(
                field,
                path,
                "not a key path (expected keys separated by '.' and [index], "
                "e.g. impact.offset.position[1])",
            )
        tokens.append(m.group(1) if m.group(1) is not None else int(m.group(2)))
        pos = m.end()
    if not tokens or not isinstance(tokens[0], str) or text.endswith("."):
        raise SweepError(field, path, "not a key path (expected e.g. impact.friction)")
    return tuple(tokens)


def format_path(tokens: Sequence[Token]) -> str:
    """The key path of ``tokens`` as written in a sweep file (``impact.restitution[1]``)."""
    out = ""
    for t in tokens:
        out += f"[{t}]" if isinstance(t, int) else (f".{t}" if out else t)
    return out


def _children(prefix: tuple[Token, ...], node: Any) -> list[str]:
    if isinstance(node, Mapping):
        keys = [k for k in node if not (not prefix and k in _NOT_AXES)]
        return [format_path((*prefix, k)) for k in keys]
    if isinstance(node, (list, tuple)):
        return [format_path((*prefix, i)) for i in range(len(node))]
    return []


def check_path(
    base: Mapping[str, Any], tokens: Sequence[Token], field: str, joint_names: Sequence[str] = ()
) -> Any:
    """Check that ``tokens`` names a value of ``base`` (the full scenario mapping); return it.

    ``joints.NAME`` may name any joint in ``joint_names`` even if the base does not set it
    (the value returned is then None).

    Raises:
        UnknownPathError: an unknown key (lists the valid paths at that level).
        SweepError: an index out of range, or a key into a number.
    """
    path = format_path(tokens)
    node: Any = base
    for depth, token in enumerate(tokens):
        prefix = tuple(tokens[:depth])
        if prefix == ("joints",) and isinstance(token, str):
            if token not in joint_names:
                raise UnknownPathError(field, path, [f"joints.{j}" for j in joint_names])
            return node.get(token) if isinstance(node, Mapping) else None
        if isinstance(node, Mapping):
            if (
                not isinstance(token, str)
                or token not in node
                or (depth == 0 and token in _NOT_AXES)
            ):
                raise UnknownPathError(field, path, _children(prefix, node))
            node = node[token]
        elif isinstance(node, (list, tuple)):
            if not isinstance(token, int):
                raise SweepError(
                    field,
                    path,
                    f"{format_path(prefix)} is a list: use an index [0..{len(node) - 1}]",
                )
            if token >= len(node):
                raise SweepError(
                    field,
                    path,
                    f"index {token} out of range: {format_path(prefix)} has {len(node)} items",
                )
            node = node[token]
        elif node is None:
            raise SweepError(
                field,
                path,
                f"{format_path(prefix)} is not set in the base scenario: set it there first",
            )
        else:
            raise SweepError(
                field, path, f"{format_path(prefix)} is a value ({node!r}), not a mapping or a list"
            )
    return node


def get_path(base: Any, tokens: Sequence[Token]) -> Any:
    """The value of ``base`` (nested mappings and lists) at ``tokens``."""
    node = base
    for t in tokens:
        node = node[t]
    return node


def set_path(base: Any, tokens: Sequence[Token], value: Any) -> Any:
    """A copy of ``base`` with ``value`` at ``tokens``; only the containers on the path are copied.

    Args:
        base: Nested mappings and lists.
        tokens: The key path.
        value: The new value.

    Returns:
        The copy.

    Raises:
        TypeError: A key into a list.
    """
    if not tokens:
        return value
    head, rest = tokens[0], tokens[1:]
    if isinstance(base, Mapping):
        out = dict(base)
        out[head] = set_path(base[head], rest, value) if rest else value
        return out
    if not isinstance(head, int):
        raise TypeError(f"list indices are integers, not {head!r}")
    out_list = list(base)
    out_list[head] = set_path(base[head], rest, value)
    return out_list
