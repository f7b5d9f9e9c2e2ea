"""The static parts of the node relaxation, as flat templates a node masks.

A *base* holds the convex part common to every node: all variables (``full``: exact at integral
nodes) or, when the problem allows it, the condensed one (:func:`_condensed_base`: the ALIP
states and torques of eq. 5.12a-d eliminated through one KKT solve, a lower bound). The
*templates* (:func:`_templates`) hold, for every member of every group, its hull rows, its
perspective cone, its direct rows (when it is its group's only member) and the linking rows of
its group, so that :meth:`footfall.solvers.bnb.relaxation.HullRelaxation.solve` assembles a
node by masking arrays instead of looping over members.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall.solvers.bnb.model import _Group, _Member, _Structure
from footfall.solvers.problem import MIQCQP


class _Coo:
    """Row blocks collected as COO arrays."""

    def __init__(self) -> None:
        self.r: list[IntArray] = []
        self.c: list[IntArray] = []
        self.v: list[FloatArray] = []
        self.b: list[FloatArray] = []
        self.m = 0

    def add(self, rows: IntArray, cols: IntArray, vals: FloatArray, rhs: FloatArray) -> None:
        self.r.append(np.asarray(rows, dtype=np.int64) + self.m)
        self.c.append(np.asarray(cols, dtype=np.int64))
        self.v.append(np.asarray(vals, dtype=float))
        self.b.append(np.asarray(rhs, dtype=float))
        self.m += len(rhs)

    def add_csr(self, mat: sp.csr_matrix, rhs: FloatArray) -> None:
        coo = mat.tocoo()
        self.add(coo.row, coo.col, coo.data, rhs)

    def copy(self) -> _Coo:
        out = _Coo()
        out.r, out.c, out.v, out.b, out.m = [*self.r], [*self.c], [*self.v], [*self.b], self.m
        return out


@dataclass
class _Base:
    """The node-independent part of a relaxation over ``n_cols`` columns.

    ``col`` maps original variables to columns (-1: condensed out). For a condensed base the
    eliminated variables ``y`` are recovered as ``y = y_lin @ x[y_from] + y_off``.
    """

    n_cols: int
    col: IntArray
    eq: _Coo
    le: _Coo
    soc: _Coo
    soc_dims: list[int]
    p_mat: sp.csc_matrix  # Clarabel's P (upper triangle), n_cols x n_cols
    q_vec: FloatArray
    const: float
    y_idx: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    y_from: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    y_lin: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    y_off: FloatArray = field(default_factory=lambda: np.zeros(0))


def _cost_pq(
    f_mat: sp.csr_matrix, target: FloatArray, weight: FloatArray
) -> tuple[sp.csc_matrix, FloatArray, float]:
    """``sum w (F x - f)^2`` as Clarabel's ``(1/2) x^T P x + q^T x + const``."""
    wf = sp.diags(weight) @ f_mat
    p_mat = sp.triu(2.0 * (f_mat.T @ wf), format="csc")
    q_vec = -2.0 * np.asarray(wf.T @ target).ravel()
    return p_mat, q_vec, float(np.sum(weight * target**2))


def _full_base(s: _Structure) -> _Base:
    """All variables, rows, bounds and cones of the problem (binaries' bounds are per node)."""
    pr = s.problem
    eq = _Coo()
    eq.add_csr(pr.a_eq.tocsr(), pr.b_eq)
    le = _Coo()
    le.add_csr(s.plain_le, s.plain_b)
    cont = np.flatnonzero(~pr.integer)
    fin_u = cont[np.isfinite(pr.ub[cont])]
    fin_l = cont[np.isfinite(pr.lb[cont])]
    le.add(np.arange(len(fin_u)), fin_u, np.ones(len(fin_u)), pr.ub[fin_u])
    le.add(np.arange(len(fin_l)), fin_l, -np.ones(len(fin_l)), -pr.lb[fin_l])
    soc = _Coo()
    dims = []
    for idx, radius in pr.cones:
        k = len(idx)
        b = np.zeros(k + 1)
        b[0] = radius
        soc.add(np.arange(1, k + 1), idx, -np.ones(k), b)
        dims.append(k + 1)
    keep = ~s.assigned
    p_mat, q_vec, const = _cost_pq(
        pr.cost_matrix.tocsr()[keep], pr.cost_target[keep], pr.cost_weight[keep]
    )
    return _Base(pr.n, np.arange(pr.n, dtype=np.int64), eq, le, soc, dims, p_mat, q_vec, const)


