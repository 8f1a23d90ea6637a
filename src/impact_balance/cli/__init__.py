"""Command line: ``impact-balance COMMAND ...``.

One module per command (``demo``, ``analyze``, ...), each with ``add_parser(sub)`` and
``run(args) -> int``; this module assembles them and applies the one error rule of
:mod:`impact_balance.exit_status` to whatever a command raises (the project, the operating system,
PyYAML, pyarrow, Dask, numpy): one line on stderr, exit status 2 for bad input and 1 for a
failure of the machine, no traceback unless ``--debug`` (anywhere on the line) or
``IMPACT_BALANCE_DEBUG=1``. A closed stdout (``analyze --json | head -c 10``) ends quietly
with status 141, what a shell reports for a command stopped by SIGPIPE; Ctrl-C and SIGTERM end
with one line (``interrupted``, ``terminated (SIGTERM)``) and status 130 (``gui`` keeps the
system's default action for SIGTERM: it ends at once). Two failures of the machine that a
library raises as something else are status 1 here: a
:class:`~impact_balance.exceptions.GovernorError` (the command's governor is fed by the command
itself, not by the user: a worker that died, a posture it refused) and a broken pipe that is
not stdout's (a worker process that ended).
"""

from __future__ import annotations

import argparse
import errno
import os
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Sequence
from types import ModuleType
from typing import Any, NoReturn, TextIO

from impact_balance.cli import (
    analyze,
    approach,
    calibrate,
    check_log,
    demo,
    frames,
    gui,
    listing,
    phase_portrait,
    pose,
    push_test,
    simulate,
    sweep,
    validate,
)
from impact_balance.cli.demo import DEMO_SCENARIOS, FRICTION_SWEEP
from impact_balance.cli.help_text import describe
from impact_balance.exceptions import (
    EnvironmentFailure,
    GovernorError,
    ImpactBalanceWarning,
    one_line,
)
from impact_balance.exit_status import (
    EXIT_BROKEN_PIPE,
    EXIT_ENVIRONMENT,
    EXIT_INTERRUPTED,
    debug_requested,
    describe_error,
)
from impact_balance.extras import require_for

__all__ = ["COMMANDS", "DEMO_SCENARIOS", "EXIT_BROKEN_PIPE", "FRICTION_SWEEP", "main"]

#: Command modules, in the order of ``--help``.
COMMANDS: tuple[ModuleType, ...] = (
    demo,
    analyze,
    phase_portrait,
    listing,
    frames,
    pose,
    gui,
    simulate,
    validate,
    push_test,
    calibrate,
    approach,
    check_log,
    sweep,
)


def _kernel_is_compiled() -> bool:
    """Whether numba's on-disk cache holds the projection kernel (else a run compiles it)."""
    # Imported here: the kernel's module brings numba and scipy, which `robots` does not need.
    from impact_balance.projection.walk import kernel_is_compiled

    return kernel_is_compiled()


#: ``impact_balance._jit.JIT_VARIABLE``, named here: importing ``_jit`` would import numba.
_JIT_VARIABLE = "IMPACT_BALANCE_JIT"


def _interpret_kernels() -> None:
    """A one-shot command (``INTERPRETED = True``) runs the kernels as Python.

    Numba's import and cached-kernel load (0.4 to 0.8 s) cost more than one interpreted
    analysis. Only in a fresh process (``_jit`` not yet imported) and only when
    ``IMPACT_BALANCE_JIT`` is unset.
    """
    if _JIT_VARIABLE in os.environ or "impact_balance._jit" in sys.modules:
        return
    os.environ[_JIT_VARIABLE] = "0"
    try:
        import impact_balance._jit  # noqa: F401 - reads the variable now, once
    finally:
        del os.environ[_JIT_VARIABLE]  # not inherited by anything this process starts


def _version() -> str:
    """The installed version of impact-balance, or "unknown (not installed)"."""
    import importlib.metadata  # here: only --version reads it (the import costs ~50 ms)

    try:
        return importlib.metadata.version("impact-balance")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - run from a source tree
        return "unknown (not installed)"


def _silence_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout is not a file (tests capture it)
        pass


