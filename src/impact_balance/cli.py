"""Command line: ``impact-balance {demo, analyze, phase-portrait, scenarios, robots, gui}``.

Errors of the library (bad scenario, unknown frame...) print one line on stderr and exit
with status 2; no traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from .exceptions import ImpactBalanceError
from .projection.walk import kernel_is_compiled

__all__ = ["main", "DEMO_SCENARIOS", "FRICTION_SWEEP"]

#: The bundled studies the demo runs (paper sec. VI).
DEMO_SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot")
#: The impact-friction sweep (paper Fig. miu-compare).
FRICTION_SWEEP = ("palm_push_mu010", "palm_push_mu024", "palm_push_mu040")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="impact-balance",
        description="Impact-aware multi-contact balance: CoM velocity area and maximum contact velocity.",
    )
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("demo", help="run the bundled studies on the default robot, print a report, write figures")
    d.add_argument("--out", default="impact-balance-demo", help="folder for the figures (default: %(default)s)")
    d.add_argument("--no-plots", action="store_true", help="skip the figures")
    a = sub.add_parser("analyze", help="analyze one scenario (file or bundled name)")
    a.add_argument("scenario", help="YAML file, or the name of a bundled scenario (see `impact-balance scenarios`)")
    a.add_argument("--json", action="store_true", help="print one JSON object")
    a.add_argument("--plots", metavar="DIR", help="write the scenario's figures to DIR")
    a.add_argument("--qp", action="store_true", help="also solve the paper's QP in joint velocities")
    pp = sub.add_parser("phase-portrait", help="LIPM phase portrait and CoM velocity bounds (paper sec. III-B)")
    pp.add_argument("--com-height", type=float, required=True, metavar="H", help="CoM height above the ZMP plane, m")
    pp.add_argument("--zmp-range", type=float, nargs=2, required=True, metavar=("LO", "HI"), help="ZMP interval, m")
    pp.add_argument("--gravity", type=float, default=9.81, help="m/s^2 (default: %(default)s)")
    pp.add_argument("--json", action="store_true", help="print one JSON object")
    pp.add_argument("--plot", metavar="FILE", help="write the phase portrait figure (PNG)")
    sub.add_parser("scenarios", help="list the bundled scenarios")
    sub.add_parser("robots", help="list the bundled robots")
    g = sub.add_parser("gui", help="interactive web GUI: edit a stance, see its areas and limits live")
    g.add_argument("scenario", nargs="?", default=None,
                   help="YAML file or bundled scenario name (default: palm_push_two_feet)")
    g.add_argument("--host", default="127.0.0.1", help="interface to listen on (default: %(default)s, this machine only)")
    g.add_argument("--port", type=int, default=8080, help="TCP port (default: %(default)s; the next free one if taken)")
    return p


def _cmd_scenarios(_: argparse.Namespace) -> int:
    from .scenario import bundled_scenarios

    items = bundled_scenarios()
    width = max(map(len, items), default=0)
    for name, description in items.items():
        print(f"{name:<{width}}  {description}")
    return 0


def _cmd_robots(_: argparse.Namespace) -> int:
    from .robot import BUNDLED_ROBOTS

    for name, spec in BUNDLED_ROBOTS.items():
        print(f"{name:<6}  {spec.description}")
    return 0


def _cmd_analyze(args: argparse.Namespace) -> int:
    from .analysis import analyze
    from .report import format_analysis

    analysis = analyze(args.scenario, solve_qp=True if args.qp else None)
    written = []
    if args.plots:
        from .plots import save_figures

        written = save_figures(analysis, Path(args.plots))
    if args.json:
        print(json.dumps(analysis.to_dict()))
    else:
        print(format_analysis(analysis))
        for path in written:
            print(f"  figure: {path}")
    return 0


def _cmd_phase_portrait(args: argparse.Namespace) -> int:
    from .lipm import phase_portrait

    portrait = phase_portrait(args.com_height, tuple(args.zmp_range), args.gravity)
    if args.plot:
        from .plots import plot_phase_portrait

        fig = plot_phase_portrait(portrait)
        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        fig.savefig(args.plot, dpi=120)
    if args.json:
        print(json.dumps({"omega": portrait.omega, "com_height": args.com_height, "zmp_range": list(portrait.zmp_range),
                          "gravity": args.gravity, "com_velocity_bounds": list(portrait.com_velocity_bounds)}))
    else:
        lo, hi = portrait.com_velocity_bounds
        print(f"omega = {portrait.omega:.4f} 1/s; CoM velocity bounds at c = 0: [{lo:.4f}, {hi:.4f}] m/s")
        if args.plot:
            print(f"figure: {args.plot}")
    return 0


def _cmd_gui(args: argparse.Namespace) -> int:
    try:
        from .gui.app import run
        from .gui.state import DEFAULT_SCENARIO
    except ImportError as exc:  # pragma: no cover - viser is a dependency
        print(f"impact-balance: error: the GUI needs viser ({exc})", file=sys.stderr)
        return 2

    def ready(app) -> None:
        print(f"impact-balance gui: {app.session.state.scenario.name or 'scenario'} at {app.url}  (Ctrl-C to stop)",
              flush=True)

    run(args.scenario or DEFAULT_SCENARIO, host=args.host, port=args.port, ready=ready)
    return 0


def _cmd_demo(args: argparse.Namespace) -> int:
    from .analysis import analyze
    from .report import format_analysis, format_speed

    out = Path(args.out)
    print("impact-balance demo: the paper's studies on Talos (bundled scenarios)\n")
    written: list[Path] = []
    for name in DEMO_SCENARIOS:
        analysis = analyze(name, solve_qp=True)
        print(format_analysis(analysis) + "\n")
        if not args.no_plots:
            from .plots import save_figures

            written += save_figures(analysis, out)
    sweep = [analyze(name) for name in FRICTION_SWEEP]
    print("impact-friction sweep (palm push, two coplanar feet):")
    print(f"  {'mu':>5}  {'CoM criterion':>14}  {'ZMP criterion':>14}")
    for a in sweep:
        im = a.impact
        print(f"  {im.model.spec.friction:>5.2f}  {format_speed(im.max_contact_velocity):>14}  "
              f"{format_speed(im.zmp_max_contact_velocity):>14}")
    if not args.no_plots:
        from .lipm import phase_portrait
        from .plots import plot_friction_comparison, plot_phase_portrait

        out.mkdir(parents=True, exist_ok=True)
        for fig, fname in ((plot_friction_comparison(sweep), "friction_comparison.png"),
                           (plot_phase_portrait(phase_portrait(0.78, (-0.13, 0.13))), "phase_portrait.png")):
            fig.savefig(out / fname, dpi=120)
            written.append(out / fname)
        print(f"\n{len(written)} figures written to {out}/")
    from .lipm import com_velocity_bounds

    bounds = np.round(com_velocity_bounds(0.78, (-0.13, 0.13)), 4)
    print(f"LIPM check (paper sec. III-B): c_z 0.78 m, ZMP in [-0.13, 0.13] m -> CoM velocity in [{bounds[0]}, {bounds[1]}] m/s")
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    handler = {
        "demo": _cmd_demo,
        "analyze": _cmd_analyze,
        "phase-portrait": _cmd_phase_portrait,
        "scenarios": _cmd_scenarios,
        "robots": _cmd_robots,
        "gui": _cmd_gui,
    }[args.command]
    if args.command in ("demo", "analyze", "gui") and not kernel_is_compiled():
        print("impact-balance: compiling the projection kernel (first run only, 10-30 s; cached afterwards) ...",
              file=sys.stderr, flush=True)
    try:
        return handler(args)
    except ImpactBalanceError as exc:
        print(f"impact-balance: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
