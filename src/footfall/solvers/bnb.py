"""Branch and bound on convex-hull relaxations, with Clarabel as the node solver.

This backend solves the :class:`~footfall.solvers.problem.MIQCQP` exactly as built (same variables,
rows, cones and objective), for problems of the shape the footstep planner builds (document 000,
eq. 5.11-5.18):

* every integer variable is a binary and belongs to exactly one *choice group*: an equality row
  ``sum_{z in G} z = 1`` (one region per footstep, eq. 5.12j; one heading segment, eq. 5.12k);
* every inequality row holds at most one binary ``z``, as a big-M row ``a^T x + M z <= b`` with
  ``M > 0`` whose ``z = 0`` form ``a^T x <= b`` is implied by the variable bounds (rows built by
  :meth:`ProblemBuilder.add_le_big_m`); it reads "z = 1 implies a^T x <= b - M";
* binaries do not appear in the objective, the cones or other equality rows.

Relaxation (Balas' extended formulation of each disjunction). For a group ``G`` whose allowed
members at a node are ``Z``, let ``V`` be the continuous variables of its indicator rows. Each member
``z`` gets a copy ``y^z`` of ``x_V`` and

    x_V = sum_{z in Z} y^z,   lb_V z <= y^z <= ub_V z,   a^T y^z <= (b - M) z  (rows of z),

with ``z`` in [0, 1] (the group row gives ``sum z = 1``). This is the convex hull of the union of
the member sets intersected with the bounds, the tightest convex relaxation of each group, where
big-M only gives its bounding box. Excluded members are fixed to 0; a group with one allowed
member gets its rows on ``x`` directly. Everything else (dynamics, cones, objective) is kept as is,
so a node whose relaxation has every group at a vertex (one ``z = 1``) is feasible for the MIQCQP and
its value is exact.

Search: best-first on the relaxation bound; a node branches on its most fractional group by
splitting the allowed members (in index order, which for heading segments is the angle order) where
the cumulative weight crosses 1/2 (SOS1 branching); children are solved at once and pruned against
the incumbent. Incumbents come from relaxation solutions that are already integral and from
rounding (each group to its largest weight, then one convex solve). The search stops when
``(incumbent - bound) / |incumbent| <= gap`` (SCIP's definition) or at the time limit, with the best
plan and an honest gap.
"""

from __future__ import annotations

import heapq
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall.solvers.base import SolverOptions, SolverResult, SolveStatus
from footfall.solvers.problem import MIQCQP

NAME = "bnb"

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: a relaxation weight within this of 0 or 1 counts as integral
INT_TOL = 1e-6
#: largest violation [problem units] accepted for a solution returned to the caller
FEAS_TOL = 1e-6
#: the z = 0 form of a big-M row must be implied by the bounds within this
REDUNDANT_TOL = 1e-7
#: a member's indicator rows count as satisfied by a relaxation solution within this
ROW_TOL = 1e-7
#: try rounding the relaxation solution to an incumbent at every this many nodes
ROUNDING_EVERY = 8


class UnsupportedProblem(ValueError):
    """The problem does not have the choice-group / big-M shape this backend handles."""


@dataclass(frozen=True)
class _Member:
    """Indicator rows of one binary: ``a^T x <= beta`` when the binary is 1.

    ``rows``, ``cols``, ``vals`` are COO entries (row numbering local to the member, columns are
    original variable indices), ``beta`` the right-hand sides, ``pos`` the position of each column
    in the group's variable list ``V``.
    """

    var: int
    rows: IntArray
    cols: IntArray
    vals: FloatArray
    beta: FloatArray
    pos: IntArray


@dataclass(frozen=True)
class _Group:
    members: tuple[int, ...]  # binary variable indices, ascending
    variables: IntArray  # V: continuous variables of the indicator rows


@dataclass
class _Structure:
    """The problem split into its static convex part and its choice groups."""

    problem: MIQCQP
    groups: list[_Group]
    member: dict[int, _Member]
    group_of: dict[int, int]
    plain_le: sp.csr_matrix
    plain_b: FloatArray
    p_mat: sp.csc_matrix  # Clarabel's P (upper triangle) over the original variables
    q_vec: FloatArray
    const: float


