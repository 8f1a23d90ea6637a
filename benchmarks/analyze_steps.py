#!/usr/bin/env python
"""Where an ``analyze()`` goes, step by step, inside the pipeline (issue 28).

    python benchmarks/analyze_steps.py [--json] [--ticks N] [--passes P] [--scenarios NAME ...]

For each scenario of the wall study, ``impact_balance.analyze`` of the N moving postures of
``benchmarks/governor.py`` (the equivalent scenario of each tick, built before timing), CPU
time (``time.process_time``), best of P passes, the garbage collector paused:

- ``analyze``: the call as users make it (no timer inside);
- then the same passes with a timer around each step of the pipeline (the module attributes
  that ``analyze()`` calls are wrapped, and restored after): per step its CPU time per call
  (the mean over the passes), nested steps indented under the step that calls them, less the
  timers' own cost (calibrated on a function that does nothing: what a timer adds to the step
  it times, and to the step around it). ``instrumented`` is the CPU time with the timers,
  ``steps`` the sum of the top-level steps, and ``glue`` the rest of ``analyze()`` (its own
  lines; ``instrumented`` less ``steps`` and less the timers' cost).

The steps are timed where they run (in the pipeline's caches), not apart: a part timed alone in
warm caches is faster than inside a whole analysis. Exit status 0; 2 for a bad argument.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import json
import sys
import time
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

# Run as a file, only the script's folder is on sys.path: put the repository root first.
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.speed.machine import machine_info
from benchmarks.speed.ticks import trajectory
from benchmarks.speed.timing import progress

__all__ = ["STEPS", "main", "profile_scenario", "timed_steps"]

SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")

#: (depth, label, module, owner attribute path): what is wrapped. Depth 0 are analyze()'s own
#: steps (their sum is ``steps``); deeper ones are inside the step above them.
STEPS: tuple[tuple[int, str, str, str], ...] = (
    (0, "robot (cached)", "impact_balance.scenario.schema", "Scenario.load_robot"),
    (0, "stance", "impact_balance.scenario.schema", "Scenario.build_stance"),
    (1, "configuration", "impact_balance.scenario.schema", "Scenario.configuration_vector"),
    (1, "contact specs", "impact_balance.scenario.schema", "Scenario.contact_specs"),
    (1, "Stance (pinocchio)", "impact_balance.scenario.schema", "Stance"),
    (0, "criterion's contacts", "impact_balance.analysis.analyze", "scaled_stance"),
    (0, "posture", "impact_balance.analysis.analyze", "_posture"),
    (1, "impact point", "impact_balance.contacts.stance", "Stance.local_point"),
    (1, "stance's arrays", "impact_balance.analysis.analyze", "_stance_arrays"),
    (1, "compiled call", "impact_balance.analysis.analyze", "posture_kernel"),
    (1, "its objects", "impact_balance.analysis.analyze", "posture_answer"),
    (1, "the areas' objects", "impact_balance.balance.areas", "Projected.areas"),
    (0, "finiteness", "impact_balance.analysis.analyze", "_posture_finite"),
    (0, "answer", "impact_balance.analysis.analyze", "_answer"),
    (1, "CoM criterion", "impact_balance.criteria.com", "ComCriterion.limit"),
    (1, "ZMP criterion", "impact_balance.analysis.analyze", "zmp_max_contact_velocity"),
    (1, "safe velocity", "impact_balance.analysis.analyze", "safe_contact_velocity"),
    (0, "diagnostics", "impact_balance.analysis.analyze", "diagnose"),
    (0, "Analysis", "impact_balance.analysis.analyze", "Analysis"),
)


@contextlib.contextmanager
def timed_steps(totals: Counter[str]) -> Iterator[None]:
    """Wrap every step of :data:`STEPS` with a timer adding its CPU time (ns) to ``totals``."""
    import importlib

    saved = []
    clock = time.process_time_ns
    try:
        for _, label, module, path in STEPS:
            *owners, name = path.split(".")
            owner: Any = importlib.import_module(module)
            for part in owners:
                owner = getattr(owner, part)
            original = owner.__dict__[name] if isinstance(owner, type) else getattr(owner, name)
            saved.append((owner, name, original))
            setattr(owner, name, _timer(original, label, totals, clock))
        yield
    finally:
        for owner, name, original in reversed(saved):
            setattr(owner, name, original)


def _timer(
    fn: Callable[..., Any], label: str, totals: Counter[str], clock: Callable[[], int]
) -> Callable[..., Any]:
    def timed(*args: Any, **kwargs: Any) -> Any:
        t = clock()
        try:
            return fn(*args, **kwargs)
        finally:
            totals[label] += clock() - t

    return timed


def _best(fn: Callable[[], Any], n: int, passes: int) -> float:
    """Best CPU time per call (us) of ``passes`` passes of ``fn`` (n calls each)."""
    best = float("inf")
    for _ in range(passes):
        t = time.process_time()
        fn()
        best = min(best, (time.process_time() - t) / n * 1e6)
    return best


def profile_scenario(name: str, ticks: int, passes: int) -> dict[str, Any]:
    """``analyze()`` of the scenario's ``ticks`` moving postures, whole and step by step (us)."""
    import impact_balance as ib
    from impact_balance.governor import Governor

    governor = Governor(name)
    qs, vs = trajectory(governor, ticks)
    answers = [governor.limit(q, v) for q, v in zip(qs, vs, strict=True)]
    scenarios = [governor.scenario_at(q, a.com_velocity) for q, a in zip(qs, answers, strict=True)]

    def run() -> None:
        for scenario in scenarios:
            ib.analyze(scenario)

    run()  # warm: kernels loaded, caches filled
    gc.disable()
    try:
        whole = _best(run, ticks, passes)
        totals: Counter[str] = Counter()
        with timed_steps(totals):
            run()
            totals.clear()
            instrumented = _best(run, ticks, 1)
            for _ in range(passes - 1):  # the steps of the passes after the first, averaged
                run()
    finally:
        gc.enable()
    own, added = _timer_cost()
    per_call = {}
    for i, (depth, label, _, _) in enumerate(STEPS):
        inner = 0  # the timed steps directly inside this one
        for later, *_ in STEPS[i + 1 :]:
            if later <= depth:
                break
            inner += later == depth + 1
        per_call[label] = totals[label] / 1e3 / (ticks * passes) - own - inner * added
    steps = sum(per_call[label] for depth, label, _, _ in STEPS if depth == 0)
    return {
        "scenario": name,
        "ticks": ticks,
        "passes": passes,
        "analyze_us": whole,
        "instrumented_us": instrumented,
        "timer_us": {"own": own, "added": added},
        "steps_us": steps,
        "glue_us": instrumented - steps - len(STEPS) * added,
        "step_us": per_call,
    }


