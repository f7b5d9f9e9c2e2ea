"""Solver options, results and statuses shared by every backend."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._validate import non_negative, positive
from footfall.errors import InputError
from footfall.solvers.settings import BnbSettings


def relative_gap(objective: float, bound: float) -> float:
    """SCIP's relative gap ``(objective - bound) / min(|objective|, |bound|)`` of a minimisation:
    0 when the bound reaches the objective, inf without an objective, without a bound (nan) or
    with a zero denominator."""
    if not math.isfinite(objective) or math.isnan(bound):
        return math.inf
    if objective <= bound:
        return 0.0
    denom = min(abs(objective), abs(bound))
    return math.inf if denom == 0.0 else (objective - bound) / denom


class SolveStatus(str, Enum):
    """Outcome of a solve, as written to ``plan.json``."""

    OPTIMAL = "optimal"  # proven optimal within the requested relative gap
    FEASIBLE = "feasible"  # a solution, stopped for another reason (gap reported)
    TIME_LIMIT = "time_limit"  # stopped by the time limit; a solution may or may not exist
    INFEASIBLE = "infeasible"  # proven infeasible
    ERROR = "error"  # the solver failed or reported unboundedness
    INCOMPLETE = (
        "incomplete"  # a heuristic stopped short of the goal: proves nothing about feasibility
    )


@dataclass(frozen=True)
class SolveProgress:
    """Where a running branch and bound is (``SolverOptions.progress``).

    Attributes:
        nodes: node relaxations solved so far.
        seconds: wall time since the solve started [s].
        incumbent: objective of the best solution found, None before the first one.
        bound: proven lower bound on the optimum (the best open node's bound).
        gap: relative gap between them (inf without an incumbent).
    """

    nodes: int
    seconds: float
    incumbent: float | None
    bound: float
    gap: float


@dataclass(frozen=True)
class SolverOptions:
    """Options every backend understands.

    Attributes:
        time_limit: wall-clock limit [s].
        gap: relative optimality gap at which to stop (|primal - dual| / |primal|).
        abs_gap: absolute gap at which to stop (needed when the optimum is near zero, where a
            relative gap cannot close).
        threads: number of threads the backend may use; for ``bnb``, the number of forked worker
            processes that solve node relaxations in parallel (1: all in the calling process).
        verbose: print the backend's log.
        seed: random seed of the backend.
        initial_solution: optional full variable vector used as a warm start (MIP start).
        bnb: settings of the ``bnb`` backend (:class:`footfall.solvers.settings.BnbSettings`; the
            other backends ignore them).
        progress: called with a :class:`SolveProgress` about once a second while ``bnb``
            searches (in the calling process; the other backends do not call it). Not part of
            the options' identity (it changes no result).
    """

    time_limit: float = 60.0
    gap: float = 1e-4
    abs_gap: float = 1e-9
    threads: int = 1
    verbose: bool = False
    seed: int = 0
    initial_solution: NDArray[np.float64] | None = field(default=None, compare=False)
    bnb: BnbSettings = field(default_factory=BnbSettings)
    progress: Callable[[SolveProgress], None] | None = field(default=None, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "time_limit", positive("time_limit", self.time_limit))
        object.__setattr__(self, "gap", non_negative("gap", self.gap))
        object.__setattr__(self, "abs_gap", non_negative("abs_gap", self.abs_gap))
        if isinstance(self.threads, bool) or not isinstance(self.threads, int) or self.threads < 1:
            raise InputError("threads", self.threads, "an integer >= 1")
        if not isinstance(self.bnb, BnbSettings):
            raise InputError("bnb", self.bnb, "a footfall.solvers.bnb.BnbSettings")


@dataclass(frozen=True)
class SolverResult:
    """What a backend returns.

    Attributes:
        status: see :class:`SolveStatus`.
        x: best solution found, shape (n,), or None.
        objective: objective of ``x`` (nan without a solution).
        bound: proven lower bound on the optimum (nan if unknown).
        gap: relative gap between ``objective`` and ``bound`` (inf if unknown).
        solve_time: wall time spent in the backend [s].
        solver: backend name.
        stats: backend statistics (nodes, number of solutions, raw status, ...).
    """

    status: SolveStatus
    x: NDArray[np.float64] | None
    objective: float
    bound: float
    gap: float
    solve_time: float
    solver: str
    stats: dict[str, Any] = field(default_factory=dict)

    @property
    def has_solution(self) -> bool:
        """True when ``x`` holds a solution."""
        return self.x is not None
