"""The one error rule: any exception, whoever raised it, as one line and an exit status.

The command line (:func:`impact_balance.cli.main`) and the GUI
(:func:`impact_balance.gui.files.describe`)
report every failure through :func:`describe_error`, so that a new command or a new dependency
gets the rule without code of its own:

- the project's errors (:class:`~impact_balance.exceptions.ImpactBalanceError`) say what they
  say, with their own status: 2 for bad input, 1 for a failure of the machine;
- the operating system's errors (``OSError``: a file, a socket, a full disk, a closed stream)
  name the file when there is one, status 1;
- out of memory and a missing module, status 1;
- PyYAML's errors (should one escape the bounded reader), status 2;
- anything else is a bug of impact-balance: its type and message, status 1, and a hint to
  rerun with ``--debug`` (or ``IMPACT_BALANCE_DEBUG=1``), which shows the traceback.
"""

from __future__ import annotations

import errno
import os
import sys

from impact_balance.exceptions import ImpactBalanceError, one_line, short_repr

__all__ = [
    "DEBUG_ENV",
    "EXIT_BROKEN_PIPE",
    "EXIT_ENVIRONMENT",
    "EXIT_INPUT",
    "EXIT_INTERRUPTED",
    "debug_requested",
    "describe_error",
]

#: Environment variable that turns on tracebacks (any value but "", "0", "no", "false").
DEBUG_ENV = "IMPACT_BALANCE_DEBUG"
#: Exit status of bad input (a file, a field, an option).
EXIT_INPUT = 2
#: Exit status of a failure of the machine (files, network, memory, missing packages) or a bug.
EXIT_ENVIRONMENT = 1
#: Exit status after Ctrl-C or SIGTERM (128 + SIGINT, as a shell reports it).
EXIT_INTERRUPTED = 130
#: Exit status when stdout is closed early (128 + SIGPIPE, as a shell reports it).
EXIT_BROKEN_PIPE = 141


def debug_requested(argv: list[str] | None = None) -> bool:
    """``--debug`` in ``argv`` or :data:`DEBUG_ENV` set."""
    value = os.environ.get(DEBUG_ENV, "").strip().lower()
    return value not in ("", "0", "no", "false") or "--debug" in (argv or ())


def _qualified(exc: BaseException) -> str:
    cls = type(exc)
    module = cls.__module__
    return (
        cls.__qualname__ if module in ("builtins", "__main__") else f"{module}.{cls.__qualname__}"
    )


def _os_line(exc: OSError) -> str:
    reason = (
        exc.strerror
        or (os.strerror(exc.errno) if exc.errno else None)
        or str(exc)
        or type(exc).__name__
    )
    if isinstance(exc, TimeoutError) and not exc.strerror:
        reason = f"timed out{f' ({exc})' if str(exc) else ''}"
    names = [n for n in (exc.filename, exc.filename2) if n is not None]
    where = " -> ".join(
        short_repr(os.fsdecode(n) if isinstance(n, bytes) else str(n), 120).strip("'\"")
        for n in names
    )
    return f"{where}: {reason}" if where else reason


def describe_error(exc: BaseException, quote: bool = True) -> tuple[str, int]:
    """One line (no prefix) and the exit status for ``exc``.

    ``quote=False`` leaves out the message of an exception that is not the project's (a YAML
    problem, a bug's text), which may quote input: the GUI shows such errors to whoever can
    reach the page.
    """
    if isinstance(exc, ImpactBalanceError):
        return str(exc), int(exc.exit_status)
    if isinstance(exc, KeyboardInterrupt):
        return "interrupted", EXIT_INTERRUPTED
    if isinstance(exc, MemoryError):
        return (
            "out of memory: the input asks for more memory than this machine has",
            EXIT_ENVIRONMENT,
        )
    if isinstance(exc, OSError):
        line = _os_line(exc)
        if exc.errno == errno.ENOSPC and "space" not in line:
            line += " (no space left on the device)"
        return one_line(line), EXIT_ENVIRONMENT
    if isinstance(exc, ImportError):
        name = exc.name or str(exc)
        return one_line(
            f"cannot import {name}: {exc} (a package is missing or broken)"
        ), EXIT_ENVIRONMENT
    yaml = sys.modules.get("yaml")
    if yaml is not None and isinstance(exc, yaml.YAMLError):
        problem = getattr(exc, "problem", None) or str(exc)
        return one_line(f"not valid YAML: {problem}" if quote else "not valid YAML"), EXIT_INPUT
    if isinstance(exc, RecursionError):
        return "input nested too deeply for this program", EXIT_INPUT
    text = str(exc) if quote else ""
    detail = f": {text}" if text else ""
    return one_line(
        f"internal error ({_qualified(exc)}{detail}); rerun with --debug for the traceback "
        "and please report it"
    ), EXIT_ENVIRONMENT