def _timer_cost(n: int = 20000) -> tuple[float, float]:
    """A timer's cost (us): what it records around a call that does nothing, and what it adds
    to its caller's time (best of 5 passes of ``n`` calls)."""
    totals: Counter[str] = Counter()

    def nothing() -> None:
        return None

    timed = _timer(nothing, "nothing", totals, time.process_time_ns)

    def bare() -> None:
        for _ in range(n):
            nothing()

    def wrapped() -> None:
        for _ in range(n):
            timed()

    added = _best(wrapped, n, 5) - _best(bare, n, 5)
    totals.clear()
    wrapped()
    return totals["nothing"] / 1e3 / n, added


def text_report(result: dict[str, Any]) -> str:
    rows = result["scenarios"]
    lines = [
        f"CPU time per analyze() (us), {result['ticks']} moving postures, best of "
        f"{result['passes']} passes; load average {result['load_average']}",
        "",
        f"{'step':28s}" + "".join(f"{r['scenario'][:18]:>20s}" for r in rows),
    ]
    lines.append("-" * len(lines[-1]))

    def row(label: str, key: Callable[[dict[str, Any]], float]) -> None:
        lines.append(f"{label:28s}" + "".join(f"{key(r):20.1f}" for r in rows))

    row("analyze()", lambda r: r["analyze_us"])
    row("with timers", lambda r: r["instrumented_us"])
    row("(a timer's cost, per step)", lambda r: r["timer_us"]["added"])
    for depth, label, _, _ in STEPS:
        row("  " * (depth + 1) + label, lambda r, label=label: r["step_us"][label])
    row("  glue (analyze's own lines)", lambda r: r["glue_us"])
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--ticks", type=int, default=300, help="postures per scenario")
    parser.add_argument("--passes", type=int, default=5, help="passes over them (best kept)")
    parser.add_argument("--scenarios", nargs="*", default=list(SCENARIOS))
    args = parser.parse_args(argv)
    if args.ticks < 1 or args.passes < 1:
        print("analyze_steps.py: --ticks and --passes must be >= 1", file=sys.stderr)
        return 2
    rows = []
    for name in args.scenarios:
        progress(f"{name} ...")
        rows.append(profile_scenario(name, args.ticks, args.passes))
    with open("/proc/loadavg") as fh:
        load = " ".join(fh.read().split()[:3])
    result = {
        "benchmark": "analyze_steps",
        "machine": machine_info(),
        "ticks": args.ticks,
        "passes": args.passes,
        "load_average": load,
        "scenarios": rows,
    }
    print(json.dumps(result, indent=1) if args.json else text_report(result))
    return 0


if __name__ == "__main__":
    sys.exit(main())
