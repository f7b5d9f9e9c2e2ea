"""A fixed-shape LP node relaxation for the footstep MIQCQP's branch and bound, measured.

The exact search (:mod:`footfall.solvers.bnb`) assembles every node's hull relaxation afresh and
solves it cold with Clarabel. This script measures the alternative that ``benchmarks/RESULTS.md``
("Warm-started node solvers, measured") left open: one fixed-shape problem, the ROOT's columns,
in which a node's branching is only column bounds (the excluded members' weights ``z`` fixed to
0, which forces their copies, perspective terms and link flows to 0), every second-order cone
replaced up front by Ben-Tal and Nemirovski's lifted polyhedral approximation of depth ``nu``
(each cone of dimension d > 3 split into a tower of 3-dimensional ones), and every node solved
by HiGHS's dual simplex from its parent's basis.

For each instance (random stepping stones, 8 regions, K = 10, one thread, gap 1e-4):

1. the root node problem is captured as Clarabel gets it (by wrapping ``HullRelaxation._run``)
   and solved again: its bound must equal the planner's root bound;
2. the polyhedral LP is built for every ``--nus`` depth; the construction is checked on a lone
   cone (every point of the cone lifts into the polytope; every point outside the cone by more
   than the stated accuracy is cut), and its root bound against Clarabel's;
3. a depth-first search from the root (the search's own branching, :func:`_branch`, from the
   exact relaxation point; both children of a node pushed, the second explored first; nodes
   whose exact bound reaches the planner's objective are not branched) visits ``--nodes`` nodes.
   Each is solved interleaved, in the same process, by: the search's own node solve
   (``HullRelaxation.solve``: per-node assembly and Clarabel), the fixed-shape problem with
   Clarabel (the same bound: a check of the fixed-shape encoding), and every HiGHS variant
   warm-started from the parent's basis: the LP for each ``nu`` with the quadratic objective as
   an epigraph (one more polyhedral cone), and, with ``--qp n``, HiGHS's QP solver with the
   Hessian on the same polytope (the last ``--nus`` depth, the first n nodes: it is slow);
4. a summary per instance and variant: median / p90 time of a node against the search's node
   solve (ratios from the same run), median simplex iterations, the bound loss against the exact
   bound, and the nodes the exact bound prunes (within the search's gap 1e-4 of the planner's
   objective) that the LP bound does not.

Needs ``pip install highspy`` (HiGHS 1.16; not a footfall dependency). Run from the repository
root (one thread; 1-3 minutes per instance)::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_node_lp.py \\
        --steps 10 --seeds 0 --nus 5,6,7,8 --nodes 300 --qp 3
    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_node_lp.py \\
        --steps 15 --seeds 0 --nus 5,6,7,8 --nodes 300

Results: ``benchmarks/RESULTS.md``, "A fixed-shape LP node relaxation, measured".
"""

from __future__ import annotations

import argparse
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp

import footfall.solvers.bnb.relaxation as relaxation
from footfall.models.biped import BipedParams
from footfall.planning.miqcqp import plan_footsteps
from footfall.planning.plan import PlannerOptions
from footfall.solvers.bnb.branching import _branch, _root_allowed
from footfall.terrain.scene import random_stepping_stones

Allowed = tuple[tuple[int, ...], ...]


# ------------------------------------------------------------------------------------ capture
@dataclass
class Root:
    """The root node problem as Clarabel gets it, and what is needed to branch on it."""

    a_mat: sp.csr_matrix  # rows: equalities, inequalities, cones
    b: np.ndarray
    m_eq: int
    m_le: int
    socs: list[np.ndarray]  # row indices of each second-order cone
    p_mat: sp.csc_matrix  # upper triangle of the Hessian (1/2 x^T P x)
    q: np.ndarray
    const: float
    z_col: dict[int, int]  # member variable index -> its weight's column
    #: member variable index -> the columns that are 0 when it is excluded: its weight, its
    #: copies of the forms, its perspective variable and its link-flow weights
    member_cols: dict[int, np.ndarray]
    allowed: Allowed  # the root's allowed members per group
    relax: Any  # the planner's HullRelaxation (to solve nodes as the search does)
    planner_root_bound: float
    objective: float  # the planner's optimum
    planner_nodes: int

    @property
    def n(self) -> int:
        """Number of columns."""
        return len(self.q)