def _with_prefix(s: _Structure, base: _Base) -> _Base:
    """``base`` with the prefix columns of the staircase links (see :func:`_staircase`): per group
    in a prefix row, ``P_k = sum_{j <= k} z_j`` as a chain ``P_k - P_{k-1} - z_k = 0`` (sparse,
    where the sums written out would be dense rows), and the rows ``P_{g,k} - P_{g',k'} <= 0``."""
    if not s.prefix_rows:
        return base
    used = sorted({g for g, _, _, _ in s.prefix_rows} | {g for _, _, g, _ in s.prefix_rows})
    start: dict[int, int] = {}
    n_cols = base.n_cols
    eq, le = base.eq.copy(), base.le.copy()
    for g in used:
        mem = s.groups[g].members
        start[g] = n_cols
        cols = n_cols + np.arange(len(mem))
        zc = base.col[list(mem)]
        r = np.arange(len(mem))
        eq.add(
            np.r_[r, r[1:], r],
            np.r_[cols, cols[:-1], zc],
            np.r_[np.ones(len(mem)), -np.ones(len(mem) - 1), -np.ones(len(mem))],
            np.zeros(len(mem)),
        )
        n_cols += len(mem)
    pr = np.array(s.prefix_rows, dtype=np.int64).reshape(-1, 4)
    m = len(pr)
    left = np.array([start[int(g)] for g in pr[:, 0]]) + pr[:, 1]
    right = np.array([start[int(g)] for g in pr[:, 2]]) + pr[:, 3]
    le.add(np.r_[np.arange(m), np.arange(m)], np.r_[left, right], np.r_[np.ones(m), -np.ones(m)],
           np.zeros(m))  # fmt: skip
    pm = base.p_mat
    p_mat = sp.csc_matrix(
        (pm.data, pm.indices, np.r_[pm.indptr, np.full(n_cols - base.n_cols, pm.nnz)]),
        shape=(n_cols, n_cols),
    )
    q_vec = np.r_[base.q_vec, np.zeros(n_cols - base.n_cols)]
    return dataclasses.replace(base, n_cols=n_cols, eq=eq, le=le, p_mat=p_mat, q_vec=q_vec)


def _condensed_base(s: _Structure) -> _Base | None:
    """Eliminate the variables ``y`` that appear only in equality rows, the objective, bounds and
    cones (the ALIP states and torques of the planner, eq. 5.12a-d): ``V(w) = min_y cost`` subject
    to the equality rows is a convex quadratic of the remaining ``w``, computed once from the KKT
    system. Dropping the bounds and cones of ``y`` gives a valid lower bound; a point whose
    recovered ``y`` satisfies them is exact. Returns None when nothing can be eliminated or the
    KKT system is singular (e.g. a zero torque weight).
    """
    split = _condensed_columns(s)
    if split is None:
        return None
    y_idx, w_idx = split
    pr = s.problem
    a_eq = pr.a_eq.tocsr()
    touches_y = np.asarray(abs(a_eq[:, y_idx]).sum(axis=1) > 0).ravel()
    f_mat = pr.cost_matrix.tocsr()
    rows_y = np.asarray(abs(f_mat[:, y_idx]).sum(axis=1) > 0).ravel()
    law = _optimal_y(pr, a_eq[touches_y], f_mat[rows_y], y_idx, w_idx, rows_y, touches_y)
    if law is None:
        return None
    support, y_lin, y_off = law
    if np.any(rows_y & s.assigned):  # pragma: no cover - assigned rows hold only group variables
        return None
    p_mat, q_vec, const = _condensed_cost(s, f_mat, rows_y, y_idx, w_idx, support, y_lin, y_off)
    # rows over w: equality rows without y, plain le rows, bounds of w
    eq = _Coo()
    eq.add_csr(a_eq[~touches_y][:, w_idx].tocsr(), pr.b_eq[~touches_y])
    le = _Coo()
    le.add_csr(s.plain_le[:, w_idx].tocsr(), s.plain_b)
    cont = np.flatnonzero(~pr.integer[w_idx])
    fin_u = cont[np.isfinite(pr.ub[w_idx][cont])]
    fin_l = cont[np.isfinite(pr.lb[w_idx][cont])]
    le.add(np.arange(len(fin_u)), fin_u, np.ones(len(fin_u)), pr.ub[w_idx][fin_u])
    le.add(np.arange(len(fin_l)), fin_l, -np.ones(len(fin_l)), -pr.lb[w_idx][fin_l])
    w_pos = np.full(pr.n, -1, dtype=np.int64)
    w_pos[w_idx] = np.arange(len(w_idx))
    return _Base(
        len(w_idx),
        w_pos,
        eq,
        le,
        _Coo(),
        [],
        p_mat,
        q_vec,
        const,
        y_idx=y_idx,
        y_from=w_idx[support],
        y_lin=y_lin,
        y_off=y_off,
    )


