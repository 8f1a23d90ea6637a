"""What a user waits for: command start-up, the scenario cache, and the kernel's first compile.

```bash
python benchmarks/startup.py            # ~2 min on the 2-core machine (mostly one kernel compile)
python benchmarks/startup.py --runs 20  # more runs per command (default 10)
python benchmarks/startup.py --no-compile   # skip the from-scratch kernel compile
python benchmarks/startup.py --json
```

Measured, with the load average (``/proc/loadavg``) printed before and after:

1. **Wall time of commands** (a new process each, the projection kernel cached):
   ``impact-balance robots``, ``scenarios``, ``analyze NAME --json``, run round-robin so that a
   load change hits every command alike; median and minimum.
2. **The scenario cache**: ``ib.analyze(NAME)`` against ``analyze(scenario)`` of the loaded
   scenario, interleaved in one process, median of many calls; the difference is what loading a
   cached scenario costs (README: within 0.2 ms).
3. **The kernel's first compile** (what the first run after an installation pays): a fresh
   process with an empty numba cache (``NUMBA_CACHE_DIR`` set to a new folder), then a second
   process that loads the kernel from that cache.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
COMMANDS = {
    "robots": ["robots"],
    "scenarios": ["scenarios"],
    "analyze --json": ["analyze", "palm_push_ramp", "--json"],
}


def load_average() -> list[float]:
    """The 1, 5 and 15 minute load averages (``/proc/loadavg``)."""
    return [round(x, 2) for x in os.getloadavg()]


def _env(**extra: str) -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT / "src") + (
        os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else ""
    )
    env.update(extra)
    return env


def _wall(argv: list[str], env: dict[str, str]) -> float:
    t = time.perf_counter()
    proc = subprocess.run(argv, capture_output=True, text=True, env=env)
    elapsed = time.perf_counter() - t
    if proc.returncode != 0:
        raise SystemExit(f"{' '.join(argv)} failed: {proc.stderr.strip()[-300:]}")
    return elapsed


def command_times(runs: int) -> dict[str, dict[str, float]]:
    env = _env()
    argv = {
        name: [sys.executable, "-m", "impact_balance", *args] for name, args in COMMANDS.items()
    }
    for a in argv.values():  # warm: the kernel cached, the files in the page cache
        _wall(a, env)
    times: dict[str, list[float]] = {name: [] for name in argv}
    for _ in range(runs):
        for name, a in argv.items():
            times[name].append(_wall(a, env))
    return {
        name: {"median_s": statistics.median(t), "min_s": min(t), "max_s": max(t)}
        for name, t in times.items()
    }


_CACHE_SCRIPT = """
import json, statistics, sys, time
import impact_balance as ib
name, n = sys.argv[1], int(sys.argv[2])
loaded = ib.load_scenario(name)
ib.analyze(loaded); ib.analyze(name)
by_name, by_object = [], []
for _ in range(n):  # interleaved: a load change hits both alike
    t = time.perf_counter(); ib.analyze(name); by_name.append(time.perf_counter() - t)
    t = time.perf_counter(); ib.analyze(loaded); by_object.append(time.perf_counter() - t)
t = time.perf_counter()
for _ in range(n):
    ib.load_scenario(name)
load = (time.perf_counter() - t) / n
print(json.dumps({"analyze_name_ms": 1e3 * statistics.median(by_name),
                  "analyze_loaded_ms": 1e3 * statistics.median(by_object),
                  "load_scenario_cached_ms": 1e3 * load}))
"""


def scenario_cache(name: str = "palm_push_ramp", n: int = 2000) -> dict[str, float]:
    proc = subprocess.run(
        [sys.executable, "-c", _CACHE_SCRIPT, name, str(n)],
        capture_output=True,
        text=True,
        env=_env(),
        check=True,
    )
    out = json.loads(proc.stdout)
    out["difference_ms"] = out["analyze_name_ms"] - out["analyze_loaded_ms"]
    return out


_KERNEL_SCRIPT = "from impact_balance.projection.walk import warm_up; print(warm_up())"


def kernel_compile() -> dict[str, float]:
    with tempfile.TemporaryDirectory() as cache:
        env = _env(NUMBA_CACHE_DIR=cache)
        first = subprocess.run(
            [sys.executable, "-c", _KERNEL_SCRIPT],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        second = subprocess.run(
            [sys.executable, "-c", _KERNEL_SCRIPT],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
    return {
        "compile_s": float(first.stdout.split()[-1]),
        "cached_load_s": float(second.stdout.split()[-1]),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=10, help="runs per command (default 10)")
    ap.add_argument(
        "--no-compile", action="store_true", help="skip the from-scratch kernel compile"
    )
    ap.add_argument("--json", action="store_true", help="one JSON object on stdout")
    args = ap.parse_args(argv)
    result: dict = {
        "load_average_before": load_average(),
        "cpu_count": os.cpu_count(),
        "python": sys.version.split()[0],
    }
    result["commands"] = command_times(args.runs)
    result["scenario_cache"] = scenario_cache()
    if not args.no_compile:
        result["kernel"] = kernel_compile()
    result["load_average_after"] = load_average()
    if args.json:
        print(json.dumps(result, indent=1))
        return 0
    print(
        f"load average before: {' '.join(map(str, result['load_average_before']))} "
        f"({result['cpu_count']} cores, Python {result['python']})"
    )
    print(f"\ncommand wall time, a new process each ({args.runs} runs, round-robin):")
    for name, t in result["commands"].items():
        print(
            f"  impact-balance {name:<16} median {t['median_s']:.3f} s   min {t['min_s']:.3f} s   "
            f"max {t['max_s']:.3f} s"
        )
    c = result["scenario_cache"]
    print(
        f"\nib.analyze('palm_push_ramp') {c['analyze_name_ms']:.3f} ms, analyze(loaded scenario) "
        f"{c['analyze_loaded_ms']:.3f} ms: difference {c['difference_ms']:.3f} ms "
        f"(load_scenario from the cache {c['load_scenario_cached_ms']:.3f} ms)"
    )
    if "kernel" in result:
        k = result["kernel"]
        print(
            f"\nprojection kernel: first compile {k['compile_s']:.1f} s, load from numba's cache "
            f"{k['cached_load_s']:.2f} s"
        )
    print(f"\nload average after: {' '.join(map(str, result['load_average_after']))}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