def capture(n_steps: int, seed: int) -> Root:
    """Plan the instance and keep its root node problem (the first node solve, all the root's
    members allowed) with the planner's root bound."""
    got: dict[str, Any] = {}
    run = relaxation.HullRelaxation._run

    def spy(self: Any, base: Any, t: Any, a: Any, pb: Any, keep_col: Any) -> Any:
        res = run(self, base, t, a, pb, keep_col)
        if not got:
            cones = [int(d) for d in base.soc_dims] + [int(d) for d in t.cost_dim[a.persp]]
            got.update(relax=self, t=t, a=a, keep_col=keep_col, cones=cones, res=res)
            got["pb"] = {
                k: np.copy(v) if isinstance(v, np.ndarray) else v for k, v in vars(pb).items()
            }
        return res

    relaxation.HullRelaxation._run = spy  # type: ignore[method-assign]
    try:
        scene = random_stepping_stones(seed, 8, robot=BipedParams(n_nodes=10))
        plan = plan_footsteps(
            scene, None, n_steps, PlannerOptions(gap=1e-4, threads=1, solver="bnb")
        )
    finally:
        relaxation.HullRelaxation._run = run  # type: ignore[method-assign]
    relax, t, a, pb = got["relax"], got["t"], got["a"], got["pb"]
    allowed = _root_allowed(relax.s)
    n_allowed = sum(len(m) for m in allowed)
    if int(np.count_nonzero(a.sel)) != n_allowed:
        raise RuntimeError("the first node solve is not the root")
    n = len(pb["q"])
    keep = got["keep_col"] if got["keep_col"] is not None else np.ones(a.ncol, dtype=bool)
    col_map = np.cumsum(keep) - 1
    z_col, member_cols = {}, {}
    for grp in relax.s.groups:
        for z in grp.members:
            m = int(relax.member_index[z])
            c = int(t.zcol[m])
            if not keep[c]:
                continue
            z_col[z] = int(col_map[c])
            cols = [c]
            if a.multi[m]:
                cols += list(range(int(a.copy_start[m]), int(a.copy_start[m] + t.k[m])))
            if a.persp[m]:
                cols.append(int(a.t_col[m]))
            pairs = np.flatnonzero((relax.p_m[:, 0] == m) | (relax.p_m[:, 1] == m))
            cols += [int(a.w_col[i]) for i in pairs]  # every pair is allowed at the root
            cols_a = np.array(cols, dtype=np.int64)
            member_cols[z] = col_map[cols_a[keep[cols_a]]]
    r = a.m_eq + pb["m_le"]
    socs = []
    for dim in got["cones"]:
        socs.append(np.arange(r, r + dim))
        r += dim
    return Root(
        a_mat=sp.csr_matrix((pb["vals"], (pb["rows"], pb["cols"])), shape=(pb["n_rows"], n)),
        b=pb["b"],
        m_eq=a.m_eq,
        m_le=pb["m_le"],
        socs=socs,
        p_mat=sp.csc_matrix((pb["p_v"], (pb["p_i"], pb["p_j"])), shape=(n, n)),
        q=pb["q"],
        const=float(pb["const"]),
        z_col=z_col,
        member_cols=member_cols,
        allowed=allowed,
        relax=relax,
        planner_root_bound=float(got["res"].bound),
        objective=float(plan.objective),
        planner_nodes=int(plan.stats.get("nodes", -1)) if isinstance(plan.stats, dict) else -1,
    )


# ------------------------------------------------------------------- exact (Clarabel) solves
def excluded(root: Root, allowed: Allowed) -> list[int]:
    """Columns that are 0 where ``allowed`` excludes some of the root's members: their weights,
    copies, perspective variables and link flows (a weight fixed to 0 alone does not force a
    copy to 0 when the member's set is unbounded: the hull rows only bound its recession)."""
    keep = {z for mem in allowed for z in mem}
    out = [root.member_cols[z] for mem in root.allowed for z in mem if z not in keep]
    return sorted({int(c) for c in np.concatenate([np.zeros(0, dtype=np.int64), *out])})


def clarabel_fixed(
    root: Root, fixed_zero: list[int]
) -> tuple[float, float, str, np.ndarray | None]:
    """Time [s], bound, status and point of Clarabel (the search's settings) on the fixed-shape conic
    problem with the columns ``fixed_zero`` set to 0 by extra equality rows."""
    import clarabel

    n, k = root.n, len(fixed_zero)
    fix = sp.csr_matrix((np.ones(k), (np.arange(k), fixed_zero)), shape=(k, n))
    a_mat = sp.vstack([fix, root.a_mat]).tocsc()
    b = np.concatenate([np.zeros(k), root.b])
    cones = [clarabel.ZeroConeT(root.m_eq + k), clarabel.NonnegativeConeT(root.m_le)]
    cones += [clarabel.SecondOrderConeT(len(idx)) for idx in root.socs]
    settings = relaxation._clarabel_settings(clarabel, dict(relaxation.BnbSettings().clarabel))
    t0 = time.perf_counter()
    sol = clarabel.DefaultSolver(root.p_mat, root.q, a_mat, b, cones, settings).solve()
    elapsed = time.perf_counter() - t0
    status = str(sol.status)
    if status not in ("Solved", "AlmostSolved"):
        return elapsed, math.inf, status, None
    return elapsed, min(sol.obj_val, sol.obj_val_dual) + root.const, status, np.asarray(sol.x)


# ------------------------------------------------------------- Ben-Tal--Nemirovski polytope
def bn_accuracy(nu: int) -> float:
    """Accuracy of the depth-``nu`` polytope of a 3-dimensional cone: its points satisfy
    ``||(a, b)|| <= (1 + eps) c``."""
    return 1.0 / math.cos(math.pi / 2 ** (nu + 1)) - 1.0


def tower_depth(k: int) -> int:
    """Levels of 3-dimensional cones that a cone ``||v|| <= c`` with ``k`` entries is split into."""
    return max(1, math.ceil(math.log2(k)))


