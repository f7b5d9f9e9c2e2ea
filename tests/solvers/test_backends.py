"""The solver-neutral problem and its backends."""

from __future__ import annotations

import importlib.util

import numpy as np
import pytest

from footfall.errors import InputError, SolverUnavailableError
from footfall.solvers import ProblemBuilder, SolverOptions, SolveStatus, available_solvers, solve
from footfall.solvers.problem import MIQCQP, fix_variables


def small_problem() -> MIQCQP:
    """min (x0 - 0.3)^2 + (x1 - 4)^2, |x0| >= 1 by a disjunction, ||x|| <= 3.

    Optimum by hand: x0 = 1 (the nearer branch to 0.3), x1 = sqrt(9 - 1) = 2.8284,
    objective 0.49 + (4 - sqrt 8)^2.
    """
    b = ProblemBuilder()
    x = b.add_vars("x", (2,), -5.0, 5.0)
    z = b.add_binaries("z", (2,))
    b.add_eq({int(z[0]): 1.0, int(z[1]): 1.0}, 1.0, "one branch")
    b.add_le_big_m({int(x[0]): 1.0}, -1.0, int(z[0]), "x0 <= -1")
    b.add_le_big_m({int(x[0]): -1.0}, -1.0, int(z[1]), "x0 >= 1")
    b.add_cone(x, 3.0)
    b.add_square({int(x[0]): 1.0}, 0.3, 1.0, "a")
    b.add_square({int(x[1]): 1.0}, 4.0, 1.0, "b")
    return b.build()


OPTIMUM = 0.49 + (4 - np.sqrt(8)) ** 2


@pytest.mark.parametrize("backend", ["bnb", "scip", "gurobi"])
def test_backend_finds_the_hand_computed_optimum(backend: str) -> None:
    # gurobipy is in the [dev] extra: its size-limited pip licence covers this small problem
    prob = small_problem()
    res = solve(prob, backend, SolverOptions(gap=1e-9))
    assert res.solver == backend
    assert "fallback" not in res.stats  # bnb takes this problem's shape itself
    assert res.status is SolveStatus.OPTIMAL
    assert res.x is not None
    assert res.objective == pytest.approx(OPTIMUM, abs=1e-6)
    np.testing.assert_allclose(res.x[:2], [1.0, np.sqrt(8)], atol=1e-5)
    assert prob.violation(res.x) < 1e-6
    assert res.bound <= res.objective + 1e-6


def test_big_m_is_the_smallest_valid_constant() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (2,), [-1.0, 0.0], [2.0, 3.0])
    z = b.add_binaries("z", ())
    b.add_le_big_m({int(x[0]): 1.0, int(x[1]): 2.0}, 1.0, int(z), "row")
    prob = b.build()
    row = prob.a_le.toarray()[0]
    # max of x0 + 2 x1 over the box is 2 + 6 = 8, so M = 8 - 1 = 7: x0 + 2 x1 + 7 z <= 8
    np.testing.assert_allclose(row, [1.0, 2.0, 7.0])
    assert prob.b_le[0] == pytest.approx(8.0)


def test_redundant_big_m_row_is_dropped() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (1,), -1.0, 1.0)
    z = b.add_binaries("z", ())
    b.add_le_big_m({int(x[0]): 1.0}, 5.0, int(z), "never violated")
    assert b.build().a_le.shape[0] == 0


def test_unbounded_variable_in_big_m_row_is_refused() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (1,))
    z = b.add_binaries("z", ())
    with pytest.raises(InputError, match=r"big-M row 'row': got \['x\[0\]'\].*unbounded"):
        b.add_le_big_m({int(x[0]): 1.0}, 0.0, int(z), "row")


def test_negative_cost_weight_is_an_input_error() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (1,))
    with pytest.raises(InputError, match="weight of cost term 'a'"):
        b.add_square({int(x[0]): 1.0}, 0.0, -1.0, "a")


def test_solver_errors_derive_from_the_footfall_root() -> None:
    from footfall.errors import FootfallError, SolverError
    from footfall.solvers.bnb import UnsupportedProblem, WorkerError

    assert issubclass(UnsupportedProblem, SolverError) and issubclass(
        UnsupportedProblem, ValueError
    )
    assert issubclass(WorkerError, SolverError) and issubclass(WorkerError, RuntimeError)
    assert issubclass(SolverError, FootfallError)


def test_fixing_variables_changes_only_their_bounds() -> None:
    prob = small_problem()
    fixed = fix_variables(prob, np.array([2, 3]), np.array([1.0, 0.0]))
    res = solve(fixed, "scip", SolverOptions(gap=1e-9))
    assert res.x is not None and res.x[0] <= -1.0 + 1e-9  # the other branch
    assert prob.lb[2] == 0.0 and prob.ub[2] == 1.0


def test_infeasible_problem_is_reported() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (2,), -1.0, 1.0)
    b.add_cone(x, 0.5)
    b.add_le({int(x[0]): 1.0, int(x[1]): 1.0}, -2.0, "impossible")
    b.add_square({int(x[0]): 1.0}, 0.0, 1.0, "c")
    res = solve(b.build(), "scip")
    assert res.status is SolveStatus.INFEASIBLE and res.x is None


def test_unknown_and_missing_backends(monkeypatch: pytest.MonkeyPatch) -> None:
    with pytest.raises(InputError, match="scip, gurobi"):
        solve(small_problem(), "cplex")
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "gurobipy" else real(name, *a)
    )
    with pytest.raises(SolverUnavailableError, match="pip install"):
        solve(small_problem(), "gurobi")
    assert "gurobi" not in available_solvers() and "scip" in available_solvers()
