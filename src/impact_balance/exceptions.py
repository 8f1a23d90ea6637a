"""Exceptions raised by impact-balance.

Every error the library raises on purpose derives from :class:`ImpactBalanceError` and
carries the data that explains it (field, value, valid names), so that callers can react
programmatically and the command line can print one clear line.

One formatting rule bounds every message: a value is shown by :func:`short_repr` (at most
:data:`VALUE_CHARS` characters, built lazily so that a huge or deeply shared structure, such as
a YAML alias bomb, is never expanded), a list of valid names is cut to the closest few and a
count, and a whole message is one line of at most :data:`MESSAGE_CHARS` characters.
"""

from __future__ import annotations

import difflib
import reprlib
from collections.abc import Iterable, Sequence
from typing import Any

__all__ = [
    "MESSAGE_CHARS",
    "VALUE_CHARS",
    "EnvironmentFailure",
    "FieldError",
    "GovernorError",
    "ImpactBalanceError",
    "ImpactBalanceWarning",
    "ImpactModelError",
    "MissingExtraError",
    "ModelRepairWarning",
    "NonFiniteResultError",
    "OptionError",
    "OutputError",
    "RobotLoadError",
    "ScenarioError",
    "SimulationError",
    "SolverError",
    "StrictWarningsError",
    "SweepError",
    "UnknownConfigurationError",
    "UnknownFrameError",
    "UnknownJointError",
    "UnknownKeyError",
    "UnknownNameError",
    "UnknownPathError",
    "UnknownRobotError",
    "UnknownScenarioError",
    "WorkspaceError",
    "one_line",
    "short_repr",
]

#: Longest shown repr of a value in a message (characters).
VALUE_CHARS = 80
#: Longest message (characters); longer ones are cut with "...".
MESSAGE_CHARS = 400
#: A list of valid names longer than this is replaced by the closest few and a count.
LISTED_NAMES = 12
#: Names longer than this are never compared with difflib (quadratic in the length).
_MATCHED_CHARS = 255


def _reprer() -> reprlib.Repr:
    r = reprlib.Repr()
    # reprlib stops at these sizes instead of walking the whole structure: an alias bomb
    # (a small YAML file that expands to 10^9 items) is shown in microseconds.
    r.maxlevel, r.maxlist, r.maxtuple, r.maxdict, r.maxset = 3, 4, 4, 3, 4
    r.maxstring, r.maxother, r.maxlong = VALUE_CHARS, VALUE_CHARS, 40
    return r


_REPR = _reprer()


def _cut(text: str, limit: int) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def short_repr(value: Any, limit: int = VALUE_CHARS) -> str:
    """``repr(value)`` cut to ``limit`` characters, without ever building the full repr."""
    if isinstance(value, (int, float, bool)) or value is None:
        try:
            return _cut(repr(value), limit)
        except ValueError:  # an int too large to convert to a string
            return "<a very large integer>"
    try:
        text = _REPR.repr(value)
    except Exception:  # a broken __repr__ must not hide the error being reported
        text = f"<{type(value).__name__}>"
    return _cut(text, limit)


def one_line(text: str, limit: int = MESSAGE_CHARS) -> str:
    """``text`` on one line (line breaks become spaces) of at most ``limit`` characters."""
    return _cut(" ".join(str(text).split()), limit)


def _closest(value: Any, valid: Sequence[str], n: int = 3) -> list[str]:
    if not isinstance(value, str) or len(value) > _MATCHED_CHARS:
        return []
    return difflib.get_close_matches(value, valid, n=n, cutoff=0.5)


class ImpactBalanceError(Exception):
    """Base class of all errors raised by impact-balance.

    ``str()`` is one line of at most :data:`MESSAGE_CHARS` characters.

    Attributes:
        exit_status: The command line's exit status for this error: 2 for bad input (the
            default), 1 for a failure of the machine (a file that cannot be written, a server
            that does not answer, a missing package). A subclass that is also an ``OSError``,
            ``ImportError`` or ``MemoryError`` gets 1 without saying so; any subclass may set
            ``exit_status`` as a class attribute.
    """

    @property
    def exit_status(self) -> int:
        """The command line's exit status for this error: 1 or 2 (see the class docstring)."""
        return 1 if isinstance(self, (OSError, ImportError, MemoryError)) else 2

    def __str__(self) -> str:
        return one_line(self.args[0] if self.args else self.__class__.__name__)


