"""The node relaxation: hull, perspective and condensed dynamics, solved by Clarabel.

:class:`HullRelaxation` assembles a node's convex problem from the templates of
:mod:`footfall.solvers.bnb.templates` (each group may use only its allowed members) and solves it
with Clarabel. Every bound is ``min(primal, dual)`` of a solve of a convex relaxation, so it is
valid; a solve that ends in another status is retried once with Clarabel's robust defaults.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall.solvers.bnb.model import _Structure
from footfall.solvers.bnb.templates import (
    _Base,
    _cat,
    _condensed_base,
    _full_base,
    _Templates,
    _templates,
    _with_prefix,
)
from footfall.solvers.settings import BnbSettings

#: Clarabel statuses that end a node solve (anything else is retried once, then "failed")
_CLARABEL_DONE = ("Solved", "AlmostSolved", "PrimalInfeasible", "AlmostPrimalInfeasible")


def _clarabel_settings(clarabel: Any, overrides: dict[str, Any]) -> Any:
    """Clarabel's default settings, quiet, with ``overrides`` applied."""
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for key, value in overrides.items():
        setattr(settings, key, value)
    return settings


@dataclass
class _Relaxation:
    """Result of one node relaxation: ``x`` holds the original variables (condensed ones recovered)."""

    status: str  # "solved", "infeasible", "failed"
    bound: float = math.inf
    x: FloatArray | None = None
    iterations: int = 0
    #: Clarabel's status when ``status`` is "failed"
    raw: str = ""
    #: solved with the full model (asked for, or the condensed point broke a dropped bound/cone)
    full: bool = False


class _CscLists:
    """A sparse matrix in CSC form with its arrays as Python lists, for ``clarabel.DefaultSolver``.

    Clarabel's Python wrapper (0.11) reads ``data``, ``indices`` and ``indptr`` element by element,
    which is much cheaper from lists (built by ``tolist``) than from numpy arrays (see
    ``benchmarks/RESULTS.md``). It reads only these attributes and ``shape`` and
    ``has_canonical_format``. :meth:`from_coo` builds the canonical form (columns in order, rows
    sorted within a column, duplicates summed) straight from a node's COO entries: one stable sort
    of ``column * n_rows + row``, without scipy's checks and conversions (2-4 % of a search's time
    on one thread, same nodes; inside the noise with two workers; ``benchmarks/RESULTS.md``).
    """

    __slots__ = ("data", "has_canonical_format", "indices", "indptr", "shape")

    def __init__(
        self, data: list[float], indices: list[int], indptr: list[int], shape: tuple[int, int]
    ) -> None:
        self.data = data
        self.indices = indices
        self.indptr = indptr
        self.shape = shape
        self.has_canonical_format = True

    @classmethod
    def from_coo(
        cls, rows: IntArray, cols: IntArray, vals: FloatArray, shape: tuple[int, int]
    ) -> _CscLists:
        """The matrix with entries ``vals`` at ``(rows, cols)``, shape ``(m, n)``; entries at the
        same position are summed (in their given order), explicit zeros are kept."""
        m, n = shape
        key = np.asarray(cols, dtype=np.int64) * m + np.asarray(rows, dtype=np.int64)
        order = np.argsort(key, kind="stable")
        key = key[order]
        data = np.asarray(vals, dtype=float)[order]
        if len(key) > 1:
            first = np.empty(len(key), dtype=bool)
            first[0] = True
            np.not_equal(key[1:], key[:-1], out=first[1:])
            if not first.all():
                starts = np.flatnonzero(first)
                data = np.add.reduceat(data, starts)
                key = key[starts]
        col, row = np.divmod(key, m) if m else (key, key)
        indptr = np.zeros(n + 1, dtype=np.int64)
        np.cumsum(np.bincount(col, minlength=n), out=indptr[1:])
        return cls(data.tolist(), row.tolist(), indptr.tolist(), (m, n))


def _offsets(counts: IntArray, mask: NDArray[np.bool_]) -> IntArray:
    """Start of each selected item in a packed layout (garbage where not selected)."""
    c = np.where(mask, counts, 0)
    return np.cumsum(c) - c