class _Stdout:
    """stdout for the time of a command.

    A write that fails (a full disk, a closed stream, ``>&-``) becomes
    :class:`~impact_balance.exceptions.EnvironmentFailure` naming standard output, so the error
    rule says what failed; a closed pipe stays a ``BrokenPipeError`` (quiet, 141).
    """

    def __init__(self, stream: TextIO | None):
        self._stream = stream
        #: A write or flush of this stream met a closed pipe.
        self.broken = False

    def _failed(self, exc: OSError) -> EnvironmentFailure:
        """The :class:`EnvironmentFailure` of a failed write to this stream."""
        reason = (
            "it is closed"
            if self._stream is None
            else (exc.strerror or str(exc) or type(exc).__name__)
        )
        return EnvironmentFailure("standard output", None, f"cannot write the output: {reason}")

    def write(self, text: str) -> int:
        """Write ``text``; a failure other than a closed pipe names standard output."""
        if self._stream is None:
            raise self._failed(OSError(errno.EBADF, "closed"))
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self.broken = True
            raise
        except OSError as exc:
            raise self._failed(exc) from None

    def flush(self) -> None:
        """Flush the stream; a failure other than a closed pipe names standard output."""
        if self._stream is None:
            return
        try:
            self._stream.flush()
        except BrokenPipeError:
            self.broken = True
            raise
        except OSError as exc:
            raise self._failed(exc) from None

    def isatty(self) -> bool:
        """Whether the stream is a terminal (False when it is closed)."""
        return self._stream is not None and self._stream.isatty()

    def __getattr__(self, name: str) -> Any:
        return getattr(self._stream, name)


def _stdout_pipe_closed() -> bool:
    """Is file descriptor 1 a pipe whose reader has gone (poll says POLLERR)?"""
    try:
        import select

        poller = select.poll()
        poller.register(1, select.POLLOUT)
        return any(event & select.POLLERR for _, event in poller.poll(0))
    except (OSError, ValueError, AttributeError):  # no poll (Windows), fd 1 closed
        return False


def _broken_pipe(exc: BaseException) -> bool:
    """Whether ``exc`` is a closed pipe (``EPIPE``), whoever raised it."""
    return isinstance(exc, BrokenPipeError) or (
        isinstance(exc, OSError) and exc.errno == errno.EPIPE
    )


class _Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main thread: handled as Ctrl-C is, reported as SIGTERM."""


def _on_sigterm(signum: int, frame: Any) -> None:
    """The SIGTERM handler: raise :class:`_Terminated` in the main thread."""
    raise _Terminated("SIGTERM")


def _describe(exc: BaseException) -> tuple[str, int]:
    """:func:`describe_error`, with the command line's own classes (see the module docstring)."""
    if isinstance(exc, _Terminated):
        return "terminated (SIGTERM)", EXIT_INTERRUPTED
    if _broken_pipe(exc):
        return (
            "a pipe to another process closed (Broken pipe): a worker process or a connection "
            "ended unexpectedly",
            EXIT_ENVIRONMENT,
        )
    line, status = describe_error(exc)
    if isinstance(exc, GovernorError):
        status = EXIT_ENVIRONMENT
    return line, status


def _report(exc: BaseException, debug: bool, stdout: _Stdout | None = None) -> int:
    """The one error rule: one line on stderr and the exit status.

    With ``--debug``, the traceback first. A closed stdout (``stdout.broken``, or a pipe whose
    reader has gone) ends quietly with 141; any other broken pipe is a failure, status 1.
    """
    if _broken_pipe(exc) and ((stdout is not None and stdout.broken) or _stdout_pipe_closed()):
        _silence_stdout()
        return EXIT_BROKEN_PIPE
    line, status = _describe(exc)
    if isinstance(exc, EnvironmentFailure) and exc.field == "standard output":
        _silence_stdout()  # what is left in its buffer must not fail again at exit
    try:
        if debug:
            traceback.print_exception(exc, file=sys.stderr)
        print(f"impact-balance: error: {one_line(line)}", file=sys.stderr, flush=True)
    except (OSError, ValueError):  # stderr itself is closed or full: the status is all that is left
        pass
    return status


