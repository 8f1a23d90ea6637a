"""The HiGHS backend: one model re-solved per objective, against scipy's linprog, and silent.

Independent reference: ``scipy.optimize.linprog`` (its own HiGHS build, called afresh for each
objective, so no warm start is shared with the backend under test).
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from scipy.optimize import linprog

from impact_balance.solvers import HighsLP, LinearProgram


def _reference(c, problem: LinearProgram) -> float:
    """max c^T x over the problem, by scipy (x free)."""
    res = linprog(
        -np.asarray(c),
        A_ub=problem.A if problem.A.size else None,
        b_ub=problem.b if problem.A.size else None,
        A_eq=problem.C if problem.C.size else None,
        b_eq=problem.d if problem.C.size else None,
        bounds=(None, None),
        method="highs",
    )
    assert res.status == 0, res.message
    return -float(res.fun)


def test_warm_resolves_match_linprog_for_many_objectives():
    rng = np.random.default_rng(7)
    # A random bounded polytope: the hull of the unit box cut by random half-spaces through it.
    A = np.vstack([np.eye(3), -np.eye(3), rng.normal(size=(12, 3))])
    b = np.concatenate([np.ones(6), rng.uniform(0.5, 1.5, 12)])
    C, d = np.array([[1.0, 1.0, 1.0]]), np.array([0.2])
    problem = LinearProgram(A, b, C, d)
    lp = HighsLP(problem)
    assert lp.dim == 3
    for c in rng.normal(size=(25, 3)):
        got = lp.maximize(c)
        assert got.optimal and got.x is not None
        assert got.objective == pytest.approx(_reference(c, problem), abs=1e-8)
        assert np.all(A @ got.x <= b + 1e-8) and abs(C[0] @ got.x - d[0]) < 1e-8


def test_infeasible_and_unbounded_are_statuses_not_errors():
    box = LinearProgram(
        np.vstack([np.eye(2), -np.eye(2)]), np.ones(4), np.zeros((0, 2)), np.zeros(0)
    )
    empty = LinearProgram(box.A, box.b, np.array([[1.0, 0.0]]), np.array([5.0]))  # x = 5, |x| <= 1
    answer = HighsLP(empty, warm=False).maximize(np.array([1.0, 0.0]))
    assert answer.status == "infeasible" and answer.x is None and np.isnan(answer.objective)
    half_plane = LinearProgram(
        np.array([[1.0, 0.0]]), np.array([1.0]), np.zeros((0, 2)), np.zeros(0)
    )
    answer = HighsLP(half_plane).maximize(np.array([0.0, 1.0]))
    assert answer.status == "unbounded" and answer.x is None and answer.objective == np.inf
    assert HighsLP(half_plane).maximize(np.array([1.0, 0.0])).objective == pytest.approx(1.0)


def test_highs_prints_nothing():
    code = (
        "import numpy as np\nfrom impact_balance.solvers import HighsLP, LinearProgram\n"
        "lp = HighsLP(LinearProgram(np.eye(2), np.ones(2), np.zeros((0, 2)), np.zeros(0)))\n"
        "assert lp.maximize(np.ones(2)).objective == 2.0\n"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "" and proc.stderr == ""  # the "Running HiGHS ..." banner went to stdout