class FieldError(ImpactBalanceError):
    """An error about one named field, option or argument: ``field = value: reason``.

    Attributes:
        field: What is at fault (a scenario field, an option, an argument).
        value: Its value (shown cut to :data:`VALUE_CHARS` characters).
        reason: Why it is refused.
    """

    def __init__(self, field: str, value: Any, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        super().__init__(f"{field} = {short_repr(value)}: {reason}")


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
        where = f"{_cut(str(source), 120)}: " if source else ""
        super().__init__(f"{where}{_cut(str(field), 120)} = {short_repr(value)}: {reason}")


class UnknownNameError(ScenarioError, KeyError):
    """A name (robot, frame, joint, configuration) is not known; lists the valid ones.

    Attributes:
        kind: What kind of name it is ("frame", "joint", ...).
        valid: The valid names, sorted.
    """

    kind = "name"
    #: Up to how many valid names the message lists (at least ``LISTED_NAMES``).
    listed = 0

    def __init__(
        self,
        field: str,
        value: str,
        valid: Iterable[str],
        source: str | None = None,
        listing: str | None = None,
    ):
        """``listing`` says where the full list is when it is too long to print (a command)."""
        self.valid: Sequence[str] = sorted(valid)
        close = _closest(value, self.valid)
        hint = f" (did you mean {', '.join(close)}?)" if close else ""
        if len(self.valid) <= max(LISTED_NAMES, self.listed):
            names = f"valid {self.kind}s: {', '.join(self.valid)}"
        else:
            where = f"; `{listing}` lists them" if listing else ""
            names = f"{len(self.valid)} valid {self.kind}s{where}"
        super().__init__(field, value, f"unknown {self.kind}{hint}; {names}", source)

    def __str__(self) -> str:  # KeyError would otherwise quote the message
        return one_line(self.args[0])


class UnknownRobotError(UnknownNameError):
    """The robot name is not one that loads (``impact-balance robots --all``)."""

    kind = "robot"
    listed = 40  # every robot by name, as a scenario's author needs them


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


class WorkspaceError(ScenarioError):
    """A file name outside what the workspace allows (see :mod:`impact_balance.gui.workspace`).

    Attributes:
        field: What named the file ("file", "extends", "robot.urdf", "workspace").
        value: The name, cut to 80 characters.
        reason: Why it is refused.
    """

    def __init__(self, field: str, value: str, reason: str):
        text = str(value)
        super().__init__(field, text if len(text) <= 80 else text[:77] + "...", reason)


class RobotLoadError(ImpactBalanceError):
    """A robot description (URDF/SRDF) cannot be read.

    Attributes:
        path: The file that failed.
    """

    def __init__(self, path: str, reason: str):
        self.path = path
        self.reason = reason
        super().__init__(f"cannot load robot description {path}: {reason}")


class ImpactModelError(FieldError, ValueError):
    """The impact data are inconsistent (e.g. an impulse direction that does not push).

    Attributes:
        field: The scenario field at fault.
        value: Its value.
    """


class SolverError(ImpactBalanceError, RuntimeError):
    """A numerical solver failed in a way that is not an answer (not infeasibility).

    Attributes:
        solver: Solver name.
        status: The solver's status string.
        field: What was being computed, in the user's terms (e.g. "com_velocity_area",
            "impact.qp"), or None when the solver's caller did not say.
    """

    def __init__(self, solver: str, status: str, detail: str = "", field: str | None = None):
        self.solver = solver
        self.status = status
        self.detail = detail
        self.field = field
        extra = f": {detail}" if detail else ""
        where = f"{field}: " if field else ""
        super().__init__(f"{where}{solver} failed with status {status}{extra}")

    def within(self, field: str) -> SolverError:
        """The same failure, attributed to ``field`` (kept if already attributed)."""
        if self.field is not None:
            return self
        return SolverError(self.solver, self.status, self.detail, field)


class UnknownKeyError(ScenarioError):
    """A scenario mapping has a key the schema does not know; suggests the nearest valid key.

    Attributes:
        key: The unknown key.
        valid: The keys valid at that place, sorted.
        suggestion: The nearest valid key, or None.
    """

    def __init__(
        self, field: str, key: str, value: Any, valid: Iterable[str], source: str | None = None
    ):
        self.key = key
        self.valid: Sequence[str] = sorted(valid)
        close = _closest(key, self.valid, n=1)
        self.suggestion = close[0] if close else None
        hint = f" (did you mean {self.suggestion}?)" if self.suggestion else ""
        super().__init__(field, value, f"unknown key{hint}", source)


class StrictWarningsError(ImpactBalanceError):
    """Warnings were raised while warnings are errors (``--strict``).

    Attributes:
        warnings: The diagnostics (:class:`impact_balance.analysis.diagnostics.Diagnostic`).
    """

    def __init__(self, warnings: Sequence[Any]):
        self.warnings = tuple(warnings)
        more = f" (and {len(self.warnings) - 1} more)" if len(self.warnings) > 1 else ""
        super().__init__(f"warning treated as an error (--strict): {self.warnings[0]}{more}")


class NonFiniteResultError(ImpactBalanceError, ValueError):
    """A computed quantity overflowed (inf or NaN): the input's numbers are out of scale.

    Raised instead of returning NaN or infinity (which strict JSON cannot carry).

    Attributes:
        field: The result field that is not finite, e.g. ``impact.W``.
        inputs: The scenario fields whose size can cause it.
    """

    def __init__(self, field: str, inputs: Sequence[str]):
        self.field = field
        self.inputs = tuple(inputs)
        hint = f" (check {', '.join(self.inputs)})" if self.inputs else ""
        super().__init__(f"{field} is not finite: the scenario's numbers are too large{hint}")


class SimulationError(FieldError, ValueError):
    """A simulation request cannot be carried out (bad option, no impact, no renderer...).

    Attributes:
        field: The option or scenario field at fault (e.g. ``--speed``, ``impact``).
        value: Its value.
        reason: Why it is refused.
    """


class SweepError(ScenarioError):
    """A sweep file field has a bad value (same data as :class:`ScenarioError`).

    Also raised when an output folder holds the results of a different sweep.
    """


class UnknownPathError(UnknownNameError):
    """A sweep axis path names a scenario key that does not exist; lists the valid paths."""

    kind = "key"
    #: A scenario's top-level keys are listed in full.
    listed = 20


class MissingExtraError(ImpactBalanceError, ImportError):
    """An optional part of impact-balance is not installed.

    It installs with ``pip install 'impact-balance[EXTRA]'``.

    Attributes:
        what: What needs it: a command (``simulate``) or an option (``--plots``).
        extra: The extra that installs it (``sim``, ``gui``, ``sweep``, ``plots``, ``logs``).
        missing: The Python modules that could not be imported.
    """

    def __init__(self, what: str, extra: str, missing: Sequence[str]):
        self.what, self.extra, self.missing = what, extra, tuple(missing)
        super().__init__(
            f"{what} needs the {extra!r} extra: pip install 'impact-balance[{extra}]' "
            f"({', '.join(self.missing)} not installed)"
        )


class ImpactBalanceWarning(UserWarning):
    """Base class of the warnings impact-balance emits through :mod:`warnings`.

    The command line prints each as one ``impact-balance: warning:`` line.
    """


class ModelRepairWarning(ImpactBalanceWarning):
    """A robot model was changed to be simulated (see :mod:`impact_balance.sim.model.inertia`).

    Attributes:
        robot: The robot's name.
        bodies: The bodies changed.
    """

    def __init__(self, robot: str, bodies: Sequence[str], message: str):
        self.robot = robot
        self.bodies = tuple(bodies)
        super().__init__(message)


class OptionError(FieldError, ValueError):
    """A command-line option (or a library argument) has a value the code cannot use.

    Attributes:
        field: The option, e.g. ``--scheduler`` or ``--plots``.
        value: Its value.
        reason: Why it is refused (with the valid range or form).
    """


class EnvironmentFailure(ImpactBalanceError):
    """The machine refused what the input asked for, which was itself good.

    A folder that cannot be written, a server that does not answer, a stream that is closed or
    full.

    Exit status 1 (bad input is 2).

    Attributes:
        field: What named the resource (an option, "standard output", a file name).
        value: Its value (None when there is none to show).
        reason: What the system said.
    """

    exit_status = 1

    def __init__(self, field: str, value: Any, reason: str):
        self.field = field
        self.value = value
        self.reason = reason
        shown = "" if value is None else f" = {short_repr(value)}"
        super().__init__(f"{field}{shown}: {reason}")


class OutputError(EnvironmentFailure):
    """An output file or folder cannot be written (checked before the command computes)."""


class GovernorError(FieldError, ValueError):
    """A governor call got a bad argument; see :mod:`impact_balance.governor`.

    A configuration of the wrong size, a NaN velocity, an unknown criterion...

    Attributes:
        field: The argument at fault (``q``, ``v``, ``reference_velocity``, ``criterion``...).
        value: Its value (shown cut to :data:`VALUE_CHARS` characters).
        reason: Why it is refused.
    """
