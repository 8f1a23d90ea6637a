"""Numerical backends: linear programs (HiGHS) and quadratic programs (qpsolvers)."""

from impact_balance.solvers.highs import HighsLP
from impact_balance.solvers.lp import LinearProgram, LPSolution

__all__ = ["HighsLP", "LPSolution", "LinearProgram"]
