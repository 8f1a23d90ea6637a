"""Skipping a test whose extra is not installed, with the extra's marker.

Module-level checks use ``pytest.importorskip`` directly; a single test of a core module that
needs an extra (a command with ``--plots``, a log, a sweep, a simulation) is decorated with
:func:`needs_extra`, which skips it when a module of that extra is missing (as
:func:`impact_balance.extras.require` checks, without importing it) and marks it ``sim``,
``gui`` or ``sweep`` for those extras.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TypeVar

import pytest

from impact_balance.extras import EXTRAS, installed

__all__ = ["missing_modules", "needs_extra"]

F = TypeVar("F", bound=Callable[..., object])

#: Extras whose tests carry a marker of the same name (pyproject.toml registers them).
MARKED = ("sim", "gui", "sweep")


def missing_modules(extra: str) -> list[str]:
    """The modules of ``extra`` that are not installed (empty when it is)."""
    return [name for name in EXTRAS[extra] if not installed(name)]


def needs_extra(*extras: str) -> Callable[[F], F]:
    """Decorator: skip the test unless every module of ``extras`` is installed; mark it."""

    def decorate(test: F) -> F:
        for extra in extras:
            missing = missing_modules(extra)
            test = pytest.mark.skipif(
                bool(missing), reason=f"needs the {extra} extra ({', '.join(missing)} missing)"
            )(test)
            if extra in MARKED:
                test = getattr(pytest.mark, extra)(test)
        return test

    return decorate
