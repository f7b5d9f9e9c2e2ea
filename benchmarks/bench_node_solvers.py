"""Node solvers for the footstep MIQCQP's branch and bound, measured on its own node problems.

The exact search (:mod:`footfall.solvers.bnb`) solves every node's convex relaxation (hull and
perspective cones, document 000 eq. 5.11-5.18) with Clarabel, an interior-point method that
cannot be warm-started. This script captures the node problems of one seeded instance exactly as
Clarabel receives them and solves them again with:

* ``clarabel``: the planner's settings, cold (what the search does);
* ``highs-oa``: HiGHS's QP solver on an outer approximation of the second-order cones (each
  ``||s[1:]|| <= s[0]`` replaced by ``s[0] >= 0`` and ``s[0] >= +-s[i]``, then tangent cuts at
  the violated cones, the solver hot-started after each round of cuts): the LP/QP-based branch and
  bound that commercial MIQP solvers use. Every round's value is a valid lower bound;
* ``daqp``: the dense active-set solver of the short-horizon planner on the first round of the
  same outer approximation (one solve; its setup is dense in rows x columns).

Needs ``pip install highspy`` (not a footfall dependency). Run from the repository root::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_node_solvers.py \\
        --steps 15 --seed 0 --nodes 0,100,300 --max-rounds 12

Results: ``benchmarks/RESULTS.md``, "Warm-started node solvers, measured".
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import numpy as np
import scipy.sparse as sp

import footfall.solvers.bnb.relaxation as relaxation
from footfall.models.biped import BipedParams
from footfall.planning.miqcqp import plan_footsteps
from footfall.planning.plan import PlannerOptions
from footfall.terrain.scene import random_stepping_stones


def capture(n_steps: int, seed: int, keep: set[int]) -> list[dict[str, Any]]:
    """Plan the instance (K = 10, 8 regions, one thread, gap 1e-4) and keep the node problems
    whose solve index is in ``keep``, with Clarabel's bound as the planner got it."""
    got: list[dict[str, Any]] = []
    counter = [0]
    run = relaxation.HullRelaxation._run

    def spy(self: Any, base: Any, t: Any, a: Any, pb: Any, keep_col: Any) -> Any:
        i = counter[0]
        counter[0] += 1
        if i in keep:
            cones = [int(d) for d in base.soc_dims] + [int(d) for d in t.cost_dim[a.persp]]
            pb_copy = {
                k: np.copy(v) if isinstance(v, np.ndarray) else v for k, v in vars(pb).items()
            }
            got.append({"index": i, "m_eq": a.m_eq, "socs": cones, **pb_copy})
        return run(self, base, t, a, pb, keep_col)

    relaxation.HullRelaxation._run = spy  # type: ignore[method-assign]
    try:
        scene = random_stepping_stones(seed, 8, robot=BipedParams(n_nodes=10))
        plan_footsteps(scene, None, n_steps, PlannerOptions(gap=1e-4, threads=1, solver="bnb"))
    finally:
        relaxation.HullRelaxation._run = run  # type: ignore[method-assign]
    return got


def matrices(d: dict[str, Any]) -> tuple[sp.csr_matrix, sp.csc_matrix, list[np.ndarray]]:
    """The node's constraint matrix A (rows: equalities, inequalities, cones), its upper
    triangular Hessian P, and the row indices of each second-order cone."""
    n = len(d["q"])
    a_mat = sp.csr_matrix((d["vals"], (d["rows"], d["cols"])), shape=(d["n_rows"], n))
    p_mat = sp.csc_matrix((d["p_v"], (d["p_i"], d["p_j"])), shape=(n, n))
    r = d["m_eq"] + d["m_le"]
    socs = []
    for dim in d["socs"]:
        socs.append(np.arange(r, r + dim))
        r += dim
    return a_mat, p_mat, socs


