"""Command line: ``impact-balance COMMAND ...``.

One module per command (``demo``, ``analyze``, ...), each with ``add_parser(sub)`` and
``run(args) -> int``; this module assembles them and applies the one error rule: an error of
the library (bad scenario, unknown frame...) prints one line on stderr and exits with status
2, with no traceback.
"""

from __future__ import annotations

import argparse
import sys
from types import ModuleType

from ..exceptions import ImpactBalanceError
from ..projection.walk import kernel_is_compiled
from . import analyze, check_log, demo, gui, listing, phase_portrait, push_test, simulate, validate
from .demo import DEMO_SCENARIOS, FRICTION_SWEEP

__all__ = ["main", "DEMO_SCENARIOS", "FRICTION_SWEEP", "COMMANDS"]

#: Command modules, in the order of ``--help``.
COMMANDS: tuple[ModuleType, ...] = (demo, analyze, phase_portrait, listing, gui, simulate, validate, push_test, check_log)


def _parser() -> tuple[argparse.ArgumentParser, dict[str, ModuleType]]:
    p = argparse.ArgumentParser(
        prog="impact-balance",
        description="Impact-aware multi-contact balance: CoM velocity area and maximum contact velocity.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    owners: dict[str, ModuleType] = {}
    for module in COMMANDS:
        for name in module.add_parser(sub):
            owners[name] = module
    return p, owners


def main(argv: list[str] | None = None) -> int:
    parser, owners = _parser()
    args = parser.parse_args(argv)
    module = owners[args.command]
    if getattr(module, "USES_KERNEL", False) and not kernel_is_compiled():
        print("impact-balance: compiling the projection kernel (first run only, 10-30 s; cached afterwards) ...",
              file=sys.stderr, flush=True)
    try:
        return module.run(args)
    except ImpactBalanceError as exc:
        print(f"impact-balance: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130
