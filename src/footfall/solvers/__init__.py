"""Optimisation backends behind one interface: build a :class:`MIQCQP`, then :func:`solve` it.

Backends register themselves when their Python package imports: ``bnb`` (the default, installed
with footfall: footfall's own branch and bound on convex-hull relaxations with Clarabel node
solves, exact and fast on the footstep planner's problems, handing any other problem shape to
SCIP; see :mod:`footfall.solvers.bnb`), ``scip`` (PySCIPOpt, installed with footfall: the direct
model) and ``gurobi`` (optional: ``pip install "footfall[gurobi]"`` and a licence).
"""

from __future__ import annotations

import importlib.util
from collections.abc import Callable

from footfall.errors import InputError, SolverUnavailableError
from footfall.solvers.base import SolveProgress, SolverOptions, SolverResult, SolveStatus
from footfall.solvers.problem import MIQCQP, ProblemBuilder

#: every backend footfall knows: name -> (python module to import, pip hint)
KNOWN_BACKENDS = {
    "scip": ("pyscipopt", "pip install pyscipopt (installed with footfall by default)"),
    "gurobi": ("gurobipy", 'pip install "footfall[gurobi]" and a Gurobi licence'),
    "bnb": ("clarabel", "pip install clarabel (installed with footfall by default)"),
}
#: the backend :func:`solve` and the planners use unless told otherwise
DEFAULT_SOLVER = "bnb"


def available_solvers() -> list[str]:
    """Backends whose Python package is importable here."""
    return [
        n for n, (mod, _) in KNOWN_BACKENDS.items() if importlib.util.find_spec(mod) is not None
    ]


def _backend(name: str) -> Callable[[MIQCQP, SolverOptions], SolverResult]:
    if name not in KNOWN_BACKENDS:
        raise InputError("solver", name, f"one of {', '.join(KNOWN_BACKENDS)}")
    module, hint = KNOWN_BACKENDS[name]
    if importlib.util.find_spec(module) is None:
        raise SolverUnavailableError(f"solver {name!r} needs the package {module!r}: {hint}")
    if name == "scip":
        from footfall.solvers import scip

        return scip.solve
    if name == "bnb":
        from footfall.solvers import bnb

        return bnb.solve
    from footfall.solvers import gurobi

    return gurobi.solve


def solve(
    problem: MIQCQP, solver: str = DEFAULT_SOLVER, options: SolverOptions | None = None
) -> SolverResult:
    """Solve a built problem with the named backend."""
    return _backend(solver)(problem, options or SolverOptions())


__all__ = [
    "DEFAULT_SOLVER",
    "KNOWN_BACKENDS",
    "MIQCQP",
    "ProblemBuilder",
    "SolveProgress",
    "SolveStatus",
    "SolverOptions",
    "SolverResult",
    "available_solvers",
    "solve",
]