def analyse(problem: MIQCQP) -> _Structure:
    """Split ``problem`` into choice groups and indicator rows; raise :class:`UnsupportedProblem`."""
    n = problem.n
    integer = problem.integer
    if np.any(integer & ((problem.lb < 0.0) | (problem.ub > 1.0))):
        raise UnsupportedProblem("integer variables must be binaries")
    a_eq = problem.a_eq.tocsr()
    groups: list[_Group] = []
    group_of: dict[int, int] = {}
    group_rows: list[list[int]] = []
    for r in range(a_eq.shape[0]):
        cols = a_eq.indices[a_eq.indptr[r] : a_eq.indptr[r + 1]]
        vals = a_eq.data[a_eq.indptr[r] : a_eq.indptr[r + 1]]
        ints = integer[cols]
        if not np.any(ints):
            continue
        if not (np.all(ints) and np.allclose(vals, 1.0) and abs(problem.b_eq[r] - 1.0) < 1e-12):
            raise UnsupportedProblem(f"equality row {problem.eq_labels[r]!r} mixes binaries")
        for c in cols:
            if int(c) in group_of:
                raise UnsupportedProblem(f"binary {problem.names[c]} is in two choice groups")
            group_of[int(c)] = len(group_rows)
        group_rows.append(sorted(int(c) for c in cols))
    for c in np.flatnonzero(integer):
        if int(c) not in group_of:
            raise UnsupportedProblem(f"binary {problem.names[c]} is in no choice group")
    for mat, what in ((problem.cost_matrix, "objective"),):
        if mat.shape[0] and np.any(integer[mat.tocsc().indices]):
            raise UnsupportedProblem(f"binaries in the {what}")
    for idx, _ in problem.cones:
        if np.any(integer[idx]):
            raise UnsupportedProblem("binaries in a cone")

    a_le = problem.a_le.tocsr()
    plain: list[int] = []
    ind_rows: dict[int, list[tuple[IntArray, FloatArray, float]]] = {}
    for r in range(a_le.shape[0]):
        cols = a_le.indices[a_le.indptr[r] : a_le.indptr[r + 1]]
        vals = a_le.data[a_le.indptr[r] : a_le.indptr[r + 1]]
        ints = integer[cols]
        k = int(np.count_nonzero(ints))
        if k == 0:
            plain.append(r)
            continue
        if k > 1 or vals[ints][0] <= 0.0:
            raise UnsupportedProblem(f"row {problem.le_labels[r]!r} is not a big-M row")
        z = int(cols[ints][0])
        big_m = float(vals[ints][0])
        cc, vv = cols[~ints].astype(np.int64), vals[~ints].astype(float)
        top = float(np.sum(np.where(vv > 0, vv * problem.ub[cc], vv * problem.lb[cc])))
        if not math.isfinite(top) or top > problem.b_le[r] + REDUNDANT_TOL * max(1.0, abs(top)):
            raise UnsupportedProblem(f"row {problem.le_labels[r]!r}: its z = 0 form is not implied")
        ind_rows.setdefault(z, []).append((cc, vv, float(problem.b_le[r]) - big_m))

    member: dict[int, _Member] = {}
    for g, mem in enumerate(group_rows):
        cols_all = sorted({int(c) for z in mem for cc, _, _ in ind_rows.get(z, []) for c in cc})
        variables = np.array(cols_all, dtype=np.int64)
        where = {c: k for k, c in enumerate(cols_all)}
        for z in mem:
            rr, cc_l, vv_l, beta = [], [], [], []
            for j, (cc, vv, bb) in enumerate(ind_rows.get(z, [])):
                rr.append(np.full(len(cc), j, dtype=np.int64))
                cc_l.append(cc)
                vv_l.append(vv)
                beta.append(bb)
            cols = np.concatenate(cc_l) if cc_l else np.zeros(0, dtype=np.int64)
            member[z] = _Member(
                var=z,
                rows=np.concatenate(rr) if rr else np.zeros(0, dtype=np.int64),
                cols=cols,
                vals=np.concatenate(vv_l) if vv_l else np.zeros(0),
                beta=np.array(beta, dtype=float),
                pos=np.array([where[int(c)] for c in cols], dtype=np.int64),
            )
        for c in cols_all:
            if not (math.isfinite(problem.lb[c]) and math.isfinite(problem.ub[c])):
                raise UnsupportedProblem(f"{problem.names[c]} is in an indicator row but unbounded")
        groups.append(_Group(members=tuple(mem), variables=variables))

    w = problem.cost_weight
    f_mat = problem.cost_matrix.tocsr()
    wf = sp.diags(w) @ f_mat
    p_full = 2.0 * (f_mat.T @ wf)
    p_mat = sp.triu(p_full, format="csc")
    q_vec = -2.0 * np.asarray(wf.T @ problem.cost_target).ravel()
    const = float(np.sum(w * problem.cost_target**2))
    return _Structure(
        problem=problem,
        groups=groups,
        member=member,
        group_of=group_of,
        plain_le=a_le[plain],
        plain_b=problem.b_le[plain],
        p_mat=p_mat,
        q_vec=q_vec,
        const=const,
    )


