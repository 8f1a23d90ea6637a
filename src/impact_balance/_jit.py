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
import time
from collections.abc import Iterator
from contextlib import ExitStack, contextmanager
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

    def now(self) -> float:
        """``time.perf_counter()`` (s) without the kernel time counted so far."""
        return time.perf_counter() - self.loading

    @contextmanager
    def running(self) -> Iterator[KernelClock]:
        """Count numba's loading and compiling while the block runs; yields this clock."""
        if not HAVE_NUMBA:
            yield self
            return
        from numba.core import event

        timer = _timer_class()
        with ExitStack() as stack:
            stack.enter_context(
                event.install_listener("numba:compiler_lock", timer(self, "loading"))
            )
            stack.enter_context(event.install_listener("numba:compile", timer(self, "compiling")))
            yield self


@functools.cache
def _timer_class() -> type:
    """The numba event listener that adds a block's time to a :class:`KernelClock` field.

    Made once (numba is imported on first use, not with this module).
    """
    from numba.core import event

    class _Timer(event.Listener):
        def __init__(self, clock: KernelClock, field: str) -> None:
            self.clock, self.field, self.depth, self.start = clock, field, 0, 0.0

        def on_start(self, ev: Any) -> None:
            if self.depth == 0:
                self.start = time.perf_counter()
            self.depth += 1

        def on_end(self, ev: Any) -> None:
            self.depth -= 1
            if self.depth == 0:
                elapsed = time.perf_counter() - self.start
                setattr(self.clock, self.field, getattr(self.clock, self.field) + elapsed)

    return _Timer
