"""Linear-program data types shared by the LP backends."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["LPSolution", "LinearProgram"]


@dataclass(frozen=True)
class LinearProgram:
    """``max c^T x  s.t.  A x <= b,  C x = d,  lo <= R x <= hi`` (x free).

    The objective is given per solve; the constraints are fixed, so a backend can keep one
    model and warm-start it across objectives (what ray shooting needs).
    """

    A: np.ndarray
    b: np.ndarray
    C: np.ndarray
    d: np.ndarray
    R: np.ndarray | None = None
    lo: np.ndarray | None = None
    hi: np.ndarray | None = None


@dataclass(frozen=True)
class LPSolution:
    """Result of one solve.

    Attributes:
        status: "optimal", "infeasible" or "unbounded".
        x: Primal solution when optimal, else None.
        objective: Optimal value when optimal, else nan.
    """

    status: str
    x: np.ndarray | None
    objective: float

    @property
    def optimal(self) -> bool:
        """Whether the status is "optimal"."""
        return self.status == "optimal"
