#!/usr/bin/env python
"""The contact-aware governor option (experimental): every table of docs/contact_aware_governor.md.

    python benchmarks/contact_aware_governor.py score --out DIR
            [--variant union|warm|cold|off|async]
            [--scenarios ...] [--references 0.5 1 2] [--distances 0.12 0.15 0.18]
    python benchmarks/contact_aware_governor.py sweep --out DIR [--scenarios ...] [--references ...]
    python benchmarks/contact_aware_governor.py bounds [--scenarios ...] [--margins 0 0.01]
    python benchmarks/contact_aware_governor.py preload --out DIR [--scenarios ...] [--speeds ...]
    python benchmarks/contact_aware_governor.py trace --out DIR [--scenario S]
            [--governor com|none] [--contact-aware]
            [--reference R] [--wall D] [--every MS] [--branches]

Every simulated trial is the ``approach`` command's (``id`` controller, ``servo`` joints held
through the impact: ``--rigid-impact``; the governor uses the areas inset by the controller's
10 mm ZMP margin), run in this process with the library calls the command makes, as
``benchmarks/governor_study.py`` does.

- ``score``: the governed trials, ``impact-balance approach SCEN --reference R --governor com
  --rigid-impact --contact-aware --wall-distance-range 0.12 0.18 --json`` for the wall study's
  four stances and references 0.5, 1, 2 m/s (36 trials, ~2 min). One governor serves the walls
  of a reference, in order, as in that command (the option's kept solutions carry over); any
  list of walls (``--distances``, m) and references. ``--variant union`` (default): the option
  as frozen for section 5 (the union of the LCP's solutions from the kept solutions and the cold
  start); ``--variant warm``: as frozen in commit 5e477e6 (section 4's, one fixed point
  warm-started from the previous answer); ``--variant cold``: the post hoc cold start (gauges 0
  at every recomputation, a new governor per wall; not frozen); ``--variant off``: without the
  option (the study's ``com`` governor); ``--variant async``: the union's starts computed by a
  worker process off the tick (``contact_aware_async``; trials record the rates' age, in
  postures, when the worker's answer replaced them). ``--velocity-margin D``: the governor's
  margin (m/s, docs/velocity_margin.md). Each trial also records its recomputations' cost (ms)
  and the most rows (solutions) of the rates.
- ``sweep``: ungoverned approaches (``--governor none``, wall 15 cm) over references around each
  stance's fall (33 trials on four stances, ~2 min): the outcome against the post-impact CoM
  velocity's margin (m/s) in the CoM velocity area ("raw", the trial's own) and in the area inset
  by the controller's ZMP margin ("inset"), both from the measured CoM velocity at the end of the
  impact; then per stance the fastest trial that did not fall and the slowest that fell.
- ``bounds``: no simulation. The maximum approach speed at each scenario's posture (pre-impact
  CoM velocity 0) of the governor without and with the option, in the area without margin and
  inset by 10 mm, and the bound the rejected preload model would give (10 mm).
- ``preload``: the preload model (gravity acts over the impact's duration T, the scenario's
  ``impact.duration``: every point's pre-impact velocity is shifted by ``-g T e_z``) against the
  training stances' rigid-impact trials of ``benchmarks/contact_impact.py`` (the error of the
  predicted CoM velocity jump with T = 0 and T = duration), and the ramp's jumps with and
  without it at the speeds of its fall.
- ``trace``: one recorded approach (log and summary kept in ``--out``; rerun reads them back):
  from the contact on, each support's force, the CoM velocity, the desired and measured ZMP and
  the DCM margin; with ``--branches``, along the approach before the contact, the floating cap
  and the contact-aware jump and cap with the fixed point warm-started from the previous posture
  and cold (the frictional LCP's two solutions near the ramp's wall), and the union's solutions
  and cap (every posture a recomputation) with its cost per recomputation (ms).

Trials go to journals under ``--out`` (``DIR/journals/``) as they finish: a crash or one failing
trial loses nothing else (the failure is printed, the exit status is 1) and the same command
resumes. The tables (markdown) go to stdout, progress to stderr, and ``DIR/<command>.json`` holds
every row. Results and their reading: docs/contact_aware_governor.md.

The command line only; the benchmark itself is the package ``benchmarks/contact_aware/`` (one
concept per module: ``journal``, ``trials``, ``preload``, ``trace``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

# Run as a file, only the script's folder is on sys.path: put the repository root first,
# for the ``benchmarks`` package.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.contact_aware.preload import (
    TRAINING,
    bounds,
    bounds_table,
    preload,
    preload_table,
    ramp_jumps,
)
from benchmarks.contact_aware.trace import trace
from benchmarks.contact_aware.trials import (
    SWEEP_REFERENCES,
    VARIANTS,
    score,
    score_table,
    sweep,
    sweep_table,
)
from benchmarks.governor_study import SCENARIOS, _load


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    s = sub.add_parser("score", help="the governed trials (36 with the defaults)")
    s.add_argument(
        "--out", default="contact-aware-governor", help="folder of the journals and score.json"
    )
    s.add_argument(
        "--variant",
        choices=VARIANTS,
        default="union",
        help="union: --contact-aware, the union of the LCP's solutions (default, section 5); "
        "async: the same computed off the tick (--contact-aware-async); warm: as frozen in "
        "5e477e6 (section 4's 'aware'); cold: post hoc cold start; off: without it",
    )
    s.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    s.add_argument("--references", type=float, nargs="+", default=[0.5, 1.0, 2.0], help="m/s")
    s.add_argument(
        "--distances",
        type=float,
        nargs="+",
        default=[0.12, 0.15, 0.18],
        help="walls, m, in this order",
    )
    s.add_argument(
        "--velocity-margin",
        type=float,
        default=0.0,
        help="the governor's velocity margin, m/s (default 0; docs/governor.md)",
    )
    w = sub.add_parser("sweep", help="ungoverned approaches at wall 15 cm (33 with the defaults)")
    w.add_argument(
        "--out", default="contact-aware-governor", help="folder of the journals and sweep.json"
    )
    w.add_argument("--scenarios", nargs="+", default=list(SWEEP_REFERENCES))
    w.add_argument(
        "--references",
        type=float,
        nargs="+",
        help="m/s (default: each stance's own, SWEEP_REFERENCES)",
    )
    b = sub.add_parser("bounds", help="the caps at the scenario postures (no simulation)")
    b.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    b.add_argument(
        "--margins", type=float, nargs="+", default=[0.0, 0.01], help="ZMP margins, m, ascending"
    )
    b.add_argument(
        "--velocity-margin", type=float, default=0.0, help="the governors' velocity margin, m/s"
    )
    r = sub.add_parser(
        "preload", help="the preload model against the training stances' trials, the ramp's jumps"
    )
    r.add_argument(
        "--out", default="contact-aware-governor", help="folder of the journals and preload.json"
    )
    r.add_argument("--scenarios", nargs="+", default=list(TRAINING))
    r.add_argument(
        "--speeds", type=float, nargs="+", default=[0.25, 0.5, 0.75], help="commanded, m/s"
    )
    t = sub.add_parser(
        "trace", help="one logged approach: after the impact, and the warm/cold branches"
    )
    t.add_argument(
        "--out", default="contact-aware-governor", help="folder of the trial's log and summary"
    )
    t.add_argument("--scenario", default="palm_push_ramp")
    t.add_argument("--governor", choices=("com", "none"), default="com")
    t.add_argument("--contact-aware", action="store_true", help="the governor with the option")
    t.add_argument("--reference", type=float, default=1.0, help="m/s")
    t.add_argument("--wall", type=float, default=0.12, help="m")
    t.add_argument(
        "--every", type=float, default=50.0, help="rows of the table after the impact, ms"
    )
    t.add_argument(
        "--branches",
        action="store_true",
        help="warm and cold contact-aware answers before the contact",
    )
    args = p.parse_args(argv)
    print(f"{_load()} at the start", file=sys.stderr, flush=True)
    if args.command == "bounds":
        print(bounds_table(bounds(args), args.margins))
        print(f"\n{_load()} at the end")
        return 0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.command == "trace":
        trace(args, out)
        return 0
    run, table = {
        "score": (score, score_table),
        "sweep": (sweep, sweep_table),
        "preload": (preload, preload_table),
    }[args.command]
    rows, failures = run(args, out)
    print(table(rows))
    if args.command == "preload":
        print("\nThe ramp (palm_push_ramp, scenario posture, 10 mm inset):\n")
        print(ramp_jumps())
    print(f"\n{_load()} at the end; {len(rows)} trials, {failures} failed")
    tag = (
        ""
        if args.command != "score"
        else f"_{args.variant}" + (f"_v{args.velocity_margin:g}" if args.velocity_margin else "")
    )
    (out / f"{args.command}{tag}.json").write_text(json.dumps(rows, allow_nan=False, default=float))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