def _condensed_columns(s: _Structure) -> tuple[IntArray, IntArray] | None:
    """The variables to eliminate (``y``) and to keep (``w``); None when there is no ``y`` or a
    cone mixes them."""
    pr = s.problem
    keep = np.zeros(pr.n, dtype=bool)
    keep[pr.integer] = True
    keep[s.plain_le.indices] = True
    for grp in s.groups:
        keep[grp.variables] = True
        keep[grp.private] = True
    # a variable in no equality row and no cost row has nothing to determine it: keep it
    keep[np.asarray(abs(pr.a_eq).sum(axis=0) + abs(pr.cost_matrix).sum(axis=0)).ravel() == 0] = True
    for idx, _ in pr.cones:
        if np.any(keep[idx]):
            return None
    y_idx = np.flatnonzero(~keep)
    if len(y_idx) == 0:
        return None
    return y_idx, np.flatnonzero(keep)


def _optimal_y(
    pr: MIQCQP,
    e_rows: sp.csr_matrix,
    f_rows: sp.csr_matrix,
    y_idx: IntArray,
    w_idx: IntArray,
    rows_y: NDArray[np.bool_],
    touches_y: NDArray[np.bool_],
) -> tuple[IntArray, FloatArray, FloatArray] | None:
    """The minimiser ``y = Y w_S + y0`` of the ``y`` cost rows ``f_rows`` subject to the ``y``
    equality rows ``e_rows`` (one KKT solve), with ``S`` the ``w`` columns that move it; returns
    ``(S, Y, y0)``, or None when the KKT system is singular."""
    e_y, e_w = e_rows[:, y_idx], e_rows[:, w_idx]
    f_y, f_wy = f_rows[:, y_idx], f_rows[:, w_idx]
    t_y, wt_y = pr.cost_target[rows_y], pr.cost_weight[rows_y]
    # Parameters that move y: w columns of the y equality rows and of the y cost rows.
    support = np.flatnonzero(
        np.asarray(abs(e_w).sum(axis=0)).ravel() + np.asarray(abs(f_wy).sum(axis=0)).ravel()
    )
    h = 2.0 * (f_y.T @ sp.diags(wt_y) @ f_y)
    kkt = sp.bmat([[h, e_y.T], [e_y, None]], format="csc")
    rhs_lin = np.vstack(
        [
            -2.0 * (f_y.T @ sp.diags(wt_y) @ f_wy[:, support]).toarray(),
            -e_w[:, support].toarray(),
        ]
    )
    rhs_off = np.concatenate([2.0 * (f_y.T @ (wt_y * t_y)), pr.b_eq[touches_y]])
    try:
        lu = sp.linalg.splu(kkt)
        sol = lu.solve(np.column_stack([rhs_lin, rhs_off]))
    except RuntimeError:
        return None
    kkt_res = kkt @ sol - np.column_stack([rhs_lin, rhs_off])
    if not np.all(np.isfinite(sol)) or float(np.max(np.abs(kkt_res))) > 1e-6 * max(
        1.0, float(np.max(np.abs(sol)))
    ):
        return None
    ny = len(y_idx)
    return support, sol[:ny, :-1], sol[:ny, -1]


