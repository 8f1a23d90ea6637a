"""numba's ``njit`` when numba is installed, else a no-op decorator (same code, run by Python).

numba is a dependency; the fallback keeps the library importable where its wheel is missing.
"""

from __future__ import annotations

from typing import Any, Callable

__all__ = ["njit", "HAVE_NUMBA"]

try:
    from numba import njit

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover - exercised only where numba is missing
    HAVE_NUMBA = False

    def njit(*args: Any, **kwargs: Any) -> Any:  # type: ignore[no-redef]
        if args and callable(args[0]):
            return args[0]
        return lambda f: f