@dataclass
class _Relaxation:
    """Result of one node relaxation."""

    status: str  # "solved", "infeasible", "failed"
    bound: float = math.inf
    x: FloatArray | None = None  # original variables only
    iterations: int = 0


class _Coo:
    """Row blocks collected as COO arrays."""

    def __init__(self) -> None:
        self.r: list[IntArray] = []
        self.c: list[IntArray] = []
        self.v: list[FloatArray] = []
        self.b: list[FloatArray] = []
        self.m = 0

    def add(self, rows: IntArray, cols: IntArray, vals: FloatArray, rhs: FloatArray) -> None:
        self.r.append(rows + self.m)
        self.c.append(cols)
        self.v.append(vals)
        self.b.append(rhs)
        self.m += len(rhs)

    def add_csr(self, mat: sp.csr_matrix, rhs: FloatArray) -> None:
        coo = mat.tocoo()
        self.add(coo.row.astype(np.int64), coo.col.astype(np.int64), coo.data.astype(float), rhs)


class HullRelaxation:
    """Builds and solves the node relaxation of :mod:`footfall.solvers.bnb` (see module docstring)."""

    def __init__(self, structure: _Structure) -> None:
        import clarabel

        self._clarabel = clarabel
        self.s = structure
        pr = structure.problem
        n = pr.n
        # Static rows: equalities (with the group rows), plain inequalities, bounds and cones.
        eq = _Coo()
        eq.add_csr(pr.a_eq.tocsr(), pr.b_eq)
        self._eq = eq
        le = _Coo()
        le.add_csr(structure.plain_le, structure.plain_b)
        cont = np.flatnonzero(~pr.integer)
        fin_u = cont[np.isfinite(pr.ub[cont])]
        fin_l = cont[np.isfinite(pr.lb[cont])]
        le.add(np.arange(len(fin_u)), fin_u, np.ones(len(fin_u)), pr.ub[fin_u])
        le.add(np.arange(len(fin_l)), fin_l, -np.ones(len(fin_l)), -pr.lb[fin_l])
        self._le = le
        self._binaries = np.flatnonzero(pr.integer)
        soc_r, soc_c, soc_v, soc_b, dims = [], [], [], [], []
        m = 0
        for idx, radius in pr.cones:
            k = len(idx)
            soc_r.append(np.arange(1, k + 1) + m)
            soc_c.append(np.asarray(idx, dtype=np.int64))
            soc_v.append(-np.ones(k))
            b = np.zeros(k + 1)
            b[0] = radius
            soc_b.append(b)
            dims.append(k + 1)
            m += k + 1
        self._soc = (
            np.concatenate(soc_r) if soc_r else np.zeros(0, dtype=np.int64),
            np.concatenate(soc_c) if soc_c else np.zeros(0, dtype=np.int64),
            np.concatenate(soc_v) if soc_v else np.zeros(0),
            np.concatenate(soc_b) if soc_b else np.zeros(0),
            dims,
            m,
        )
        self.n = n
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        self._settings = settings
        self.solves = 0
        self.solve_time = 0.0

    def solve(self, allowed: tuple[tuple[int, ...], ...]) -> _Relaxation:
        """Solve the relaxation where group ``g`` may use only the binaries ``allowed[g]``."""
        s = self.s
        pr = s.problem
        n = self.n
        ncol = n
        eq_r, eq_c, eq_v, eq_b = list(self._eq.r), list(self._eq.c), list(self._eq.v), []
        eq_b = list(self._eq.b)
        m_eq = self._eq.m
        le_r, le_c, le_v, le_b = list(self._le.r), list(self._le.c), list(self._le.v), []
        le_b = list(self._le.b)
        m_le = self._le.m
        # binaries: 0 <= z <= 1 (allowed) or z = 0 (excluded)
        zb_ub = np.zeros(pr.n)
        for g, mem in enumerate(allowed):
            del g
            zb_ub[list(mem)] = 1.0
        bins = self._binaries
        le_r.append(np.arange(len(bins)) + m_le)
        le_c.append(bins)
        le_v.append(np.ones(len(bins)))
        le_b.append(zb_ub[bins])
        m_le += len(bins)
        le_r.append(np.arange(len(bins)) + m_le)
        le_c.append(bins)
        le_v.append(-np.ones(len(bins)))
        le_b.append(np.zeros(len(bins)))
        m_le += len(bins)
        for g, mem in enumerate(allowed):
            grp = s.groups[g]
            if len(mem) == 1:
                mb = s.member[mem[0]]
                if len(mb.beta):
                    le_r.append(mb.rows + m_le)
                    le_c.append(mb.cols)
                    le_v.append(mb.vals)
                    le_b.append(mb.beta)
                    m_le += len(mb.beta)
                continue
            nv = len(grp.variables)
            if nv == 0:
                continue
            # linking x_V - sum_z y^z = 0
            eq_r.append(np.arange(nv) + m_eq)
            eq_c.append(grp.variables)
            eq_v.append(np.ones(nv))
            for _ in mem:
                eq_r.append(np.arange(nv) + m_eq)
                eq_c.append(ncol + np.arange(nv))
                eq_v.append(-np.ones(nv))
                ncol += nv
            ncol -= nv * len(mem)
            eq_b.append(np.zeros(nv))
            m_eq += nv
            lbv, ubv = pr.lb[grp.variables], pr.ub[grp.variables]
            for z in mem:
                mb = s.member[z]
                ycols = ncol + np.arange(nv)
                # y - ub z <= 0 ; -y + lb z <= 0
                rr = np.arange(nv) + m_le
                le_r += [rr, rr, rr + nv, rr + nv]
                le_c += [ycols, np.full(nv, z), ycols, np.full(nv, z)]
                le_v += [np.ones(nv), -ubv, -np.ones(nv), lbv]
                le_b.append(np.zeros(2 * nv))
                m_le += 2 * nv
                if len(mb.beta):
                    k = len(mb.beta)
                    le_r += [mb.rows + m_le, np.arange(k) + m_le]
                    le_c += [ncol + mb.pos, np.full(k, z)]
                    le_v += [mb.vals, -mb.beta]
                    le_b.append(np.zeros(k))
                    m_le += k
                ncol += nv
        soc_r, soc_c, soc_v, soc_b, dims, m_soc = self._soc
        rows = np.concatenate([*eq_r, *(r + m_eq for r in le_r), soc_r + m_eq + m_le])
        cols = np.concatenate([*eq_c, *le_c, soc_c])
        vals = np.concatenate([*eq_v, *le_v, soc_v])
        b = np.concatenate([*eq_b, *le_b, soc_b])
        a_mat = sp.csc_matrix((vals, (rows, cols)), shape=(m_eq + m_le + m_soc, ncol))
        p_mat = sp.csc_matrix(
            (s.p_mat.data, s.p_mat.indices, np.r_[s.p_mat.indptr, [s.p_mat.nnz] * (ncol - n)]),
            shape=(ncol, ncol),
        )
        q = np.zeros(ncol)
        q[:n] = s.q_vec
        cl = self._clarabel
        cones: list[Any] = [cl.ZeroConeT(m_eq), cl.NonnegativeConeT(m_le)]
        cones += [cl.SecondOrderConeT(d) for d in dims]
        t0 = time.perf_counter()
        solver = cl.DefaultSolver(p_mat, q, a_mat, b, cones, self._settings)
        sol = solver.solve()
        self.solve_time += time.perf_counter() - t0
        self.solves += 1
        status = str(sol.status)
        if status in ("Solved", "AlmostSolved"):
            bound = min(float(sol.obj_val), float(sol.obj_val_dual)) + s.const
            return _Relaxation("solved", bound, np.asarray(sol.x)[:n], int(sol.iterations))
        if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
            return _Relaxation("infeasible", iterations=int(sol.iterations))
        return _Relaxation("failed", iterations=int(sol.iterations))


