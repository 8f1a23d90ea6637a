#!/usr/bin/env python
"""Issue 28 item 3: ``Governor.limits`` (N postures in one call) beside N single ticks.

    python benchmarks/batch.py [--json] [--n N] [--repeat R] [--threads T] [--scenarios NAME ...]
        [--profile] [--gil] [--chunks K ...]

For each scenario of the wall study, the moving 500 Hz trajectory of ``benchmarks/governor.py``
(N ticks, default 1000: every posture differs), timed round-robin in one run, R rounds (the
garbage collector paused):

- ``single``: N calls of ``governor.limit(q_k, v_k)`` (a posture-changing tick each);
- ``batch``: one ``governor.limits(q, v)`` of the N rows;
- ``batch_threads``: the same with ``threads=T`` (default 2);
- ``velocity``: N calls of ``governor.limit(q_0, v_k)`` (one posture, N velocities: the
  velocity-only tick), beside ``batch_velocity``: one ``governor.limits`` of the N rows
  ``(q_0, v_k)`` (a row that repeats the previous row's q reuses its posture).

Reported per scenario: the time per posture (median over rounds, us) of each case, the
throughput ratio single / batch (target >= 3 at N = 1000), the same ratio in CPU time (best of
R more rounds of ``single`` and ``batch``: the machine is shared) and the worst difference of the
batch's maximum contact velocity from the single ticks' (must be <= 1e-12 m/s), with the load
average before and after (the machine is shared: absolute times move with it, ratios less).
Exit status 1 if an answer disagrees, else 0. ``--profile`` reports instead, per scenario, where a
batch row's microseconds go (:mod:`benchmarks.speed.batch_profile`). ``--gil`` reports instead,
per scenario, one thread beside ``--threads`` T (best wall time of R passes each): the batch's
wall time per row, the compiled calls' thread CPU time per row summed over the threads (the part
that runs without the GIL), the rest of the threads' wall time per row (Python holding the GIL,
or waiting for it or for a core), the slowest thread's compiled CPU over the threads' mean (the
threads' shares: a chunk goes to the thread that asks first) and the compiled calls' wall over
their thread CPU (above 1: a thread waited for a core the machine did not give it).
``--chunks K ...`` reports instead, per scenario and chunk size K (postures per chunk:
``CHUNK`` and ``MIN_CHUNK`` of ``impact_balance.governor.batch`` set to K; the sizes
alternated round-robin, best of R passes): the one-thread batch's CPU time per row (what the
chunks' cold starts cost), the ``--threads`` T batch's wall time per row, and the wall time per
row T free cores would take (the one-thread pass's chunks, their CPU times, handed out in order
to the first free core: what the chunks' balance buys, whatever the machine's load).
"""

from __future__ import annotations

import argparse
import itertools
import json
import os
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from benchmarks.speed.ticks import trajectory
from benchmarks.speed.timing import Case, measure, progress
from impact_balance.governor import Governor

SCENARIOS = ("palm_push_two_feet", "palm_push_ramp", "kick_one_foot", "g1_two_feet")
TARGET_RATIO = 3.0

__all__ = ["SCENARIOS", "bench_scenario", "gil_scenario", "main"]


