"""The machine and the versions a run was measured with."""

from __future__ import annotations

import importlib.metadata
import os
import platform
import sys
from typing import Any

__all__ = ["load_average", "machine_info"]


def load_average() -> list[float]:
    """The 1, 5 and 15 minute load averages (``/proc/loadavg``): the machine is shared."""
    return [round(x, 2) for x in os.getloadavg()]


def machine_info() -> dict[str, Any]:
    cpu = platform.processor() or "unknown"
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass

    def version(dist: str) -> str | None:
        try:
            return importlib.metadata.version(dist)
        except importlib.metadata.PackageNotFoundError:
            return None

    info = {
        "platform": platform.platform(),
        "cpu": cpu,
        "cpu_count": os.cpu_count(),
        "affinity": len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else None,
        "python": sys.version.split()[0],
        "load_average_before": load_average(),
        "versions": {
            d: version(d)
            for d in (
                "impact-balance",
                "numpy",
                "scipy",
                "numba",
                "highspy",
                "pin",
                "pypoman",
                "cvxopt",
            )
        },
    }
    try:  # pypoman is a test extra of the project
        from pypoman.lp import GLPK_IF_AVAILABLE
    except ImportError:  # pragma: no cover
        return info
    info["pypoman_lp_solver"] = GLPK_IF_AVAILABLE or "cvxopt"
    return info