@dataclass
class _Assembly:
    """A node problem being assembled (see :meth:`HullRelaxation.solve`): which members are
    allowed, where its columns start, and its equality and inequality rows as COO entries."""

    sel: NDArray[np.bool_]  # per member: allowed
    multi_g: NDArray[np.bool_]  # per group: two or more members allowed
    multi: NDArray[np.bool_]  # per member: allowed in a multi group (gets copies)
    single: NDArray[np.bool_]  # per member: its group's only allowed member (direct rows)
    copy_start: IntArray  # per member: first column of its copies of the forms
    persp: NDArray[np.bool_]  # per member: has a perspective cone
    t_col: IntArray  # per member: column of its perspective variable
    ncol: int
    w_col: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    ex_cols: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    eq_r: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    eq_c: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    eq_v: FloatArray = field(default_factory=lambda: np.zeros(0))
    eq_b: FloatArray = field(default_factory=lambda: np.zeros(0))
    m_eq: int = 0
    le_r: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    le_c: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    le_v: FloatArray = field(default_factory=lambda: np.zeros(0))
    le_b: FloatArray = field(default_factory=lambda: np.zeros(0))
    m_le: int = 0


@dataclass
class _NodeProblem:
    """A node's conic problem as COO entries: rows (equalities, inequalities, cones) and the
    objective ``1/2 x^T P x + q^T x + const`` (P upper triangular)."""

    rows: IntArray
    cols: IntArray
    vals: FloatArray
    b: FloatArray
    n_rows: int
    m_le: int
    p_i: IntArray
    p_j: IntArray
    p_v: FloatArray
    q: FloatArray
    const: float