def bench_scenario(name: str, n: int, repeat: int, threads: int) -> dict[str, Any]:
    """One scenario's three cases, round-robin, ``repeat`` rounds of ``n`` postures."""
    single, batched, steady = Governor(name), Governor(name), Governor(name)
    qs, vs = trajectory(single, n)
    q0s = np.tile(qs[0], (n, 1))
    load_before = os.getloadavg()
    cases = {
        "single": Case(
            lambda: [single.limit(q, v).max_contact_velocity for q, v in zip(qs, vs, strict=True)],
            keep=np.asarray,
        ),
        "batch": Case(lambda: batched.limits(qs, vs), keep=lambda r: r.max_contact_velocity),
        "batch_threads": Case(
            lambda: batched.limits(qs, vs, threads=threads), keep=lambda r: r.max_contact_velocity
        ),
        "velocity": Case(
            lambda: [steady.limit(qs[0], v).max_contact_velocity for v in vs], keep=np.asarray
        ),
        "batch_velocity": Case(
            lambda: batched.limits(q0s, vs), keep=lambda r: r.max_contact_velocity
        ),
    }
    times, results = measure(cases, repeat, 1)
    # CPU time of the one-thread cases (the machine is shared: a pass that waited for a core
    # does not count the wait), best of the rounds
    cpu, _ = measure({k: cases[k] for k in ("single", "batch")}, repeat, 0, time.process_time)
    load_after = os.getloadavg()
    worst = 0.0
    agree = True
    for case, reference in (
        ("batch", "single"),
        ("batch_threads", "single"),
        ("batch_velocity", "velocity"),
    ):
        want = results[reference][0]
        finite = np.isfinite(want)
        for got in results[case]:
            agree &= bool(np.array_equal(np.isfinite(got), finite))
            worst = max(worst, float(np.max(np.abs(got[finite] - want[finite]), initial=0.0)))
    per_posture = {case: float(np.median(t)) / n for case, t in times.items()}
    return {
        "scenario": name,
        "n": n,
        "repeat": repeat,
        "threads": threads,
        "loadavg_before": load_before,
        "loadavg_after": load_after,
        "us_per_posture": per_posture,
        "ratio_single_over_batch": per_posture["single"] / per_posture["batch"],
        "ratio_single_over_batch_threads": per_posture["single"] / per_posture["batch_threads"],
        "ratio_velocity_over_batch_velocity": per_posture["velocity"]
        / per_posture["batch_velocity"],
        "cpu_us_per_posture": {k: min(t) / n for k, t in cpu.items()},
        "cpu_ratio_single_over_batch": min(cpu["single"]) / min(cpu["batch"]),
        "worst_difference": worst,
        "agree": agree and worst <= 1e-12,
    }


def _text(rows: list[dict[str, Any]]) -> str:
    out = [
        f"{'scenario':20s} {'single':>9s} {'batch':>9s} {'threads':>9s} {'ratio':>6s} "
        f"{'ratio T':>7s} {'velocity':>9s} {'batch v':>9s} {'ratio v':>7s} {'CPU ratio':>9s}  "
        "worst diff  "
        "load avg (before, after)"
    ]
    for r in rows:
        t = r["us_per_posture"]
        out.append(
            f"{r['scenario']:20s} {t['single']:9.1f} {t['batch']:9.1f} {t['batch_threads']:9.1f} "
            f"{r['ratio_single_over_batch']:6.2f} {r['ratio_single_over_batch_threads']:7.2f} "
            f"{t['velocity']:9.1f} {t['batch_velocity']:9.1f} "
            f"{r['ratio_velocity_over_batch_velocity']:7.2f} "
            f"{r['cpu_ratio_single_over_batch']:9.2f}  "
            f"{r['worst_difference']:.1e}     {r['loadavg_before'][0]:.2f}, "
            f"{r['loadavg_after'][0]:.2f}"
        )
    out.append(f"us per posture (median over rounds); target ratio >= {TARGET_RATIO:g} at N = 1000")
    return "\n".join(out)


def _profile(names: list[str], n: int, repeat: int, as_json: bool) -> int:
    from benchmarks.speed.batch_profile import profile_batch

    load_before = os.getloadavg()
    table = {}
    for name in names:
        progress(f"{name} (profile) ...")
        table[name] = profile_batch(name, n, repeat)
    load = {"loadavg_before": load_before, "loadavg_after": os.getloadavg()}
    if as_json:
        print(json.dumps({"us_per_row": table, **load}))
        return 0
    stages = list(next(iter(table.values())))
    print(f"{'us per row':45s} " + " ".join(f"{k[:18]:>18s}" for k in table))
    for stage in stages:
        print(f"{stage:45s} " + " ".join(f"{table[k][stage]:18.2f}" for k in table))
    print(f"load average before {load_before[0]:.2f}, after {load['loadavg_after'][0]:.2f}")
    return 0


