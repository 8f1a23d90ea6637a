"""numba's ``njit`` when numba is installed, else a no-op decorator (same code, run by Python).

numba is a dependency; the fallback keeps the library importable where its wheel is missing.
``IMPACT_BALANCE_JIT=0`` in the environment (read once, when this module is first imported)
runs the same code interpreted without importing numba: loading numba and its cached kernels
costs more than one interpreted analysis, so the one-shot ``impact-balance analyze`` command
runs that way unless the variable says otherwise.

:class:`KernelClock` times a block of code without the time numba spends loading or compiling
kernels in it, and reports that time apart (what the first analysis of an installation pays).
"""

from __future__ import annotations

import functools
import hashlib
import os
import pickle
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from types import ModuleType
from typing import Any

__all__ = ["HAVE_NUMBA", "JIT_VARIABLE", "KernelClock", "cache_depends_on", "njit"]

#: The environment variable that turns compilation off ("0", "false", "no" or "off").
JIT_VARIABLE = "IMPACT_BALANCE_JIT"

try:
    if os.environ.get(JIT_VARIABLE, "1").strip().lower() in ("0", "false", "no", "off"):
        raise ImportError(f"{JIT_VARIABLE} turns numba off")
    from numba import njit

    HAVE_NUMBA = True
except ImportError:
    HAVE_NUMBA = False

    def njit(*args: Any, **kwargs: Any) -> Any:  # type: ignore[no-redef]
        if args and callable(args[0]):
            return args[0]
        return lambda f: f


def cache_depends_on(dispatcher: Any, *modules: ModuleType) -> Any:
    """Make numba's cache of ``dispatcher`` stale when a source file of ``modules`` changes.

    As it is when its own file does; returns ``dispatcher``.

    numba stamps a cached function with its own file only, but a compiled function keeps a
    copy of the compiled functions it calls: after an edit of a callee in another module, its
    cache would run the old callee. Here its stamp also covers each module's file (modified
    time and size, as numba's). Without numba, or if numba's private cache API moved (then
    numba's own rule applies), nothing changes.
    """
    if not HAVE_NUMBA:
        return dispatcher
    try:
        cache_file = dispatcher._cache._cache_file
        stamps = [cache_file._source_stamp]
        for module in modules:
            if module.__file__ is None:  # a namespace or built-in module: nothing to stamp
                continue
            st = os.stat(module.__file__)
            stamps.append((os.path.basename(module.__file__), st.st_mtime, st.st_size))
        cache_file._source_stamp = hashlib.sha256(pickle.dumps(stamps)).hexdigest()
    except (AttributeError, OSError, TypeError):
        pass
    return dispatcher


class KernelClock:
    """A clock that stops while numba loads or compiles a kernel.

    Inside :meth:`running`, :meth:`now` is ``time.perf_counter()`` (s) less the time spent in
    numba's compiler so far; that time is :attr:`loading` (s: a cached kernel loaded or a
    kernel compiled), of which :attr:`compiling` (s) compiled. Both stay 0 without numba or
    once every kernel a block calls is loaded. numba's compiler events are process-wide: a
    kernel another thread loads meanwhile is counted too.
    """

    def __init__(self) -> None:
        #: Seconds spent in numba's compiler lock (loading from its cache, or compiling).
        self.loading = 0.0
        #: Seconds of :attr:`loading` spent compiling (numba's cache had no kernel).
        self.compiling = 0.0
        self._since = 0.0  # when running() began (perf_counter, s)

    def now(self) -> float:
        """``time.perf_counter()`` (s) without the kernel time counted so far."""
        return time.perf_counter() - self.loading

    @contextmanager
    def running(self) -> Iterator[KernelClock]:
        """Count numba's loading and compiling while the block runs; yields this clock."""
        if not HAVE_NUMBA:
            yield self
            return
        _register_timers()
        self._since = time.perf_counter()
        with _RUNNING_LOCK:
            _RUNNING.append(self)
        try:
            yield self
        finally:
            with _RUNNING_LOCK:
                _RUNNING.remove(self)


#: The clocks inside :meth:`KernelClock.running` (any thread), and their lock.
_RUNNING: list[KernelClock] = []
_RUNNING_LOCK = threading.Lock()


@functools.cache
def _register_timers() -> None:
    """Listen to numba's compiler events once, for every running :class:`KernelClock`.

    numba's events are process-wide and its compiler lock is one lock: one event at a time
    (nested in the same thread). The time of each outermost event (from its start, or from
    the clock's start when it began later) is added to every clock running at its end.
    """
    from numba.core import event

    class _Timer(event.Listener):
        def __init__(self, field: str) -> None:
            self.field, self.depth, self.start = field, 0, 0.0

        def on_start(self, ev: Any) -> None:
            if self.depth == 0:
                self.start = time.perf_counter()
            self.depth += 1

        def on_end(self, ev: Any) -> None:
            self.depth -= 1
            if self.depth == 0:
                end = time.perf_counter()
                with _RUNNING_LOCK:
                    clocks = list(_RUNNING)
                for clock in clocks:
                    elapsed = end - max(self.start, clock._since)
                    setattr(clock, self.field, getattr(clock, self.field) + elapsed)

    event.register("numba:compiler_lock", _Timer("loading"))  # type: ignore[no-untyped-call]
    event.register("numba:compile", _Timer("compiling"))  # type: ignore[no-untyped-call]