@dataclass
class Expr:
    """An affine expression ``sum vals * x[cols] + const``."""

    cols: np.ndarray
    vals: np.ndarray
    const: float = 0.0

    @staticmethod
    def col(j: int, coef: float = 1.0) -> Expr:
        """``coef * x[j]``."""
        return Expr(np.array([j]), np.array([coef]))

    def scaled(self, s: float) -> Expr:
        """``s * self``."""
        return Expr(self.cols, s * self.vals, s * self.const)

    def plus(self, other: Expr) -> Expr:
        """``self + other`` (a column in both gets two entries, summed by the matrix)."""
        return Expr(
            np.concatenate([self.cols, other.cols]),
            np.concatenate([self.vals, other.vals]),
            self.const + other.const,
        )


@dataclass
class LpBuilder:
    """Rows ``lo <= A x <= hi`` and columns ``lo <= x <= hi`` collected as COO entries."""

    n: int
    col_lo: list[float] = field(default_factory=list)
    col_hi: list[float] = field(default_factory=list)
    r: list[np.ndarray] = field(default_factory=list)
    c: list[np.ndarray] = field(default_factory=list)
    v: list[np.ndarray] = field(default_factory=list)
    row_lo: list[float] = field(default_factory=list)
    row_hi: list[float] = field(default_factory=list)

    def new_col(self, lo: float = -math.inf, hi: float = math.inf) -> int:
        """A new column; returns its index."""
        self.col_lo.append(lo)
        self.col_hi.append(hi)
        self.n += 1
        return self.n - 1

    def row(self, terms: list[Expr], lo: float, hi: float) -> None:
        """The row ``lo <= sum(terms) <= hi`` (constants moved to the bounds)."""
        k = len(self.row_lo)
        const = sum(e.const for e in terms)
        cols = np.concatenate([e.cols for e in terms])
        self.r.append(np.full(len(cols), k, dtype=np.int64))
        self.c.append(cols.astype(np.int64))
        self.v.append(np.concatenate([e.vals for e in terms]))
        self.row_lo.append(lo - const)
        self.row_hi.append(hi - const)

    def ge0(self, *terms: Expr) -> None:
        """``sum(terms) >= 0``."""
        self.row(list(terms), 0.0, math.inf)

    def matrix(self) -> sp.csc_matrix:
        """The rows as a CSC matrix over all columns."""
        m = len(self.row_lo)
        if not self.r:
            return sp.csc_matrix((m, self.n))
        return sp.csc_matrix(
            (np.concatenate(self.v), (np.concatenate(self.r), np.concatenate(self.c))),
            shape=(m, self.n),
        )


#: write each ``xi_j`` of :func:`bn_cone3` as its expression in ``xi_0, eta_0..eta_{j-1}`` (no
#: column and equality row per level) rather than as a column
SUBSTITUTE_XI = True


def bn_cone3(lp: LpBuilder, a: Expr, b: Expr, c: Expr, nu: int, a_nonneg: bool = False) -> None:
    """Ben-Tal and Nemirovski's lifted polytope of ``||(a, b)|| <= c`` (Glineur's form):
    ``xi_0 >= |a|``, ``eta_0 >= |b|``, ``xi_j = cos(t_j) xi_{j-1} + sin(t_j) eta_{j-1}``,
    ``eta_j >= |cos(t_j) eta_{j-1} - sin(t_j) xi_{j-1}|`` with ``t_j = pi / 2^(j+1)``,
    ``xi_nu <= c`` and ``eta_nu <= tan(t_nu) xi_nu``. Contains the cone; its projection lies in
    ``||(a, b)|| <= (1 + eps) c`` (:func:`bn_accuracy`). With :data:`SUBSTITUTE_XI` the
    ``xi_j`` (j >= 1) are expressions, not columns."""
    xi = Expr.col(lp.new_col())
    eta = lp.new_col()
    lp.ge0(xi, a.scaled(-1.0))
    if not a_nonneg:
        lp.ge0(xi, a)
    lp.ge0(Expr.col(eta), b.scaled(-1.0))
    lp.ge0(Expr.col(eta), b)
    for j in range(1, nu + 1):
        th = math.pi / 2 ** (j + 1)
        cj, sj = math.cos(th), math.sin(th)
        eta_n = lp.new_col()
        lp.ge0(Expr.col(eta_n), Expr.col(eta, -cj), xi.scaled(sj))
        lp.ge0(Expr.col(eta_n), Expr.col(eta, cj), xi.scaled(-sj))
        xi_n = xi.scaled(cj).plus(Expr.col(eta, sj))
        if not SUBSTITUTE_XI:
            col = lp.new_col()
            lp.row([Expr.col(col), xi_n.scaled(-1.0)], 0.0, 0.0)
            xi_n = Expr.col(col)
        xi, eta = xi_n, eta_n
    lp.ge0(c, xi.scaled(-1.0))
    lp.ge0(xi.scaled(math.tan(math.pi / 2 ** (nu + 1))), Expr.col(eta, -1.0))