def gil_scenario(name: str, n: int, repeat: int, threads: int) -> dict[str, Any]:
    """One scenario's batch on 1 and ``threads`` threads: where the threads' time goes."""
    import threading

    import impact_balance.governor.batch as batch_module

    spent: dict[int, list[float]] = {}  # thread id -> [compiled wall, compiled thread CPU] (s)
    lock = threading.Lock()
    originals = batch_module.postures_kernel, batch_module.tree_postures

    def timed(f: Any) -> Any:
        def call(*args: Any) -> Any:
            wall, cpu = time.perf_counter(), time.thread_time()
            out = f(*args)
            wall, cpu = time.perf_counter() - wall, time.thread_time() - cpu
            with lock:
                row = spent.setdefault(threading.get_ident(), [0.0, 0.0])
                row[0] += wall
                row[1] += cpu
            return out

        return call

    governor = Governor(name)
    qs, vs = trajectory(governor, n)
    out: dict[str, Any] = {"scenario": name, "n": n, "loadavg_before": os.getloadavg()}
    batch_module.postures_kernel, batch_module.tree_postures = (timed(f) for f in originals)
    try:
        for t in (1, threads):
            governor.limits(qs, vs, threads=t)  # warm-up: the threads' evaluators
            best: tuple[float, dict[int, list[float]]] | None = None
            for _ in range(repeat):
                spent.clear()
                start = time.perf_counter()
                governor.limits(qs, vs, threads=t)
                wall = time.perf_counter() - start
                if best is None or wall < best[0]:
                    best = (wall, {k: list(v) for k, v in spent.items()})
            assert best is not None
            wall, per_thread = best
            compiled_wall = sum(v[0] for v in per_thread.values())
            cpus = [v[1] for v in per_thread.values()]
            out[f"threads_{t}"] = {
                "us_per_row": wall / n * 1e6,
                "compiled_cpu_us_per_row": sum(cpus) / n * 1e6,
                "outside_compiled_us_per_row": (wall * t - compiled_wall) / n * 1e6,
                "imbalance": max(cpus) / (sum(cpus) / len(cpus)),
                "compiled_wall_over_cpu": compiled_wall / sum(cpus),
            }
    finally:
        batch_module.postures_kernel, batch_module.tree_postures = originals
    out["speedup"] = out["threads_1"]["us_per_row"] / out[f"threads_{threads}"]["us_per_row"]
    out["loadavg_after"] = os.getloadavg()
    return out


def _gil(names: list[str], n: int, repeat: int, threads: int, as_json: bool) -> int:
    rows = []
    for name in names:
        progress(f"{name} (gil) ...")
        rows.append(gil_scenario(name, n, repeat, threads))
    if as_json:
        print(json.dumps({"scenarios": rows, "threads": threads}))
        return 0
    print(
        f"{'scenario':20s} {'T':>2s} {'us/row':>7s} {'compiled CPU':>12s} {'outside':>8s} "
        f"{'imbalance':>9s} {'wall/CPU':>8s} {'speedup':>7s}  load avg (before, after)"
    )
    for r in rows:
        for t in (1, threads):
            c = r[f"threads_{t}"]
            print(
                f"{r['scenario']:20s} {t:2d} {c['us_per_row']:7.1f} "
                f"{c['compiled_cpu_us_per_row']:12.1f} {c['outside_compiled_us_per_row']:8.1f} "
                f"{c['imbalance']:9.2f} {c['compiled_wall_over_cpu']:8.2f} "
                + (f"{r['speedup']:7.2f}" if t != 1 else " " * 7)
                + f"  {r['loadavg_before'][0]:.2f}, {r['loadavg_after'][0]:.2f}"
            )
    print("us per row of the batch (best wall time of the passes); outside: the threads' wall")
    print("time outside the compiled calls (Python holding the GIL, or waiting for it or a core)")
    return 0


def _makespan(durations: list[float], threads: int) -> float:
    """The wall time of ``durations`` handed out in order, each to the first free of ``threads``."""
    free = [0.0] * threads
    for d in durations:
        free[free.index(min(free))] += d
    return max(free)


