"""Exceptions raised by impact-balance.

Every error the library raises on purpose derives from :class:`ImpactBalanceError` and
carries the data that explains it (field, value, valid names), so that callers can react
programmatically and the command line can print one clear line.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = [
    "ImpactBalanceError",
    "ScenarioError",
    "UnknownNameError",
    "UnknownRobotError",
    "UnknownFrameError",
    "UnknownJointError",
    "UnknownConfigurationError",
    "UnknownScenarioError",
    "RobotLoadError",
    "ImpactModelError",
    "SolverError",
    "SimulationError",
]


class ImpactBalanceError(Exception):
    """Base class of all errors raised by impact-balance."""


class ScenarioError(ImpactBalanceError, ValueError):
    """A scenario field has a bad value.

    Attributes:
        field: Dotted path of the field, e.g. ``contacts[0].friction``.
        value: The offending value.
        reason: Why it is refused.
        source: File the scenario came from, if any.
    """

    def __init__(self, field: str, value: Any, reason: str, source: str | None = None):
        self.field = field
        self.value = value
        self.reason = reason
        self.source = source
        where = f"{source}: " if source else ""
        super().__init__(f"{where}{field} = {value!r}: {reason}")


class UnknownNameError(ScenarioError, KeyError):
    """A name (robot, frame, joint, configuration) is not known; lists the valid ones.

    Attributes:
        kind: What kind of name it is ("frame", "joint", ...).
        valid: The valid names, sorted.
    """

    kind = "name"

    def __init__(self, field: str, value: str, valid: Iterable[str], source: str | None = None):
        self.valid: Sequence[str] = sorted(valid)
        close = difflib.get_close_matches(str(value), self.valid, n=3, cutoff=0.5)
        hint = f" (did you mean {', '.join(close)}?)" if close else ""
        reason = f"unknown {self.kind}{hint}; valid {self.kind}s: {', '.join(self.valid)}"
        super().__init__(field, value, reason, source)

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return self.args[0]


class UnknownRobotError(UnknownNameError):
    """The robot name is not one of the bundled robots."""

    kind = "robot"


class UnknownFrameError(UnknownNameError):
    """The frame is not in the robot model."""

    kind = "frame"


class UnknownJointError(UnknownNameError):
    """The joint is not in the robot model."""

    kind = "joint"


class UnknownConfigurationError(UnknownNameError):
    """The named reference configuration is not in the robot's SRDF."""

    kind = "configuration"


class UnknownScenarioError(UnknownNameError):
    """The scenario is neither a file nor a bundled scenario's name."""

    kind = "scenario"


class RobotLoadError(ImpactBalanceError):
    """A robot description (URDF/SRDF) cannot be read.

    Attributes:
        path: The file that failed.
    """

    def __init__(self, path: str, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"cannot load robot description {path}: {reason}")


class ImpactModelError(ImpactBalanceError, ValueError):
    """The impact data are inconsistent (e.g. an impulse direction that does not push).

    Attributes:
        field: The scenario field at fault.
        value: Its value.
    """

    def __init__(self, field: str, value: Any, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {value!r}: {reason}")


class SolverError(ImpactBalanceError, RuntimeError):
    """A numerical solver failed in a way that is not an answer (not infeasibility).

    Attributes:
        solver: Solver name.
        status: The solver's status string.
    """

    def __init__(self, solver: str, status: str, detail: str = ""):
        self.solver = solver
        self.status = status
        extra = f": {detail}" if detail else ""
        super().__init__(f"{solver} failed with status {status}{extra}")


class SimulationError(ImpactBalanceError, ValueError):
    """A simulation request cannot be carried out (bad option, no impact, no renderer...).

    Attributes:
        field: The option or scenario field at fault (e.g. ``--speed``, ``impact``).
        value: Its value.
        reason: Why it is refused.
    """

    def __init__(self, field: str, value: Any, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {value!r}: {reason}")