@dataclass(order=True)
class _Node:
    bound: float
    order: int
    allowed: tuple[tuple[int, ...], ...] = field(compare=False)
    x: FloatArray | None = field(compare=False, default=None)
    depth: int = field(compare=False, default=0)


def _weights(x: FloatArray, mem: tuple[int, ...]) -> FloatArray:
    return np.clip(x[list(mem)], 0.0, 1.0)


def _violations(s: _Structure, x: FloatArray, mem: tuple[int, ...]) -> FloatArray:
    """Largest violation of each member's indicator rows at ``x``, shape (len(mem),)."""
    out = np.empty(len(mem))
    for k, z in enumerate(mem):
        mb = s.member[z]
        if not len(mb.beta):
            out[k] = 0.0
            continue
        lhs = np.bincount(mb.rows, weights=mb.vals * x[mb.cols], minlength=len(mb.beta))
        out[k] = float(np.max(lhs - mb.beta))
    return out


def _choice(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[int, ...], ...] | None:
    """A member per group whose rows ``x`` satisfies within ``tol`` (None if some group has none).

    ``x`` then is a feasible point of the MIQCQP with those binaries set to 1: the relaxation solution
    is integer feasible even when the IPM spread the weights over several equally good members.
    """
    out = []
    for mem in allowed:
        if len(mem) == 1:
            out.append(mem)
            continue
        v = _violations(s, x, mem)
        k = int(np.argmin(v))
        if v[k] > tol:
            return None
        out.append((mem[k],))
    return tuple(out)


