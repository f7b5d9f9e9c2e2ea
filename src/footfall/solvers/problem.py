"""A solver-neutral mixed-integer QCQP, built once and handed to any registered backend.

The planners build a :class:`MIQCQP` with :class:`ProblemBuilder`; tests inspect its matrices and
backends (:mod:`footfall.solvers.scip`, :mod:`footfall.solvers.gurobi`) translate it. The form is

    minimise    sum_j w_j (F_j x - f_j)^2                      (weighted squared residuals)
    subject to  A_eq x = b_eq,   A_le x <= b_le,   lb <= x <= ub,
                ||x[idx_c]||_2 <= radius_c                     (second-order cones)
                x_i integer for i in integers.

Least-squares objective rows keep the data well scaled and map one-to-one onto the documents'
cost terms; every row carries a label so infeasibility can be explained.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from numpy.typing import NDArray

from footfall._typing import FloatArray, IntArray
from footfall.errors import InputError


@dataclass(frozen=True)
class MIQCQP:
    """A built problem. All matrices are CSR with ``n`` columns, one per variable.

    Attributes:
        names: variable names, length n.
        lb, ub: variable bounds, shape (n,).
        integer: True for integer (binary when bounds are [0, 1]) variables, shape (n,).
        cost_matrix: F, shape (m_c, n); cost_target: f, shape (m_c,); cost_weight: w >= 0, (m_c,).
        cost_group: label of each cost row (the document term it implements), length m_c.
        a_eq, b_eq: equality rows; eq_labels: their labels.
        a_le, b_le: inequality rows; le_labels: their labels.
        cones: list of ``(indices, radius)``: ``||x[indices]||_2 <= radius``.
    """

    names: list[str]
    lb: FloatArray
    ub: FloatArray
    integer: NDArray[np.bool_]
    cost_matrix: sp.csr_matrix
    cost_target: FloatArray
    cost_weight: FloatArray
    cost_group: list[str]
    a_eq: sp.csr_matrix
    b_eq: FloatArray
    eq_labels: list[str]
    a_le: sp.csr_matrix
    b_le: FloatArray
    le_labels: list[str]
    cones: list[tuple[IntArray, float]]

    @property
    def n(self) -> int:
        """Number of variables."""
        return len(self.names)

    @property
    def n_integer(self) -> int:
        """Number of integer variables."""
        return int(np.count_nonzero(self.integer))

    def bounds_conflict(self, tol: float = 1e-9) -> bool:
        """True when some variable has ``lb > ub`` (the problem is trivially infeasible)."""
        return bool(np.any(self.lb > self.ub + tol))

    def objective(self, x: FloatArray) -> float:
        """Objective value at ``x``."""
        r = self.cost_matrix @ x - self.cost_target
        return float(np.sum(self.cost_weight * r * r))

    def objective_by_group(self, x: FloatArray) -> dict[str, float]:
        """Objective split by cost label."""
        r = self.cost_matrix @ x - self.cost_target
        terms = self.cost_weight * r * r
        out: dict[str, float] = {}
        for g, v in zip(self.cost_group, terms, strict=True):
            out[g] = out.get(g, 0.0) + float(v)
        return out

    def violation(self, x: FloatArray) -> float:
        """Largest violation of any bound, row or cone at ``x`` (0 when feasible)."""
        worst = max(
            0.0, float(np.max(self.lb - x, initial=0.0)), float(np.max(x - self.ub, initial=0.0))
        )
        if self.a_eq.shape[0]:
            worst = max(worst, float(np.max(np.abs(self.a_eq @ x - self.b_eq))))
        if self.a_le.shape[0]:
            worst = max(worst, float(np.max(self.a_le @ x - self.b_le, initial=0.0)))
        for idx, radius in self.cones:
            worst = max(worst, float(np.linalg.norm(x[idx]) - radius))
        ints = self.integer
        if np.any(ints):
            worst = max(worst, float(np.max(np.abs(x[ints] - np.round(x[ints])))))
        return worst


@dataclass
class _Rows:
    rows: list[int] = field(default_factory=list)
    cols: list[int] = field(default_factory=list)
    vals: list[float] = field(default_factory=list)
    rhs: list[float] = field(default_factory=list)
    labels: list[str] = field(default_factory=list)

    def add(self, coeffs: dict[int, float], rhs: float, label: str) -> None:
        r = len(self.rhs)
        for c, v in coeffs.items():
            if v != 0.0:
                self.rows.append(r)
                self.cols.append(c)
                self.vals.append(float(v))
        self.rhs.append(float(rhs))
        self.labels.append(label)

    def matrix(self, n: int) -> sp.csr_matrix:
        return sp.csr_matrix((self.vals, (self.rows, self.cols)), shape=(len(self.rhs), n))


class ProblemBuilder:
    """Incremental construction of a :class:`MIQCQP`.

    Linear expressions are dicts ``{variable index: coefficient}``; ``add_vars`` returns the
    indices of a block of variables as an array of any shape.
    """

    def __init__(self) -> None:
        self.names: list[str] = []
        self._lb: list[float] = []
        self._ub: list[float] = []
        self._int: list[bool] = []
        self._eq = _Rows()
        self._le = _Rows()
        self._cost = _Rows()
        self._weights: list[float] = []
        self._cones: list[tuple[IntArray, float]] = []

    def add_vars(
        self,
        name: str,
        shape: tuple[int, ...],
        lb: float | FloatArray = -np.inf,
        ub: float | FloatArray = np.inf,
        integer: bool = False,
    ) -> IntArray:
        """Add a block of variables named ``name[i,j,..]``; returns their indices, shape ``shape``."""
        count = int(np.prod(shape)) if shape else 1
        start = len(self.names)
        idx = np.arange(start, start + count, dtype=np.int64).reshape(shape)
        lbs = np.broadcast_to(np.asarray(lb, dtype=float), shape).ravel()
        ubs = np.broadcast_to(np.asarray(ub, dtype=float), shape).ravel()
        for k, multi in enumerate(np.ndindex(*shape) if shape else [()]):
            self.names.append(f"{name}[{','.join(map(str, multi))}]")
            self._lb.append(float(lbs[k]))
            self._ub.append(float(ubs[k]))
            self._int.append(integer)
        return idx

    def add_binaries(self, name: str, shape: tuple[int, ...]) -> IntArray:
        """Add a block of 0/1 variables."""
        return self.add_vars(name, shape, 0.0, 1.0, integer=True)

    def set_bounds(self, index: int, lb: float, ub: float) -> None:
        """Tighten the bounds of one variable."""
        self._lb[index] = max(self._lb[index], lb)
        self._ub[index] = min(self._ub[index], ub)

    def bounds(self, index: int) -> tuple[float, float]:
        """Current bounds of one variable."""
        return self._lb[index], self._ub[index]

    def add_eq(self, coeffs: dict[int, float], rhs: float, label: str) -> None:
        """Add ``sum coeffs[i] x_i = rhs``."""
        self._eq.add(coeffs, rhs, label)

    def add_le(self, coeffs: dict[int, float], rhs: float, label: str) -> None:
        """Add ``sum coeffs[i] x_i <= rhs``."""
        self._le.add(coeffs, rhs, label)

    def add_le_big_m(
        self, coeffs: dict[int, float], rhs: float, indicator: int, label: str, slack: float = 0.0
    ) -> None:
        """Add ``indicator = 1  =>  sum coeffs x <= rhs`` with the smallest valid big-M.

        M is the largest value the row can take over the current variable bounds minus ``rhs``; a
        row that can never be violated is dropped, and one whose M is infinite raises (every
        variable in an indicator row must be bounded).
        """
        top = 0.0
        for i, c in coeffs.items():
            lo, hi = self._lb[i], self._ub[i]
            top += c * (hi if c > 0 else lo)
        m = top - rhs
        if not np.isfinite(m):
            unbounded = [
                self.names[i] for i in coeffs if not np.isfinite(self._ub[i] - self._lb[i])
            ]
            raise InputError(
                f"big-M row {label!r}",
                unbounded,
                "finite bounds on every variable of an indicator row (these are unbounded)",
            )
        if m <= slack:
            return
        row = dict(coeffs)
        row[indicator] = row.get(indicator, 0.0) + m
        self._le.add(row, rhs + m, label)

    def add_cone(self, indices: IntArray, radius: float) -> None:
        """Add ``||x[indices]||_2 <= radius``."""
        self._cones.append((np.asarray(indices, dtype=np.int64).ravel(), float(radius)))

    def add_square(
        self, coeffs: dict[int, float], target: float, weight: float, label: str
    ) -> None:
        """Add the cost term ``weight * (sum coeffs x - target)^2``."""
        if weight < 0:
            raise InputError(f"weight of cost term {label!r}", weight, "a cost weight >= 0")
        if weight == 0.0:
            return
        self._cost.add(coeffs, target, label)
        self._weights.append(float(weight))

    def build(self) -> MIQCQP:
        """Freeze into a :class:`MIQCQP`."""
        n = len(self.names)
        return MIQCQP(
            names=list(self.names),
            lb=np.array(self._lb),
            ub=np.array(self._ub),
            integer=np.array(self._int, dtype=bool),
            cost_matrix=self._cost.matrix(n),
            cost_target=np.array(self._cost.rhs),
            cost_weight=np.array(self._weights),
            cost_group=list(self._cost.labels),
            a_eq=self._eq.matrix(n),
            b_eq=np.array(self._eq.rhs),
            eq_labels=list(self._eq.labels),
            a_le=self._le.matrix(n),
            b_le=np.array(self._le.rhs),
            le_labels=list(self._le.labels),
            cones=list(self._cones),
        )


def fix_variables(problem: MIQCQP, indices: IntArray, values: FloatArray) -> MIQCQP:
    """A copy of ``problem`` with ``x[indices]`` fixed to ``values`` (through their bounds)."""
    import dataclasses

    lb = problem.lb.copy()
    ub = problem.ub.copy()
    idx = np.asarray(indices, dtype=np.int64).ravel()
    vals = np.asarray(values, dtype=float).ravel()
    lb[idx] = vals
    ub[idx] = vals
    return dataclasses.replace(problem, lb=lb, ub=ub)
