"""``impact-balance gui [SCENARIO]``: the interactive web GUI (see ``impact_balance.gui``)."""

from __future__ import annotations

import argparse
import sys

__all__ = ["add_parser", "run", "USES_KERNEL"]

USES_KERNEL = True


def add_parser(sub) -> list[str]:
    g = sub.add_parser("gui", help="interactive web GUI: edit a stance, see its areas and limits live")
    g.add_argument("scenario", nargs="?", default=None,
                   help="YAML file or bundled scenario name (default: palm_push_two_feet)")
    g.add_argument("--host", default="127.0.0.1", help="interface to listen on (default: %(default)s, this machine only)")
    g.add_argument("--port", type=int, default=8080, help="TCP port (default: %(default)s; the next free one if taken)")
    return ["gui"]


def run(args: argparse.Namespace) -> int:
    try:
        from ..gui.app import run as run_app
        from ..gui.state import DEFAULT_SCENARIO
    except ImportError as exc:  # pragma: no cover - viser is a dependency
        print(f"impact-balance: error: the GUI needs viser ({exc})", file=sys.stderr)
        return 2

    def ready(app) -> None:
        print(f"impact-balance gui: {app.session.state.scenario.name or 'scenario'} at {app.url}  (Ctrl-C to stop)",
              flush=True)

    run_app(args.scenario or DEFAULT_SCENARIO, host=args.host, port=args.port, ready=ready)
    return 0