def _condensed_cost(
    s: _Structure,
    f_mat: sp.csr_matrix,
    rows_y: NDArray[np.bool_],
    y_idx: IntArray,
    w_idx: IntArray,
    support: IntArray,
    y_lin: FloatArray,
    y_off: FloatArray,
) -> tuple[sp.csc_matrix, FloatArray, float]:
    """The objective over ``w`` with ``y`` at its minimiser: ``(P, q, const)``, ``P`` upper
    triangular. The ``y`` cost rows become ``F_y (Y w_S + y0) + F_wy w - t``; the rows the groups
    charge in perspective form are left out."""
    pr = s.problem
    f_y, f_wy = f_mat[rows_y][:, y_idx], f_mat[rows_y][:, w_idx]
    t_y, wt_y = pr.cost_target[rows_y], pr.cost_weight[rows_y]
    f_eff = (f_y @ y_lin) + f_wy[:, support].toarray()
    t_eff = t_y - f_y @ y_off
    sq = np.sqrt(wt_y)
    a_s = sq[:, None] * f_eff
    t_s = sq * t_eff
    # other cost rows (only w)
    other = ~rows_y & ~s.assigned
    f_o = f_mat[other][:, w_idx]
    p_o, q_o, c_o = _cost_pq(f_o.tocsr(), pr.cost_target[other], pr.cost_weight[other])
    nw = len(w_idx)
    p_s = np.zeros((nw, nw))
    p_s[np.ix_(support, support)] = 2.0 * (a_s.T @ a_s)
    p_mat = sp.triu(p_o + sp.csc_matrix(np.triu(p_s)), format="csc")
    q_vec = q_o.copy()
    q_vec[support] += -2.0 * (a_s.T @ t_s)
    return p_mat, q_vec, c_o + float(t_s @ t_s)


def _cat(parts: list[Any], dtype: Any) -> Any:
    return np.concatenate(parts) if parts else np.zeros(0, dtype=dtype)


@dataclass
class _Templates:
    """Per-node pieces of the relaxation over one base, as flat arrays gathered by member mask.

    Members are numbered globally (group after group). Entry arrays carry the owning member
    (``*_mem``) and a column kind: 0 = the member's copy of form ``loc``, 1 = the member's binary,
    2 = the member's perspective variable ``t``.
    """

    base: _Base
    # static rows of the base, concatenated
    eq_r: IntArray
    eq_c: IntArray
    eq_v: FloatArray
    eq_b: FloatArray
    le_r: IntArray
    le_c: IntArray
    le_v: FloatArray
    le_b: FloatArray
    m_eq: int
    m_le: int
    # per member
    group: IntArray  # group of each member
    zcol: IntArray  # column of each member's binary
    k: IntArray  # number of forms of the member's group
    n_rows: IntArray  # hull rows of the member (copy bounds + its rows)
    has_cost: NDArray[np.bool_]
    cost_dim: IntArray  # cone dimension of its perspective term
    # hull rows (multi-member groups)
    h_mem: IntArray
    h_row: IntArray
    h_kind: IntArray
    h_loc: IntArray
    h_val: FloatArray
    # perspective cones
    c_mem: IntArray
    c_row: IntArray
    c_kind: IntArray
    c_loc: IntArray
    c_val: FloatArray
    # direct rows (single-member groups)
    d_mem: IntArray
    d_row: IntArray
    d_col: IntArray
    d_val: FloatArray
    d_nrows: IntArray
    d_beta: FloatArray  # concatenated in member order
    d_beta_mem: IntArray
    # direct cost (single-member groups), upper triangle entries
    dp_mem: IntArray
    dp_i: IntArray
    dp_j: IntArray
    dp_v: FloatArray
    dq_mem: IntArray
    dq_i: IntArray
    dq_v: FloatArray
    d_const: FloatArray  # per member
    # linking rows per group: B x_V - sum f^z = 0
    l_grp: IntArray
    l_row: IntArray
    l_col: IntArray
    l_val: FloatArray
    # rows of the separable forms per multi group (see :func:`_separable_forms`): entries of
    # kind 0 (column ``s_col``) or 1 (the binary of member ``s_mem``), rows per group
    s_grp: IntArray
    s_row: IntArray
    s_kind: IntArray
    s_col: IntArray
    s_mem: IntArray
    s_val: FloatArray
    s_nrows: IntArray
    # base columns left out of every node problem (see :func:`_dropped_columns`), their values
    drop_col: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    drop_val: FloatArray = field(default_factory=lambda: np.zeros(0))
    # static inequality rows that hold binaries only (they may lose every entry at a node)
    le_bin_rows: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    # the base's P (upper triangle) as COO entries
    p_i: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    p_j: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    p_v: FloatArray = field(default_factory=lambda: np.zeros(0))


