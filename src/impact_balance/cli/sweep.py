"""``impact-balance sweep SPEC``: a study over many points, on all cores or a Dask cluster.

``impact-balance sweep --summary DIR`` prints the best and worst points of a sweep folder;
``impact-balance sweep --verify DIR`` checks every part of a folder (exit status 2 when a part is
bad); ``impact-balance sweep --list`` the bundled sweep files.

Order, so that nothing is created for bad input: the options are checked when the line is read
(``--out`` and ``--plots`` writable, ``--scheduler`` well formed), then the sweep file and its
plan (robot loaded, axes checked, size bounded), then the workers or the scheduler, and only
then is the output folder made.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from impact_balance.cli._options import CommandLineError, output_folder
from impact_balance.cli.output import print_json

if TYPE_CHECKING:
    from impact_balance.cli._options import Subcommands

__all__ = ["USES_KERNEL", "add_parser", "run"]

USES_KERNEL = True


def _positive(text: str) -> int:
    """An integer >= 1 (argparse type; a bad value is a usage error)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} must be >= 1")
    return value


def _seconds(text: str) -> float:
    """A positive, finite number of seconds (argparse type)."""
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"{text} must be a positive, finite number of seconds")
    return value


def _scheduler(text: str) -> str:
    """A Dask scheduler address ``tcp://HOST:PORT``, checked (refused: exit 2)."""
    from impact_balance.exceptions import OptionError
    from impact_balance.sweep.cluster import check_scheduler_address

    try:
        return check_scheduler_address(text)
    except OptionError as exc:
        raise CommandLineError(exc.field, exc.value, exc.reason) from None


def add_parser(sub: Subcommands) -> list[str]:
    """Add the ``sweep`` command to the subcommands ``sub``.

    Args:
        sub: The subcommands of the ``impact-balance`` parser.

    Returns:
        The names of the commands added (their runner is :func:`run`).
    """
    s = sub.add_parser(
        "sweep",
        help="evaluate a sweep file (grid or quasi-random points) on all cores or a Dask cluster",
        description="Evaluate every point of a sweep file and write one Parquet row per point. "
        "Finished chunks "
        "are written at once: after Ctrl-C or a crash, the same command resumes.",
    )
    s.add_argument(
        "spec", nargs="?", help="sweep YAML file, or the name of a bundled sweep (see --list)"
    )
    s.add_argument(
        "--out",
        metavar="DIR",
        type=output_folder("--out"),
        help="output folder (default: sweep-<name> in the current folder)",
    )
    s.add_argument(
        "--workers",
        type=_positive,
        metavar="N",
        help="local worker processes (default: every core)",
    )
    s.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        type=_scheduler,
        help="Dask scheduler address, tcp://HOST:PORT (e.g. tcp://10.0.0.5:8786)",
    )
    s.add_argument(
        "--chunk-timeout",
        type=_seconds,
        metavar="S",
        default=None,
        help="longest wait for the workers to start and for the next chunk to finish, s; "
        "then the sweep fails (exit status 1, the finished chunks kept) "
        "(default 900; worker processes and Dask)",
    )
    s.add_argument("--no-progress", action="store_true", help="no progress bar")
    s.add_argument(
        "--no-plots", action="store_true", help="do not write the figures when the sweep completes"
    )
    s.add_argument(
        "--summary",
        metavar="DIR",
        help="print the best and worst points of a sweep folder, and exit",
    )
    s.add_argument(
        "--verify",
        metavar="DIR",
        help="check every part of a sweep folder (digest, chunk, rows, checksum), and exit",
    )
    s.add_argument(
        "--plots",
        metavar="DIR",
        dest="plots_dir",
        type=output_folder("--plots"),
        help="with --summary: write the figures to DIR; after a run: instead of OUT/figures",
    )
    s.add_argument(
        "--top", type=_positive, default=5, help="best and worst points shown (default 5)"
    )
    s.add_argument(
        "--json", action="store_true", help="print one JSON object (the summary) on stdout"
    )
    s.add_argument("--list", action="store_true", help="list the bundled sweep files")
    return ["sweep"]


def _print(summary: dict[str, Any], as_json: bool) -> None:
    """Print a sweep summary as text or as one JSON document."""
    from impact_balance.sweep.summary import format_summary

    if as_json:
        print_json(summary)
    else:
        print(format_summary(summary))


