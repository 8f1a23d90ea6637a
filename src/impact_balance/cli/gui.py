"""``impact-balance gui [SCENARIO]``: the interactive web GUI (see ``impact_balance.gui``)."""

from __future__ import annotations

import argparse
import sys
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands
    from impact_balance.gui.app import GuiApp

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``gui`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    g = sub.add_parser(
        "gui", help="interactive web GUI: edit a stance, see its areas and limits live"
    )
    g.add_argument(
        "scenario",
        nargs="?",
        default=None,
        help="YAML file or bundled scenario name (default: palm_push_two_feet)",
    )
    g.add_argument(
        "--host",
        default="127.0.0.1",
        help="interface to listen on (default: %(default)s, this machine only)",
    )
    g.add_argument(
        "--port",
        type=int,
        default=8080,
        help="TCP port (default: %(default)s; the next free one if taken)",
    )
    g.add_argument(
        "--workspace",
        default=".",
        metavar="DIR",
        help="the only folder the GUI loads and saves .yaml files in (default: the current folder)",
    )
    g.add_argument(
        "--allow-origin",
        action="append",
        default=[],
        metavar="ORIGIN",
        help="also accept pages from ORIGIN (scheme://host[:port], e.g. a reverse proxy); "
        "repeatable. "
        "By default only the GUI's own page may connect",
    )
    return ["gui"]


def run(args: argparse.Namespace) -> int:
    """Run ``gui`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    try:
        from impact_balance.gui.app import run as run_app
        from impact_balance.gui.state import DEFAULT_SCENARIO
    except ImportError as exc:  # pragma: no cover - viser is a dependency
        print(f"impact-balance: error: the GUI needs viser ({exc})", file=sys.stderr)
        return 2

    from impact_balance.gui.guard import normalize_origin
    from impact_balance.gui.workspace import Workspace

    # Check the flags before anything loads or listens (errors: one line, exit 2).
    workspace = Workspace(args.workspace)
    origins = tuple(normalize_origin(o) for o in args.allow_origin)

    def ready(app: GuiApp) -> None:
        """Print the URL, the workspace and the extra origins once the server listens."""
        print(
            f"impact-balance gui: {app.session.state.scenario.name or 'scenario'} at {app.url}  "
            "(Ctrl-C to stop)\n"
            f"  workspace: {app.workspace.root}  (the GUI loads and saves .yaml files here only)",
            flush=True,
        )
        if origins:
            print(f"  also accepting pages from: {', '.join(origins)}", flush=True)

    run_app(
        args.scenario or DEFAULT_SCENARIO,
        host=args.host,
        port=args.port,
        ready=ready,
        workspace=workspace,
        allow_origins=origins,
    )
    return 0