def _dropped_columns(s: _Structure, t: _Templates) -> _Templates:
    """``t`` without the base columns that only their own bounds constrain.

    A column with no cost that appears in no row but single-variable inequality rows (its bounds),
    in no cone and in no group's rows is a free coordinate of the relaxation: leaving it out (with
    those rows) is the exact projection, so every node bound stays the same while each node's KKT
    system loses a column and two rows. In the planner these are the private sin/cos of the
    heading segments (their member rows are eliminated, see :func:`analyse`). Their value in a
    relaxation point is any value within their bounds (the midpoint, or the finite bound).
    Columns with conflicting bounds are kept, so the node solve still reports infeasibility.
    """
    base = t.base
    n = base.n_cols
    le_cnt = np.bincount(t.le_r, minlength=t.m_le)
    single = le_cnt[t.le_r] == 1
    used = np.zeros(n, dtype=bool)
    pm = base.p_mat.tocoo()
    soc_c = _cat(base.soc.c, np.int64)
    special = base.col[np.r_[np.flatnonzero(s.problem.integer), base.y_from]]
    for cols in (t.eq_c, t.le_c[~single], soc_c, t.l_col, t.d_col, t.dp_i, t.dp_j, t.dq_i,
                 t.zcol, pm.row, pm.col, special[special >= 0]):  # fmt: skip
        used[cols] = True
    used[base.q_vec != 0.0] = True
    lo = np.full(n, -np.inf)
    hi = np.full(n, np.inf)
    sc, sv, sb = t.le_c[single], t.le_v[single], t.le_b[t.le_r[single]]
    pos = sv > 0
    np.minimum.at(hi, sc[pos], sb[pos] / sv[pos])
    np.maximum.at(lo, sc[~pos], sb[~pos] / sv[~pos])
    drop = ~used & (lo <= hi)
    if not np.any(drop):
        return t
    both = np.isfinite(lo) & np.isfinite(hi)
    val = np.clip(0.0, lo, hi)
    val[both] = 0.5 * (lo[both] + hi[both])
    keep_row = np.ones(t.m_le, dtype=bool)
    keep_row[t.le_r[single & drop[t.le_c]]] = False
    ent = keep_row[t.le_r]
    row_map = np.cumsum(keep_row) - 1
    is_bin = np.zeros(n, dtype=bool)
    is_bin[t.zcol] = True
    le_r = row_map[t.le_r[ent]]
    m_le = int(np.count_nonzero(keep_row))
    nonbin = np.bincount(le_r, weights=~is_bin[t.le_c[ent]], minlength=m_le)
    return dataclasses.replace(
        t,
        le_r=le_r,
        le_c=t.le_c[ent],
        le_v=t.le_v[ent],
        le_b=t.le_b[keep_row],
        m_le=m_le,
        drop_col=np.flatnonzero(drop),
        drop_val=val[drop],
        le_bin_rows=np.flatnonzero(nonbin == 0),
    )


def _separable_forms(
    s: _Structure, grp: _Group, compact: bool
) -> tuple[IntArray, IntArray, FloatArray, FloatArray, dict[int, NDArray[np.bool_]]]:
    """Forms of ``grp`` whose copies can be projected out of the hull exactly.

    A form ``j`` that appears in no cost row and, in every member, only in rows on ``j`` alone
    (``lo_z z <= f^z_j <= hi_z z``, e.g. a heading segment's heading interval, a region's height)
    enters the hull only through ``B_j x_V = sum_z f^z_j``. With ``z >= 0`` (a row or the
    perspective cone) its projection is ``sum_z lo_z z <= B_j x_V <= sum_z hi_z z``: two rows per
    group instead of a copy and two rows per member, the same relaxation. A side is written when
    every member bounds it and left out when none does; a form where only some members bound a
    side, or a member's interval is empty, keeps its copies (so does every form without
    ``compact``).

    Returns:
        The kept forms, the separable forms, per member and separable form ``lo`` and ``hi``
        (members x separable forms, +-inf where unbounded), and per member the mask of its rows
        on separable forms (left out of its hull rows).
    """
    k = grp.basis.shape[0]
    mem = grp.members
    sep = np.ones(k, dtype=bool) if compact and len(mem) > 1 else np.zeros(k, dtype=bool)
    if len(grp.cost_rows):
        sep &= ~np.any(grp.cost_f != 0.0, axis=0)
    for z in mem:
        nz = s.member[z].a_f != 0.0
        sep &= ~np.any(nz[np.count_nonzero(nz, axis=1) != 1], axis=0)
    lo = np.full((len(mem), k), -np.inf)
    hi = np.full((len(mem), k), np.inf)
    for i, z in enumerate(mem):
        a_f, beta = s.member[z].a_f, s.member[z].beta
        for r in np.flatnonzero(np.count_nonzero(a_f, axis=1) == 1):
            j = int(np.flatnonzero(a_f[r])[0])
            if a_f[r, j] > 0:
                hi[i, j] = min(hi[i, j], beta[r] / a_f[r, j])
            else:
                lo[i, j] = max(lo[i, j], beta[r] / a_f[r, j])
    fin_lo, fin_hi = np.isfinite(lo), np.isfinite(hi)
    sep &= np.all(fin_lo, axis=0) | ~np.any(fin_lo, axis=0)
    sep &= np.all(fin_hi, axis=0) | ~np.any(fin_hi, axis=0)
    sep &= np.all(lo <= hi, axis=0)
    sepf = np.flatnonzero(sep)
    rows = {}
    for z in mem:
        nz = s.member[z].a_f != 0.0
        rows[z] = (np.count_nonzero(nz, axis=1) == 1) & np.any(nz[:, sep], axis=1)
    return np.flatnonzero(~sep), sepf, lo[:, sepf], hi[:, sepf], rows