def _rounded(x: FloatArray, allowed: tuple[tuple[int, ...], ...]) -> tuple[tuple[int, ...], ...]:
    return tuple(m if len(m) == 1 else (m[int(np.argmax(_weights(x, m)))],) for m in allowed)


def _branch(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[tuple[int, ...], ...], tuple[tuple[int, ...], ...]] | None:
    """Split the group whose best member is violated most, at the weighted mean member position."""
    best, best_g = tol, -1
    for g, mem in enumerate(allowed):
        if len(mem) < 2:
            continue
        viol = float(np.min(_violations(s, x, mem)))
        if viol > best:
            best, best_g = viol, g
    if best_g < 0:
        return None
    mem = allowed[best_g]
    w = _weights(x, mem)
    centre = float(np.dot(w, np.arange(len(mem)))) / max(float(np.sum(w)), 1e-12)
    k = min(max(round(centre + 0.5), 1), len(mem) - 1)
    left = [*allowed]
    right = [*allowed]
    left[best_g] = mem[:k]
    right[best_g] = mem[k:]
    return tuple(left), tuple(right)


def _finish(pr: MIQCQP, x: FloatArray, chosen: tuple[tuple[int, ...], ...]) -> FloatArray:
    """The relaxation solution as a MIQCQP point: binaries of the chosen members set to 1."""
    out = x.copy()
    out[pr.integer] = 0.0
    for mem in chosen:
        out[mem[0]] = 1.0
    return out


