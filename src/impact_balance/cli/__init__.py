"""Command line: ``impact-balance COMMAND ...``.

One module per command (``demo``, ``analyze``, ...), each with ``add_parser(sub)`` and
``run(args) -> int``; this module assembles them and applies the one error rule: an error of
the library (bad scenario, unknown frame...) prints one line on stderr and exits with status
2, with no traceback. A closed stdout (``analyze --json | head -c 10``) ends quietly with
status 141, what a shell reports for a command stopped by SIGPIPE.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from types import ModuleType

from ..exceptions import ImpactBalanceError, ImpactBalanceWarning, one_line
from ..extras import require_for
from . import (analyze, approach, check_log, demo, frames, gui, listing, phase_portrait, pose, push_test, simulate, sweep,
               validate)
from .demo import DEMO_SCENARIOS, FRICTION_SWEEP

__all__ = ["main", "DEMO_SCENARIOS", "FRICTION_SWEEP", "COMMANDS", "EXIT_BROKEN_PIPE"]

#: Command modules, in the order of ``--help``.
COMMANDS: tuple[ModuleType, ...] = (demo, analyze, phase_portrait, listing, frames, pose, gui, simulate, validate, push_test,
                                     approach, check_log, sweep)

#: Exit status when stdout is closed early (128 + SIGPIPE, as a shell reports it).
EXIT_BROKEN_PIPE = 141


def _kernel_is_compiled() -> bool:
    # Imported here: the kernel's module brings numba and scipy, which `robots` does not need.
    from ..projection.walk import kernel_is_compiled

    return kernel_is_compiled()


def _version() -> str:
    import importlib.metadata  # here: only --version reads it (the import costs ~50 ms)

    try:
        return importlib.metadata.version("impact-balance")
    except importlib.metadata.PackageNotFoundError:  # pragma: no cover - run from a source tree
        return "unknown (not installed)"


def _stdout_closed() -> int:
    """Point stdout at /dev/null so that the interpreter's final flush cannot fail again."""
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError, AttributeError):  # stdout is not a file (tests capture it)
        pass
    return EXIT_BROKEN_PIPE


class _VersionAction(argparse.Action):
    """``--version``, looked up only when asked for."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest, default=default, nargs=0,
                         help=help or "show the program's version number and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"impact-balance {_version()}")  # on stdout, as argparse's own version action
        parser.exit()


class _Parser(argparse.ArgumentParser):
    """argparse, with the project's error rule: a usage error is one line on stderr, exit 2
    (argparse's default prints the whole usage block first)."""

    def error(self, message: str):  # noqa: D102 - argparse's hook
        self.exit(2, one_line(f"{self.prog}: error: {message} (see {self.prog} --help)") + "\n")


def _parser() -> tuple[argparse.ArgumentParser, dict[str, ModuleType]]:
    p = _Parser(
        prog="impact-balance",
        description="Impact-aware multi-contact balance: CoM velocity area and maximum contact velocity.",
    )
    p.add_argument("--version", action=_VersionAction)
    sub = p.add_subparsers(dest="command", required=True)
    owners: dict[str, ModuleType] = {}
    for module in COMMANDS:
        for name in module.add_parser(sub):
            owners[name] = module
    return p, owners


_show_warning = warnings.showwarning


def _warning_line(message, category, filename, lineno, file=None, line=None):
    """The library's own warnings as one ``impact-balance: warning:`` line (no source location)."""
    if issubclass(category, ImpactBalanceWarning):
        print(f"impact-balance: warning: {' '.join(str(message).split())}", file=sys.stderr if file is None else file)
    else:
        _show_warning(message, category, filename, lineno, file, line)


def main(argv: list[str] | None = None) -> int:
    warnings.showwarning = _warning_line
    parser, owners = _parser()
    args = parser.parse_args(argv)
    module = owners[args.command]
    if getattr(module, "USES_KERNEL", False) and not _kernel_is_compiled():
        print("impact-balance: compiling the projection kernel (first run only, 0.5 to 1.5 min; cached afterwards) ...",
              file=sys.stderr, flush=True)
    try:
        require_for(args.command, args)  # a missing optional part is one line naming its extra
        status = module.run(args)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler, not at exit
        return status
    except BrokenPipeError:
        return _stdout_closed()
    except ImpactBalanceError as exc:
        print(f"impact-balance: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130