def bn_cone(lp: LpBuilder, head: Expr, entries: list[Expr], nu: int) -> None:
    """``||entries|| <= head`` as a tower of 3-dimensional polytopes (:func:`bn_cone3`): entries
    are paired into new columns ``u >= ||(e1, e2)||`` until two remain."""
    level = list(entries)
    if len(level) == 1:
        lp.ge0(head, level[0].scaled(-1.0))
        lp.ge0(head, level[0])
        return
    nonneg = [False] * len(level)
    while len(level) > 2:
        nxt, nxt_nonneg = [], []
        for i in range(0, len(level) - 1, 2):
            u = lp.new_col(0.0, math.inf)
            bn_cone3(lp, level[i], level[i + 1], Expr.col(u), nu, a_nonneg=nonneg[i])
            nxt.append(Expr.col(u))
            nxt_nonneg.append(True)
        if len(level) % 2:
            nxt.append(level[-1])
            nxt_nonneg.append(nonneg[-1])
        level, nonneg = nxt, nxt_nonneg
    bn_cone3(lp, level[0], level[1], head, nu, a_nonneg=nonneg[0])


def cone_row(a_mat: sp.csr_matrix, b: np.ndarray, i: int) -> Expr:
    """The slack ``b_i - A_i x`` of a cone row."""
    lo, hi = a_mat.indptr[i], a_mat.indptr[i + 1]
    return Expr(a_mat.indices[lo:hi].copy(), -a_mat.data[lo:hi], float(b[i]))


@dataclass
class NodeLp:
    """The fixed-shape polyhedral relaxation as HiGHS data."""

    model: Any  # highspy.HighsModel
    n_cols: int
    n_rows: int
    nnz: int
    eps: float  # the whole relaxation's accuracy: every cone holds within (1 + eps)
    fix_cols: np.ndarray  # the columns a node may fix to 0 (see :func:`excluded`)
    fix_lo: np.ndarray  # their bounds at the root
    fix_hi: np.ndarray


def build_lp(
    root: Root, nu: int, qp: bool, centre: np.ndarray | None = None, sigma: float = 1.0
) -> NodeLp:
    """The root problem with every cone replaced by its depth-``nu`` polytope.

    The objective's ``1/2 x^T P x`` is kept as a Hessian (``qp``) or written about ``centre`` c
    (the root's optimum) as ``1/2 (x - c)^T P (x - c) + (P c)^T x - 1/2 c^T P c`` with ``tau >=
    1/2 ||L^T (x - c)||^2`` (``P = L L^T`` on its support, by its eigenvectors): one more
    polyhedral cone ``||(sqrt(sigma) L^T (x - c), tau - sigma/2)|| <= tau + sigma/2``. Its
    outer approximation loses about ``eps (tau + sigma/2)^2 / (2 sigma)`` of the objective, least
    where ``tau ~ sigma / 2``: ``sigma`` is twice the objective increase expected in a node."""
    import highspy

    n = root.n
    z_cols = np.array(sorted(root.z_col.values()), dtype=np.int64)
    col_lo = np.full(n, -math.inf)
    col_hi = np.full(n, math.inf)
    col_lo[z_cols], col_hi[z_cols] = 0.0, 1.0  # valid: z in [0, 1] in every node
    lp = LpBuilder(n, list(col_lo), list(col_hi))
    a_mat, b = root.a_mat, root.b
    lin = a_mat[: root.m_eq + root.m_le]
    depth = 1
    for idx in root.socs:
        entries = [cone_row(a_mat, b, int(i)) for i in idx[1:]]
        bn_cone(lp, cone_row(a_mat, b, int(idx[0])), entries, nu)
        depth = max(depth, tower_depth(len(entries)))
    hess = None
    offset = root.const
    full_p = (root.p_mat + root.p_mat.T - sp.diags(root.p_mat.diagonal())).tocsc()
    tau = -1
    if qp:
        hess = sp.tril(full_p).tocsc()
        lin_cost = root.q
    else:
        c = np.zeros(n) if centre is None else centre
        lin_cost = root.q + full_p @ c
        offset -= 0.5 * float(c @ (full_p @ c))
        support = np.flatnonzero(np.asarray(abs(full_p).sum(axis=0)).ravel() > 0)
        sub = full_p[support][:, support].toarray()
        # sub = V diag(lam) V^T = L L^T with L = V sqrt(lam); eigenvalues below 1e-12 of the
        # largest are dropped (a smaller objective: the bound stays valid)
        lam, vec = np.linalg.eigh(sub)
        big_lam = lam > 1e-12 * float(np.max(lam))
        chol = vec[:, big_lam] * np.sqrt(lam[big_lam] * sigma)
        ys = []
        for k in range(chol.shape[1]):
            nz = np.flatnonzero(np.abs(chol[:, k]) > 1e-14)
            ys.append(Expr(support[nz], chol[nz, k], -float(chol[nz, k] @ c[support[nz]])))
        tau = lp.new_col(0.0, math.inf)
        head = Expr(np.array([tau]), np.array([1.0]), 0.5 * sigma)
        bn_cone(lp, head, [*ys, Expr(np.array([tau]), np.array([1.0]), -0.5 * sigma)], nu)
        depth = max(depth, tower_depth(len(ys) + 1))
    cost = np.concatenate([lin_cost, np.zeros(lp.n - n)])
    if tau >= 0:
        cost[tau] = 1.0
    extra = lp.matrix()
    m_lin = lin.shape[0]
    big = sp.vstack([sp.hstack([lin, sp.csr_matrix((m_lin, lp.n - n))]), extra.tocsr()]).tocsc()
    inf = highspy.kHighsInf
    row_lo = np.concatenate([b[: root.m_eq], np.full(root.m_le, -inf), np.asarray(lp.row_lo)])
    row_hi = np.concatenate([b[: root.m_eq + root.m_le], np.asarray(lp.row_hi)])
    h_lp = highspy.HighsLp()
    h_lp.num_col_, h_lp.num_row_ = lp.n, big.shape[0]
    h_lp.col_cost_ = cost
    h_lp.offset_ = offset
    h_lp.col_lower_ = np.maximum(np.asarray(lp.col_lo), -inf)
    h_lp.col_upper_ = np.minimum(np.asarray(lp.col_hi), inf)
    h_lp.row_lower_ = np.maximum(row_lo, -inf)
    h_lp.row_upper_ = np.minimum(row_hi, inf)
    h_lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    h_lp.a_matrix_.start_ = big.indptr
    h_lp.a_matrix_.index_ = big.indices
    h_lp.a_matrix_.value_ = big.data
    h_lp.a_matrix_.num_col_, h_lp.a_matrix_.num_row_ = lp.n, big.shape[0]
    model = highspy.HighsModel()
    model.lp_ = h_lp
    if hess is not None:
        h_hess = highspy.HighsHessian()
        h_hess.dim_, h_hess.format_ = lp.n, highspy.HessianFormat.kTriangular
        start = np.concatenate([hess.indptr, np.full(lp.n - n, hess.indptr[-1])])
        h_hess.start_, h_hess.index_, h_hess.value_ = start, hess.indices, hess.data
        model.hessian_ = h_hess
    eps = (1.0 + bn_accuracy(nu)) ** depth - 1.0
    fix = np.unique(np.concatenate(list(root.member_cols.values())))
    lo, hi = np.asarray(h_lp.col_lower_)[fix], np.asarray(h_lp.col_upper_)[fix]
    return NodeLp(model, lp.n, big.shape[0], big.nnz, eps, fix, lo, hi)