def solve(problem: MIQCQP, options: SolverOptions) -> SolverResult:
    """Solve ``problem`` by branch and bound on hull relaxations (see the module docstring)."""
    start = time.perf_counter()
    deadline = start + options.time_limit
    structure = analyse(problem)
    relax = HullRelaxation(structure)
    root_allowed = tuple(g.members for g in structure.groups)
    incumbent: FloatArray | None = None
    inc_obj = math.inf
    tried: set[tuple[tuple[int, ...], ...]] = set()
    nodes = 0
    counter = 0

    def offer(x: FloatArray, chosen: tuple[tuple[int, ...], ...]) -> None:
        nonlocal incumbent, inc_obj
        cand = _finish(problem, x, chosen)
        if problem.violation(cand) > FEAS_TOL:
            return
        obj = problem.objective(cand)
        if obj < inc_obj:
            incumbent, inc_obj = cand, obj

    def try_rounding(x: FloatArray, allowed: tuple[tuple[int, ...], ...]) -> None:
        fixed = _rounded(x, allowed)
        if fixed in tried:
            return
        tried.add(fixed)
        res = relax.solve(fixed)
        if res.status == "solved" and res.x is not None:
            offer(res.x, fixed)

    if options.initial_solution is not None:
        x0 = np.asarray(options.initial_solution, dtype=float)
        if problem.violation(x0) <= FEAS_TOL:
            incumbent, inc_obj = x0.copy(), problem.objective(x0)

    def gap_of(bound: float) -> float:
        if not math.isfinite(inc_obj):
            return math.inf
        if inc_obj <= bound:
            return 0.0
        denom = min(abs(inc_obj), abs(bound))
        return math.inf if denom == 0.0 else (inc_obj - bound) / denom

    heap: list[_Node] = []
    failed = False

    def evaluate(allowed: tuple[tuple[int, ...], ...], parent_bound: float, depth: int) -> None:
        """Solve a node; keep it when it may hold a better plan than the incumbent."""
        nonlocal nodes, counter, failed
        res = relax.solve(allowed)
        nodes += 1
        if res.status == "failed":
            failed = True
            return
        if res.status != "solved" or res.x is None:
            return
        bound = max(res.bound, parent_bound)
        chosen = _choice(structure, res.x, allowed, ROW_TOL)
        if chosen is not None:
            offer(res.x, chosen)  # the relaxation optimum is feasible: the node is solved
            return
        if bound >= inc_obj:
            return
        heapq.heappush(heap, _Node(bound, counter, allowed, res.x, depth))
        counter += 1
        if depth == 0 or nodes % ROUNDING_EVERY == 0:
            try_rounding(res.x, allowed)

    evaluate(root_allowed, -math.inf, 0)
    timed_out = False
    while heap:
        if gap_of(heap[0].bound) <= options.gap:
            break
        if time.perf_counter() > deadline:
            timed_out = True
            break
        node = heapq.heappop(heap)
        if node.bound >= inc_obj:
            continue
        assert node.x is not None
        split = _branch(structure, node.x, node.allowed, ROW_TOL)
        if split is None:  # pragma: no cover - evaluate() resolved such nodes
            continue
        for child in split:
            evaluate(child, node.bound, node.depth + 1)

    best_bound = min((nd.bound for nd in heap), default=inc_obj)
    if incumbent is None:
        if timed_out:
            status = SolveStatus.TIME_LIMIT
        elif failed:
            status = SolveStatus.ERROR
        else:
            status = SolveStatus.INFEASIBLE
        gap = math.inf
    else:
        gap = max(0.0, gap_of(best_bound))
        if failed:
            status = SolveStatus.FEASIBLE
        elif gap <= options.gap:
            status = SolveStatus.OPTIMAL
        elif timed_out:
            status = SolveStatus.TIME_LIMIT
        else:
            status = SolveStatus.FEASIBLE
    return SolverResult(
        status=status,
        x=incumbent,
        objective=inc_obj if incumbent is not None else math.nan,
        bound=best_bound if math.isfinite(best_bound) else math.nan,
        gap=gap,
        solve_time=time.perf_counter() - start,
        solver=NAME,
        stats={
            "raw_status": status.value,
            "nodes": nodes,
            "relaxations": relax.solves,
            "relaxation_time_s": relax.solve_time,
            "variables": problem.n,
            "integer_variables": problem.n_integer,
            "groups": len(structure.groups),
        },
    )
