"""numba's ``njit`` when numba is installed, else a no-op decorator (same code, run by Python).

numba is a dependency; the fallback keeps the library importable where its wheel is missing.
``IMPACT_BALANCE_JIT=0`` in the environment (read once, when this module is first imported)
runs the same code interpreted without importing numba: loading numba and its cached kernels
costs more than one interpreted analysis, so the one-shot ``impact-balance analyze`` command
runs that way unless the variable says otherwise.
"""

from __future__ import annotations

import hashlib
import os
import pickle
from types import ModuleType
from typing import Any

__all__ = ["HAVE_NUMBA", "JIT_VARIABLE", "cache_depends_on", "njit"]

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
