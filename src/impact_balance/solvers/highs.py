"""HiGHS backend (through highspy): one model, re-solved for each new objective."""

from __future__ import annotations

import highspy
import numpy as np

from impact_balance.exceptions import SolverError
from impact_balance.solvers.lp import LinearProgram, LPSolution

__all__ = ["HighsLP"]

_INF = highspy.kHighsInf
#: The statuses that answer the LP; any other is retried from scratch once.
_DECIDED = (
    highspy.HighsModelStatus.kOptimal,
    highspy.HighsModelStatus.kInfeasible,
    highspy.HighsModelStatus.kUnbounded,
    highspy.HighsModelStatus.kUnboundedOrInfeasible,
)

try:
    # highspy.Highs() enables its Python callbacks in its constructor, and that first call into
    # HiGHS prints the "Running HiGHS ..." banner on stdout before any option can be set,
    # which would break `analyze --json` (stdout must be one JSON document). The core object
    # it wraps has every method used here, and prints nothing until asked to solve; the
    # output flag is switched off before that.
    from highspy._core import _Highs as _Solver
except ImportError:  # pragma: no cover - a highspy without the private core name
    _Solver = highspy.Highs  # type: ignore[misc]


class HighsLP:
    """Persistent HiGHS model of a :class:`LinearProgram`; :meth:`maximize` re-solves it.

    Only the objective changes between solves, so HiGHS restarts from the previous optimal
    basis (a warm start), which is what makes ray shooting cheap.

    Args:
        problem: The constraints.
        tolerance: Primal and dual feasibility tolerance.
        warm: Tune HiGHS for many re-solves from a warm basis (no presolve, primal simplex,
            as ray shooting wants); False keeps HiGHS's defaults, sturdier for a one-off LP
            (the tuned settings can end a zero-objective feasibility LP with status Unknown).
    """

    def __init__(self, problem: LinearProgram, tolerance: float = 1e-9, warm: bool = True):
        A, C = np.atleast_2d(problem.A), np.atleast_2d(problem.C)
        n = max(A.shape[1], C.shape[1])
        blocks, lower, upper = [], [], []
        if A.size:
            blocks.append(A)
            lower.append(np.full(A.shape[0], -_INF))
            upper.append(np.asarray(problem.b, dtype=float))
        if C.size:
            blocks.append(C)
            lower.append(np.asarray(problem.d, dtype=float))
            upper.append(np.asarray(problem.d, dtype=float))
        if problem.R is not None:
            blocks.append(np.atleast_2d(problem.R))
            lower.append(np.asarray(problem.lo, dtype=float))
            upper.append(np.asarray(problem.hi, dtype=float))
        # here: scipy.sparse is slow to import, and most analyses never build an LP
        import scipy.sparse as sp

        M = sp.csc_matrix(np.vstack(blocks)) if blocks else sp.csc_matrix((0, n))
        M.eliminate_zeros()
        lp = highspy.HighsLp()
        lp.num_col_ = n
        lp.num_row_ = M.shape[0]
        lp.col_cost_ = np.zeros(n)
        lp.col_lower_ = np.full(n, -_INF)
        lp.col_upper_ = np.full(n, _INF)
        lp.row_lower_ = np.concatenate(lower) if lower else np.zeros(0)
        lp.row_upper_ = np.concatenate(upper) if upper else np.zeros(0)
        lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
        lp.a_matrix_.start_ = M.indptr
        lp.a_matrix_.index_ = M.indices
        lp.a_matrix_.value_ = M.data
        lp.sense_ = highspy.ObjSense.kMaximize
        self._n = n
        self._warm = bool(warm)
        self._h = _Solver()
        h = self._h
        h.setOptionValue("output_flag", False)
        h.setOptionValue("log_to_console", False)
        h.setOptionValue("primal_feasibility_tolerance", tolerance)
        h.setOptionValue("dual_feasibility_tolerance", tolerance)
        h.setOptionValue("random_seed", 0)
        # Small LPs re-solved from a warm basis: presolve and threads only cost time here
        # (measured in benchmarks/: 5.7 -> 3.6 ms on a two-foot stance).
        h.setOptionValue("threads", 1)
        if warm:
            h.setOptionValue("presolve", "off")
            h.setOptionValue("simplex_strategy", 4)  # primal simplex
        status = h.passModel(lp)
        if status == highspy.HighsStatus.kError:
            raise SolverError("HiGHS", "kError", "the LP could not be passed to HiGHS")
        self._cols = np.arange(n, dtype=np.int32)

    @property
    def dim(self) -> int:
        """The number of variables."""
        return int(self._n)

    def maximize(self, c: np.ndarray) -> LPSolution:
        """Solve ``max c^T x`` over the fixed constraints."""
        h = self._h
        h.changeColsCost(self._n, self._cols, np.asarray(c, dtype=float))
        h.run()
        status = h.getModelStatus()
        if status not in _DECIDED:
            status = self._rerun_cold()
        if status == highspy.HighsModelStatus.kOptimal:
            x = np.array(h.getSolution().col_value, dtype=float)
            return LPSolution("optimal", x, float(np.dot(c, x)))
        if status == highspy.HighsModelStatus.kInfeasible:
            return LPSolution("infeasible", None, float("nan"))
        if status in (
            highspy.HighsModelStatus.kUnbounded,
            highspy.HighsModelStatus.kUnboundedOrInfeasible,
        ):
            # Resolve the ambiguity: a zero objective tells feasibility apart.
            if status == highspy.HighsModelStatus.kUnboundedOrInfeasible and not self._feasible():
                return LPSolution("infeasible", None, float("nan"))
            return LPSolution("unbounded", None, float("inf"))
        raise SolverError("HiGHS", h.modelStatusToString(status))

    def _rerun_cold(self) -> highspy.HighsModelStatus:
        """The same LP from scratch with HiGHS's default strategy (presolve on, no basis).

        The warm-started primal simplex can stop undecided ("Unknown") on a badly scaled LP (a ramp
        foot at friction 2.5e4, the unnormalised polytope), where a cold solve answers.
        """
        h = self._h
        h.clearSolver()
        h.setOptionValue("presolve", "on")
        h.setOptionValue("simplex_strategy", 1)  # dual simplex, HiGHS's default
        try:
            h.run()
            return h.getModelStatus()
        finally:
            if self._warm:
                h.setOptionValue("presolve", "off")
                h.setOptionValue("simplex_strategy", 4)

    def _feasible(self) -> bool:
        h = self._h
        h.changeColsCost(self._n, self._cols, np.zeros(self._n))
        h.run()
        return h.getModelStatus() == highspy.HighsModelStatus.kOptimal
