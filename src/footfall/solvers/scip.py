"""SCIP backend through PySCIPOpt: the direct model (pip-installable, exact on MIQCQPs)."""

from __future__ import annotations

import math
import time
from typing import Any

import numpy as np

from footfall.solvers.base import SolverOptions, SolverResult, SolveStatus
from footfall.solvers.problem import MIQCQP

NAME = "scip"


def solve(problem: MIQCQP, options: SolverOptions) -> SolverResult:
    """Solve ``problem`` with SCIP (the model of :func:`build_model`)."""
    start = time.perf_counter()
    m, x = build_model(problem, options)
    build_time = time.perf_counter() - start
    m.optimize()
    return _result(problem, m, x, start, build_time)


def build_model(problem: MIQCQP, options: SolverOptions) -> tuple[Any, list[Any]]:
    """The SCIP model of ``problem`` and its variables, one per problem variable.

    The least-squares objective becomes one epigraph variable per cost label,
    ``t_g >= sum_j w_j (F_j x - f_j)^2`` (a convex quadratic constraint), and the objective is
    ``sum_g t_g``. Cones become ``sum x_i^2 <= r^2``.
    """
    import pyscipopt as scip

    m = scip.Model("footfall")
    if not options.verbose:
        m.hideOutput()
    m.setParam("limits/time", options.time_limit)
    m.setParam("limits/gap", options.gap)
    m.setParam("limits/absgap", options.abs_gap)
    m.setParam("randomization/randomseedshift", options.seed)
    m.setParam("parallel/maxnthreads", options.threads)

    x = []
    for i, name in enumerate(problem.names):
        lb = problem.lb[i] if np.isfinite(problem.lb[i]) else None
        ub = problem.ub[i] if np.isfinite(problem.ub[i]) else None
        vtype = "C"
        if problem.integer[i]:
            vtype = "B" if lb == 0.0 and ub == 1.0 else "I"
        x.append(m.addVar(name=name, vtype=vtype, lb=lb, ub=ub))

    _add_rows(m, x, problem.a_eq, problem.b_eq, problem.eq_labels, equal=True)
    _add_rows(m, x, problem.a_le, problem.b_le, problem.le_labels, equal=False)
    for k, (idx, radius) in enumerate(problem.cones):
        m.addCons(
            scip.quicksum(x[int(i)] * x[int(i)] for i in idx) <= radius * radius, name=f"cone{k}"
        )
    _add_objective(m, x, problem)
    if options.initial_solution is not None:
        sol = m.createSol()
        for i, v in enumerate(options.initial_solution):
            m.setSolVal(sol, x[i], float(v))
        m.addSol(sol, free=True)
    return m, x


def _add_rows(m: Any, x: list[Any], mat: Any, rhs: Any, labels: list[str], equal: bool) -> None:
    """Add the rows ``mat x = rhs`` (``equal``) or ``mat x <= rhs``, named by their labels."""
    import pyscipopt as scip

    for r in range(mat.shape[0]):
        lo, hi = mat.indptr[r], mat.indptr[r + 1]
        expr = scip.quicksum(
            float(v) * x[int(c)] for c, v in zip(mat.indices[lo:hi], mat.data[lo:hi], strict=True)
        )
        if equal:
            m.addCons(expr == float(rhs[r]), name=labels[r][:200])
        else:
            m.addCons(expr <= float(rhs[r]), name=labels[r][:200])


def _add_objective(m: Any, x: list[Any], problem: MIQCQP) -> None:
    """Minimise ``sum_g t_g`` with ``t_g >= sum_{j in g} w_j (F_j x - f_j)^2`` per cost label."""
    import pyscipopt as scip

    groups: dict[str, list[int]] = {}
    for r, g in enumerate(problem.cost_group):
        groups.setdefault(g, []).append(r)
    epi = []
    cm = problem.cost_matrix
    for g, rlist in groups.items():
        t = m.addVar(name=f"epi[{g}]", lb=0.0)
        epi.append(t)
        terms = []
        for r in rlist:
            lo, hi = cm.indptr[r], cm.indptr[r + 1]
            e = scip.quicksum(
                float(v) * x[int(c)] for c, v in zip(cm.indices[lo:hi], cm.data[lo:hi], strict=True)
            ) - float(problem.cost_target[r])
            terms.append(float(problem.cost_weight[r]) * e * e)
        m.addCons(scip.quicksum(terms) <= t, name=f"cost[{g}]")
    m.setObjective(scip.quicksum(epi), "minimize")


def _status(raw: str, n_sols: int) -> SolveStatus:
    """The :class:`SolveStatus` of SCIP's status ``raw`` with ``n_sols`` solutions found."""
    if raw in ("optimal", "gaplimit"):
        return SolveStatus.OPTIMAL
    if raw == "infeasible":
        return SolveStatus.INFEASIBLE
    if raw == "timelimit":
        return SolveStatus.TIME_LIMIT
    if raw in ("unbounded", "inforunbd"):
        return SolveStatus.ERROR
    return SolveStatus.FEASIBLE if n_sols > 0 else SolveStatus.ERROR


def _result(problem: MIQCQP, m: Any, x: list[Any], start: float, build_time: float) -> SolverResult:
    """The :class:`SolverResult` of the solved model ``m``."""
    raw = m.getStatus()
    n_sols = m.getNSols()
    xs = None
    objective = math.nan
    if n_sols > 0:
        best = m.getBestSol()
        xs = np.array([m.getSolVal(best, v) for v in x])
        objective = problem.objective(xs)
    stats = {
        "raw_status": raw,
        "nodes": int(m.getNNodes()),
        "solutions": int(n_sols),
        "build_time_s": build_time,
        "scip_time_s": float(m.getSolvingTime()),
        "variables": problem.n,
        "integer_variables": problem.n_integer,
    }
    return SolverResult(
        status=_status(raw, n_sols),
        x=xs,
        objective=objective,
        bound=float(m.getDualbound()) if raw != "infeasible" else math.nan,
        gap=float(m.getGap()) if n_sols > 0 else math.inf,
        solve_time=time.perf_counter() - start,
        solver=NAME,
        stats=stats,
    )
