"""numba's ``njit`` when numba is installed, else a no-op decorator (same code, run by Python).

numba is a dependency; the fallback keeps the library importable where its wheel is missing.
``IMPACT_BALANCE_JIT=0`` in the environment (read once, when this module is first imported)
runs the same code interpreted without importing numba: loading numba and its cached kernels
costs 0.4 to 0.8 s per process, more than one interpreted analysis (30 to 400 ms), so the
one-shot ``impact-balance analyze`` command runs that way unless the variable says otherwise.
"""

from __future__ import annotations

import os
from typing import Any

__all__ = ["njit", "HAVE_NUMBA", "JIT_VARIABLE"]

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
