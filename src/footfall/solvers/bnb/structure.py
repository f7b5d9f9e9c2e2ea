"""The problem split into its choice groups and indicator rows (see :mod:`footfall.solvers.bnb`).

:func:`analyse` checks the shape the backend handles (every binary in one choice group
``sum_{z in G} z = 1``, eq. 5.12j-k; every mixed row a big-M row whose ``z = 0`` form the bounds
imply) and raises :class:`UnsupportedProblem` otherwise. Per group it writes the members' rows
over an orthonormal basis of their row space (the *forms*), eliminates the variables private to
the group by Fourier-Motzkin, and assigns the objective rows that lie in the forms (the
horizontal step terms of eq. 5.11) to the group for the perspective relaxation.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall.errors import SolverError
from footfall.solvers.bnb.links import _links, _staircase
from footfall.solvers.bnb.model import _Group, _Member, _Structure
from footfall.solvers.problem import MIQCQP
from footfall.solvers.settings import BnbSettings


class UnsupportedProblem(SolverError, ValueError):
    """The problem does not have the choice-group / big-M shape this backend handles."""


def _eliminate(
    rows: list[tuple[dict[int, float], float]], v: int, lb: float, ub: float, max_rows: int
) -> list[tuple[dict[int, float], float]] | None:
    """Fourier-Motzkin elimination of ``v`` from ``rows`` (each ``sum coef x <= rhs``) given
    ``lb <= v <= ub``: the exact projection. None when it would make more than ``max_rows`` rows."""
    upper = [(r, b) for r, b in rows if r.get(v, 0.0) > 0.0]
    lower = [(r, b) for r, b in rows if r.get(v, 0.0) < 0.0]
    rest = [(r, b) for r, b in rows if r.get(v, 0.0) == 0.0]
    if len(upper) * len(lower) + len(upper) + len(lower) > max_rows:
        return None
    out = list(rest)
    for r, b in upper:  # v <= (b - r x)/a and v >= lb
        a = r[v]
        out.append(({k: c for k, c in r.items() if k != v}, b - a * lb))
    for r, b in lower:  # v >= (b - r x)/a and v <= ub
        a = r[v]
        out.append(({k: c for k, c in r.items() if k != v}, b - a * ub))
    for ru, bu in upper:
        for rl, bl in lower:
            au, al = ru[v], -rl[v]
            comb: dict[int, float] = {}
            for k, c in ru.items():
                if k != v:
                    comb[k] = comb.get(k, 0.0) + c / au
            for k, c in rl.items():
                if k != v:
                    comb[k] = comb.get(k, 0.0) + c / al
            out.append((comb, bu / au + bl / al))
    return out


def _drop_redundant(
    a_v: FloatArray, beta: FloatArray, lb: FloatArray, ub: FloatArray, tol: float
) -> tuple[FloatArray, FloatArray]:
    """Remove rows implied by the box that the bounds and the single-variable rows define.

    The single-variable rows of one variable and direction are replaced by the tightest of them
    (they bound the member's copies; e.g. the Fourier-Motzkin rows of the private sin/cos bound the
    heading less than the segment's own rows do). Removing implied rows leaves the member's set
    unchanged. ``tol``: a row implied within ``tol * max(1, |rhs|)`` counts as implied.
    """
    if not len(beta):
        return a_v, beta
    lo, hi = lb.copy(), ub.copy()
    has_lo = np.zeros(len(lb), dtype=bool)
    has_hi = np.zeros(len(lb), dtype=bool)
    nnz = np.count_nonzero(a_v, axis=1)
    for j in np.flatnonzero(nnz == 1):
        c = int(np.flatnonzero(a_v[j])[0])
        v = a_v[j, c]
        if v > 0:
            hi[c] = min(hi[c], beta[j] / v)
            has_hi[c] = True
        else:
            lo[c] = max(lo[c], beta[j] / v)
            has_lo[c] = True
    top = np.sum(np.maximum(a_v * lo, a_v * hi), axis=1)
    keep = (nnz > 1) & ~(top <= beta - tol * np.maximum(1.0, np.abs(beta)))
    # a row with no variables left is kept only if it is violated (the member is impossible)
    keep |= (nnz == 0) & (beta < -tol)
    eye = np.eye(len(lb))
    rows = [a_v[keep], eye[has_hi], -eye[has_lo]]
    rhs = [beta[keep], hi[has_hi], -lo[has_lo]]
    return np.vstack(rows), np.concatenate(rhs)


#: a member row or cost row lies in a row space when its residual is within this (relative)
SPAN_TOL = 1e-9

IndicatorRows = dict[int, list[tuple[IntArray, FloatArray, float]]]


def analyse(
    problem: MIQCQP, perspective: bool = True, settings: BnbSettings | None = None
) -> _Structure:
    """Split ``problem`` into choice groups and indicator rows; raise :class:`UnsupportedProblem`.

    With ``perspective``, objective rows within one group's forms are assigned to that group;
    ``settings`` give the tolerances and whether to build links (default :class:`BnbSettings`).
    """
    settings = BnbSettings() if settings is None else settings
    group_of, group_rows = _choice_groups(problem)
    plain, ind_rows = _indicator_rows(problem, settings)
    used, owner = _usage(problem, plain, group_rows, ind_rows)
    groups: list[_Group] = []
    member: dict[int, _Member] = {}
    for g, mem in enumerate(group_rows):
        grp, members = _group(problem, g, mem, ind_rows, used, owner, settings)
        groups.append(grp)
        member.update(members)
    assigned = np.zeros(problem.cost_matrix.shape[0], dtype=bool)
    if perspective:
        assigned = _assign_cost_rows(problem, groups)
    out = _Structure(
        problem=problem,
        groups=groups,
        member=member,
        group_of=group_of,
        plain_le=problem.a_le.tocsr()[plain],
        plain_b=problem.b_le[plain],
        assigned=assigned,
    )
    if settings.links:
        _add_links(out, settings)
    return out


def _choice_groups(problem: MIQCQP) -> tuple[dict[int, int], list[list[int]]]:
    """The choice groups: binary -> group, and each group's binaries (ascending). Every integer
    variable must be a binary in exactly one row ``sum_{z in G} z = 1`` (eq. 5.12j-k) and in no
    objective row or cone."""
    integer = problem.integer
    if np.any(integer & ((problem.lb < 0.0) | (problem.ub > 1.0))):
        raise UnsupportedProblem("integer variables must be binaries")
    a_eq = problem.a_eq.tocsr()
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
        if mat.shape[0] and np.any(integer[mat.tocsr().indices]):
            raise UnsupportedProblem(f"binaries in the {what}")
    for idx, _ in problem.cones:
        if np.any(integer[idx]):
            raise UnsupportedProblem("binaries in a cone")
    return group_of, group_rows


def _indicator_rows(problem: MIQCQP, settings: BnbSettings) -> tuple[list[int], IndicatorRows]:
    """The plain inequality rows (no binary, or binaries only) and, per binary ``z``, its
    indicator rows ``(columns, coefficients, rhs)``: "z = 1 implies a^T x <= b - M" from each
    big-M row ``a^T x + M z <= b`` whose ``z = 0`` form the bounds imply."""
    integer = problem.integer
    a_le = problem.a_le.tocsr()
    plain: list[int] = []
    ind_rows: IndicatorRows = {}
    for r in range(a_le.shape[0]):
        cols = a_le.indices[a_le.indptr[r] : a_le.indptr[r + 1]]
        vals = a_le.data[a_le.indptr[r] : a_le.indptr[r + 1]]
        ints = integer[cols]
        k = int(np.count_nonzero(ints))
        if k == 0 or k == len(cols):  # continuous rows, or valid inequalities on binaries only
            plain.append(r)
            continue
        if k > 1 or vals[ints][0] <= 0.0:
            raise UnsupportedProblem(f"row {problem.le_labels[r]!r} is not a big-M row")
        z = int(cols[ints][0])
        big_m = float(vals[ints][0])
        cc, vv = cols[~ints].astype(np.int64), vals[~ints].astype(float)
        top = float(np.sum(np.where(vv > 0, vv * problem.ub[cc], vv * problem.lb[cc])))
        if not math.isfinite(top) or top > problem.b_le[r] + settings.redundant_tol * max(
            1.0, abs(top)
        ):
            raise UnsupportedProblem(f"row {problem.le_labels[r]!r}: its z = 0 form is not implied")
        ind_rows.setdefault(z, []).append((cc, vv, float(problem.b_le[r]) - big_m))
    return plain, ind_rows


def _usage(
    problem: MIQCQP, plain: list[int], group_rows: list[list[int]], ind_rows: IndicatorRows
) -> tuple[NDArray[np.bool_], dict[int, set[int]]]:
    """Where each continuous variable appears: outside the indicator rows (True/False), and the
    groups whose indicator rows hold it."""
    used = np.zeros(problem.n, dtype=bool)
    used[problem.cost_matrix.tocsr().indices] = True
    used[problem.a_eq.tocsr().indices] = True
    used[problem.a_le.tocsr()[plain].indices] = True
    for idx, _ in problem.cones:
        used[idx] = True
    owner: dict[int, set[int]] = {}
    for g, mem in enumerate(group_rows):
        for z in mem:
            for cc, _, _ in ind_rows.get(z, []):
                for c in cc:
                    owner.setdefault(int(c), set()).add(g)
    return used, owner


def _group(
    problem: MIQCQP,
    g: int,
    mem: list[int],
    ind_rows: IndicatorRows,
    used: NDArray[np.bool_],
    owner: dict[int, set[int]],
    settings: BnbSettings,
) -> tuple[_Group, dict[int, _Member]]:
    """Group ``g`` with members ``mem``: its private variables eliminated, its members' rows
    dense over the rest (redundant rows dropped) and over the forms (their row space)."""
    rows_of, private = _eliminate_private(problem, g, mem, ind_rows, used, owner, settings)
    cols_all = sorted({int(c) for z in mem for cc, _, _ in ind_rows.get(z, []) for c in cc})
    variables = np.array([c for c in cols_all if c not in private], dtype=np.int64)
    for c in variables:
        if not (math.isfinite(problem.lb[c]) and math.isfinite(problem.ub[c])):
            raise UnsupportedProblem(f"{problem.names[c]} is in an indicator row but unbounded")
    where = {int(c): k for k, c in enumerate(variables)}
    dense: dict[int, tuple[FloatArray, FloatArray]] = {}
    for z in mem:
        a_v = np.zeros((len(rows_of[z]), len(variables)))
        beta = np.zeros(len(rows_of[z]))
        for j, (row, rhs) in enumerate(rows_of[z]):
            for c, v in row.items():
                a_v[j, where[c]] += v
            beta[j] = rhs
        dense[z] = _drop_redundant(
            a_v, beta, problem.lb[variables], problem.ub[variables], settings.redundant_tol
        )
    stacked = np.vstack([dense[z][0] for z in mem] + [np.zeros((0, len(variables)))])
    if stacked.shape[0] and len(variables):
        _, sv, vt = np.linalg.svd(stacked, full_matrices=False)
        k = int(np.count_nonzero(sv > settings.rank_tol * max(float(sv[0]), 1e-300)))
        basis = vt[:k]
    else:
        basis = np.zeros((0, len(variables)))
    lbv, ubv = problem.lb[variables], problem.ub[variables]
    members: dict[int, _Member] = {}
    for z in mem:
        a_v, beta = dense[z]
        a_f = a_v @ basis.T
        if a_v.size and float(np.max(np.abs(a_f @ basis - a_v))) > SPAN_TOL * max(
            1.0, float(np.max(np.abs(a_v)))
        ):
            raise UnsupportedProblem(
                "indicator rows are not in their row space"
            )  # pragma: no cover
        members[z] = _Member(var=z, a_v=a_v, a_f=a_f, beta=beta, orig=tuple(ind_rows.get(z, [])))
    grp = _Group(
        members=tuple(mem),
        variables=variables,
        basis=basis,
        f_lb=np.sum(np.minimum(basis * lbv, basis * ubv), axis=1),
        f_ub=np.sum(np.maximum(basis * lbv, basis * ubv), axis=1),
        private=np.array(private, dtype=np.int64),
    )
    return grp, members


def _eliminate_private(
    problem: MIQCQP,
    g: int,
    mem: list[int],
    ind_rows: IndicatorRows,
    used: NDArray[np.bool_],
    owner: dict[int, set[int]],
    settings: BnbSettings,
) -> tuple[dict[int, list[tuple[dict[int, float], float]]], list[int]]:
    """Each member's rows as ``({column: coefficient}, rhs)`` with the variables private to group
    ``g`` (in its rows only, e.g. the sin/cos of eq. 5.12g-h) eliminated by Fourier-Motzkin where
    that stays small; returns those rows and the eliminated variables."""
    rows_of = {
        z: [
            (dict(zip(cc.tolist(), vv.tolist(), strict=True)), bb)
            for cc, vv, bb in ind_rows.get(z, [])
        ]
        for z in mem
    }
    cols_all = sorted({int(c) for z in mem for cc, _, _ in ind_rows.get(z, []) for c in cc})
    private: list[int] = []
    for c in cols_all:
        if used[c] or owner[c] != {g}:
            continue
        reduced = {
            z: _eliminate(rows_of[z], c, problem.lb[c], problem.ub[c], settings.max_fm_rows)
            for z in mem
        }
        if any(r is None for r in reduced.values()):
            continue
        rows_of = {z: r for z, r in reduced.items() if r is not None}
        private.append(c)
    return rows_of, private


def _assign_cost_rows(problem: MIQCQP, groups: list[_Group]) -> NDArray[np.bool_]:
    """Assign each objective row that lies in the span of a group's forms (the horizontal step
    terms of eq. 5.11 in a heading-segment group) to the first such group with two or more
    members, in place; returns the mask of assigned rows (charged in perspective form)."""
    assigned = np.zeros(problem.cost_matrix.shape[0], dtype=bool)
    f_csr = problem.cost_matrix.tocsr()
    for g, grp in enumerate(groups):
        if grp.basis.shape[0] == 0 or len(grp.members) < 2:
            continue
        where = {int(c): k for k, c in enumerate(grp.variables)}
        c_rows: list[int] = []
        c_dense: list[FloatArray] = []
        for j in range(f_csr.shape[0]):
            if assigned[j]:
                continue
            cc = f_csr.indices[f_csr.indptr[j] : f_csr.indptr[j + 1]]
            if not all(int(c) in where for c in cc):
                continue
            crow = np.zeros(len(grp.variables))
            for c, v in zip(cc, f_csr.data[f_csr.indptr[j] : f_csr.indptr[j + 1]], strict=True):
                crow[where[int(c)]] += v
            if np.max(np.abs(crow @ grp.basis.T @ grp.basis - crow)) > SPAN_TOL * max(
                1.0, float(np.max(np.abs(crow)))
            ):
                continue
            c_rows.append(j)
            c_dense.append(crow)
        if c_rows:
            assigned[c_rows] = True
            cost_v = np.array(c_dense)
            groups[g] = dataclasses.replace(
                grp,
                cost_rows=np.array(c_rows, dtype=np.int64),
                cost_v=cost_v,
                cost_f=cost_v @ grp.basis.T,
                cost_t=problem.cost_target[c_rows],
                cost_w=problem.cost_weight[c_rows],
            )
    return assigned


def _add_links(out: _Structure, settings: BnbSettings) -> None:
    """Add the links of ``out`` (see :mod:`footfall.solvers.bnb.links`) in place: staircases as
    prefix rows, the others as pair weights, members without a partner fixed to 0."""
    zero: list[int] = []
    out.compat = _links(out, settings)
    for link in out.compat:
        spec = _staircase(out, link) if settings.staircase else None
        if spec is None:
            out.links.append(link)
        else:
            out.prefix_rows += spec[0]
            zero += spec[1]
    if zero:  # members without a compatible partner: z <= 0, a row on binaries only
        n = out.problem.n
        rows = sp.csr_matrix(
            (np.ones(len(zero)), (np.arange(len(zero)), zero)), shape=(len(zero), n)
        )
        out.plain_le = sp.vstack([out.plain_le, rows], format="csr")
        out.plain_b = np.concatenate([out.plain_b, np.zeros(len(zero))])