# ------------------------------------------------------------------------------ HiGHS solves
#: HiGHS's dual edge weights for the node solves (1: Devex; 2, steepest edge, its default
#: choice here, pivots less but costs more per pivot and after every ``setBasis``)
EDGE_WEIGHTS = 1


def new_highs(model: Any, presolve: str = "off") -> Any:
    """A quiet one-thread HiGHS instance (dual simplex, :data:`EDGE_WEIGHTS`) holding
    ``model``."""
    import highspy

    h = highspy.Highs()
    h.setOptionValue("output_flag", False)
    h.setOptionValue("threads", 1)
    h.setOptionValue("presolve", presolve)
    h.setOptionValue("simplex_strategy", 1)
    h.setOptionValue("simplex_dual_edge_weight_strategy", EDGE_WEIGHTS)
    h.passModel(model)
    return h


def run_limited(h: Any, limit: float = 30.0) -> None:
    """``h.run()`` with at most ``limit`` seconds for this run (HiGHS's ``time_limit`` counts
    the instance's whole run time, over every earlier run)."""
    h.setOptionValue("time_limit", h.getRunTime() + limit)
    h.run()


def iterations(h: Any) -> int:
    """Simplex plus QP iterations of the last run."""
    info = h.getInfo()
    return int(info.simplex_iteration_count) + max(0, int(info.qp_iteration_count))


def highs_bound(h: Any) -> tuple[float, str]:
    """The optimum (the objective's constant included) or inf, and the model status."""
    import highspy

    status = h.getModelStatus()
    if status == highspy.HighsModelStatus.kOptimal:
        return float(h.getInfo().objective_function_value), "optimal"
    if status == highspy.HighsModelStatus.kInfeasible:
        return math.inf, "infeasible"
    return math.nan, str(status)


def cold_root(node_lp: NodeLp) -> tuple[float, int, float, str, float, int]:
    """Cold root solves: with presolve (time [s], iterations, bound, status) and without
    (time [s], iterations)."""
    out: list[Any] = []
    for presolve in ("choose", "off"):
        h = new_highs(node_lp.model, presolve)
        t0 = time.perf_counter()
        run_limited(h)
        elapsed = time.perf_counter() - t0
        bound, status = highs_bound(h)
        out.append((elapsed, iterations(h), bound, status))
    return out[0][0], out[0][1], out[0][2], out[0][3], out[1][0], out[1][1]


class WarmNodes:
    """One HiGHS instance over the fixed-shape problem: a node sets the weight columns' upper
    bounds (0: excluded) and starts from its parent's basis (the instance's own state when the
    parent was the last node solved, else ``setBasis``)."""

    def __init__(self, node_lp: NodeLp) -> None:
        self.lp = node_lp
        self.h = new_highs(node_lp.model)
        self.last: int | None = None
        self.bases: dict[int, Any] = {}

    def solve(self, node: int, parent: int | None, fixed_zero: list[int]) -> dict[str, Any]:
        """Solve ``node`` (its columns ``fixed_zero`` fixed to 0) from ``parent``'s basis; time
        [s], iterations, bound, status and whether the basis had to be set."""
        cols = self.lp.fix_cols
        off = np.isin(cols, fixed_zero)
        lower = np.where(off, 0.0, self.lp.fix_lo)
        upper = np.where(off, 0.0, self.lp.fix_hi)
        t0 = time.perf_counter()
        self.h.changeColsBounds(len(cols), cols.astype(np.int32), lower, upper)
        set_basis = parent is not None and parent != self.last
        if set_basis:
            if parent in self.bases:
                self.h.setBasis(self.bases[parent])
            else:  # the parent's solve left no valid basis: start cold
                self.h.clearSolver()
        run_limited(self.h)
        elapsed = time.perf_counter() - t0
        bound, status = highs_bound(self.h)
        self.last = node
        basis = self.h.getBasis()
        if basis.valid:
            self.bases[node] = basis
        return {"t": elapsed, "it": iterations(self.h), "bound": bound, "status": status,
                "set_basis": set_basis}  # fmt: skip


