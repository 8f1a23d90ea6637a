"""Numerical backends: linear programs (HiGHS) and quadratic programs (qpsolvers)."""

from .highs import HighsLP
from .lp import LinearProgram, LPSolution

__all__ = ["HighsLP", "LinearProgram", "LPSolution"]
