"""The kernels' compile and load time is reported apart from the analysis (issue 29, item 7)."""

from __future__ import annotations

import time

import pytest

import impact_balance as ib
import impact_balance.analysis.analyze as analyze_module
from impact_balance._jit import HAVE_NUMBA, KernelClock
from impact_balance.analysis.report import format_timings

needs_numba = pytest.mark.skipif(not HAVE_NUMBA, reason="numba is off (IMPACT_BALANCE_JIT=0)")


def _fresh_kernel():
    """A compiled function no cache holds: its first call compiles."""
    from numba import njit

    @njit(cache=False)
    def twice(x):
        return 2.0 * x

    return twice


@needs_numba
def test_the_clock_stops_while_numba_compiles():
    kernel = _fresh_kernel()
    clock = KernelClock()
    with clock.running():
        wall0, t0 = time.perf_counter(), clock.now()
        assert kernel(1.5) == 3.0
        wall, elapsed = time.perf_counter() - wall0, clock.now() - t0
    assert clock.compiling > 0.0
    assert clock.loading >= clock.compiling
    # the two clocks are read one call apart: a loaded machine puts microseconds between them
    assert elapsed == pytest.approx(wall - clock.loading, abs=1e-4)
    assert elapsed < wall
    # Once compiled, calling it costs numba nothing more.
    again = KernelClock()
    with again.running():
        kernel(2.0)
    assert again.loading == 0.0 and again.compiling == 0.0


def test_the_clock_outside_running_is_perf_counter():
    clock = KernelClock()
    a = time.perf_counter()
    b = clock.now()
    assert clock.loading == 0.0 and 0.0 <= b - a < 1.0


@needs_numba
def test_analysis_time_leaves_the_compile_out(monkeypatch):
    ib.analyze("palm_push_two_feet")  # everything loaded already
    kernel = _fresh_kernel()
    monkeypatch.setattr(analyze_module, "warm_up", lambda: kernel(1.0))
    wall0 = time.perf_counter()
    analysis = ib.analyze("palm_push_two_feet")
    wall = time.perf_counter() - wall0
    t = analysis.timings
    assert t["kernel_compiling"] > 0.0 and t["kernel_loading"] >= t["kernel_compiling"]
    assert t["total"] + t["kernel_loading"] <= wall
    steps = sum(t[k] for k in ("stance", "constraints", "areas", "impact"))
    assert t["total"] >= steps
    text = format_timings(t)
    assert f"(+ {t['kernel_compiling']:.1f} s compiling the kernels once)" in text
    assert text.startswith(f"analysis {1e3 * t['total']:.1f} ms (+ ")


def test_the_message_says_compile_and_load_apart():
    text = format_timings(
        {"total": 0.0031, "kernel_loading": 14.5, "kernel_compiling": 14.2, "robot_loading": 0.2}
    )
    assert text.startswith("analysis 3.1 ms (+ 14.2 s compiling the kernels once); not included:")
    assert "compiled kernel loading 300 ms (first call)" in text
    assert "robot model loading 200 ms (first use)" in text
    assert format_timings({"total": 0.0031}) == "analysis 3.1 ms"
    # A loaded kernel's dispatch (microseconds) is not worth a word.
    assert format_timings({"total": 0.0031, "kernel_loading": 1e-6}) == "analysis 3.1 ms"


@needs_numba
def test_every_running_clock_counts_a_compile_and_a_finished_one_does_not():
    finished, outer, inner = KernelClock(), KernelClock(), KernelClock()
    with finished.running():
        pass
    with outer.running():
        wall0 = time.perf_counter()
        with inner.running():
            assert _fresh_kernel()(2.0) == 4.0
        wall = time.perf_counter() - wall0
    assert finished.loading == 0.0 and finished.compiling == 0.0
    assert inner.compiling > 0.0
    # the same compile, seen by both running clocks (the outer one started before it)
    assert outer.compiling == pytest.approx(inner.compiling, rel=1e-9)
    assert outer.loading == pytest.approx(inner.loading, rel=1e-9)
    assert outer.loading <= wall
    after = KernelClock()  # a clock started after the compile never sees it
    with after.running():
        _fresh_kernel()  # made, not called: nothing compiles
    assert after.loading == 0.0