def solve_clarabel(d: dict[str, Any]) -> tuple[float, float, str]:
    """Time [s], bound and status of Clarabel with the planner's settings, cold."""
    import clarabel

    a_mat, p_mat, _ = matrices(d)
    cones = [clarabel.ZeroConeT(d["m_eq"]), clarabel.NonnegativeConeT(d["m_le"])]
    cones += [clarabel.SecondOrderConeT(dim) for dim in d["socs"]]
    settings = relaxation._clarabel_settings(clarabel, dict(relaxation.BnbSettings().clarabel))
    t0 = time.perf_counter()
    sol = clarabel.DefaultSolver(p_mat, d["q"], a_mat.tocsc(), d["b"], cones, settings).solve()
    elapsed = time.perf_counter() - t0
    return elapsed, min(sol.obj_val, sol.obj_val_dual) + d["const"], str(sol.status)


def first_cuts(d: dict[str, Any]) -> tuple[sp.csr_matrix, np.ndarray]:
    """The initial outer approximation of every cone as rows ``C x <= c``: ``s0 >= 0`` and
    ``s0 >= +-s_i`` with ``s = b - A x`` over the cone's rows."""
    a_mat, _, socs = matrices(d)
    b = d["b"]
    rows, rhs = [], []
    for idx in socs:
        a0, b0 = a_mat[idx[0]], b[idx[0]]
        rows.append(a0)
        rhs.append(b0)
        for i in idx[1:]:
            for sign in (1.0, -1.0):
                rows.append(a0 + sign * a_mat[i])
                rhs.append(b0 + sign * b[i])
    return sp.vstack(rows).tocsr(), np.asarray(rhs)


def solve_highs_oa(d: dict[str, Any], max_rounds: int, tol: float = 1e-7) -> dict[str, Any]:
    """HiGHS QP on the outer approximation, cut rounds until every cone holds within ``tol`` or
    ``max_rounds``; per round its bound, QP iterations and cumulative time."""
    import highspy

    a_mat, p_mat, socs = matrices(d)
    b, n, m_eq, m_le = d["b"], len(d["q"]), d["m_eq"], d["m_le"]
    cut_a, cut_b = first_cuts(d)
    big = sp.vstack([a_mat[: m_eq + m_le], cut_a]).tocsc()
    inf = highspy.kHighsInf
    lower = np.concatenate([b[:m_eq], np.full(m_le + len(cut_b), -inf)])
    upper = np.concatenate([b[: m_eq + m_le], cut_b])
    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("time_limit", 10.0)
    lp = highspy.HighsLp()
    lp.num_col_, lp.num_row_ = n, big.shape[0]
    lp.col_cost_ = d["q"]
    lp.col_lower_, lp.col_upper_ = np.full(n, -inf), np.full(n, inf)
    lp.row_lower_, lp.row_upper_ = lower, upper
    lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    lp.a_matrix_.start_, lp.a_matrix_.index_, lp.a_matrix_.value_ = (
        big.indptr,
        big.indices,
        big.data,
    )
    lp.a_matrix_.num_col_, lp.a_matrix_.num_row_ = n, big.shape[0]
    lower_tri = sp.tril((p_mat + p_mat.T - sp.diags(p_mat.diagonal())).tocsc()).tocsc()
    hess = highspy.HighsHessian()
    hess.dim_, hess.format_ = n, highspy.HessianFormat.kTriangular
    hess.start_, hess.index_, hess.value_ = lower_tri.indptr, lower_tri.indices, lower_tri.data
    model = highspy.HighsModel()
    model.lp_, model.hessian_ = lp, hess
    t0 = time.perf_counter()
    h.passModel(model)
    rounds: list[tuple[float, int, float, float]] = []
    status = "round limit"
    for _ in range(max_rounds):
        h.run()
        info = h.getInfo()
        if h.getModelStatus() != highspy.HighsModelStatus.kOptimal:
            status = str(h.getModelStatus())
            break
        x = np.asarray(h.getSolution().col_value)
        s = b - a_mat @ x
        new_a, new_b, worst = [], [], 0.0
        for idx in socs:
            v = s[idx]
            norm = float(np.linalg.norm(v[1:]))
            worst = max(worst, norm - v[0])
            if norm - v[0] > tol:
                g = v[1:] / norm
                new_a.append(a_mat[idx[0]] - sp.csr_matrix(g @ a_mat[idx[1:]].toarray()))
                new_b.append(b[idx[0]] - g @ b[idx[1:]])
        bound = info.objective_function_value + d["const"]
        rounds.append((bound, int(info.qp_iteration_count), time.perf_counter() - t0, worst))
        if not new_a:
            status = "cones hold"
            break
        cuts = sp.vstack(new_a).tocsr()
        h.addRows(
            len(new_b), np.full(len(new_b), -inf), np.asarray(new_b), cuts.nnz,
            cuts.indptr[:-1].astype(np.int32), cuts.indices.astype(np.int32), cuts.data,
        )  # fmt: skip
    return {"status": status, "rounds": rounds}


