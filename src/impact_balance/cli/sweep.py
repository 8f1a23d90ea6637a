"""``impact-balance sweep SPEC``: a study over many points, on all cores or a Dask cluster.

``impact-balance sweep --summary DIR`` prints the best and worst points of a sweep folder;
``impact-balance sweep --list`` the bundled sweep files.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

__all__ = ["add_parser", "run", "USES_KERNEL"]

USES_KERNEL = True


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be >= 1")
    return value


def add_parser(sub) -> list[str]:
    s = sub.add_parser(
        "sweep",
        help="evaluate a sweep file (grid or quasi-random points) on all cores or a Dask cluster",
        description="Evaluate every point of a sweep file and write one Parquet row per point. Finished chunks "
        "are written at once: after Ctrl-C or a crash, the same command resumes.",
    )
    s.add_argument("spec", nargs="?", help="sweep YAML file, or the name of a bundled sweep (see --list)")
    s.add_argument("--out", metavar="DIR", help="output folder (default: sweep-<name> in the current folder)")
    s.add_argument("--workers", type=_positive, metavar="N", help="local worker processes (default: every core)")
    s.add_argument("--scheduler", metavar="ADDRESS", help="Dask scheduler address, e.g. tcp://10.0.0.5:8786")
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument("--no-plots", action="store_true", help="do not write the figures when the sweep completes")
    s.add_argument("--summary", metavar="DIR", help="print the best and worst points of a sweep folder, and exit")
    s.add_argument("--plots", metavar="DIR", dest="plots_dir",
                   help="with --summary: write the figures to DIR; after a run: instead of OUT/figures")
    s.add_argument("--top", type=_positive, default=5, help="best and worst points shown (default 5)")
    s.add_argument("--json", action="store_true", help="print one JSON object (the summary) on stdout")
    s.add_argument("--list", action="store_true", help="list the bundled sweep files")
    return ["sweep"]


def _print(summary: dict, as_json: bool) -> None:
    from ..sweep.summary import format_summary

    if as_json:
        print(json.dumps(summary, allow_nan=False))
    else:
        print(format_summary(summary))


def run(args: argparse.Namespace) -> int:
    from ..exceptions import SweepError
    from ..sweep import bundled_sweeps, load_sweep_spec, make_plan, run_sweep
    from ..sweep.figures import save_sweep_figures
    from ..sweep.summary import summarize

    if args.list:
        for name, description in bundled_sweeps().items():
            print(f"{name:32s} {description}")
        return 0
    if args.summary:
        if args.spec:
            raise SweepError("SPEC", args.spec, "give either a sweep file or --summary DIR, not both")
        summary = summarize(args.summary, args.top)
        if args.plots_dir:
            summary["figures"] = [str(p) for p in save_sweep_figures(args.summary, args.plots_dir)]
        _print(summary, args.json)
        if not args.json:
            for path in summary.get("figures", []):
                print(f"  figure: {path}")
        return 0
    if not args.spec:
        raise SweepError("SPEC", None, "give a sweep file (or a bundled name: see --list), or --summary DIR")
    spec = load_sweep_spec(args.spec)
    plan = make_plan(spec)
    out = Path(args.out) if args.out else Path(f"sweep-{Path(spec.source).stem}")
    report = run_sweep(plan, out, workers=args.workers, scheduler=args.scheduler, progress=not args.no_progress)
    where = args.scheduler or f"{report.workers} worker{'s' if report.workers != 1 else ''}"
    print(f"impact-balance sweep: {report.points_computed} points in {report.elapsed_s:.1f} s on {where} "
          f"({report.rate:.0f} points/s; {report.chunks_before} of {report.n_chunks} chunks were already done) -> {out}",
          file=sys.stderr)
    if report.interrupted:
        print(f"impact-balance sweep: interrupted; {report.chunks_before + report.chunks_computed} of {report.n_chunks} "
              "chunks are written: run the same command to resume", file=sys.stderr)
        return 130
    summary = summarize(out, args.top)
    if not args.no_plots:
        summary["figures"] = [str(p) for p in save_sweep_figures(out, args.plots_dir)]
    _print(summary, args.json)
    if not args.json:
        for path in summary.get("figures", []):
            print(f"  figure: {path}")
    return 0