@dataclass
class _Parts:
    """The pieces :func:`_templates` collects, as lists of per-group and per-member arrays (each
    tuple: the fields of one block of :class:`_Templates`, in its order)."""

    groups: list[int] = field(default_factory=list)
    zcol: list[int] = field(default_factory=list)
    kk: list[int] = field(default_factory=list)
    nrows: list[int] = field(default_factory=list)
    has_cost: list[bool] = field(default_factory=list)
    cdim: list[int] = field(default_factory=list)
    #: hull rows: member, row, kind, location, value
    h: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], [], []))
    #: perspective cones: member, row, kind, location, value
    c: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], [], []))
    #: direct rows: member, row, column, value, row count, rhs, rhs member
    d: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], [], [], [], []))
    #: direct cost: quadratic (member, i, j, value), linear (member, i, value), constants
    dp: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], []))
    dq: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], []))
    dconst: list[float] = field(default_factory=list)
    #: linking rows B x_V = sum_z f^z: group, row, column, value
    link: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], []))
    #: separable-form rows: group, row, kind, column, member, value; rows per group
    sep: tuple[list[Any], ...] = field(default_factory=lambda: ([], [], [], [], [], []))
    sep_rows: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class _GroupCost:
    """A group's perspective cost rows over its kept forms, and their direct (one-member) form."""

    sw: FloatArray  # 2 sqrt(w)
    cf: FloatArray  # 2 sqrt(w) C over the kept forms
    cr: IntArray
    cc: IntArray
    pg: FloatArray  # upper triangle of the quadratic over V
    pi: IntArray
    pj: IntArray
    qg: FloatArray  # linear term over V


def _templates(s: _Structure, base: _Base, compact: bool) -> _Templates:
    """The node relaxation's pieces over ``base``, for every member of every group (see the
    module docstring); with ``compact``, separable forms lose their copies and free columns are
    left out (:func:`_dropped_columns`)."""
    col = base.col
    parts = _Parts()
    mi = 0
    for g, grp in enumerate(s.groups):
        vcols = col[grp.variables]
        keepf, sepf, s_lo, s_hi, is_sep_row = _separable_forms(s, grp, compact)
        _group_rows(parts, g, grp, vcols, keepf, sepf, s_lo, s_hi, mi)
        cost = _group_cost(grp, keepf) if len(grp.cost_rows) else None
        for z in grp.members:
            parts.groups.append(g)
            parts.zcol.append(col[z])
            parts.kk.append(len(keepf))
            _member_rows(parts, grp, s.member[z], mi, vcols, keepf, is_sep_row[z], cost)
            mi += 1
    out = _pack(base, parts)
    is_bin = np.zeros(base.n_cols, dtype=bool)
    is_bin[out.zcol] = True
    nonbin = np.bincount(out.le_r, weights=~is_bin[out.le_c], minlength=out.m_le)
    out = dataclasses.replace(out, le_bin_rows=np.flatnonzero(nonbin == 0))
    return _dropped_columns(s, out) if compact else out


