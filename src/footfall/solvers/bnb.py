"""Branch and bound on convex-hull relaxations, with Clarabel as the node solver.

This backend solves the :class:`~footfall.solvers.problem.MIQCQP` exactly as built (same variables,
rows, cones, bounds and objective), for problems of the shape the footstep planner builds
(document 000, eq. 5.11-5.18):

* every integer variable is a binary and belongs to exactly one *choice group*: an equality row
  ``sum_{z in G} z = 1`` (one region per footstep, eq. 5.12j; one heading segment, eq. 5.12k);
* every inequality row holds no binary, only binaries (a valid inequality), or one binary ``z`` as a
  big-M row ``a^T x + M z <= b`` (``M > 0``) whose ``z = 0`` form is implied by the variable bounds
  (rows of :meth:`ProblemBuilder.add_le_big_m`): "z = 1 implies a^T x <= b - M";
* binaries appear in no objective row, cone or other equality row.

Anything else raises :class:`UnsupportedProblem` in :func:`analyse`, and :func:`solve` hands the
problem to SCIP (``stats["fallback"]``).

Relaxation of a node (each group ``G`` may use the members ``Z`` still allowed):

* Hull (Balas' extended formulation). The member rows of ``G`` are written over *forms*
  ``f = B x_V`` (an orthonormal basis of their row space; for a heading segment: heading and the
  two step components). Each member ``z`` gets a copy ``f^z`` and ``B x_V = sum_z f^z``,
  ``a_f^T f^z <= beta z`` (its rows scaled by ``z``), ``z >= 0``; the group row gives ``sum z = 1``.
  This is the convex hull of the union of the member sets, where big-M only gives a box. A group
  with one allowed member gets its rows on ``x`` directly; excluded members are fixed to 0.
  Variables private to a group's rows (the piecewise-linear sin/cos of eq. 5.12g-h) are removed by
  Fourier-Motzkin elimination (the exact projection) and recovered from the chosen member.
* Perspective. Objective rows that lie in one group's forms (the horizontal step-length terms of
  eq. 5.11 in the heading-segment group) are charged ``sum_z w (C f^z - t z)^2 / z`` (rotated
  second-order cones): equal at integral points, tighter in between.
* Condensed dynamics. Variables that appear only in equality rows, the objective, their bounds and
  cones (the ALIP states and torques) are eliminated: their optimal cost is a convex quadratic of
  the rest, from one KKT solve. Dropping their bounds and cones keeps a lower bound; when a node's
  recovered point violates one, the node is re-solved with the full model.

* Compact node problems (``BnbSettings.compact``). The same relaxation with a smaller KKT system (a node
  solve costs about linearly in its size): excluded binaries are left out instead of fixed to 0,
  as are columns that only their own bounds constrain (the private sin/cos) and the rows
  ``z >= 0`` that a perspective cone implies; a form that every member bounds only by its own
  interval (a segment's heading) loses its copies, ``sum_z lo_z z <= B_j x_V <= sum_z hi_z z``
  being their exact projection (:func:`_separable_forms`).

* Links (``BnbSettings.links``, off: tighter but dearer per node, see ``benchmarks/RESULTS.md``). Two groups
  coupled by a plain row (the heading rate, eq. 5.12e, between the segment groups of consecutive
  steps) keep only the member pairs that row allows on the members' boxes; the group weights must
  be the marginals of weights on those pairs, written as prefix rows when the pairs form a
  staircase (:func:`_staircase`), and children drop the members left without a partner.

Every bound is ``min(primal, dual)`` of a Clarabel solve of a convex problem, so it is valid.

Search: best-first on the bound. A relaxation point that satisfies the rows of one member of every
group is a feasible point of the MIQCQP (the binaries are then set to those members), so the node
is solved exactly even when the interior-point weights are spread. Otherwise the group whose nearest
member is violated most is split where the cumulative weight of its members (in index order, the
angle order for segments) crosses 1/2 (SOS1 branching). Incumbents come from such nodes and a dive
from the root.

Probing (``probe_rounds``). A search still open after ``probe_after`` nodes per undecided root member
solves the root once with each member fixed and kills the members whose bound reaches the
incumbent (or that are infeasible): no better point uses them, so every open node drops them (a
node that loses any is solved again before it is branched), and the node problems shrink. One
round ranks the members; two primal heuristics then look for a better incumbent (a search of at
most ``heur_nodes`` nodes over each group's ``heur_top`` members of the lowest probe bound, and a
one-group-at-a-time local search), and further rounds probe with it until a round kills nothing.

With ``threads >= 2`` forked worker processes (:class:`_Workers`) solve the nodes asynchronously:
whenever one is free, the best open node is branched and its children submitted; the dive runs in
a worker meanwhile. The queue, incumbent and pruning stay in the calling process, so the search is
the serial one with the node solves moved out (node order may differ, the optimum within the gap
does not). A worker that dies or raises stops the search with :class:`WorkerError`; every worker
is reaped however the search ends. The search stops when ``(incumbent - bound) /
min(|incumbent|, |bound|) <= gap`` (SCIP's definition) or at the time limit, returning the best
point and an honest gap; a node whose solve fails numerically makes the result ``feasible`` at
best, never ``optimal``.
"""

from __future__ import annotations

import dataclasses
import heapq
import math
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall._validate import non_negative
from footfall.errors import InputError
from footfall.solvers.base import SolverOptions, SolverResult, SolveStatus
from footfall.solvers.problem import MIQCQP

NAME = "bnb"


#: Clarabel statuses that end a node solve (anything else is retried once, then "failed")
_CLARABEL_DONE = ("Solved", "AlmostSolved", "PrimalInfeasible", "AlmostPrimalInfeasible")


def _pairs(name: str, value: object) -> tuple[tuple[str, bool | int | float], ...]:
    """``value`` as a tuple of ``(Clarabel setting name, value)`` pairs (a mapping is accepted)."""
    items: Any = value.items() if isinstance(value, Mapping) else value
    try:
        out = tuple((str(k), v) for k, v in items)
    except (TypeError, ValueError):
        raise InputError(name, value, "(name, value) pairs of Clarabel settings") from None
    if any(not isinstance(v, bool | int | float) for _, v in out):
        raise InputError(name, value, "Clarabel settings with bool, int or float values")
    return out