def solve_daqp(d: dict[str, Any]) -> tuple[float, float, int, int]:
    """One dense daqp solve of the first outer approximation: total time [s], its setup [s],
    exit flag and iterations."""
    from ctypes import c_double, c_int

    import daqp

    a_mat, p_mat, _ = matrices(d)
    cut_a, cut_b = first_cuts(d)
    m_eq, m_le, b = d["m_eq"], d["m_le"], d["b"]
    dense = np.vstack([a_mat[: m_eq + m_le].toarray(), cut_a.toarray()]).astype(c_double)
    upper = np.concatenate([b[: m_eq + m_le], cut_b]).astype(c_double)
    lower = np.concatenate([b[:m_eq], np.full(m_le + len(cut_b), -1e30)]).astype(c_double)
    sense = np.zeros(len(upper), dtype=c_int)
    sense[:m_eq] = 5  # equality: active and immutable
    hess = (p_mat + p_mat.T - sp.diags(p_mat.diagonal())).toarray()
    t0 = time.perf_counter()
    _, _, exitflag, info = daqp.solve(hess, d["q"].astype(c_double), dense, upper, lower, sense)
    return (
        time.perf_counter() - t0,
        float(info["setup_time"]),
        int(exitflag),
        int(info["iterations"]),
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=15, help="footsteps N")
    ap.add_argument("--seed", type=int, default=0, help="random stepping stones seed")
    ap.add_argument("--nodes", default="0,100,300", help="node solves to capture (0: the root)")
    ap.add_argument("--max-rounds", type=int, default=12, help="cut rounds of highs-oa")
    ap.add_argument("--no-daqp", action="store_true", help="skip the dense daqp solve")
    args = ap.parse_args()
    try:
        keep = {int(s) for s in args.nodes.split(",")}
    except ValueError:
        ap.error(f"--nodes: {args.nodes!r} is not a comma-separated list of node-solve indices")
    if args.steps < 1 or args.max_rounds < 1 or min(keep) < 0:
        ap.error("--steps and --max-rounds must be >= 1 and --nodes >= 0")
    try:
        import highspy  # noqa: F401
    except ImportError:
        ap.error("HiGHS is not installed: pip install highspy (not a footfall dependency)")
    for d in capture(args.steps, args.seed, keep):
        n, m = len(d["q"]), d["n_rows"]
        t_c, bound_c, st_c = solve_clarabel(d)
        print(f"node {d['index']}: {n} columns, {m} rows, {len(d['socs'])} cones")
        print(f"  clarabel  {t_c * 1e3:8.1f} ms  bound {bound_c:.6f}  {st_c}")
        oa = solve_highs_oa(d, args.max_rounds)
        for k, (bound, iters, elapsed, worst) in enumerate(oa["rounds"], start=1):
            print(
                f"  highs-oa round {k:2d}: bound {bound:.6f}  QP iterations {iters:5d}  "
                f"{elapsed * 1e3:8.1f} ms so far  worst cone violation {worst:.3g}"
            )
        print(f"  highs-oa  {oa['status']}")
        if not args.no_daqp:
            t_d, setup, flag, iters = solve_daqp(d)
            print(
                f"  daqp      {t_d * 1e3:8.1f} ms (setup {setup * 1e3:.1f} ms) exit {flag}, {iters} iterations"
            )


if __name__ == "__main__":
    main()