def _group_rows(
    parts: _Parts,
    g: int,
    grp: _Group,
    vcols: IntArray,
    keepf: IntArray,
    sepf: IntArray,
    s_lo: FloatArray,
    s_hi: FloatArray,
    mi: int,
) -> None:
    """Group ``g``'s linking rows ``B x_V = sum_z f^z`` (kept forms) and the rows of its
    separable forms, ``sum_z lo_z z <= B_j x_V <= sum_z hi_z z`` (the copies projected out);
    ``mi``: the index of its first member."""
    basis = grp.basis[keepf]
    br, bc = np.nonzero(basis)
    parts.link[0].append(np.full(len(br), g))
    parts.link[1].append(br)
    parts.link[2].append(vcols[bc])
    parts.link[3].append(basis[br, bc])
    sep = parts.sep
    n_sep = 0
    for i, j in enumerate(sepf):
        bj = np.flatnonzero(grp.basis[j])
        for sign, bnd in ((1.0, s_hi[:, i]), (-1.0, s_lo[:, i])):
            if not np.all(np.isfinite(bnd)):
                continue  # no member bounds this side (see _separable_forms)
            m_idx = mi + np.arange(len(grp.members))
            sep[0].append(np.full(len(bj) + len(m_idx), g))
            sep[1].append(np.full(len(bj) + len(m_idx), n_sep))
            sep[2].append(np.r_[np.zeros(len(bj)), np.ones(len(m_idx))].astype(np.int64))
            sep[3].append(np.r_[vcols[bj], np.zeros(len(m_idx), dtype=np.int64)])
            sep[4].append(np.r_[np.full(len(bj), -1), m_idx].astype(np.int64))
            sep[5].append(np.r_[sign * grp.basis[j, bj], -sign * bnd])
            n_sep += 1
    parts.sep_rows.append(n_sep)


def _group_cost(grp: _Group, keepf: IntArray) -> _GroupCost:
    """The group's cost rows ``w (C f - t)^2`` (eq. 5.11's horizontal step terms) prepared for
    the perspective cones and for the direct form of a lone member."""
    sw = 2.0 * np.sqrt(grp.cost_w)
    cf = sw[:, None] * grp.cost_f[:, keepf]
    cr, cc = np.nonzero(cf)
    wv = grp.cost_w[:, None] * grp.cost_v
    pg = np.triu(2.0 * grp.cost_v.T @ wv)
    pi, pj = np.nonzero(pg)
    return _GroupCost(sw, cf, cr, cc, pg, pi, pj, -2.0 * wv.T @ grp.cost_t)


def _member_rows(
    parts: _Parts,
    grp: _Group,
    mb: _Member,
    mi: int,
    vcols: IntArray,
    keepf: IntArray,
    is_sep_row: NDArray[np.bool_],
    cost: _GroupCost | None,
) -> None:
    """Member ``mi``'s hull rows, perspective cone (with a cost), and direct rows and cost (used
    when it is its group's only allowed member)."""
    a_f = mb.a_f[~is_sep_row][:, keepf]
    beta = mb.beta[~is_sep_row]
    nb = len(beta)
    n_cost = len(grp.cost_rows)
    parts.nrows.append(nb)
    parts.has_cost.append(n_cost > 0)
    parts.cdim.append(n_cost + 2 if n_cost else 0)
    # hull rows: a_f f - beta z <= 0 (the copies are bounded through the member rows)
    rr, cc2 = np.nonzero(a_f)
    for lst, arr in zip(
        parts.h,
        (
            np.full(len(rr) + nb, mi),
            np.r_[rr, np.arange(nb)],
            np.r_[np.zeros(len(rr)), np.ones(nb)].astype(np.int64),
            np.r_[cc2, np.zeros(nb)].astype(np.int64),
            np.r_[a_f[rr, cc2], -beta],
        ),
        strict=True,
    ):
        lst.append(arr)
    if cost is not None:
        # perspective: ||(2 sqrt(w) (C f^z - t z), t_z - z)|| <= t_z + z
        cr, cc = cost.cr, cost.cc
        rows = np.r_[0, 0, 1, 1, cr + 2, np.arange(n_cost) + 2]
        for lst, arr in zip(
            parts.c,
            (
                np.full(len(rows), mi),
                rows,
                np.r_[2, 1, 2, 1, np.zeros(len(cr)), np.ones(n_cost)].astype(np.int64),
                np.r_[0, 0, 0, 0, cc, np.zeros(n_cost)].astype(np.int64),
                np.r_[-1.0, -1.0, -1.0, 1.0, -cost.cf[cr, cc], cost.sw * grp.cost_t],
            ),
            strict=True,
        ):
            lst.append(arr)
    # direct rows
    rr, cc2 = np.nonzero(mb.a_v)
    d = parts.d
    d[0].append(np.full(len(rr), mi))
    d[1].append(rr)
    d[2].append(vcols[cc2])
    d[3].append(mb.a_v[rr, cc2])
    d[4].append(len(mb.beta))
    d[5].append(mb.beta)
    d[6].append(np.full(len(mb.beta), mi))
    if cost is None:
        parts.dconst.append(0.0)
        return
    pi, pj = cost.pi, cost.pj
    parts.dp[0].append(np.full(len(pi), mi))
    parts.dp[1].append(np.minimum(vcols[pi], vcols[pj]))
    parts.dp[2].append(np.maximum(vcols[pi], vcols[pj]))
    parts.dp[3].append(cost.pg[pi, pj])
    parts.dq[0].append(np.full(len(vcols), mi))
    parts.dq[1].append(vcols)
    parts.dq[2].append(cost.qg)
    parts.dconst.append(float(np.sum(grp.cost_w * grp.cost_t**2)))