@dataclass(frozen=True)
class BnbSettings:
    """Settings of the ``bnb`` branch and bound (see :mod:`footfall.solvers.bnb`).

    Passed in with the solve (``SolverOptions.bnb``, ``PlannerOptions.bnb``) and echoed in the
    result (``stats["settings"]``); the defaults are the tuned search.

    Attributes:
        feas_tol: largest violation [problem units] accepted for a solution returned to the
            caller; also the slack of a link's pair test (default 1e-6).
        redundant_tol: the ``z = 0`` form of a big-M row must be implied by the variable bounds
            within this (relative to max(1, |rhs|)); a member row implied by its box within
            it is dropped (default 1e-7).
        row_tol: a member's indicator rows count as satisfied by a relaxation point within this
            [problem units] (default 1e-7).
        rank_tol: singular values below this (relative to the largest) do not count in a group's
            row space (default 1e-10).
        max_fm_rows: eliminate a private variable only when Fourier-Motzkin makes at most this
            many rows per member (default 8).
        compact: node problems leave out the columns only their own bounds constrain, the
            binaries of excluded members (instead of rows fixing them to 0), the rows ``z >= 0``
            that a member's perspective cone implies, and the copies of separable forms: the same
            relaxation with a smaller KKT system (default True).
        links: couple groups linked by plain rows (the heading rate, eq. 5.12e) through weights on
            their compatible member pairs: tighter, dearer per node (default False).
        link_min_drop: keep a link only when its rows rule out at least this share of the member
            pairs, in [0, 1] (default 0.25).
        staircase: write a staircase link as prefix rows on its binaries instead of pair weights
            (default True).
        local_solves: with threads >= 2, the search process solves nodes too, beside
            ``threads - 1`` workers, each kept two tasks deep (default False).
        clarabel: Clarabel settings of the node solves, ``(name, value)`` pairs over Clarabel's
            defaults (default: iterative refinement and equilibration off).
        clarabel_retry: Clarabel settings of the one retry of a node whose solve ended in a status
            other than solved or infeasible (default: Clarabel's defaults, ``max_iter`` 200).
        probe_rounds: probing rounds at most: the root relaxation solved once with each member of
            every undecided group fixed, a member whose bound reaches the incumbent (or that is
            infeasible) dropped for the whole search (0: no probing; default 8).
        probe_first_rounds: probing rounds before the primal heuristics, whose incumbent the
            other rounds then use (default 1).
        probe_after: probe once the search has solved this many nodes per member of the root's
            undecided groups without finishing (default 2).
        probe_budget: probing, the restricted search and the local search each solve at most this
            many relaxations per node solved before probing (default 1: together at most three
            times the work before probing).
        probe_min_drop: stop probing when a round dropped less than this share of the members it
            probed and found no better incumbent, in [0, 1] (default 0).
        heur_top: the restricted search after probing keeps each group's this many members of the
            lowest probe bound (0: off; default 2).
        heur_nodes: the restricted search solves at most this many nodes (0: off; default 1000).
        ls_sweeps: local-search sweeps at most (one group moved to another member at a time,
            best improvement per sweep; 0: off; default 20).
        map_depth: tasks in flight per worker in a synchronous batch (default 2).
        drain_timeout: at the end of a parallel search, the workers get this long [s] to finish
            their solves in flight and exit before they are terminated (default 1.0).
    """

    feas_tol: float = 1e-6
    redundant_tol: float = 1e-7
    row_tol: float = 1e-7
    rank_tol: float = 1e-10
    max_fm_rows: int = 8
    compact: bool = True
    links: bool = False
    link_min_drop: float = 0.25
    staircase: bool = True
    local_solves: bool = False
    clarabel: tuple[tuple[str, bool | int | float], ...] = (
        ("iterative_refinement_enable", False),
        ("equilibrate_enable", False),
    )
    clarabel_retry: tuple[tuple[str, bool | int | float], ...] = (("max_iter", 200),)
    probe_rounds: int = 8
    probe_first_rounds: int = 1
    probe_after: float = 2.0
    probe_budget: float = 1.0
    probe_min_drop: float = 0.0
    heur_top: int = 2
    heur_nodes: int = 1000
    ls_sweeps: int = 20
    map_depth: int = 2
    drain_timeout: float = 1.0

    def __post_init__(self) -> None:
        for name in ("feas_tol", "redundant_tol", "row_tol", "rank_tol", "probe_min_drop",
                     "drain_timeout", "link_min_drop"):  # fmt: skip
            object.__setattr__(self, name, non_negative(name, getattr(self, name)))
        for name in ("probe_after", "probe_budget"):  # inf: never / no budget
            value = getattr(self, name)
            if value != math.inf:
                object.__setattr__(self, name, non_negative(name, value))
        for name in ("max_fm_rows", "probe_rounds", "probe_first_rounds", "heur_top",
                     "heur_nodes", "ls_sweeps", "map_depth"):  # fmt: skip
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InputError(name, value, "an integer >= 0")
        for name in ("compact", "links", "staircase", "local_solves"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(name, getattr(self, name), "True or False")
        if self.map_depth < 1:
            raise InputError("map_depth", self.map_depth, "an integer >= 1")
        for name in ("clarabel", "clarabel_retry"):
            object.__setattr__(self, name, _pairs(name, getattr(self, name)))


class UnsupportedProblem(ValueError):
    """The problem does not have the choice-group / big-M shape this backend handles."""


@dataclass(frozen=True)
class _Member:
    """Indicator rows of one binary: ``a^T x <= beta`` when the binary is 1.

    Attributes:
        var: the binary's index.
        a_v: rows over the group's variables ``V`` (private variables eliminated), (m, |V|).
        a_f: the same rows over the group's forms ``f = B x_V``, (m, k).
        beta: right-hand sides, (m,).
        orig: the original rows ``(columns, coefficients, rhs)``, to recover private variables.
    """

    var: int
    a_v: FloatArray
    a_f: FloatArray
    beta: FloatArray
    orig: tuple[tuple[IntArray, FloatArray, float], ...]


@dataclass(frozen=True)
class _Group:
    """A choice group ``sum_{z in members} z = 1``.

    Attributes:
        members: binary variable indices, ascending.
        variables: ``V``, the continuous variables of the members' rows (private ones removed).
        basis: ``B`` (k, |V|), orthonormal basis of the row space of every member row over ``V``;
            the relaxation copies the k forms ``B x_V`` instead of ``x_V``.
        f_lb, f_ub: bounds of the forms over the variable bounds, (k,).
        private: variables that appear in this group's rows and nowhere else but their bounds;
            they are eliminated (Fourier-Motzkin) and recovered from the chosen member.
        cost_rows: objective rows ``w (F x - t)^2`` that lie in the span of the group's forms
            (e.g. the horizontal step-length terms of eq. 5.11 in a heading-segment group); the
            relaxation charges them in perspective form (see :class:`HullRelaxation`).
        cost_v, cost_f: those rows over ``V`` (m, |V|) and over the forms (m, k).
        cost_t, cost_w: their targets and weights, (m,).
    """

    members: tuple[int, ...]
    variables: IntArray
    basis: FloatArray
    f_lb: FloatArray
    f_ub: FloatArray
    private: IntArray
    cost_rows: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    cost_v: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    cost_f: FloatArray = field(default_factory=lambda: np.zeros((0, 0)))
    cost_t: FloatArray = field(default_factory=lambda: np.zeros(0))
    cost_w: FloatArray = field(default_factory=lambda: np.zeros(0))


@dataclass(frozen=True)
class _Link:
    """Two choice groups coupled by plain rows, and the member pairs those rows allow.

    Attributes:
        groups: the two group indices ``(g1, g2)``.
        pairs: binaries ``(z1, z2)`` of the compatible member pairs, (P, 2); a pair is dropped only
            when the plain rows between the groups cannot hold on the box both members imply.
    """

    groups: tuple[int, int]
    pairs: IntArray


@dataclass
class _Structure:
    """The problem split into its static convex part and its choice groups."""

    problem: MIQCQP
    groups: list[_Group]
    member: dict[int, _Member]
    group_of: dict[int, int]
    plain_le: sp.csr_matrix
    plain_b: FloatArray
    assigned: NDArray[np.bool_]  # cost rows charged in perspective form by a group
    #: compatible member pairs of groups linked by plain rows (see :func:`_links`)
    links: list[_Link] = field(default_factory=list)
    #: every link (also those written as prefix rows), for :func:`_propagate`
    compat: list[_Link] = field(default_factory=list)
    #: staircase links as prefix rows ``(g, k, g', k')`` (see :func:`_staircase`)
    prefix_rows: list[tuple[int, int, int, int]] = field(default_factory=list)
    #: per group, its members' rows stacked (see :func:`_violations`), built on first use
    stacked: dict[int, tuple[FloatArray, FloatArray, IntArray, dict[int, int]]] = field(
        default_factory=dict
    )


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


def analyse(
    problem: MIQCQP, perspective: bool = True, settings: BnbSettings | None = None
) -> _Structure:
    """Split ``problem`` into choice groups and indicator rows; raise :class:`UnsupportedProblem`.

    With ``perspective``, objective rows within one group's forms are assigned to that group;
    ``settings`` give the tolerances and whether to build links (default :class:`BnbSettings`).
    """
    settings = BnbSettings() if settings is None else settings
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
        if mat.shape[0] and np.any(integer[mat.tocsr().indices]):
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

    # Where each continuous variable appears outside the indicator rows.
    used = np.zeros(n, dtype=bool)
    used[problem.cost_matrix.tocsr().indices] = True
    used[a_eq.indices] = True
    used[a_le[plain].indices] = True
    for idx, _ in problem.cones:
        used[idx] = True
    owner: dict[int, set[int]] = {}
    for g, mem in enumerate(group_rows):
        for z in mem:
            for cc, _, _ in ind_rows.get(z, []):
                for c in cc:
                    owner.setdefault(int(c), set()).add(g)

    member: dict[int, _Member] = {}
    for g, mem in enumerate(group_rows):
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
        f_lb = np.sum(np.minimum(basis * lbv, basis * ubv), axis=1)
        f_ub = np.sum(np.maximum(basis * lbv, basis * ubv), axis=1)
        for z in mem:
            a_v, beta = dense[z]
            a_f = a_v @ basis.T
            if a_v.size and float(np.max(np.abs(a_f @ basis - a_v))) > 1e-9 * max(
                1.0, float(np.max(np.abs(a_v)))
            ):
                raise UnsupportedProblem(
                    "indicator rows are not in their row space"
                )  # pragma: no cover
            member[z] = _Member(var=z, a_v=a_v, a_f=a_f, beta=beta, orig=tuple(ind_rows.get(z, [])))
        groups.append(
            _Group(
                members=tuple(mem),
                variables=variables,
                basis=basis,
                f_lb=f_lb,
                f_ub=f_ub,
                private=np.array(private, dtype=np.int64),
            )
        )

    assigned = np.zeros(problem.cost_matrix.shape[0], dtype=bool)
    if perspective:
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
                if np.max(np.abs(crow @ grp.basis.T @ grp.basis - crow)) > 1e-9 * max(
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
    out = _Structure(
        problem=problem,
        groups=groups,
        member=member,
        group_of=group_of,
        plain_le=a_le[plain],
        plain_b=problem.b_le[plain],
        assigned=assigned,
    )
    if settings.links:
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
            rows = sp.csr_matrix(
                (np.ones(len(zero)), (np.arange(len(zero)), zero)), shape=(len(zero), n)
            )
            out.plain_le = sp.vstack([out.plain_le, rows], format="csr")
            out.plain_b = np.concatenate([out.plain_b, np.zeros(len(zero))])
    return out


def _staircase(
    s: _Structure, link: _Link
) -> tuple[list[tuple[int, int, int, int]], list[int]] | None:
    """The link's flow condition as prefix rows, when the compatible pairs form a staircase; None
    otherwise.

    Staircase: in member order, each member of either group is compatible with a contiguous run
    of the other group's members, and the runs move forward with the member (heading segments of
    consecutive steps under the heading rate, eq. 5.12e). Weights ``z1``, ``z2`` (each summing to
    1) are then the marginals of weights on the compatible pairs exactly when every prefix of one
    group fits into the members its prefix reaches: ``sum_{a <= k} z1_a <= sum_{b <= hi1(k)} z2_b``
    and the same with the groups swapped (an interval of members splits into a prefix and a suffix,
    and a suffix condition is the other group's prefix condition).

    Returns:
        Rows ``(g, k, g', k')``: prefix ``k`` of group ``g`` <= prefix ``k'`` of group ``g'``
        (prefix ``k``: the sum of the first ``k + 1`` members' binaries), and the binaries of the
        members with no compatible partner (fixed to 0).
    """
    mem = [s.groups[g].members for g in link.groups]
    pos = [{z: k for k, z in enumerate(m)} for m in mem]
    adj = np.zeros((len(mem[0]), len(mem[1])), dtype=bool)
    for z1, z2 in link.pairs:
        adj[pos[0][int(z1)], pos[1][int(z2)]] = True
    rows: list[tuple[int, int, int, int]] = []
    zero: list[int] = []
    for side, a_mat in ((0, adj), (1, adj.T)):
        prev_lo, prev_hi = -1, -1
        reach = -1  # furthest partner of the prefix so far
        for k in range(a_mat.shape[0]):
            hits = np.flatnonzero(a_mat[k])
            if not len(hits):
                zero.append(mem[side][k])
                continue
            lo, hi = int(hits[0]), int(hits[-1])
            if hi - lo + 1 != len(hits) or lo < prev_lo or hi < prev_hi:
                return None
            prev_lo, prev_hi = lo, hi
            reach = max(reach, hi)
            if reach < len(mem[1 - side]) - 1:
                rows.append((link.groups[side], k, link.groups[1 - side], reach))
    return rows, zero


def _member_box(s: _Structure, g: int, z: int) -> tuple[FloatArray, FloatArray]:
    """Bounds of the group's variables when ``z = 1``: the variable bounds tightened by the
    member's single-variable rows (lower, upper), each (|V|,)."""
    grp = s.groups[g]
    lo = s.problem.lb[grp.variables].copy()
    hi = s.problem.ub[grp.variables].copy()
    mb = s.member[z]
    nnz = np.count_nonzero(mb.a_v, axis=1)
    for j in np.flatnonzero(nnz == 1):
        c = int(np.flatnonzero(mb.a_v[j])[0])
        v = float(mb.a_v[j, c])
        if v > 0:
            hi[c] = min(hi[c], mb.beta[j] / v)
        else:
            lo[c] = max(lo[c], mb.beta[j] / v)
    return lo, hi


def _links(s: _Structure, settings: BnbSettings) -> list[_Link]:
    """Member pairs of two groups that the plain rows between them allow.

    A plain row whose variables all lie in the variables of two groups ``g1 != g2`` (e.g. the
    heading rate of eq. 5.12e between the segment groups of consecutive steps) couples them: the
    pair ``(z1, z2)`` is incompatible when the row's smallest activity over the box that ``z1``
    and ``z2`` imply exceeds its right-hand side. The relaxation then requires the weights of the
    two groups to be the marginals of weights on the compatible pairs (a transportation flow),
    which every integral point satisfies with one pair at weight 1.
    """
    pr = s.problem
    a = s.plain_le.tocsr()
    in_groups: dict[int, set[int]] = {}
    for g, grp in enumerate(s.groups):
        if len(grp.members) < 2:
            continue
        for c in grp.variables:
            in_groups.setdefault(int(c), set()).add(g)
    rows_of: dict[tuple[int, int], list[int]] = {}
    for r in range(a.shape[0]):
        cols = a.indices[a.indptr[r] : a.indptr[r + 1]]
        if len(cols) < 2:
            continue
        cover = [in_groups.get(int(c), set()) for c in cols]
        if any(not cv for cv in cover):
            continue
        for g1 in cover[0] | cover[1]:
            for g2 in cover[0] | cover[1]:
                if g1 < g2 and all(g1 in cv or g2 in cv for cv in cover):
                    rows_of.setdefault((g1, g2), []).append(r)
    links = []
    for (g1, g2), rows in sorted(rows_of.items()):
        v1, v2 = s.groups[g1].variables, s.groups[g2].variables
        cols = np.union1d(v1, v2)
        pos1, pos2 = np.searchsorted(cols, v1), np.searchsorted(cols, v2)
        sub = a[rows][:, cols].toarray()
        rhs = s.plain_b[rows]
        boxes2 = [_member_box(s, g2, z2) for z2 in s.groups[g2].members]
        pairs = []
        for z1 in s.groups[g1].members:
            lo1, hi1 = _member_box(s, g1, z1)
            for z2, (lo2, hi2) in zip(s.groups[g2].members, boxes2, strict=True):
                lo, hi = pr.lb[cols].copy(), pr.ub[cols].copy()
                lo[pos1], hi[pos1] = np.maximum(lo[pos1], lo1), np.minimum(hi[pos1], hi1)
                lo[pos2], hi[pos2] = np.maximum(lo[pos2], lo2), np.minimum(hi[pos2], hi2)
                low = np.sum(np.minimum(sub * lo, sub * hi), axis=1)
                tol = settings.feas_tol
                if np.all(lo <= hi + tol) and np.all(
                    low <= rhs + tol * np.maximum(1.0, np.abs(rhs))
                ):
                    pairs.append((z1, z2))
        n_all = len(s.groups[g1].members) * len(s.groups[g2].members)
        if len(pairs) <= (1.0 - settings.link_min_drop) * n_all:
            links.append(_Link((g1, g2), np.array(pairs, dtype=np.int64).reshape(-1, 2)))
    return links


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
    cones (the ALIP states and torques of the planner): ``V(w) = min_y cost`` subject to the
    equality rows is a convex quadratic of the remaining ``w``, computed once from the KKT system.
    Dropping the bounds and cones of ``y`` gives a valid lower bound; a point whose recovered ``y``
    satisfies them is exact. Returns None when nothing can be eliminated or the KKT system is
    singular (e.g. a zero torque weight).
    """
    pr = s.problem
    n = pr.n
    keep = np.zeros(n, dtype=bool)
    keep[pr.integer] = True
    keep[s.plain_le.indices] = True
    for grp in s.groups:
        keep[grp.variables] = True
        keep[grp.private] = True
    # a variable in no equality row and no cost row has nothing to determine it: keep it
    keep[np.asarray(abs(pr.a_eq).sum(axis=0) + abs(pr.cost_matrix).sum(axis=0)).ravel() == 0] = True
    y_mask = ~keep
    for idx, _ in pr.cones:
        if np.any(keep[idx]):
            return None
    y_idx = np.flatnonzero(y_mask)
    w_idx = np.flatnonzero(keep)
    if len(y_idx) == 0:
        return None
    a_eq = pr.a_eq.tocsr()
    touches_y = np.asarray(abs(a_eq[:, y_idx]).sum(axis=1) > 0).ravel()
    e_y = a_eq[touches_y][:, y_idx]
    e_w = a_eq[touches_y][:, w_idx]
    e_rhs = pr.b_eq[touches_y]
    f_mat = pr.cost_matrix.tocsr()
    rows_y = np.asarray(abs(f_mat[:, y_idx]).sum(axis=1) > 0).ravel()
    f_y = f_mat[rows_y][:, y_idx]
    f_wy = f_mat[rows_y][:, w_idx]
    t_y = pr.cost_target[rows_y]
    wt_y = pr.cost_weight[rows_y]
    # Parameters that move y: w columns of the y equality rows and of the y cost rows.
    support = np.flatnonzero(
        np.asarray(abs(e_w).sum(axis=0)).ravel() + np.asarray(abs(f_wy).sum(axis=0)).ravel()
    )
    h = 2.0 * (f_y.T @ sp.diags(wt_y) @ f_y)
    m_y = e_y.shape[0]
    kkt = sp.bmat([[h, e_y.T], [e_y, None]], format="csc")
    ny = len(y_idx)
    rhs_lin = np.vstack(
        [
            -2.0 * (f_y.T @ sp.diags(wt_y) @ f_wy[:, support]).toarray(),
            -e_w[:, support].toarray(),
        ]
    )
    rhs_off = np.concatenate([2.0 * (f_y.T @ (wt_y * t_y)), e_rhs])
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
    y_lin, y_off = sol[:ny, :-1], sol[:ny, -1]
    del m_y
    # New cost rows over w: F_y (Y w_S + y0) + F_wy w - t.
    w_pos = np.full(n, -1, dtype=np.int64)
    w_pos[w_idx] = np.arange(len(w_idx))
    f_eff = (f_y @ y_lin) + f_wy[:, support].toarray()
    t_eff = t_y - f_y @ y_off
    sq = np.sqrt(wt_y)
    a_s = sq[:, None] * f_eff
    t_s = sq * t_eff
    # other cost rows (only w)
    other = ~rows_y & ~s.assigned
    if np.any(rows_y & s.assigned):  # pragma: no cover - assigned rows hold only group variables
        return None
    f_o = f_mat[other][:, w_idx]
    p_o, q_o, c_o = _cost_pq(f_o.tocsr(), pr.cost_target[other], pr.cost_weight[other])
    nw = len(w_idx)
    p_s = np.zeros((nw, nw))
    p_s_sub = 2.0 * (a_s.T @ a_s)
    p_s[np.ix_(support, support)] = p_s_sub
    p_mat = sp.triu(p_o + sp.csc_matrix(np.triu(p_s)), format="csc")
    q_vec = q_o.copy()
    q_vec[support] += -2.0 * (a_s.T @ t_s)
    const = c_o + float(t_s @ t_s)
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
    return _Base(
        nw,
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


def _templates(s: _Structure, base: _Base, compact: bool) -> _Templates:
    col = base.col
    groups: list[int] = []
    zcol: list[int] = []
    kk: list[int] = []
    nrows: list[int] = []
    has_cost: list[bool] = []
    cdim: list[int] = []
    h: tuple[list[Any], ...] = ([], [], [], [], [], [])
    c: tuple[list[Any], ...] = ([], [], [], [], [], [])
    d: tuple[list[Any], ...] = ([], [], [], [], [], [], [])
    dp: tuple[list[Any], ...] = ([], [], [], [])
    dq: tuple[list[Any], ...] = ([], [], [])
    dconst: list[float] = []
    link: tuple[list[Any], ...] = ([], [], [], [])
    sep: tuple[list[Any], ...] = ([], [], [], [], [], [])
    sep_rows: list[int] = []
    mi = 0
    for g, grp in enumerate(s.groups):
        vcols = col[grp.variables]
        keepf, sepf, s_lo, s_hi, is_sep_row = _separable_forms(s, grp, compact)
        basis = grp.basis[keepf]
        k = len(keepf)
        br, bc = np.nonzero(basis)
        link[0].append(np.full(len(br), g))
        link[1].append(br)
        link[2].append(vcols[bc])
        link[3].append(basis[br, bc])
        # separable forms: sum_z lo_z z <= B_j x_V <= sum_z hi_z z (the copies projected out)
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
        sep_rows.append(n_sep)
        n_cost = len(grp.cost_rows)
        if n_cost:
            sw = 2.0 * np.sqrt(grp.cost_w)
            cf = sw[:, None] * grp.cost_f[:, keepf]
            cr, cc = np.nonzero(cf)
            wv = grp.cost_w[:, None] * grp.cost_v
            pg = np.triu(2.0 * grp.cost_v.T @ wv)
            pi, pj = np.nonzero(pg)
            qg = -2.0 * wv.T @ grp.cost_t
        for z in grp.members:
            mb = s.member[z]
            groups.append(g)
            zcol.append(col[z])
            kk.append(k)
            a_f = mb.a_f[~is_sep_row[z]][:, keepf]
            beta = mb.beta[~is_sep_row[z]]
            nb = len(beta)
            nrows.append(nb)
            has_cost.append(n_cost > 0)
            cdim.append(n_cost + 2 if n_cost else 0)
            # hull rows: a_f f - beta z <= 0 (the copies are bounded through the member rows)
            rr, cc2 = np.nonzero(a_f)
            rows = np.r_[rr, np.arange(nb)]
            kind = np.r_[np.zeros(len(rr)), np.ones(nb)].astype(np.int64)
            loc = np.r_[cc2, np.zeros(nb)].astype(np.int64)
            val = np.r_[a_f[rr, cc2], -beta]
            h[0].append(np.full(len(rows), mi))
            h[1].append(rows)
            h[2].append(kind)
            h[3].append(loc)
            h[4].append(val)
            if n_cost:
                # perspective: ||(2 sqrt(w) (C f^z - t z), t_z - z)|| <= t_z + z
                rows = np.r_[0, 0, 1, 1, cr + 2, np.arange(n_cost) + 2]
                kind = np.r_[2, 1, 2, 1, np.zeros(len(cr)), np.ones(n_cost)].astype(np.int64)
                loc = np.r_[0, 0, 0, 0, cc, np.zeros(n_cost)].astype(np.int64)
                val = np.r_[-1.0, -1.0, -1.0, 1.0, -cf[cr, cc], sw * grp.cost_t]
                c[0].append(np.full(len(rows), mi))
                c[1].append(rows)
                c[2].append(kind)
                c[3].append(loc)
                c[4].append(val)
            # direct rows
            rr, cc2 = np.nonzero(mb.a_v)
            d[0].append(np.full(len(rr), mi))
            d[1].append(rr)
            d[2].append(vcols[cc2])
            d[3].append(mb.a_v[rr, cc2])
            d[4].append(len(mb.beta))
            d[5].append(mb.beta)
            d[6].append(np.full(len(mb.beta), mi))
            if n_cost:
                lo = np.minimum(vcols[pi], vcols[pj])
                hi = np.maximum(vcols[pi], vcols[pj])
                dp[0].append(np.full(len(pi), mi))
                dp[1].append(lo)
                dp[2].append(hi)
                dp[3].append(pg[pi, pj])
                dq[0].append(np.full(len(vcols), mi))
                dq[1].append(vcols)
                dq[2].append(qg)
                dconst.append(float(np.sum(grp.cost_w * grp.cost_t**2)))
            else:
                dconst.append(0.0)
            mi += 1
    i64, f64 = np.int64, float
    out = _Templates(
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
        group=np.array(groups, dtype=i64),
        zcol=np.array(zcol, dtype=i64),
        k=np.array(kk, dtype=i64),
        n_rows=np.array(nrows, dtype=i64),
        has_cost=np.array(has_cost, dtype=bool),
        cost_dim=np.array(cdim, dtype=i64),
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
        d_const=np.array(dconst, dtype=f64),
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
        s_nrows=np.array(sep_rows, dtype=i64),
    )
    pm = base.p_mat.tocoo()
    out = dataclasses.replace(
        out, p_i=pm.row.astype(i64), p_j=pm.col.astype(i64), p_v=pm.data.astype(f64)
    )
    is_bin = np.zeros(base.n_cols, dtype=bool)
    is_bin[out.zcol] = True
    nonbin = np.bincount(out.le_r, weights=~is_bin[out.le_c], minlength=out.m_le)
    out = dataclasses.replace(out, le_bin_rows=np.flatnonzero(nonbin == 0))
    return _dropped_columns(s, out) if compact else out


class _CscLists:
    """A CSC matrix with its arrays as Python lists, to hand to ``clarabel.DefaultSolver``.

    Clarabel's Python wrapper (0.11) reads ``data``, ``indices`` and ``indptr`` element by element;
    from numpy arrays that costs about 0.65 ms of a 9 ms node solve at N = 15, from lists (built by
    ``tolist``) about a third of it. It reads only these attributes and ``shape`` and
    ``has_canonical_format``; the matrices given are canonical (sorted, no duplicates).
    """

    __slots__ = ("data", "has_canonical_format", "indices", "indptr", "shape")

    def __init__(self, mat: sp.csc_matrix) -> None:
        if not mat.has_canonical_format:
            mat.sum_duplicates()
        self.data = mat.data.tolist()
        self.indices = mat.indices.tolist()
        self.indptr = mat.indptr.tolist()
        self.shape = mat.shape
        self.has_canonical_format = True


def _offsets(counts: IntArray, mask: NDArray[np.bool_]) -> IntArray:
    """Start of each selected item in a packed layout (garbage where not selected)."""
    c = np.where(mask, counts, 0)
    return np.cumsum(c) - c


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
        pr = self.s.problem
        n_groups = len(self.s.groups)
        sel = np.zeros(self.n_members, dtype=bool)
        sel[self.member_index[[z for mem in allowed for z in mem]]] = True
        count = np.bincount(t.group[sel], minlength=n_groups)
        multi_g = count >= 2
        multi = sel & multi_g[t.group]
        single = sel & ~multi
        excluded = ~sel

        ncol0 = base.n_cols
        # columns: copies of the forms, then the perspective variables
        copy_start = ncol0 + _offsets(t.k, multi)
        n_copies = int(np.sum(t.k[multi]))
        persp = multi & t.has_cost
        t_col = ncol0 + n_copies + _offsets(np.ones_like(t.k), persp)
        ncol = ncol0 + n_copies + int(np.count_nonzero(persp))

        # equalities: static, excluded binaries = 0 (unless left out), linking rows of multi groups
        ex_cols = t.zcol[excluded]
        n_ex = 0 if self.settings.compact else len(ex_cols)
        k_group = np.zeros(n_groups, dtype=np.int64)
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
        eq_c = np.concatenate([t.eq_c, ex_cols[:n_ex], t.l_col[lm], copy_start[cm] + cj])
        eq_v = np.concatenate([t.eq_v, np.ones(n_ex), t.l_val[lm], -np.ones(len(cm))])
        m_eq = t.m_eq + n_ex + int(np.sum(k_group[multi_g]))
        # link flows: sum_{pairs of z} w - z = 0 per (link, side, allowed member), w >= 0
        lrsel = sel[self.lr_mem]
        renum = m_eq + np.cumsum(lrsel) - 1
        psel = sel[self.p_m[:, 0]] & sel[self.p_m[:, 1]]
        n_w = int(np.count_nonzero(psel))
        w_col = ncol + np.arange(n_w)
        ncol += n_w
        eq_r = np.concatenate(
            [eq_r, renum[self.p_r[psel, 0]], renum[self.p_r[psel, 1]], renum[lrsel]]
        )
        eq_c = np.concatenate([eq_c, w_col, w_col, t.zcol[self.lr_mem[lrsel]]])
        eq_v = np.concatenate([eq_v, np.ones(2 * n_w), -np.ones(int(np.count_nonzero(lrsel)))])
        m_eq += int(np.count_nonzero(lrsel))
        eq_b = np.concatenate([t.eq_b, np.zeros(m_eq - t.m_eq)])

        # inequalities: static, -z <= 0 for multi members (not where the perspective cone implies
        # it), hull rows, direct rows
        zrow = multi & ~t.has_cost if self.settings.compact else multi
        zm = t.zcol[zrow]
        nzm = len(zm)
        row0 = t.m_le + nzm
        h_start = row0 + _offsets(t.n_rows, multi)
        hm = multi[t.h_mem]
        hmem = t.h_mem[hm]
        hkind = t.h_kind[hm]
        h_cols = np.where(hkind == 0, copy_start[hmem] + t.h_loc[hm], t.zcol[hmem])
        n_h = int(np.sum(t.n_rows[multi]))
        d_start = row0 + n_h + _offsets(t.d_nrows, single)
        dm = single[t.d_mem]
        n_d = int(np.sum(t.d_nrows[single]))
        # rows of the separable forms of multi groups (see _separable_forms)
        s_start = row0 + n_h + n_d + n_w + _offsets(t.s_nrows, multi_g)
        sm = np.where(t.s_kind == 0, multi_g[t.s_grp], multi[np.maximum(t.s_mem, 0)])
        s_cols = np.where(t.s_kind == 0, t.s_col, t.zcol[np.maximum(t.s_mem, 0)])[sm]
        n_s = int(np.sum(t.s_nrows[multi_g]))
        le_r = np.concatenate(
            [t.le_r, t.m_le + np.arange(nzm), h_start[hmem] + t.h_row[hm],
             d_start[t.d_mem[dm]] + t.d_row[dm], row0 + n_h + n_d + np.arange(n_w),
             s_start[t.s_grp[sm]] + t.s_row[sm]]
        )  # fmt: skip
        le_c = np.concatenate([t.le_c, zm, h_cols, t.d_col[dm], w_col, s_cols])
        le_v = np.concatenate(
            [t.le_v, -np.ones(nzm), t.h_val[hm], t.d_val[dm], -np.ones(n_w), t.s_val[sm]]
        )
        le_b = np.concatenate(
            [t.le_b, np.zeros(nzm + n_h), t.d_beta[single[t.d_beta_mem]], np.zeros(n_w + n_s)]
        )
        m_le = row0 + n_h + n_d + n_w + n_s

        # cones: static (base) and perspective
        c_start = _offsets(t.cost_dim, persp)
        cmask = persp[t.c_mem]
        cmem = t.c_mem[cmask]
        ckind = t.c_kind[cmask]
        c_cols = np.where(
            ckind == 0,
            copy_start[cmem] + t.c_loc[cmask],
            np.where(ckind == 1, t.zcol[cmem], t_col[cmem]),
        )
        soc = base.soc
        soc_r = _cat(soc.r, np.int64)
        n_pc = int(np.sum(t.cost_dim[persp]))
        rows = np.concatenate(
            [
                eq_r,
                le_r + m_eq,
                soc_r + m_eq + m_le,
                c_start[cmem] + t.c_row[cmask] + m_eq + m_le + soc.m,
            ]
        )
        cols = np.concatenate([eq_c, le_c, _cat(soc.c, np.int64), c_cols])
        vals = np.concatenate([eq_v, le_v, _cat(soc.v, float), t.c_val[cmask]])
        b = np.concatenate([eq_b, le_b, _cat(soc.b, float), np.zeros(n_pc)])
        n_rows = m_eq + m_le + soc.m + n_pc

        pmask = single[t.dp_mem]
        p_i = np.concatenate([t.p_i, t.dp_i[pmask]])
        p_j = np.concatenate([t.p_j, t.dp_j[pmask]])
        p_v = np.concatenate([t.p_v, t.dp_v[pmask]])
        q = np.zeros(ncol)
        q[: base.n_cols] = base.q_vec
        qmask = single[t.dq_mem]
        np.add.at(q, t.dq_i[qmask], t.dq_v[qmask])
        q[t_col[persp]] = 1.0
        const = base.const + float(np.sum(t.d_const[single]))

        keep_col = None
        if self.settings.compact:
            # leave out the excluded binaries (0 at the node) and the free columns of the base
            keep_col = np.ones(ncol, dtype=bool)
            keep_col[ex_cols] = False
            keep_col[t.drop_col] = False
            ent = keep_col[cols]
            rows, cols, vals = rows[ent], cols[ent], vals[ent]
            col_map = np.cumsum(keep_col) - 1
            cols = col_map[cols]
            p_i, p_j = col_map[p_i], col_map[p_j]  # no cost on left-out columns
            q = q[keep_col]
            if len(t.le_bin_rows):
                # a row of binaries only that lost all its entries reads 0 <= b
                bin_rows = t.le_bin_rows + m_eq
                empty = bin_rows[np.bincount(rows, minlength=n_rows)[bin_rows] == 0]
                if len(empty):
                    if np.any(b[empty] < 0.0):
                        return _Relaxation("infeasible")
                    keep_row = np.ones(n_rows, dtype=bool)
                    keep_row[empty] = False
                    row_map = np.cumsum(keep_row) - 1
                    rows, b = row_map[rows], b[keep_row]
                    m_le -= len(empty)
                    n_rows -= len(empty)
        n_var = len(q)
        a_mat = sp.csc_matrix((vals, (rows, cols)), shape=(n_rows, n_var))
        p_mat = sp.csc_matrix((p_v, (p_i, p_j)), shape=(n_var, n_var))

        cl = self._clarabel
        cones: list[Any] = [cl.ZeroConeT(m_eq), cl.NonnegativeConeT(m_le)]
        cones += [self._soc(int(dd)) for dd in base.soc_dims]
        cones += [self._soc(int(dd)) for dd in t.cost_dim[persp]]
        t0 = time.perf_counter()
        data = (_CscLists(p_mat), q.tolist(), _CscLists(a_mat), b.tolist(), cones)
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
            bound = min(float(sol.obj_val), float(sol.obj_val_dual)) + const
            if keep_col is None:
                xs = np.asarray(sol.x)
            else:
                xs = np.zeros(ncol)
                xs[keep_col] = sol.x
                xs[t.drop_col] = t.drop_val
            x = np.zeros(pr.n)
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


@dataclass(order=True)
class _Node:
    bound: float
    order: int
    allowed: tuple[tuple[int, ...], ...] = field(compare=False)
    x: FloatArray | None = field(compare=False, default=None)
    depth: int = field(compare=False, default=0)
    full: bool = field(compare=False, default=False)


def _weights(x: FloatArray, mem: tuple[int, ...]) -> FloatArray:
    return np.clip(x[list(mem)], 0.0, 1.0)


def _violations(s: _Structure, x: FloatArray, g: int, mem: tuple[int, ...]) -> FloatArray:
    """Largest violation of each member's indicator rows at ``x``, shape (len(mem),) (0 for a
    member without rows)."""
    if g not in s.stacked:
        members = s.groups[g].members
        a = np.vstack([s.member[z].a_v for z in members])
        beta = np.concatenate([s.member[z].beta for z in members])
        owner = np.repeat(np.arange(len(members)), [len(s.member[z].beta) for z in members])
        s.stacked[g] = (a, beta, owner, {z: k for k, z in enumerate(members)})
    a, beta, owner, pos = s.stacked[g]
    worst = np.full(len(pos), -np.inf)
    np.maximum.at(worst, owner, a @ x[s.groups[g].variables] - beta)
    out = worst[[pos[z] for z in mem]]
    out[np.isneginf(out)] = 0.0
    return out


def _choice(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[int, ...], ...] | None:
    """A member per group whose rows ``x`` satisfies within ``tol`` (None if some group has none).

    ``x`` then is a feasible point of the MIQCQP with those binaries set to 1: the relaxation solution
    is integer feasible even when the IPM spread the weights over several equally good members.
    """
    out = []
    for g, mem in enumerate(allowed):
        if len(mem) == 1:
            out.append(mem)
            continue
        v = _violations(s, x, g, mem)
        k = int(np.argmin(v))
        if v[k] > tol:
            return None
        out.append((mem[k],))
    return tuple(out)


def _without(allowed: tuple[tuple[int, ...], ...], drop: set[int]) -> tuple[tuple[int, ...], ...]:
    """``allowed`` without the members ``drop``; a group with one member keeps it."""
    return tuple(
        mem if len(mem) == 1 else tuple(z for z in mem if z not in drop) for mem in allowed
    )


def _sos_point(w: FloatArray) -> int:
    """Where an SOS split of weights ``w`` (members in index order) cuts: at the weighted mean."""
    centre = float(np.dot(w, np.arange(len(w)))) / max(float(np.sum(w)), 1e-12)
    return min(max(round(centre + 0.5), 1), len(w) - 1)


def _candidates(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> list[int]:
    """Groups with every member violated at ``x`` (beyond ``tol``), the one whose nearest member
    is violated most first."""
    scored: list[tuple[float, int]] = []
    for g, mem in enumerate(allowed):
        if len(mem) < 2:
            continue
        viol = _violations(s, x, g, mem)
        if float(np.min(viol)) <= tol:
            continue
        scored.append((-float(np.min(viol)), g))
    scored.sort()
    return [g for _, g in scored]


def _split(
    x: FloatArray, allowed: tuple[tuple[int, ...], ...], g: int
) -> tuple[tuple[tuple[int, ...], ...], tuple[tuple[int, ...], ...]]:
    """Split group ``g`` into two halves at the weighted mean of its members (SOS1 branching)."""
    mem = allowed[g]
    k = _sos_point(_weights(x, mem))
    one, other = mem[:k], mem[k:]
    left = [*allowed]
    right = [*allowed]
    left[g] = one
    right[g] = other
    return tuple(left), tuple(right)


def _propagate(
    s: _Structure, allowed: tuple[tuple[int, ...], ...]
) -> tuple[tuple[int, ...], ...] | None:
    """Drop the members without a compatible allowed partner in some linked group (see
    :func:`_links`), until nothing changes; None when a group is left without members (no
    integral point of the node exists). Removes only members that no feasible point uses."""
    cur = [set(m) for m in allowed]
    changed = True
    while changed:
        changed = False
        for link in s.compat:
            g1, g2 = link.groups
            keep1 = {int(a) for a, b in link.pairs if a in cur[g1] and b in cur[g2]}
            keep2 = {int(b) for a, b in link.pairs if a in cur[g1] and b in cur[g2]}
            if keep1 != cur[g1] or keep2 != cur[g2]:
                cur[g1], cur[g2] = keep1, keep2
                changed = True
                if not keep1:
                    return None
    return tuple(m if len(m) == len(c) else tuple(z for z in m if z in c)
                 for m, c in zip(allowed, cur, strict=True))  # fmt: skip


def _branch(
    s: _Structure, x: FloatArray, allowed: tuple[tuple[int, ...], ...], tol: float
) -> tuple[tuple[tuple[int, ...], ...], ...] | None:
    """Split the best violated group (see :func:`_candidates`) into two halves (:func:`_split`);
    with links, each child is reduced by :func:`_propagate` (a child left empty is dropped)."""
    cands = _candidates(s, x, allowed, tol)
    if not cands:
        return None
    children = _split(x, allowed, cands[0])
    if not s.compat:
        return children
    return tuple(c for c in (_propagate(s, a) for a in children) if c is not None)


def _finish(s: _Structure, x: FloatArray, chosen: tuple[tuple[int, ...], ...]) -> FloatArray:
    """A relaxation solution as a MIQCQP point: the chosen binaries set to 1, the others to 0, and
    each group's private variables recovered from the chosen member's rows."""
    pr = s.problem
    out = x.copy()
    # Variables fixed by their bounds take exactly that value (the node solver returns them only
    # to its tolerance, e.g. -3e-18 for a 0).
    fixed = pr.lb == pr.ub
    out[fixed] = pr.lb[fixed]
    out[pr.integer] = 0.0
    for g, mem in enumerate(chosen):
        z = mem[0]
        out[z] = 1.0
        for v in s.groups[g].private:
            lo, hi = float(pr.lb[v]), float(pr.ub[v])
            for cc, vv, bb in s.member[z].orig:
                hit = cc == v
                if not np.any(hit):
                    continue
                a = float(vv[hit][0])
                rest = float(vv[~hit] @ out[cc[~hit]])
                if a > 0.0:
                    hi = min(hi, (bb - rest) / a)
                else:
                    lo = max(lo, (bb - rest) / a)
            out[v] = 0.5 * (lo + hi) if lo <= hi else lo
    return out


def _root_allowed(s: _Structure) -> tuple[tuple[int, ...], ...]:
    """Members allowed by the binaries' own bounds (a binary fixed to 1 excludes the others)."""
    pr = s.problem
    out = []
    for grp in s.groups:
        ones = tuple(z for z in grp.members if pr.lb[z] >= 0.5)
        out.append(ones if ones else tuple(z for z in grp.members if pr.ub[z] >= 0.5))
    return tuple(out)


def solve(problem: MIQCQP, options: SolverOptions) -> SolverResult:
    """Solve ``problem`` by branch and bound on hull relaxations (see the module docstring).

    A problem without the choice-group shape is handed to SCIP (``stats["fallback"]`` says why).
    """
    start = time.perf_counter()
    try:
        structure = analyse(problem, settings=options.bnb)
    except UnsupportedProblem as exc:
        from footfall.solvers import scip

        res = scip.solve(problem, options)
        res.stats["fallback"] = f"bnb cannot take this problem ({exc}); solved by SCIP"
        return res
    search = _Search(structure, options, start)
    return search.run()


def _dive(
    relax: HullRelaxation,
    x: FloatArray,
    allowed: tuple[tuple[int, ...], ...],
    cutoff: float,
    deadline: float,
    stop: Any = None,
) -> tuple[tuple[int, ...], ...] | None:
    """Depth-first dive from a relaxation solution: fix the group whose nearest member (least
    violated rows) is nearest to that member and re-solve, until the relaxation point satisfies
    one member per group (returns that assignment) or is hopeless (None): infeasible, or its bound
    reaches ``cutoff``. Gives up at ``deadline`` or when the shared flag ``stop`` is set."""
    s = relax.s
    cur = allowed
    for _ in range(2 * len(cur)):
        if time.perf_counter() > deadline or (stop is not None and stop.value):
            return None
        best_g, best_v, z = -1, math.inf, -1
        for g, mem in enumerate(cur):
            if len(mem) > 1:
                viol = _violations(s, x, g, mem)
                k = int(np.argmin(viol))
                if viol[k] < best_v:
                    best_g, best_v, z = g, float(viol[k]), mem[k]
        if best_g < 0:
            return None
        mem = cur[best_g]
        fixed = list(cur)
        fixed[best_g] = (z,)
        res = relax.solve(tuple(fixed))
        if res.status != "solved" or res.x is None:
            rest = list(cur)
            rest[best_g] = tuple(m for m in mem if m != z)
            cur = tuple(rest)
            res = relax.solve(cur)
            if res.status != "solved" or res.x is None:
                return None
        else:
            cur = tuple(fixed)
        if res.bound >= cutoff:
            return None
        x = res.x
        chosen = _choice(s, x, cur, relax.settings.row_tol)
        if chosen is not None:
            return chosen
    return None


_WORKER: HullRelaxation | None = None
#: in a worker: a shared flag the search sets when it ends (see :class:`_Workers`)
_STOP: Any = None


class WorkerError(RuntimeError):
    """A worker process of the search died or failed; the message says which and how."""


def _work(task: tuple[tuple[tuple[int, ...], ...], bool]) -> _Relaxation:
    """Solve one node relaxation in a worker process (forked with the relaxation built)."""
    assert _WORKER is not None
    allowed, full = task
    res = _WORKER.solve(allowed, full=full)
    if res.status == "failed" and not full:
        res = _WORKER.solve(allowed, full=True)
    return res


def _work_dive(
    task: tuple[FloatArray, tuple[tuple[int, ...], ...], float, float],
) -> tuple[tuple[tuple[int, ...], ...] | None, _Relaxation | None]:
    """Dive in a worker process (see :func:`_dive`); returns the assignment it ends at and the
    condensed relaxation with every group fixed to it."""
    assert _WORKER is not None
    chosen = _dive(_WORKER, *task, stop=_STOP)
    return chosen, None if chosen is None else _WORKER.solve(chosen)


def _serve(conn: Any, relax: HullRelaxation, stop: Any) -> None:
    """Body of a worker process: answer ``(id, kind, task)`` messages with ``(id, ok, result)``
    until ``None`` or the end of the pipe. A task's exception is sent back as text (it may not
    pickle); SIGINT is left to the search, which shuts the workers down."""
    import signal
    import traceback

    global _WORKER, _STOP
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER, _STOP = relax, stop
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return  # the search process is gone
        if msg is None:
            return
        tid, kind, task = msg
        out: tuple[int, bool, Any]
        try:
            out = (tid, True, _work_dive(task) if kind == "dive" else _work(task))
        except Exception:
            out = (tid, False, traceback.format_exc())
        try:
            conn.send(out)
        except (BrokenPipeError, OSError):
            return


class _Workers:
    """``n`` forked worker processes solving the node relaxations of one search.

    Forked, so every worker inherits the built relaxation (:class:`HullRelaxation`, with its
    templates and condensed KKT factor) instead of receiving it pickled; a task is only a node's
    allowed members (tuples of ints) and a result one :class:`_Relaxation`.

    Not :class:`multiprocessing.pool.Pool`: a Pool silently replaces a worker that dies (a crash
    in the node solver, the out-of-memory killer) and the task it held never returns, so the search
    would wait for it until its time limit (and the replacement, forked later, would not hold the
    relaxation). Here each worker has its own pipe and :meth:`wait` watches the pipes and the
    processes' sentinels together, so a dead worker raises :class:`WorkerError` at once. There are
    no helper threads, and :meth:`close` always reaps every process.
    """

    def __init__(self, relax: HullRelaxation, n: int) -> None:
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        self.settings = relax.settings
        #: shared flag: 1 ends dives early (set by :meth:`close`)
        self.stop = ctx.Value("b", 0, lock=False)
        self.conns: list[Any] = []
        self.procs: list[Any] = []
        #: per worker, the ids of the tasks sent and not answered yet
        self.pending: list[list[int]] = []
        self.closed = False
        try:
            for _ in range(n):
                here, there = ctx.Pipe(duplex=True)
                proc = ctx.Process(target=_serve, args=(there, relax, self.stop), daemon=True)
                proc.start()
                there.close()
                self.conns.append(here)
                self.procs.append(proc)
                self.pending.append([])
        except BaseException:
            self.close()
            raise

    @staticmethod
    def available() -> bool:
        """Forked workers need the fork start method (Linux, and macOS where it is not the
        default); elsewhere the search runs in one process."""
        import multiprocessing as mp

        return "fork" in mp.get_all_start_methods()

    @property
    def idle(self) -> bool:
        """Some worker has no task."""
        return any(not p for p in self.pending)

    @property
    def busy(self) -> int:
        """Tasks sent and not answered yet."""
        return sum(map(len, self.pending))

    def submit(self, tid: int, kind: str, task: Any) -> None:
        """Send task ``tid`` (``kind`` "node": :func:`_work`, "dive": :func:`_work_dive`) to the
        worker with the fewest unanswered tasks."""
        i = min(range(len(self.conns)), key=lambda k: len(self.pending[k]))
        try:
            self.conns[i].send((tid, kind, task))
        except (BrokenPipeError, OSError) as exc:
            raise self._died(i) from exc
        self.pending[i].append(tid)

    def _died(self, i: int) -> WorkerError:
        proc = self.procs[i]
        proc.join(timeout=1.0)
        return WorkerError(
            f"bnb worker process {proc.pid} died (exit code {proc.exitcode}) with "
            f"{len(self.pending[i])} node solve(s) unanswered; the search is stopped"
        )

    def wait(self, timeout: float) -> list[tuple[int, Any]]:
        """The ``(id, result)`` of the tasks answered within ``timeout`` seconds ([] if none).

        Raises :class:`WorkerError` when a worker died or a task raised in a worker.
        """
        from multiprocessing.connection import wait

        sentinels = {p.sentinel: i for i, p in enumerate(self.procs)}
        ready = wait([*self.conns, *sentinels], timeout=max(timeout, 0.0))
        out: list[tuple[int, Any]] = []
        for i, conn in enumerate(self.conns):
            try:
                while conn.poll():
                    tid, ok, res = conn.recv()
                    self.pending[i].remove(tid)
                    if not ok:
                        raise WorkerError(f"a bnb worker failed solving a node:\n{res}")
                    out.append((tid, res))
            except (EOFError, OSError) as exc:
                raise self._died(i) from exc
        for obj in ready:
            if obj in sentinels:
                raise self._died(sentinels[obj])
        return out

    def map(self, kind: str, tasks: list[Any], deadline: float = math.inf) -> list[Any]:
        """Results of ``tasks`` in their order, solved in the workers (a synchronous batch:
        probing, the local search); None for the tasks not sent before ``deadline``
        (``time.perf_counter`` seconds).

        At most ``settings.map_depth`` tasks per worker are in flight: a worker blocks sending its result
        while its pipe is full, so sending it every task at once could deadlock both ends."""
        base = 1 << 40  # ids apart from the asynchronous tasks
        got: dict[int, Any] = {}
        sent = 0
        limit = len(tasks)
        while len(got) < sent or sent < limit:
            if time.perf_counter() > deadline:
                limit = sent  # send no more; wait for those in flight
            while sent < limit and self.busy < self.settings.map_depth * len(self.conns):
                self.submit(base + sent, kind, tasks[sent])
                sent += 1
            if len(got) < sent:
                got.update(self.wait(60.0))
        return [got.get(base + k) for k in range(len(tasks))]

    def drain(self) -> None:
        """Wait for every task in flight and drop its result (the workers are then idle)."""
        while self.busy:
            self.wait(60.0)

    def close(self, grace: float | None = None) -> None:
        """Stop every worker and reap it: dives end early (shared flag), each worker finishes its
        current solve and exits on ``None``; one still alive after ``grace`` seconds (default
        ``settings.drain_timeout``) is terminated, then killed. Unanswered results are dropped.
        Safe to call twice."""
        if self.closed:
            return
        grace = self.settings.drain_timeout if grace is None else grace
        self.closed = True
        self.stop.value = 1
        for conn in self.conns:
            try:
                conn.send(None)
            except (BrokenPipeError, OSError):
                pass
        end = time.perf_counter() + grace
        from multiprocessing.connection import wait

        # read what the workers still send, so none blocks on a full pipe while exiting; a worker
        # whose sentinel is ready has exited (is_alive() may lag until it is reaped, so join it:
        # waiting on an empty list instead would sleep out the whole grace)
        while time.perf_counter() < end:
            alive = [i for i, p in enumerate(self.procs) if p.is_alive()]
            if not alive:
                break
            conns = {self.conns[i]: i for i in alive}
            sentinels = {self.procs[i].sentinel: i for i in alive}
            for obj in wait([*conns, *sentinels], timeout=max(end - time.perf_counter(), 0.0)):
                if obj in sentinels:
                    self.procs[sentinels[obj]].join()
                else:
                    try:
                        self.conns[conns[obj]].recv()
                    except (EOFError, OSError):
                        pass
        for proc in self.procs:
            if proc.is_alive():
                proc.terminate()
                proc.join(timeout=1.0)
            if proc.is_alive():  # pragma: no cover - SIGTERM is not ignored by the workers
                proc.kill()
            proc.join()
        for conn in self.conns:
            conn.close()


class _Search:
    """State of one branch-and-bound run (see the module docstring)."""

    def __init__(
        self,
        structure: _Structure,
        options: SolverOptions,
        start: float,
        relax: HullRelaxation | None = None,
    ) -> None:
        self.s = structure
        self.problem = structure.problem
        self.options = options
        self.settings = options.bnb
        self.start = start
        self.deadline = start + options.time_limit
        #: the search stops (as at the time limit) after this many nodes
        self.node_limit = math.inf
        self.relax = HullRelaxation(structure, settings=self.settings) if relax is None else relax
        self.incumbent: FloatArray | None = None
        self.inc_obj = math.inf
        self.tried: set[tuple[tuple[int, ...], ...]] = set()
        self.heap: list[_Node] = []
        self.nodes = 0
        self.counter = 0
        self.failed = False
        #: Clarabel status -> number of nodes left unsolved with it
        self.failures: dict[str, int] = {}
        self.lost_bound = math.inf
        #: probing at the root: relaxations solved, members dropped
        self.probes = 0
        self.probe_dropped = 0
        self.probe_time = 0.0
        #: the root node's allowed members and relaxation point (for probing)
        self.root: tuple[tuple[tuple[int, ...], ...], FloatArray] | None = None
        #: probing: due after this many nodes; its budget (relaxations per part, see
        #: ``settings.probe_budget``); nodes solved when it ran (None: not yet) and the gap then; the
        #: members it killed, and the incumbent objective they were last updated for
        self.probe_at = math.inf
        self.probe_budget = math.inf
        self.probed_at: int | None = None
        self.probe_gap = math.nan
        self.dead: set[int] = set()
        self.dead_at = math.inf
        #: the primal heuristics after probing: nodes of the restricted search, local-search
        #: solves, objective of the incumbent before them
        self.heur_nodes = 0
        self.ls_solves = 0
        self.heur_from = math.nan
        #: member -> its bound in the last probing round that probed it
        self.probe_bound: dict[int, float] = {}
        #: worker processes of the search (0: the search process solves every node)
        self.workers = 0
        #: (nodes, seconds, incumbent or None, best bound) every 25 nodes
        self.trace: list[tuple[int, float, float | None, float]] = []
        if options.initial_solution is not None:
            x0 = np.asarray(options.initial_solution, dtype=float)
            if x0.shape == (self.problem.n,):
                self.offer(x0.copy())

    # ----------------------------------------------------------------------------- incumbents
    def offer(self, cand: FloatArray) -> bool:
        """Take ``cand`` as incumbent if it is feasible and better; True if feasible."""
        if self.problem.violation(cand) > self.settings.feas_tol:
            return False
        obj = self.problem.objective(cand)
        if obj < self.inc_obj:
            self.incumbent, self.inc_obj = cand, obj
        return True

    def solve_fixed(self, fixed: tuple[tuple[int, ...], ...]) -> None:
        """One convex solve with every group fixed; the full model if the condensed one is off."""
        if fixed in self.tried:
            return
        self.tried.add(fixed)
        for full in (False, True):
            res = self.relax.solve(fixed, full=full)
            if res.status != "solved" or res.x is None:
                return
            if self.offer(_finish(self.s, res.x, fixed)):
                return

    def dive(self, x: FloatArray, allowed: tuple[tuple[int, ...], ...]) -> None:
        """Dive from a relaxation solution (see :func:`_dive`) and solve the assignment it ends at."""
        chosen = _dive(self.relax, x, allowed, self.inc_obj, self.deadline)
        if chosen is not None:
            self.solve_fixed(chosen)

    # ---------------------------------------------------------------------------------- search
    def gap_of(self, bound: float) -> float:
        """Relative gap of the incumbent against ``bound`` (SCIP's definition)."""
        if not math.isfinite(self.inc_obj):
            return math.inf
        if self.inc_obj <= bound:
            return 0.0
        denom = min(abs(self.inc_obj), abs(bound))
        return math.inf if denom == 0.0 else (self.inc_obj - bound) / denom

    def evaluate(
        self,
        allowed: tuple[tuple[int, ...], ...],
        parent_bound: float,
        depth: int,
        full: bool,
        res: _Relaxation | None = None,
    ) -> _Relaxation | None:
        """Solve a node (unless ``res`` holds its relaxation already); keep it when it may hold a
        better plan than the incumbent."""
        if res is None:
            res = self.relax.solve(allowed, full=full)
        self.nodes += 1
        if res.status == "failed" and not full:
            res = self.relax.solve(allowed, full=True)  # numerical trouble: try the plain model
            full = True
        if res.status == "failed":
            # unsolved node: its parent's bound stays in the reported bound (an honest gap)
            self.failed = True
            self.failures[res.raw] = self.failures.get(res.raw, 0) + 1
            self.lost_bound = min(self.lost_bound, parent_bound)
            return None
        if res.status != "solved" or res.x is None:
            return None
        bound = max(res.bound, parent_bound)
        if bound >= self.inc_obj:
            return None
        chosen = _choice(self.s, res.x, allowed, self.settings.row_tol)
        if chosen is not None:
            # The relaxation optimum satisfies one member of every group.
            if self.offer(_finish(self.s, res.x, chosen)):
                return None  # exact: the node is solved
            if not full:  # only the dropped bounds/cones of the condensed variables fail
                return self.evaluate(allowed, bound, depth, True)
            self.solve_fixed(chosen)
            return None
        heapq.heappush(self.heap, _Node(bound, self.counter, allowed, res.x, depth, full))
        self.counter += 1
        return res

    def run(self) -> SolverResult:
        """Best-first branch and bound; returns the best plan with an honest gap.

        With probing (``settings.probe_rounds``), a search still open after
        ``settings.probe_after`` nodes per
        member of the root's undecided groups probes the root once (see :meth:`probe_now`): small
        searches never pay for probing, and a large one keeps the nodes it has."""
        root_allowed = _root_allowed(self.s)
        timed_out = False
        root = None
        if all(root_allowed):
            root = self.evaluate(root_allowed, -math.inf, 0, False)
        pool = None
        if self.heap and self.options.threads >= 2 and _Workers.available():
            pool = _Workers(
                self.relax, self.options.threads - (1 if self.settings.local_solves else 0)
            )
        self.workers = 0 if pool is None else len(pool.procs)
        try:
            dive_from = None
            if root is not None and root.x is not None:
                self.root = (root_allowed, root.x)
                if self.settings.probe_rounds:
                    undecided = sum(len(m) for m in root_allowed if len(m) > 1)
                    self.probe_at = self.settings.probe_after * undecided
                if pool is not None:
                    dive_from = (root.x, root_allowed)  # a worker dives, the others branch
                else:
                    self.dive(root.x, root_allowed)
            if pool is None:
                timed_out = self._loop()
            else:
                timed_out = self._loop_async(pool, dive_from)
        finally:
            if pool is not None:
                pool.close()
        return self.result(timed_out)

    @property
    def probe_due(self) -> bool:
        """Probing is due (see :meth:`run`) and has not run yet."""
        return self.probed_at is None and self.nodes >= self.probe_at

    def probe_now(self, pool: _Workers | None) -> None:
        """Probe the root (:meth:`probe`, ``settings.probe_first_rounds`` rounds) with the
        incumbent, run the primal heuristics (:meth:`restricted_search`, :meth:`local_search`),
        then probe on (up to ``settings.probe_rounds`` rounds) with their incumbent. The members
        probing drops are dead for the rest of the search: an open node
        loses them when it is next taken from the queue (:meth:`narrowed`), and one that loses
        any is solved again before it is branched. Called with no node solve in flight."""
        self.probed_at = self.nodes
        if self.root is None:
            return
        self.probe_budget = self.settings.probe_budget * self.nodes
        self.probe_gap = self.gap_of(self.heap[0].bound) if self.heap else 0.0
        start, root_x = self.root
        # one round ranks the members for the heuristics; the rest use their incumbent
        t0 = time.perf_counter()
        allowed = self.probe(start, root_x, pool, self.settings.probe_first_rounds)
        self.probe_time += time.perf_counter() - t0
        if all(allowed) and self.heap and self.gap_of(self.heap[0].bound) > self.options.gap:
            self.heur_from = self.inc_obj
            self.restricted_search(allowed, pool)
            self.local_search(allowed, pool)
        t0 = time.perf_counter()
        allowed = self.probe(allowed, None, pool, self.settings.probe_rounds)
        self.probe_time += time.perf_counter() - t0
        kept = {z for mem in allowed for z in mem}
        self.dead |= {z for mem in start for z in mem if z not in kept}
        self.dead_at = self.inc_obj

    def narrowed(self, allowed: tuple[tuple[int, ...], ...]) -> tuple[tuple[int, ...], ...] | None:
        """``allowed`` without the dead members (see :meth:`probe_now`); None when a group loses
        all of its members (no point of the node beats the incumbent). A better incumbent since
        the last call first kills every member whose probe bound reaches it."""
        if self.inc_obj < self.dead_at:
            self.dead |= self._beaten()
            self.dead_at = self.inc_obj
        if not self.dead:
            return allowed
        out = tuple(tuple(z for z in mem if z not in self.dead) for mem in allowed)
        return out if all(out) else None

    def _beaten(self) -> set[int]:
        """The probed members whose probe bound reaches the incumbent."""
        return {z for z, b in self.probe_bound.items() if b >= self.inc_obj}

    def probe(
        self,
        allowed: tuple[tuple[int, ...], ...],
        root_x: FloatArray | None,
        pool: _Workers | None,
        rounds: int,
    ) -> tuple[tuple[int, ...], ...]:
        """Probing: solve the root relaxation with each member of every undecided group fixed,
        and drop the members whose bound reaches the incumbent or that are infeasible. Exact:
        every point using a dropped member costs at least the incumbent, and every node's allowed
        members are a subset of the root's. A probe whose relaxation point is integral offers it
        as incumbent. First the bounds of earlier rounds drop what they can against the current
        incumbent; rounds then repeat on the smaller root while they drop anything (at most
        ``rounds``; without an incumbent, the next round dives first from the smaller root
        ``root_x``). Returns the allowed members (some group may be left empty)."""
        known = self._beaten()
        if known:
            narrowed = self._narrow(allowed, known)
            if narrowed != allowed:
                allowed = narrowed
                root_x = None
        for rnd in range(rounds):
            if not all(allowed) or time.perf_counter() > self.deadline:
                break
            if rnd and not math.isfinite(self.inc_obj):
                # no incumbent yet: the smaller root may lead the dive to a plan
                if root_x is None:
                    top = self.relax.solve(allowed)
                    root_x = top.x if top.status == "solved" else None
                if root_x is not None:
                    self.dive(root_x, allowed)
            before = self.inc_obj
            tasks = [(g, z) for g, mem in enumerate(allowed) if len(mem) > 1 for z in mem]
            if not tasks or self.probes + len(tasks) > self.probe_budget:
                break
            fixed = []
            for g, z in tasks:
                one = list(allowed)
                one[g] = (z,)
                fixed.append(tuple(one))
            results = self._probe_solves(fixed, pool)
            self.probes += sum(res is not None for res in results)
            for (_, z), a, res in zip(tasks, fixed, results, strict=True):
                if res is None:
                    continue  # not solved before the time limit: kept
                if res.status == "solved":
                    self.probe_bound[z] = res.bound
                elif res.status == "infeasible":
                    self.probe_bound[z] = math.inf
                if res.status == "solved" and res.x is not None:
                    chosen = _choice(self.s, res.x, a, self.settings.row_tol)
                    if chosen is not None:
                        self.offer(_finish(self.s, res.x, chosen))
            # against the best incumbent now (a probe may have found a better one)
            drop = {z for _, z in tasks if self.probe_bound.get(z, -math.inf) >= self.inc_obj}
            root_x = None
            if drop:
                allowed = self._narrow(allowed, drop)
            few = len(drop) < self.settings.probe_min_drop * len(tasks)
            if not drop or (few and self.inc_obj >= before and math.isfinite(self.inc_obj)):
                break
        return allowed

    def _narrow(
        self, allowed: tuple[tuple[int, ...], ...], drop: set[int]
    ) -> tuple[tuple[int, ...], ...]:
        """:func:`_without`, counting the dropped members."""
        out = _without(allowed, drop)
        self.probe_dropped += sum(map(len, allowed)) - sum(map(len, out))
        return out

    def _probe_solves(
        self, fixed: list[tuple[tuple[int, ...], ...]], pool: _Workers | None
    ) -> list[_Relaxation | None]:
        """The relaxations of the probes ``fixed``, in the workers when there are any; None for a
        probe not solved before the time limit."""
        if pool is not None:
            return pool.map("node", [(a, False) for a in fixed], self.deadline)
        out: list[_Relaxation | None] = []
        for a in fixed:
            if time.perf_counter() > self.deadline:
                out.append(None)
                continue
            res = self.relax.solve(a)
            if res.status == "failed":  # as in _work
                res = self.relax.solve(a, full=True)
            out.append(res)
        return out

    def restricted_search(
        self, allowed: tuple[tuple[int, ...], ...], pool: _Workers | None
    ) -> None:
        """Primal heuristic: branch and bound (at most ``settings.heur_nodes`` nodes, cut off at the
        incumbent) over ``allowed`` restricted to each group's ``settings.heur_top`` members of the lowest
        probe bound; its best point is offered as incumbent. The restricted problem is small, and
        its optimum is often the full problem's (the probe bounds rank the members well)."""
        top, nodes = self.settings.heur_top, self.settings.heur_nodes
        if not (top and nodes):
            return
        rank = self.probe_bound
        small = tuple(
            mem if len(mem) <= top
            else tuple(sorted(mem, key=lambda z: (rank.get(z, -math.inf), z))[:top])
            for mem in allowed
        )  # fmt: skip
        if small == allowed:
            return  # the restricted problem is the search itself
        limit = min(nodes, self.probe_budget)
        sub = _Search(self.s, self.options, self.start, self.relax)
        sub.deadline = self.deadline
        sub.node_limit = limit
        sub.incumbent, sub.inc_obj = self.incumbent, self.inc_obj
        sub.tried = self.tried
        sub.evaluate(small, -math.inf, 0, False)
        try:
            if pool is None:
                sub._loop()
            else:
                sub._loop_async(pool, None)
        finally:
            if pool is not None:
                pool.drain()  # the restricted search may leave solves in flight
            self.heur_nodes += sub.nodes
        if sub.incumbent is not None:
            self.offer(sub.incumbent)

    def local_search(self, allowed: tuple[tuple[int, ...], ...], pool: _Workers | None) -> None:
        """Primal heuristic: from the incumbent's members, solve every assignment that moves one
        group to another allowed member (all groups fixed: one convex solve each) and take the
        best improvement; repeat for at most ``settings.ls_sweeps`` sweeps."""
        if self.incumbent is None or not self.settings.ls_sweeps:
            return
        x = self.incumbent
        cur = [mem[int(np.argmax(x[list(mem)]))] for mem in _root_allowed(self.s)]
        for _ in range(self.settings.ls_sweeps):
            if time.perf_counter() > self.deadline:
                return
            moves: list[tuple[tuple[int, ...], ...]] = []
            for g, mem in enumerate(allowed):
                for z in mem:
                    if z != cur[g]:
                        one: list[tuple[int, ...]] = [(m,) for m in cur]
                        one[g] = (z,)
                        moves.append(tuple(one))
            moves = [a for a in moves if a not in self.tried]
            if not moves or self.ls_solves + len(moves) > self.probe_budget:
                return
            results = self._probe_solves(moves, pool)
            self.ls_solves += sum(res is not None for res in results)
            order = sorted(
                (res.bound, k)
                for k, res in enumerate(results)
                if res is not None and res.status == "solved" and res.x is not None
            )
            before = self.inc_obj
            for bound, k in order:
                if bound >= self.inc_obj:
                    break
                a, res = moves[k], results[k]
                assert res is not None and res.x is not None
                self.tried.add(a)
                if not self.offer(_finish(self.s, res.x, a)):
                    # the condensed point broke a dropped bound: the full model decides
                    self.tried.discard(a)
                    self.solve_fixed(a)
                if self.inc_obj < before:
                    cur = [m[0] for m in a]
                    break
            else:
                return
            if self.inc_obj >= before:
                return

    def _loop(self) -> bool:
        """The serial best-first loop; returns True when stopped by the time limit."""
        while self.heap:
            top = self.heap[0].bound
            self._record(top)
            if self.gap_of(top) <= self.options.gap:
                break
            if time.perf_counter() > self.deadline or self.nodes >= self.node_limit:
                return True
            if self.probe_due:
                self.probe_now(None)
                continue
            for child, node in self._take_two():
                self.evaluate(child, node.bound, node.depth + 1, node.full)
        return False

    def _record(self, top: float) -> None:
        """Append ``(nodes, seconds, incumbent, bound)`` to the trace every 25 nodes."""
        if not self.trace or self.nodes >= self.trace[-1][0] + 25:
            inc = self.inc_obj if math.isfinite(self.inc_obj) else None  # JSON-safe
            self.trace.append((self.nodes, time.perf_counter() - self.start, inc, top))

    def _take_two(self) -> list[tuple[tuple[tuple[int, ...], ...], _Node]]:
        """Up to two node problems to solve next, with their parents: the children of the best
        open node, or an open node that lost dead members (solved again before it is branched)."""
        tasks: list[tuple[tuple[tuple[int, ...], ...], _Node]] = []
        while self.heap and len(tasks) < 2:
            node = heapq.heappop(self.heap)
            if node.bound >= self.inc_obj:
                continue
            assert node.x is not None
            narrowed = self.narrowed(node.allowed)
            if narrowed is None:
                continue
            if narrowed != node.allowed:  # it lost dead members: solve it again first
                tasks.append((narrowed, node))
                continue
            split = _branch(self.s, node.x, node.allowed, self.settings.row_tol)
            if split is None:  # pragma: no cover - evaluate() resolved such nodes
                continue
            tasks.extend((child, node) for child in split)
        return tasks

    def _loop_async(
        self, pool: _Workers, dive_from: tuple[FloatArray, tuple[tuple[int, ...], ...]] | None
    ) -> bool:
        """Best-first loop with the node solves in ``pool``, asynchronously: whenever a worker has
        no task, the best open node is branched and its children are submitted (to the least
        loaded workers), so the workers never wait for a batch. A node's bound counts in the global
        bound until its children's results are in. ``dive_from`` (a relaxation point and its
        node) starts a dive in one worker. Returns True when stopped by the time limit."""
        #: per task: (kind, assignment, parent node); kind "node" or "dive"
        inflight: dict[int, tuple[str, tuple[tuple[int, ...], ...], _Node | None]] = {}
        #: with ``settings.local_solves``: the node tasks the search process solves itself
        mine: list[tuple[int, Any]] = []
        next_id = 0
        local = self.settings.local_solves

        def submit(kind: str, task: Any, allowed: Any, node: _Node | None) -> None:
            nonlocal next_id
            tid = next_id
            next_id += 1
            inflight[tid] = (kind, allowed, node)
            if local and kind != "dive" and pool.busy >= 2 * len(pool.procs):
                mine.append((tid, task))
            else:
                pool.submit(tid, "dive" if kind == "dive" else "node", task)

        if dive_from is not None:
            x0, allowed0 = dive_from
            submit("dive", (x0, allowed0, self.inc_obj, self.deadline), allowed0, None)
        try:
            return self._async_steps(pool, submit, inflight, mine)
        finally:
            for _, _, node in inflight.values():  # their results are dropped: keep the bounds
                if node is not None:
                    self.lost_bound = min(self.lost_bound, node.bound)

    def _async_steps(
        self,
        pool: _Workers,
        submit: Any,
        inflight: dict[int, tuple[str, tuple[tuple[int, ...], ...], _Node | None]],
        mine: list[tuple[int, Any]],
    ) -> bool:
        """The body of :meth:`_loop_async`: branch until the workers are busy, check the gap,
        then take one answer. Returns True when stopped by the time limit or the node limit."""
        answered: list[tuple[int, Any]] = []
        # with local solves every worker is kept two deep, one more task for the search process
        depth = 2 * len(pool.procs) + 1 if self.settings.local_solves else None
        while True:
            due = self.probe_due
            if not due:
                self._branch_into(pool, submit, inflight, depth)
            open_nodes = [nd.bound for _, _, nd in inflight.values() if nd is not None]
            if self.heap:
                open_nodes.append(self.heap[0].bound)
            if not open_nodes:
                return False
            top = min(open_nodes)
            self._record(top)
            if self.gap_of(top) <= self.options.gap:
                return False
            if self.nodes >= self.node_limit:
                return True
            if due and not inflight:
                self.probe_now(pool)
                continue
            if not answered:
                answered = self._answers(pool, mine)
                if not answered:
                    return True
            tid, res = answered.pop()
            self._take_answer(inflight.pop(tid), res)

    def _branch_into(
        self,
        pool: _Workers,
        submit: Any,
        inflight: dict[int, tuple[str, tuple[tuple[int, ...], ...], _Node | None]],
        depth: int | None,
    ) -> None:
        """Branch the best open nodes and submit their children until every worker has a task
        (or, with ``depth``, until that many tasks are in flight). Counting the tasks in flight
        instead left a worker idle whenever both children of a node had gone to the other
        worker's queue."""
        while self.heap and (pool.idle if depth is None else len(inflight) < depth):
            node = heapq.heappop(self.heap)
            if node.bound >= self.inc_obj:
                continue
            assert node.x is not None
            allowed = self.narrowed(node.allowed)
            if allowed is None:
                continue
            if allowed != node.allowed:  # it lost dead members: solve it again first
                submit("node", (allowed, node.full), allowed, node)
                continue
            split = _branch(self.s, node.x, node.allowed, self.settings.row_tol)
            if split is None:  # pragma: no cover - evaluate() resolved such nodes
                continue
            for child in split:
                submit("node", (child, node.full), child, node)

    def _answers(self, pool: _Workers, mine: list[tuple[int, Any]]) -> list[tuple[int, Any]]:
        """The next answered tasks, oldest last (popped from the end): one of ``mine`` solved
        here with whatever the workers answered meanwhile, else the workers' answers as they
        come; [] at the time limit."""
        if mine:
            if time.perf_counter() > self.deadline:
                return []
            tid, (allowed, full) = mine.pop(0)
            answered = [(tid, self.relax.solve(allowed, full=full)), *pool.wait(0.0)]
        else:
            answered = pool.wait(self.deadline - time.perf_counter())
        answered.reverse()
        return answered

    def _take_answer(
        self, task: tuple[str, tuple[tuple[int, ...], ...], _Node | None], res: Any
    ) -> None:
        """Use the answer ``res`` of one task ``(kind, assignment, parent)``: a node's
        relaxation is evaluated; the end of the dive, every group fixed, is offered."""
        kind, allowed, parent = task
        if kind == "dive":
            allowed, res = res
            if allowed is None or allowed in self.tried:
                return
            self.tried.add(allowed)
        if parent is None:  # every group fixed: the end of the dive
            if res is not None and res.status == "solved" and res.x is not None:
                if not self.offer(_finish(self.s, res.x, allowed)):
                    self.tried.discard(allowed)
                    self.solve_fixed(allowed)  # the condensed point broke a dropped bound
            return
        self.evaluate(allowed, parent.bound, parent.depth + 1, parent.full, res)

    def result(self, timed_out: bool) -> SolverResult:
        """The :class:`SolverResult` of the search so far."""
        open_bounds = [nd.bound for nd in self.heap if nd.bound < self.inc_obj]
        best_bound = min([*open_bounds, self.lost_bound], default=self.inc_obj)
        best_bound = min(best_bound, self.inc_obj)
        if self.incumbent is None:
            if timed_out:
                status = SolveStatus.TIME_LIMIT
            elif self.failed:
                status = SolveStatus.ERROR
            else:
                status = SolveStatus.INFEASIBLE
            gap = math.inf
        else:
            gap = max(0.0, self.gap_of(best_bound))
            if gap <= self.options.gap and not self.failed:
                status = SolveStatus.OPTIMAL
            elif timed_out:
                status = SolveStatus.TIME_LIMIT
            else:
                status = SolveStatus.FEASIBLE
        return SolverResult(
            status=status,
            x=self.incumbent,
            objective=self.inc_obj if self.incumbent is not None else math.nan,
            bound=best_bound if math.isfinite(best_bound) else math.nan,
            gap=gap,
            solve_time=time.perf_counter() - self.start,
            solver=NAME,
            stats={
                "raw_status": status.value,
                "nodes": self.nodes,
                "failed_nodes": dict(self.failures),
                "relaxations": self.relax.solves,
                "relaxation_time_s": self.relax.solve_time,
                "variables": self.problem.n,
                "integer_variables": self.problem.n_integer,
                "groups": len(self.s.groups),
                "members": self.relax.n_members,
                "condensed": self.relax.condensed is not None,
                "probes": self.probes,
                "probe_dropped": self.probe_dropped,
                "probe_time_s": self.probe_time,
                "probed_at_node": self.probed_at,
                "gap_when_probed": self.probe_gap,
                "heuristic_nodes": self.heur_nodes,
                "local_search_solves": self.ls_solves,
                "incumbent_before_heuristics": self.heur_from,
                "workers": self.workers,
                "trace": self.trace,
                "settings": dataclasses.asdict(self.settings),
            },
        )