def _warn(line: str) -> None:
    """Print one ``impact-balance: warning:`` line on stderr."""
    print(f"impact-balance: warning: {line}", file=sys.stderr, flush=True)


def _verify(args: argparse.Namespace) -> int:
    """``sweep --verify``: check every part of a results folder; 0 if sound, 2 if not."""
    from impact_balance.sweep.store import check_folder

    check = check_folder(args.verify)
    if args.json:
        print_json(check.to_dict())
    else:
        for problem in check.problems:
            print(problem.line())
        state = (
            "complete"
            if not check.missing
            else f"{len(check.missing)} of {check.n_chunks} chunks not computed yet"
        )
        verdict = "ok" if check.ok else f"{len(check.problems)} bad part(s)"
        print(
            f"{args.verify}: {verdict}; {len(check.good)} good parts, {check.rows} of "
            f"{check.manifest['n_points']} "
            f"points; {state}"
        )
    return 0 if check.ok else 2


def run(args: argparse.Namespace) -> int:
    """Run ``sweep`` with the parsed command line.

    Args:
        args: The parsed command line.

    Returns:
        The exit status (0; a failure is raised, for the command line's error rule).
    """
    from impact_balance.exceptions import SweepError
    from impact_balance.sweep import bundled_sweeps, load_sweep_spec, make_plan, run_sweep
    from impact_balance.sweep.figures import save_sweep_figures
    from impact_balance.sweep.runner import CHUNK_TIMEOUT_S
    from impact_balance.sweep.summary import summarize

    if args.list:
        for name, description in bundled_sweeps().items():
            print(f"{name:32s} {description}")
        return 0
    if sum(bool(x) for x in (args.spec, args.summary, args.verify)) > 1:
        raise SweepError(
            "SPEC",
            args.spec or args.summary,
            "give one of a sweep file, --summary DIR or --verify DIR",
        )
    if args.verify:
        return _verify(args)
    if args.summary:
        summary = summarize(args.summary, args.top)
        for line in summary["problems"]:
            _warn(f"{args.summary}/{line} (left out of the summary)")
        if args.plots_dir:
            from impact_balance.cli.output_paths import writing

            with writing("--plots", args.plots_dir):
                figures = save_sweep_figures(args.summary, args.plots_dir)
            summary["figures"] = [str(p) for p in figures]
        _print(summary, args.json)
        if not args.json:
            for path in summary.get("figures", []):
                print(f"  figure: {path}")
        return 0
    if not args.spec:
        raise SweepError(
            "SPEC", None, "give a sweep file (or a bundled name: see --list), or --summary DIR"
        )
    spec = load_sweep_spec(args.spec)
    plan = make_plan(spec)
    if args.out:
        out = Path(args.out)
    else:
        from impact_balance.cli.output_paths import check_output_folder

        stem = Path(spec.source).stem if spec.source else "sweep"
        out = check_output_folder(f"sweep-{stem}", "--out")
    report = run_sweep(
        plan,
        out,
        workers=args.workers,
        scheduler=args.scheduler,
        progress=not args.no_progress,
        notify=lambda line: _warn(f"{out}/{line}"),
        chunk_timeout=args.chunk_timeout or CHUNK_TIMEOUT_S,
    )
    where = args.scheduler or f"{report.workers} worker{'s' if report.workers != 1 else ''}"
    print(
        f"impact-balance sweep: {report.points_computed} points in {report.elapsed_s:.1f} s on "
        f"{where} "
        f"({report.rate:.0f} points/s; {report.chunks_before} of {report.n_chunks} chunks were "
        f"already done) -> {out}",
        file=sys.stderr,
    )
    if report.interrupted:
        print(
            f"impact-balance sweep: interrupted; {report.chunks_before + report.chunks_computed} "
            f"of {report.n_chunks} "
            "chunks are written: run the same command to resume",
            file=sys.stderr,
        )
        return 130
    summary = summarize(out, args.top)
    if not args.no_plots:
        summary["figures"] = [str(p) for p in save_sweep_figures(out, args.plots_dir)]
    _print(summary, args.json)
    if not args.json:
        for path in summary.get("figures", []):
            print(f"  figure: {path}")
    return 0
