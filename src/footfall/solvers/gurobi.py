"""Gurobi backend (optional: needs ``gurobipy`` and a licence; the free pip licence is size-limited)."""

from __future__ import annotations

import math
import time

import numpy as np

from footfall.solvers.base import SolverOptions, SolverResult, SolveStatus
from footfall.solvers.problem import MIQCQP

NAME = "gurobi"


def solve(problem: MIQCQP, options: SolverOptions) -> SolverResult:
    """Solve ``problem`` with Gurobi's matrix API (cones as convex quadratic constraints)."""
    import gurobipy as gp
    from gurobipy import GRB

    start = time.perf_counter()
    env = gp.Env(empty=True)
    env.setParam("OutputFlag", 1 if options.verbose else 0)
    env.start()
    m = gp.Model("footfall", env=env)
    m.Params.TimeLimit = options.time_limit
    m.Params.MIPGap = options.gap
    m.Params.MIPGapAbs = options.abs_gap
    m.Params.Threads = options.threads
    m.Params.Seed = options.seed
    vtype = np.where(problem.integer, GRB.INTEGER, GRB.CONTINUOUS)
    x = m.addMVar(problem.n, lb=problem.lb, ub=problem.ub, vtype=vtype)
    if problem.a_eq.shape[0]:
        m.addMConstr(problem.a_eq, x, "=", problem.b_eq)
    if problem.a_le.shape[0]:
        m.addMConstr(problem.a_le, x, "<", problem.b_le)
    for idx, radius in problem.cones:
        sel = x[idx.tolist()]
        m.addConstr(sel @ sel <= radius * radius)
    # Residuals r = F x - f as variables keep the objective a diagonal quadratic: sum w r^2.
    r = m.addMVar(problem.cost_matrix.shape[0], lb=-GRB.INFINITY)
    m.addConstr(r == problem.cost_matrix @ x - problem.cost_target)
    m.setObjective(r @ (problem.cost_weight * r), GRB.MINIMIZE)
    if options.initial_solution is not None:
        x.setAttr("Start", options.initial_solution)
    try:
        m.optimize()
    except gp.GurobiError as exc:
        # e.g. "Model too large for size-limited license": an outcome to report, not a crash
        return SolverResult(
            status=SolveStatus.ERROR,
            x=None,
            objective=math.nan,
            bound=math.nan,
            gap=math.inf,
            solve_time=time.perf_counter() - start,
            solver=NAME,
            stats={"raw_status": f"GurobiError: {exc}"},
        )
    n_sols = m.SolCount
    xs = np.array(x.X) if n_sols > 0 else None
    objective = problem.objective(xs) if xs is not None else math.nan
    code = m.Status
    if code == GRB.OPTIMAL:
        status = SolveStatus.OPTIMAL
    elif code == GRB.INFEASIBLE:
        status = SolveStatus.INFEASIBLE
    elif code == GRB.TIME_LIMIT:
        status = SolveStatus.TIME_LIMIT
    elif n_sols > 0:
        status = SolveStatus.FEASIBLE
    else:
        status = SolveStatus.ERROR
    bound = float(m.ObjBound) if problem.n_integer and code != GRB.INFEASIBLE else objective
    gap = float(m.MIPGap) if problem.n_integer and n_sols > 0 else (0.0 if n_sols else math.inf)
    return SolverResult(
        status=status,
        x=xs,
        objective=objective,
        bound=bound,
        gap=gap,
        solve_time=time.perf_counter() - start,
        solver=NAME,
        stats={"raw_status": int(code), "nodes": float(m.NodeCount), "solutions": int(n_sols)},
    )