def chunk_scenario(
    name: str, n: int, repeat: int, threads: int, sizes: list[int]
) -> dict[str, Any]:
    """One scenario's batch per chunk size: one thread's CPU and ``threads`` threads' wall.

    Also the wall time ``threads`` free cores would take (``predicted``): the one-thread pass's
    chunks (their thread CPU times, from one ``take`` to the next) handed out in order to the
    first free core, as the batch hands them out: the balance, whatever the machine's load.
    """
    import impact_balance.governor.batch as batch_module

    governor = Governor(name)
    qs, vs = trajectory(governor, n)
    original = batch_module.CHUNK, batch_module.MIN_CHUNK, batch_module._Chunks.take
    take = original[2]
    marks: list[float] = []

    def timed_take(self: Any) -> int | None:
        marks.append(time.thread_time())
        return take(self)

    cpu = {k: float("inf") for k in sizes}
    wall = {k: float("inf") for k in sizes}
    predicted = {k: float("inf") for k in sizes}
    load_before = os.getloadavg()
    try:
        governor.limits(qs, vs, threads=threads)  # warm-up: the threads' evaluators
        for _ in range(repeat):
            for k in sizes:
                batch_module.CHUNK = batch_module.MIN_CHUNK = k
                batch_module._Chunks.take = timed_take  # type: ignore[method-assign]
                marks.clear()
                start = time.process_time()
                governor.limits(qs, vs)
                cpu[k] = min(cpu[k], time.process_time() - start)
                batch_module._Chunks.take = take  # type: ignore[method-assign]
                durations = [b - a for a, b in itertools.pairwise(marks)]
                predicted[k] = min(predicted[k], _makespan(durations, threads))
                start = time.perf_counter()
                governor.limits(qs, vs, threads=threads)
                wall[k] = min(wall[k], time.perf_counter() - start)
    finally:
        batch_module.CHUNK, batch_module.MIN_CHUNK, batch_module._Chunks.take = original  # type: ignore[method-assign]
    return {
        "scenario": name,
        "n": n,
        "threads": threads,
        "loadavg_before": load_before,
        "loadavg_after": os.getloadavg(),
        "chunks": [
            {
                "chunk": k,
                "cpu_us_per_row_one_thread": cpu[k] / n * 1e6,
                "wall_us_per_row_threads": wall[k] / n * 1e6,
                "predicted_us_per_row_threads": predicted[k] / n * 1e6,
            }
            for k in sizes
        ],
    }


def _chunks(
    names: list[str], n: int, repeat: int, threads: int, sizes: list[int], as_json: bool
) -> int:
    rows = []
    for name in names:
        progress(f"{name} (chunks) ...")
        rows.append(chunk_scenario(name, n, repeat, threads, sizes))
    if as_json:
        print(json.dumps({"scenarios": rows, "threads": threads}))
        return 0
    print(
        f"{'scenario':20s} {'chunk':>6s} {'CPU 1 thread':>12s} "
        f"{f'wall {threads} threads':>15s} {'predicted':>9s}  load avg (before, after)"
    )
    for r in rows:
        for c in r["chunks"]:
            print(
                f"{r['scenario']:20s} {c['chunk']:6d} {c['cpu_us_per_row_one_thread']:12.2f} "
                f"{c['wall_us_per_row_threads']:15.2f} {c['predicted_us_per_row_threads']:9.2f}  "
                f"{r['loadavg_before'][0]:.2f}, {r['loadavg_after'][0]:.2f}"
            )
    print("us per row of the batch (best of the passes); predicted: the one-thread pass's chunks")
    print(f"(their CPU times) handed out in order to {threads} free cores")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    parser.add_argument("--n", type=int, default=1000, help="postures per batch (default 1000)")
    parser.add_argument("--repeat", type=int, default=5, help="rounds (default 5)")
    parser.add_argument("--threads", type=int, default=2, help="threads of batch_threads")
    parser.add_argument("--scenarios", nargs="+", default=list(SCENARIOS))
    parser.add_argument("--json", action="store_true", help="one JSON document on stdout")
    parser.add_argument("--profile", action="store_true", help="where a batch row's time goes")
    parser.add_argument(
        "--gil", action="store_true", help="1 and T threads: compiled time, the GIL's, imbalance"
    )
    parser.add_argument(
        "--chunks", type=int, nargs="+", metavar="K", help="per chunk size: cold starts, balance"
    )
    args = parser.parse_args(argv)
    if args.n < 1 or args.repeat < 1 or not 1 <= args.threads <= 64:
        print("error: --n and --repeat must be >= 1, --threads in [1, 64]", file=sys.stderr)
        return 2
    if args.chunks is not None and min(args.chunks) < 1:
        print(f"error: --chunks must be >= 1, got {min(args.chunks)}", file=sys.stderr)
        return 2
    if args.chunks:
        return _chunks(args.scenarios, args.n, args.repeat, args.threads, args.chunks, args.json)
    if args.profile:
        return _profile(args.scenarios, args.n, args.repeat, args.json)
    if args.gil:
        return _gil(args.scenarios, args.n, args.repeat, args.threads, args.json)
    rows = []
    for name in args.scenarios:
        progress(f"{name} ...")
        rows.append(bench_scenario(name, args.n, args.repeat, args.threads))
    if args.json:
        print(json.dumps({"scenarios": rows, "target_ratio": TARGET_RATIO}))
    else:
        print(_text(rows))
    return 0 if all(r["agree"] for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
