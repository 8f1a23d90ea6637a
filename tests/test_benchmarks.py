"""The interleaved side-by-side driver of the benchmarks (``--baseline``), with a stand-in for
both sides: fake ``impact_balance`` trees whose one call waits a known time."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from benchmarks.speed.interleave import (
    BaselineError,
    WorkerError,
    compare,
    median_interval,
    resolve_tree,
    run_interleaved,
)

JOB = "tests.helpers.bench_standin:sleep_job"


def fake_tree(root: Path, delay: float, fail: bool = False, layout: str = "checkout") -> Path:
    package = (root / "src" if layout == "checkout" else root) / "impact_balance"
    package.mkdir(parents=True)
    (package / "__init__.py").write_text(f"DELAY = {delay!r}\nFAIL = {fail!r}\n")
    return root


def test_a_side_twice_as_slow_gives_a_ratio_of_two(tmp_path: Path) -> None:
    slow = resolve_tree(fake_tree(tmp_path / "slow", 0.002))
    fast = resolve_tree(fake_tree(tmp_path / "fast", 0.001, layout="installed"))
    run = run_interleaved(JOB, {"calls": 10}, {"current": slow, "baseline": fast}, blocks=6)
    assert run.info["current"]["info"]["delay"] == 0.002  # each side imported its own tree
    assert run.info["baseline"]["info"]["delay"] == 0.001
    assert run.info["current"]["impact_balance"].startswith(str(slow))
    assert [b["k"] for b in run.blocks["baseline"]] == list(range(6))
    assert run.order[0] == ["current", "baseline"] and run.order[1] == ["baseline", "current"]
    result = compare(run)["sleep"]
    ratio = result["ratio"]["median"]
    assert 1.8 < ratio["median"] < 2.2
    assert ratio["low"] <= ratio["median"] <= ratio["high"]
    assert ratio["blocks"] == 6 and ratio["coverage"] >= 0.95
    assert result["current"]["n"] == result["baseline"]["n"] == 60
    assert result["current"]["median"] >= 2000.0 and result["baseline"]["median"] >= 1000.0


def test_a_failing_side_is_named(tmp_path: Path) -> None:
    good = resolve_tree(fake_tree(tmp_path / "good", 0.0))
    bad = resolve_tree(fake_tree(tmp_path / "bad", 0.0, fail=True))
    with pytest.raises(WorkerError, match=r"baseline worker .*bad.*told to fail"):
        run_interleaved(JOB, {"calls": 1}, {"current": good, "baseline": bad}, blocks=2)


def test_bad_baseline_and_blocks_are_refused(tmp_path: Path) -> None:
    with pytest.raises(BaselineError, match=r"--baseline .*missing: is not a folder"):
        resolve_tree(tmp_path / "missing")
    with pytest.raises(BaselineError, match=r"--baseline .*: holds neither"):
        resolve_tree(tmp_path)
    tree = resolve_tree(fake_tree(tmp_path / "t", 0.0))
    with pytest.raises(BaselineError, match=r"--blocks 0: must be"):
        run_interleaved(JOB, {"calls": 1}, {"current": tree, "baseline": tree}, blocks=0)


@given(st.lists(st.floats(0.01, 100.0), min_size=1, max_size=40))
def test_median_interval_holds_the_median(values: list[float]) -> None:
    low, high, coverage = median_interval(values)
    values.sort()
    n = len(values)
    median = (values[(n - 1) // 2] + values[n // 2]) / 2
    assert low <= median <= high
    assert low in values and high in values
    expected = 1 - 2 ** (1 - n) if n < 6 else 0.95
    assert coverage >= expected - 1e-12
    if n >= 6:  # the narrowest such interval: one order statistic further in falls short
        k = values.index(low) + 1 if values.count(low) == 1 else None
        if k is not None and k + 1 <= n - k:
            below = sum(math.comb(n, j) for j in range(k + 1)) / 2**n
            assert 1 - 2 * below < 0.95


def test_the_batch_benchmark_reports_ratios_and_agreement(capsys) -> None:
    import json

    from benchmarks import batch

    assert batch.main(["--n", "4", "--repeat", "1", "--scenarios", "kick_one_foot", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    (row,) = out["scenarios"]
    assert row["agree"] and row["worst_difference"] <= 1e-12
    times = row["us_per_posture"]
    assert set(times) == {"single", "batch", "batch_threads", "velocity", "batch_velocity"}
    assert row["ratio_single_over_batch"] == pytest.approx(times["single"] / times["batch"])
    assert batch.main(["--n", "0"]) == 2


def test_the_batch_benchmark_times_chunk_sizes(capsys) -> None:
    import json

    from benchmarks import batch
    from impact_balance.governor import batch as batch_module

    chunk = batch_module.CHUNK
    argv = ["--n", "6", "--repeat", "1", "--scenarios", "kick_one_foot", "--chunks", "2", "5"]
    assert batch.main([*argv, "--json"]) == 0
    (row,) = json.loads(capsys.readouterr().out)["scenarios"]
    assert [c["chunk"] for c in row["chunks"]] == [2, 5]
    for c in row["chunks"]:
        assert c["cpu_us_per_row_one_thread"] > 0
        # two free cores take at least half the one thread's chunks' time, at most all of it
        assert 0 < c["predicted_us_per_row_threads"] <= c["cpu_us_per_row_one_thread"]
    assert batch._makespan([3.0, 1.0, 1.0, 2.0], 2) == 4.0  # 3 | 1 1, then 2 on the second
    assert batch_module.CHUNK == chunk  # put back
    assert batch.main(["--chunks", "0"]) == 2


@pytest.mark.slow
def test_the_approach_benchmark_pools_the_ticks_of_every_trial(capsys) -> None:
    """Every tick the command counted is timed, replayed once, and pooled over the trials."""
    import json

    import numpy as np

    pytest.importorskip("mujoco")
    from benchmarks import approach

    assert approach.main(["--trials", "2", "--wall-distances", "0.1", "0.2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)["approach"]
    side = out["sides"]["current"]
    trials = side["trials"]
    assert [t["wall_distance"] for t in trials] == [0.1, 0.2]
    assert all(t["ticks"] == t["command_ticks"] > 0 for t in trials)
    assert (
        side["tick_us"]["count"]
        == side["replayed_tick_us"]["count"]
        == sum(t["ticks"] for t in trials)
    )
    assert 0 < side["tick_us"]["median"] <= side["tick_us"]["p99"]
    assert "pooled_ratio" not in out  # no baseline, no ratio
    assert approach.main(["--trials", "0"]) == 2
    assert approach.pooled([[1.0, 2.0], [3.0]])["median"] == np.median([1.0, 2.0, 3.0])


def test_the_analyze_steps_profile_times_every_step_and_restores_the_pipeline(capsys) -> None:
    """Every wrapped step runs in an analysis the compiled posture answers; the steps' sum and
    the glue add up to the instrumented total; after the timers the pipeline is unchanged."""
    import importlib
    import json
    from collections import Counter

    import impact_balance as ib
    from benchmarks import analyze_steps

    def originals() -> list[object]:
        out = []
        for _, _, module, path in analyze_steps.STEPS:
            owner = importlib.import_module(module)
            for part in path.split("."):
                owner = getattr(owner, part)
            out.append(owner)
        return out

    before = originals()
    totals: Counter[str] = Counter()
    with analyze_steps.timed_steps(totals):
        ib.analyze("kick_one_foot")
    assert {label for _, label, _, _ in analyze_steps.STEPS} == {k for k, v in totals.items() if v}
    assert originals() == before
    assert analyze_steps.main(["--ticks", "3", "--passes", "2", "--scenarios", "kick_one_foot",
                               "--json"]) == 0  # fmt: skip
    (row,) = json.loads(capsys.readouterr().out)["scenarios"]
    steps = row["step_us"]
    top = sum(steps[label] for depth, label, _, _ in analyze_steps.STEPS if depth == 0)
    assert row["steps_us"] == pytest.approx(top)
    added = row["timer_us"]["added"] * len(analyze_steps.STEPS)
    assert row["steps_us"] + row["glue_us"] + added == pytest.approx(row["instrumented_us"])
    assert steps["compiled call"] > 0 and row["analyze_us"] > 0
    assert analyze_steps.main(["--ticks", "0"]) == 2