# ------------------------------------------------------------------------------ verification
def check_polytope(nu: int, n_points: int, rng: np.random.Generator) -> tuple[int, int, float]:
    """The construction on a lone cone ``||(x1, x2, x3)|| <= x0`` (a tower of two polytopes, as
    the perspective cones): points of the cone that fail to lift, points outside it by more than
    the stated accuracy (``||v|| = (1 + eps)(1 + 1e-6) x0``) that lift, and the largest
    ``||v|| / x0`` that the polytope allows in random directions (at most ``1 + eps``)."""
    import highspy

    lp = LpBuilder(4, [-math.inf] * 4, [math.inf] * 4)
    bn_cone(lp, Expr.col(0), [Expr.col(1), Expr.col(2), Expr.col(3)], nu)
    mat = lp.matrix()
    eps = (1.0 + bn_accuracy(nu)) ** 2 - 1.0
    h_lp = highspy.HighsLp()
    h_lp.num_col_, h_lp.num_row_ = lp.n, mat.shape[0]
    h_lp.col_cost_ = np.zeros(lp.n)
    h_lp.col_lower_ = np.maximum(np.asarray(lp.col_lo), -highspy.kHighsInf)
    h_lp.col_upper_ = np.minimum(np.asarray(lp.col_hi), highspy.kHighsInf)
    h_lp.row_lower_ = np.maximum(np.asarray(lp.row_lo), -highspy.kHighsInf)
    h_lp.row_upper_ = np.minimum(np.asarray(lp.row_hi), highspy.kHighsInf)
    h_lp.a_matrix_.format_ = highspy.MatrixFormat.kColwise
    h_lp.a_matrix_.start_, h_lp.a_matrix_.index_ = mat.indptr, mat.indices
    h_lp.a_matrix_.value_ = mat.data
    h_lp.a_matrix_.num_col_, h_lp.a_matrix_.num_row_ = lp.n, mat.shape[0]
    h = new_highs(h_lp, "choose")
    h.setOptionValue("primal_feasibility_tolerance", 1e-10)
    inside_cut, outside_kept = 0, 0
    idx4 = np.arange(4, dtype=np.int32)
    for k in range(2 * n_points):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        x0 = float(rng.uniform(0.1, 10.0))
        r = rng.uniform(0.0, 1.0) if k < n_points else (1.0 + eps) * (1.0 + 1e-6)
        pt = np.concatenate([[x0], r * x0 * d])
        h.changeColsBounds(4, idx4, pt, pt)
        h.run()
        feasible = h.getModelStatus() == highspy.HighsModelStatus.kOptimal
        if k < n_points and not feasible:
            inside_cut += 1
        if k >= n_points and feasible:
            outside_kept += 1
    # the largest ||v|| in random directions with x0 = 1
    h.changeColsBounds(4, idx4, np.array([1.0, -1e9, -1e9, -1e9]), np.array([1.0, 1e9, 1e9, 1e9]))
    h.changeObjectiveSense(highspy.ObjSense.kMaximize)
    worst = 0.0
    for _ in range(n_points):
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        h.changeColsCost(3, np.array([1, 2, 3], dtype=np.int32), d)
        h.run()
        v = np.asarray(h.getSolution().col_value)[1:4]
        worst = max(worst, float(np.linalg.norm(v)))
    return inside_cut, outside_kept, worst - 1.0


# ------------------------------------------------------------------------------------- dive
@dataclass
class Variant:
    """One HiGHS formulation of the node problem."""

    name: str
    nu: int
    qp: bool
    node_lp: NodeLp
    warm: WarmNodes
    records: list[dict[str, Any]] = field(default_factory=list)


def search_solve(root: Root, allowed: Allowed) -> tuple[float, float, Any]:
    """The search's own node solve (per-node assembly and Clarabel): wall time [s], Clarabel's
    share [s], and its relaxation."""
    relax = root.relax
    before = relax.solve_time
    t0 = time.perf_counter()
    res = relax.solve(allowed)
    return time.perf_counter() - t0, relax.solve_time - before, res


