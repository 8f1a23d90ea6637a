"""Griffe extension: the docstrings' Sphinx roles as Markdown code for the API reference.

The docstrings name other objects the Sphinx way (``:func:`~impact_balance.analyze```); the
site's Markdown shows them as code: ``analyze`` for a ``~`` target (its last part), else the
target as written.
"""

from __future__ import annotations

import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:func|class|meth|mod|attr|data|exc|obj|const):`(~?)([^`]+)`")

__all__ = ["ROLE", "SphinxRoles", "markdown_roles"]


def markdown_roles(text: str) -> str:
    """``text`` with every Sphinx role written as a Markdown code span."""

    def code(match: re.Match[str]) -> str:
        target = match.group(2)
        return f"`{target.rsplit('.', 1)[-1] if match.group(1) else target}`"

    return ROLE.sub(code, text)


class SphinxRoles(griffe.Extension):
    """Rewrite the roles of every docstring griffe loads."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        """Rewrite ``obj``'s docstring, if it has one."""
        if obj.docstring is not None:
            obj.docstring.value = markdown_roles(obj.docstring.value)