class HullRelaxation:
    """Builds and solves the node relaxation of :mod:`footfall.solvers.bnb` (see module docstring).

    Two bases: ``full`` (every variable, bound and cone: exact at integral nodes) and, when the
    problem allows it, ``condensed`` (see :func:`_condensed_base`: a lower bound, much smaller).
    A node's relaxation is assembled from flat templates by masking (no Python loop per member).
    """

    def __init__(
        self, structure: _Structure, condense: bool = True, settings: BnbSettings | None = None
    ) -> None:
        import clarabel

        self._clarabel = clarabel
        self.s = structure
        self.settings = BnbSettings() if settings is None else settings
        compact = self.settings.compact
        self.full = _with_prefix(structure, _full_base(structure))
        condensed = _condensed_base(structure) if condense else None
        self.condensed = None if condensed is None else _with_prefix(structure, condensed)
        self._tpl = {id(self.full): _templates(structure, self.full, compact)}
        if self.condensed is not None:
            self._tpl[id(self.condensed)] = _templates(structure, self.condensed, compact)
        n = structure.problem.n
        self.member_index = np.full(n, -1, dtype=np.int64)
        order = [z for grp in structure.groups for z in grp.members]
        self.member_index[order] = np.arange(len(order))
        self.n_members = len(order)
        # link flows: one marginal row per (link, side, member), one weight column per pair
        lr_mem: list[IntArray] = []
        p_r: list[IntArray] = []
        p_m: list[IntArray] = []
        n_lr = 0
        for link in structure.links:
            m1 = self.member_index[list(structure.groups[link.groups[0]].members)]
            m2 = self.member_index[list(structure.groups[link.groups[1]].members)]
            lr_mem += [m1, m2]
            # marginal row of each pair's members: position of the member in its side's block
            pm = self.member_index[link.pairs]
            p_m.append(pm)
            r1 = n_lr + np.searchsorted(m1, pm[:, 0])
            r2 = n_lr + len(m1) + np.searchsorted(m2, pm[:, 1])
            p_r.append(np.column_stack([r1, r2]))
            n_lr += len(m1) + len(m2)
        self.lr_mem = _cat(lr_mem, np.int64)
        self.p_r = np.vstack([*p_r, np.zeros((0, 2), dtype=np.int64)])
        self.p_m = np.vstack([*p_m, np.zeros((0, 2), dtype=np.int64)])
        self._settings = _clarabel_settings(clarabel, dict(self.settings.clarabel))
        self._robust_settings = _clarabel_settings(clarabel, dict(self.settings.clarabel_retry))
        self._cones: dict[int, Any] = {}
        self.solves = 0
        self.solve_time = 0.0
        #: condensed solves whose point broke a dropped bound or cone, re-solved in full
        self.escalations = 0
        self._dropped = self._dropped_checks()

    def _dropped_checks(
        self,
    ) -> tuple[IntArray, FloatArray, FloatArray, list[tuple[IntArray, FloatArray]]]:
        """What the condensed base drops: the eliminated variables, their bounds, and the cones
        over them (``||x[idx]|| <= radius``), stacked per cone dimension as ``(idx (m, d),
        radius (m,))``."""
        pr = self.s.problem
        if self.condensed is None:
            empty = np.zeros(0, dtype=np.int64)
            return empty, np.zeros(0), np.zeros(0), []
        y = self.condensed.y_idx
        is_y = np.zeros(pr.n, dtype=bool)
        is_y[y] = True
        by_dim: dict[int, tuple[list[IntArray], list[float]]] = {}
        for idx, r in pr.cones:
            idx = np.asarray(idx, dtype=np.int64)
            if np.all(is_y[idx]):
                rows, radii = by_dim.setdefault(len(idx), ([], []))
                rows.append(idx)
                radii.append(float(r))
        cones = [(np.vstack(rows), np.asarray(radii)) for rows, radii in by_dim.values()]
        return y, pr.lb[y], pr.ub[y], cones

    def dropped_violation(self, x: FloatArray) -> float:
        """Largest violation at ``x`` of the bounds and cones that the condensed base drops."""
        y, lo, hi, cones = self._dropped
        if len(y) == 0:
            return 0.0
        xy = x[y]
        worst = max(0.0, float(np.max(lo - xy, initial=0.0)), float(np.max(xy - hi, initial=0.0)))
        for idx, radius in cones:
            worst = max(worst, float(np.max(np.linalg.norm(x[idx], axis=1) - radius)))
        return worst

    def recover(self, x: FloatArray) -> FloatArray:
        """Fill the condensed-out variables of ``x`` (a full-length vector) in place; returns x."""
        base = self.condensed
        if base is not None:
            x[base.y_idx] = base.y_lin @ x[base.y_from] + base.y_off
        return x

    def solve(self, allowed: tuple[tuple[int, ...], ...], full: bool = False) -> _Relaxation:
        """Solve the relaxation where group ``g`` may use only the binaries ``allowed[g]``."""
        base = self.full if full or self.condensed is None else self.condensed
        t = self._tpl[id(base)]
        a = self._layout(base, t, allowed)
        self._equalities(t, a)
        self._inequalities(t, a)
        problem = self._stack(base, t, a)
        keep_col = None
        if self.settings.compact:
            keep_col = self._compact(t, a, problem)
            if keep_col is None:
                return _Relaxation("infeasible", full=base is self.full)
        res = self._run(base, t, a, problem, keep_col)
        res.full = base is self.full
        if (
            self.settings.escalate
            and not res.full
            and res.status == "solved"
            and res.x is not None
            and self.dropped_violation(res.x) > self.settings.feas_tol
        ):
            # The condensed optimum breaks a dropped bound or cone (e.g. the torque limit):
            # the full model's bound is tighter there, and it can prove the node infeasible.
            self.escalations += 1
            return self.solve(allowed, full=True)
        return res

    def _layout(
        self, base: _Base, t: _Templates, allowed: tuple[tuple[int, ...], ...]
    ) -> _Assembly:
        """Which members the node allows, and its columns: the base's, copies of the forms of
        every member of a group with two or more allowed members, then the perspective
        variables."""
        n_groups = len(self.s.groups)
        sel = np.zeros(self.n_members, dtype=bool)
        sel[self.member_index[[z for mem in allowed for z in mem]]] = True
        count = np.bincount(t.group[sel], minlength=n_groups)
        multi_g = count >= 2
        multi = sel & multi_g[t.group]
        ncol0 = base.n_cols
        copy_start = ncol0 + _offsets(t.k, multi)
        n_copies = int(np.sum(t.k[multi]))
        persp = multi & t.has_cost
        t_col = ncol0 + n_copies + _offsets(np.ones_like(t.k), persp)
        ncol = ncol0 + n_copies + int(np.count_nonzero(persp))
        return _Assembly(sel, multi_g, multi, sel & ~multi, copy_start, persp, t_col, ncol)

    def _equalities(self, t: _Templates, a: _Assembly) -> None:
        """The equality rows: static, excluded binaries = 0 (unless left out), linking rows
        ``B x_V = sum_z f^z`` of multi groups, and the link flows (one weight column per allowed
        pair, ``sum_{pairs of z} w - z = 0``)."""
        multi, multi_g = a.multi, a.multi_g
        ex_cols = t.zcol[~a.sel]
        n_ex = 0 if self.settings.compact else len(ex_cols)
        k_group = np.zeros(len(self.s.groups), dtype=np.int64)
        k_group[t.group] = t.k
        link_start = t.m_eq + n_ex + _offsets(k_group, multi_g)
        lm = multi_g[t.l_grp]
        # copies: -1 at (link_start[g] + j, copy_start[m] + j)
        cm = np.repeat(np.flatnonzero(multi), t.k[multi])
        cj = np.arange(len(cm)) - np.repeat(_offsets(t.k, multi)[multi], t.k[multi])
        eq_r = np.concatenate(
            [t.eq_r, t.m_eq + np.arange(n_ex), link_start[t.l_grp[lm]] + t.l_row[lm],
             link_start[t.group[cm]] + cj]
        )  # fmt: skip
        eq_c = np.concatenate([t.eq_c, ex_cols[:n_ex], t.l_col[lm], a.copy_start[cm] + cj])
        eq_v = np.concatenate([t.eq_v, np.ones(n_ex), t.l_val[lm], -np.ones(len(cm))])
        m_eq = t.m_eq + n_ex + int(np.sum(k_group[multi_g]))
        # link flows: sum_{pairs of z} w - z = 0 per (link, side, allowed member), w >= 0
        sel = a.sel
        lrsel = sel[self.lr_mem]
        renum = m_eq + np.cumsum(lrsel) - 1
        psel = sel[self.p_m[:, 0]] & sel[self.p_m[:, 1]]
        n_w = int(np.count_nonzero(psel))
        a.w_col = a.ncol + np.arange(n_w)
        a.ncol += n_w
        a.eq_r = np.concatenate(
            [eq_r, renum[self.p_r[psel, 0]], renum[self.p_r[psel, 1]], renum[lrsel]]
        )
        a.eq_c = np.concatenate([eq_c, a.w_col, a.w_col, t.zcol[self.lr_mem[lrsel]]])
        a.eq_v = np.concatenate([eq_v, np.ones(2 * n_w), -np.ones(int(np.count_nonzero(lrsel)))])
        a.m_eq = m_eq + int(np.count_nonzero(lrsel))
        a.eq_b = np.concatenate([t.eq_b, np.zeros(a.m_eq - t.m_eq)])
        a.ex_cols = ex_cols

    def _inequalities(self, t: _Templates, a: _Assembly) -> None:
        """The inequality rows: static, ``-z <= 0`` for multi members (not where the perspective
        cone implies it), hull rows, direct rows of single members, ``w >= 0`` of the link
        weights, rows of the separable forms of multi groups (see :func:`_separable_forms`)."""
        multi, multi_g, single = a.multi, a.multi_g, a.single
        n_w = len(a.w_col)
        zrow = multi & ~t.has_cost if self.settings.compact else multi
        zm = t.zcol[zrow]
        nzm = len(zm)
        row0 = t.m_le + nzm
        h_start = row0 + _offsets(t.n_rows, multi)
        hm = multi[t.h_mem]
        hmem = t.h_mem[hm]
        hkind = t.h_kind[hm]
        h_cols = np.where(hkind == 0, a.copy_start[hmem] + t.h_loc[hm], t.zcol[hmem])
        n_h = int(np.sum(t.n_rows[multi]))
        d_start = row0 + n_h + _offsets(t.d_nrows, single)
        dm = single[t.d_mem]
        n_d = int(np.sum(t.d_nrows[single]))
        s_start = row0 + n_h + n_d + n_w + _offsets(t.s_nrows, multi_g)
        sm = np.where(t.s_kind == 0, multi_g[t.s_grp], multi[np.maximum(t.s_mem, 0)])
        s_cols = np.where(t.s_kind == 0, t.s_col, t.zcol[np.maximum(t.s_mem, 0)])[sm]
        n_s = int(np.sum(t.s_nrows[multi_g]))
        a.le_r = np.concatenate(
            [t.le_r, t.m_le + np.arange(nzm), h_start[hmem] + t.h_row[hm],
             d_start[t.d_mem[dm]] + t.d_row[dm], row0 + n_h + n_d + np.arange(n_w),
             s_start[t.s_grp[sm]] + t.s_row[sm]]
        )  # fmt: skip
        a.le_c = np.concatenate([t.le_c, zm, h_cols, t.d_col[dm], a.w_col, s_cols])
        a.le_v = np.concatenate(
            [t.le_v, -np.ones(nzm), t.h_val[hm], t.d_val[dm], -np.ones(n_w), t.s_val[sm]]
        )
        a.le_b = np.concatenate(
            [t.le_b, np.zeros(nzm + n_h), t.d_beta[single[t.d_beta_mem]], np.zeros(n_w + n_s)]
        )
        a.m_le = row0 + n_h + n_d + n_w + n_s

    def _stack(self, base: _Base, t: _Templates, a: _Assembly) -> _NodeProblem:
        """The node problem: equalities, inequalities, the base's cones and the perspective cones
        stacked as COO entries, and the objective (the direct cost of single members, 1 on each
        perspective variable)."""
        persp, single = a.persp, a.single
        c_start = _offsets(t.cost_dim, persp)
        cmask = persp[t.c_mem]
        cmem = t.c_mem[cmask]
        ckind = t.c_kind[cmask]
        c_cols = np.where(
            ckind == 0,
            a.copy_start[cmem] + t.c_loc[cmask],
            np.where(ckind == 1, t.zcol[cmem], a.t_col[cmem]),
        )
        soc = base.soc
        soc_r = _cat(soc.r, np.int64)
        n_pc = int(np.sum(t.cost_dim[persp]))
        m_eq, m_le = a.m_eq, a.m_le
        rows = np.concatenate(
            [
                a.eq_r,
                a.le_r + m_eq,
                soc_r + m_eq + m_le,
                c_start[cmem] + t.c_row[cmask] + m_eq + m_le + soc.m,
            ]
        )
        cols = np.concatenate([a.eq_c, a.le_c, _cat(soc.c, np.int64), c_cols])
        vals = np.concatenate([a.eq_v, a.le_v, _cat(soc.v, float), t.c_val[cmask]])
        b = np.concatenate([a.eq_b, a.le_b, _cat(soc.b, float), np.zeros(n_pc)])
        pmask = single[t.dp_mem]
        q = np.zeros(a.ncol)
        q[: base.n_cols] = base.q_vec
        qmask = single[t.dq_mem]
        np.add.at(q, t.dq_i[qmask], t.dq_v[qmask])
        q[a.t_col[persp]] = 1.0
        return _NodeProblem(
            rows=rows,
            cols=cols,
            vals=vals,
            b=b,
            n_rows=m_eq + m_le + soc.m + n_pc,
            m_le=m_le,
            p_i=np.concatenate([t.p_i, t.dp_i[pmask]]),
            p_j=np.concatenate([t.p_j, t.dp_j[pmask]]),
            p_v=np.concatenate([t.p_v, t.dp_v[pmask]]),
            q=q,
            const=base.const + float(np.sum(t.d_const[single])),
        )

    def _compact(self, t: _Templates, a: _Assembly, pb: _NodeProblem) -> NDArray[np.bool_] | None:
        """Leave out the excluded binaries (0 at the node) and the free columns of the base, in
        place; returns the kept columns, or None when a row of binaries only that lost all its
        entries reads ``0 <= b < 0`` (the node is infeasible)."""
        keep_col = np.ones(a.ncol, dtype=bool)
        keep_col[a.ex_cols] = False
        keep_col[t.drop_col] = False
        ent = keep_col[pb.cols]
        pb.rows, pb.cols, pb.vals = pb.rows[ent], pb.cols[ent], pb.vals[ent]
        col_map = np.cumsum(keep_col) - 1
        pb.cols = col_map[pb.cols]
        pb.p_i, pb.p_j = col_map[pb.p_i], col_map[pb.p_j]  # no cost on left-out columns
        pb.q = pb.q[keep_col]
        if len(t.le_bin_rows):
            bin_rows = t.le_bin_rows + a.m_eq
            empty = bin_rows[np.bincount(pb.rows, minlength=pb.n_rows)[bin_rows] == 0]
            if len(empty):
                if np.any(pb.b[empty] < 0.0):
                    return None
                keep_row = np.ones(pb.n_rows, dtype=bool)
                keep_row[empty] = False
                row_map = np.cumsum(keep_row) - 1
                pb.rows, pb.b = row_map[pb.rows], pb.b[keep_row]
                pb.m_le -= len(empty)
                pb.n_rows -= len(empty)
        return keep_col

    def _run(
        self,
        base: _Base,
        t: _Templates,
        a: _Assembly,
        pb: _NodeProblem,
        keep_col: NDArray[np.bool_] | None,
    ) -> _Relaxation:
        """Solve the node problem with Clarabel (once more with the robust settings when the fast
        ones end in another status) and map its solution back to the problem's variables."""
        n_var = len(pb.q)
        a_mat = _CscLists.from_coo(pb.rows, pb.cols, pb.vals, (pb.n_rows, n_var))
        p_mat = _CscLists.from_coo(pb.p_i, pb.p_j, pb.p_v, (n_var, n_var))
        cl = self._clarabel
        cones: list[Any] = [cl.ZeroConeT(a.m_eq), cl.NonnegativeConeT(pb.m_le)]
        cones += [self._soc(int(dd)) for dd in base.soc_dims]
        cones += [self._soc(int(dd)) for dd in t.cost_dim[a.persp]]
        t0 = time.perf_counter()
        data = (p_mat, pb.q.tolist(), a_mat, pb.b.tolist(), cones)
        sol = cl.DefaultSolver(*data, self._settings).solve()
        status = str(sol.status)
        if status not in _CLARABEL_DONE:
            # numerical trouble with the fast settings: once more with Clarabel's own defaults
            # (equilibration, iterative refinement) and more iterations
            sol = cl.DefaultSolver(*data, self._robust_settings).solve()
            status = str(sol.status)
        self.solve_time += time.perf_counter() - t0
        self.solves += 1
        if status in ("Solved", "AlmostSolved"):
            bound = min(float(sol.obj_val), float(sol.obj_val_dual)) + pb.const
            if keep_col is None:
                xs = np.asarray(sol.x)
            else:
                xs = np.zeros(a.ncol)
                xs[keep_col] = sol.x
                xs[t.drop_col] = t.drop_val
            x = np.zeros(self.s.problem.n)
            col = base.col
            mapped = col >= 0
            x[mapped] = xs[col[mapped]]
            if base is self.condensed:
                self.recover(x)
            return _Relaxation("solved", bound, x, int(sol.iterations))
        if status in ("PrimalInfeasible", "AlmostPrimalInfeasible"):
            return _Relaxation("infeasible", iterations=int(sol.iterations))
        return _Relaxation("failed", iterations=int(sol.iterations), raw=status)

    def _soc(self, dim: int) -> Any:
        """A second-order cone of dimension ``dim`` (one object per dimension, reused)."""
        cone = self._cones.get(dim)
        if cone is None:
            cone = self._cones[dim] = self._clarabel.SecondOrderConeT(dim)
        return cone