def dive(
    root: Root, variants: list[Variant], max_nodes: int, qp_nodes: int
) -> list[dict[str, Any]]:
    """Depth-first search from the root with the search's branching (see the module docstring);
    every node solved by the search's own solve, Clarabel on the fixed shape and every variant
    warm-started (the QP variants only the first ``qp_nodes``). Returns the exact side's records
    (the variants keep theirs)."""
    s = root.relax.s
    tol = root.relax.settings.row_tol
    stack: list[tuple[Allowed, int | None, int]] = [(root.allowed, None, 0)]
    out: list[dict[str, Any]] = []
    while stack and len(out) < max_nodes:
        allowed, parent, depth = stack.pop()
        node = len(out)
        fixed = excluded(root, allowed)
        t_search, t_clar, res = search_solve(root, allowed)
        t_fixed, b_fixed, _, _ = clarabel_fixed(root, fixed)
        exact = res.bound if res.status == "solved" else math.inf
        rec = {"node": node, "depth": depth, "t_search": t_search, "t_clarabel": t_clar,
               "t_fixed": t_fixed, "exact": exact, "fixed": b_fixed, "status": res.status,
               "full": res.full}  # fmt: skip
        out.append(rec)
        for var in variants:
            if var.qp and node >= qp_nodes:
                continue
            var.records.append(var.warm.solve(node, parent, fixed))
        if res.status != "solved" or res.x is None or exact >= root.objective:
            continue
        children = _branch(s, res.x, allowed, tol)
        if children is None:
            continue
        for child in children:
            stack.append((child, node, depth + 1))
    return out


# ---------------------------------------------------------------------------------- summary
def pct(a: list[float] | np.ndarray, p: float) -> float:
    """The ``p``-th percentile (nan when empty)."""
    return float(np.percentile(a, p)) if len(a) else math.nan


def summarise(root: Root, exact: list[dict[str, Any]], variants: list[Variant]) -> list[str]:
    """Table rows (markdown) per variant, the search's node solve first."""
    obj = root.objective
    cut = obj - 1e-4 * abs(obj)  # a node whose bound reaches this closes at the search's gap
    t_search = np.array([r["t_search"] for r in exact[1:]])
    t_clar = np.array([r["t_clarabel"] for r in exact[1:]])
    rows = [
        f"| search's node solve (assembly + Clarabel) | - | - | {np.median(t_search) * 1e3:.2f} / "
        f"{pct(t_search, 90) * 1e3:.2f} ms (Clarabel alone {np.median(t_clar) * 1e3:.2f}) | 1 | "
        f"- | - | - | {sum(r['exact'] >= cut for r in exact)} |"
    ]
    for var in variants:
        recs = var.records
        t = np.array([r["t"] for r in recs[1:]])
        ratio = t / t_search[: len(t)]
        its = [r["it"] for r in recs[1:]]
        loss = []
        missed = 0
        for e, r in zip(exact, recs, strict=False):
            if math.isfinite(e["exact"]) and math.isfinite(r["bound"]):
                loss.append((e["exact"] - r["bound"]) / abs(e["exact"]))
            if e["exact"] >= cut and not r["bound"] >= cut:
                missed += 1
        loss_a = np.array(loss) if loss else np.array([math.nan])
        n_set = sum(r["set_basis"] for r in recs[1:])
        hot = [r["it"] for r in recs[1:] if not r["set_basis"]]
        cold = [r["it"] for r in recs[1:] if r["set_basis"]]
        per_pivot = float(np.sum(t) / max(1, int(np.sum(its))))
        rows.append(
            f"| {var.name} | {var.node_lp.n_cols} x {var.node_lp.n_rows} ({var.node_lp.nnz} nnz) "
            f"| {var.node_lp.eps:.1e} | {np.median(t) * 1e3:.2f} / {pct(t, 90) * 1e3:.2f} ms "
            f"| {np.median(ratio):.2f} (p90 {pct(ratio, 90):.2f}) "
            f"| {np.median(its):.0f} (p90 {pct(its, 90):.0f}; {per_pivot * 1e6:.0f} us each; "
            f"{n_set} of {len(t)} set a basis) | {pct(hot, 50):.0f} / {pct(cold, 50):.0f} "
            f"| {pct(loss_a, 50):.1e} / {pct(loss_a, 90):.1e} / {np.max(loss_a):.1e} "
            f"| {sum(r['exact'] >= cut for r in exact) - missed} ({missed} missed) |"
        )
    return rows