def _pack(base: _Base, parts: _Parts) -> _Templates:
    """The collected pieces as the flat arrays of :class:`_Templates` (``le_bin_rows`` empty)."""
    i64, f64 = np.int64, float
    h, c, d, dp, dq, link, sep = (
        parts.h,
        parts.c,
        parts.d,
        parts.dp,
        parts.dq,
        parts.link,
        parts.sep,
    )
    pm = base.p_mat.tocoo()
    return _Templates(
        base=base,
        eq_r=_cat(base.eq.r, i64),
        eq_c=_cat(base.eq.c, i64),
        eq_v=_cat(base.eq.v, f64),
        eq_b=_cat(base.eq.b, f64),
        le_r=_cat(base.le.r, i64),
        le_c=_cat(base.le.c, i64),
        le_v=_cat(base.le.v, f64),
        le_b=_cat(base.le.b, f64),
        m_eq=base.eq.m,
        m_le=base.le.m,
        group=np.array(parts.groups, dtype=i64),
        zcol=np.array(parts.zcol, dtype=i64),
        k=np.array(parts.kk, dtype=i64),
        n_rows=np.array(parts.nrows, dtype=i64),
        has_cost=np.array(parts.has_cost, dtype=bool),
        cost_dim=np.array(parts.cdim, dtype=i64),
        h_mem=_cat(h[0], i64),
        h_row=_cat(h[1], i64),
        h_kind=_cat(h[2], i64),
        h_loc=_cat(h[3], i64),
        h_val=_cat(h[4], f64),
        c_mem=_cat(c[0], i64),
        c_row=_cat(c[1], i64),
        c_kind=_cat(c[2], i64),
        c_loc=_cat(c[3], i64),
        c_val=_cat(c[4], f64),
        d_mem=_cat(d[0], i64),
        d_row=_cat(d[1], i64),
        d_col=_cat(d[2], i64),
        d_val=_cat(d[3], f64),
        d_nrows=np.array(d[4], dtype=i64),
        d_beta=_cat(d[5], f64),
        d_beta_mem=_cat(d[6], i64),
        dp_mem=_cat(dp[0], i64),
        dp_i=_cat(dp[1], i64),
        dp_j=_cat(dp[2], i64),
        dp_v=_cat(dp[3], f64),
        dq_mem=_cat(dq[0], i64),
        dq_i=_cat(dq[1], i64),
        dq_v=_cat(dq[2], f64),
        d_const=np.array(parts.dconst, dtype=f64),
        l_grp=_cat(link[0], i64),
        l_row=_cat(link[1], i64),
        l_col=_cat(link[2], i64),
        l_val=_cat(link[3], f64),
        s_grp=_cat(sep[0], i64),
        s_row=_cat(sep[1], i64),
        s_kind=_cat(sep[2], i64),
        s_col=_cat(sep[3], i64),
        s_mem=_cat(sep[4], i64),
        s_val=_cat(sep[5], f64),
        s_nrows=np.array(parts.sep_rows, dtype=i64),
        p_i=pm.row.astype(i64),
        p_j=pm.col.astype(i64),
        p_v=pm.data.astype(f64),
    )