class _VersionAction(argparse.Action):
    """``--version``, looked up only when asked for."""

    def __init__(
        self,
        option_strings: Sequence[str],
        dest: str = argparse.SUPPRESS,
        default: Any = argparse.SUPPRESS,
        help: str | None = None,
    ) -> None:
        super().__init__(
            option_strings,
            dest,
            default=default,
            nargs=0,
            help=help or "show the program's version number and exit",
        )

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: str | Sequence[Any] | None,
        option_string: str | None = None,
    ) -> None:
        print(f"impact-balance {_version()}")  # on stdout, as argparse's own version action
        parser.exit()


class _Parser(argparse.ArgumentParser):
    """argparse, with the project's error rule.

    A usage error is one line on stderr, exit 2 (argparse's default prints the whole usage block
    first).
    """

    def error(self, message: str) -> NoReturn:
        """Print ``message`` as one line and exit with status 2."""
        self.exit(2, one_line(f"{self.prog}: error: {message} (see {self.prog} --help)") + "\n")


def _parser() -> tuple[argparse.ArgumentParser, dict[str, ModuleType]]:
    """The ``impact-balance`` parser, and the module that runs each command name."""
    p = _Parser(
        prog="impact-balance",
        description="Impact-aware multi-contact balance: CoM velocity area and maximum contact "
        "velocity.",
    )
    p.add_argument("--version", action=_VersionAction)
    p.add_argument(
        "--debug",
        action="store_true",
        help="show the traceback of an error (also anywhere after the command, or "
        "IMPACT_BALANCE_DEBUG=1)",
    )
    sub = p.add_subparsers(dest="command", required=True)
    owners: dict[str, ModuleType] = {}
    for module in COMMANDS:
        for name in module.add_parser(sub):
            owners[name] = module
    describe(sub.choices)
    return p, owners


_show_warning = warnings.showwarning


def _warning_line(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: TextIO | None = None,
    line: str | None = None,
) -> None:
    """The library's own warnings as one ``impact-balance: warning:`` line (no source location)."""
    if issubclass(category, ImpactBalanceWarning):
        print(
            f"impact-balance: warning: {' '.join(str(message).split())}",
            file=sys.stderr if file is None else file,
        )
    else:
        _show_warning(message, category, filename, lineno, file, line)


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit status (see the module docstring)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = debug_requested(argv)
    argv = [a for a in argv if a != "--debug"]  # accepted anywhere on the line
    stdout = sys.stdout
    wrapped = sys.stdout = _Stdout(stdout)
    warnings.showwarning = _warning_line
    previous = _catch_sigterm()
    try:
        parser, owners = _parser()
        args = parser.parse_args(argv)  # option types check values and outputs (exit 2 or 1)
        module = owners[args.command]
        require_for(args.command, args)  # a missing optional part is one line naming its extra
        if getattr(module, "INTERPRETED", False):
            _interpret_kernels()
        if getattr(module, "USES_KERNEL", False) and not _kernel_is_compiled():
            print(
                "impact-balance: compiling the projection kernel (first run only, 0.5 to 1.5 min; "
                "cached afterwards) ...",
                file=sys.stderr,
                flush=True,
            )
        status: int = module.run(args)
        sys.stdout.flush()  # a closed or full stdout shows here, inside the rule, not at exit
        return status
    except SystemExit:  # argparse's --help, --version and usage errors: already one line
        raise
    except BaseException as exc:
        return _report(exc, debug, wrapped)
    finally:
        sys.stdout = stdout
        warnings.showwarning = _show_warning
        if previous is not _NOT_INSTALLED:
            signal.signal(signal.SIGTERM, signal.SIG_DFL if previous is None else previous)


def _catch_sigterm() -> Any:
    """SIGTERM stops the command as Ctrl-C does (main thread only); returns the previous handler.

    :data:`_NOT_INSTALLED` when nothing was installed (another thread, or no SIGTERM here).
    """
    if threading.current_thread() is not threading.main_thread():
        return _NOT_INSTALLED
    try:
        return signal.signal(signal.SIGTERM, _on_sigterm)
    except (ValueError, OSError, AttributeError):  # pragma: no cover - no SIGTERM here
        return _NOT_INSTALLED


#: What :func:`_catch_sigterm` returns when it installed nothing.
_NOT_INSTALLED = object()