def run_instance(steps: int, seed: int, nus: list[int], qp: int, max_nodes: int) -> None:
    """Capture, check and dive one instance (the QP variants on the first ``qp`` nodes only);
    prints its table."""
    qp_nodes = qp
    t0 = time.perf_counter()
    root = capture(steps, seed)
    t_plan = time.perf_counter() - t0
    t_fix, b_fix, st_fix, x_root = clarabel_fixed(root, [])
    sigma = 2.0 * max(root.objective - b_fix, 1e-3)
    print(f"\n### N = {steps}, seed {seed}\n")
    print(
        f"root: {root.n} columns, {root.a_mat.shape[0]} rows, {len(root.socs)} cones (dims "
        f"{sorted({len(i) for i in root.socs})}), Hessian on "
        f"{len(np.unique(root.p_mat.indices))} columns; planner: objective {root.objective:.6f}, "
        f"root bound {root.planner_root_bound:.9f}, plan {t_plan:.1f} s; Clarabel again: "
        f"{b_fix:.9f} ({st_fix}, {t_fix * 1e3:.2f} ms)"
    )
    variants = []
    for nu in nus:
        for as_qp in [False, True] if qp > 0 and nu == nus[-1] else [False]:
            node_lp = build_lp(root, nu, as_qp, x_root, sigma)
            name = f"{'QP' if as_qp else 'LP'} nu={nu}"
            t_c, it_c, b_c, st_c, t_c0, it_c0 = cold_root(node_lp)
            print(
                f"{name}: eps(nu) = {bn_accuracy(nu):.2e} per 3-cone, {node_lp.eps:.2e} overall; "
                f"{node_lp.n_cols} columns, {node_lp.n_rows} rows, {node_lp.nnz} nnz; cold root "
                f"{t_c * 1e3:.1f} ms ({it_c} iterations; without presolve {t_c0 * 1e3:.1f} ms, "
                f"{it_c0}), bound {b_c:.9f} ({st_c}), loss {(b_fix - b_c) / abs(b_fix):.2e} "
                f"relative, {t_c / t_fix:.1f}x Clarabel's root"
            )
            variants.append(Variant(name, nu, as_qp, node_lp, WarmNodes(node_lp)))
    exact = dive(root, variants, max_nodes, qp_nodes)
    bad = [r for r in exact if r["status"] == "solved" and not r["full"]
           and abs(r["exact"] - r["fixed"]) > 1e-5 * max(1.0, abs(r["exact"]))]  # fmt: skip
    n_inf = sum(r["status"] == "infeasible" for r in exact)
    print(
        f"dive: {len(exact)} nodes, max depth {max(r['depth'] for r in exact)}, {n_inf} "
        f"infeasible, {sum(r['full'] for r in exact)} escalated to the full model; fixed-shape "
        f"Clarabel bound differs from the search's at {len(bad)} nodes; fixed-shape Clarabel "
        f"median {np.median([r['t_fixed'] for r in exact]) * 1e3:.2f} ms"
    )
    for var in variants:
        wrong = [
            (e["exact"], r["bound"]) for e, r in zip(exact, var.records, strict=False)
            if r["bound"] > e["exact"] + 1e-6 * max(1.0, abs(e["exact"]))
        ]  # fmt: skip
        lp_inf = sum(r["status"] == "infeasible" for r in var.records)
        t0 = time.perf_counter()
        run_limited(var.warm.h)  # nothing changed: the cost of a run that needs no pivot
        t_again, it_again = time.perf_counter() - t0, iterations(var.warm.h)
        other = {r["status"] for r in var.records} - {"optimal", "infeasible"}
        print(
            f"  {var.name}: LP bound above the exact one at {len(wrong)} nodes "
            f"{wrong[:3]}; {lp_inf} infeasible; other statuses {sorted(other)}; a re-run "
            f"without change {t_again * 1e3:.2f} ms ({it_again} iterations)"
        )
    print(
        "\n| solver | size (cols x rows) | eps | node time median / p90 | time / search's, "
        "per node | simplex iterations | iterations: child of the last node / basis set | bound loss median / p90 / max | prunable nodes "
        "pruned |\n|---|---|---|---|---|---|---|---|---|"
    )
    for row in summarise(root, exact, variants):
        print(row)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="10,15", help="footsteps N, comma-separated")
    ap.add_argument("--seeds", default="0", help="random stepping stones seeds, comma-separated")
    ap.add_argument("--nus", default="5,6,7,8", help="polytope depths, comma-separated")
    ap.add_argument("--nodes", type=int, default=300, help="nodes of the depth-first search")
    ap.add_argument(
        "--qp",
        type=int,
        default=0,
        help="nodes to solve with HiGHS's QP solver too, at the last --nus depth (slow)",
    )
    ap.add_argument(
        "--edge-weights", type=int, default=1, help="HiGHS dual edge weights (1 Devex, 2 DSE)"
    )
    ap.add_argument(
        "--no-substitute", action="store_true", help="keep the polytopes' xi_j as columns"
    )
    ap.add_argument("--check-points", type=int, default=200, help="points of the cone check")
    args = ap.parse_args()
    try:
        steps = [int(v) for v in args.steps.split(",")]
        seeds = [int(v) for v in args.seeds.split(",")]
        nus = [int(v) for v in args.nus.split(",")]
    except ValueError:
        ap.error("--steps, --seeds and --nus are comma-separated integers")
    if min(steps) < 1 or min(nus) < 1 or args.nodes < 1:
        ap.error("--steps, --nus and --nodes must be >= 1")
    try:
        import highspy  # noqa: F401
    except ImportError:
        ap.error("HiGHS is not installed: pip install highspy (not a footfall dependency)")
    global EDGE_WEIGHTS, SUBSTITUTE_XI
    EDGE_WEIGHTS = args.edge_weights
    SUBSTITUTE_XI = not args.no_substitute
    rng = np.random.default_rng(0)
    print("polytope check on ||(x1, x2, x3)|| <= x0 (two levels of 3-cones):")
    for nu in nus:
        cut, kept, worst = check_polytope(nu, args.check_points, rng)
        eps = (1.0 + bn_accuracy(nu)) ** 2 - 1.0
        print(
            f"  nu = {nu}: eps {eps:.3e}; cone points cut {cut}/{args.check_points}; points "
            f"outside by > eps kept {kept}/{args.check_points}; largest ||v||/x0 - 1 found "
            f"{worst:.3e}"
        )
    for n_steps in steps:
        for seed in seeds:
            run_instance(n_steps, seed, nus, args.qp, args.nodes)


if __name__ == "__main__":
    main()
