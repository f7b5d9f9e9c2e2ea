"""Settings of the ``bnb`` branch and bound: one frozen dataclass passed in with the solve.

:class:`BnbSettings` travels in :class:`footfall.solvers.base.SolverOptions` (``bnb``) and
:class:`footfall.planning.plan.PlannerOptions` (``bnb``), and the result echoes it
(``stats["settings"]``), so a plan says how it was searched and the plan cache keys on it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from footfall._validate import check_fields, non_negative
from footfall.errors import InputError


def _pairs(name: str, value: object) -> tuple[tuple[str, bool | int | float], ...]:
    """``value`` as a tuple of ``(Clarabel setting name, value)`` pairs (a mapping is accepted)."""
    items: Any = value.items() if isinstance(value, Mapping) else value
    try:
        out = tuple((str(k), v) for k, v in items)
    except (TypeError, ValueError):
        raise InputError(f"bnb.{name}", value, "(name, value) pairs of Clarabel settings") from None
    if any(not isinstance(v, bool | int | float) for _, v in out):
        raise InputError(f"bnb.{name}", value, "Clarabel settings with bool, int or float values")
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
        escalate: a condensed node point that breaks a dropped bound or cone of the eliminated
            variables (the ALIP states and torques: the torque limit, eq. 5.12d) is solved again
            with the full model, and so is the node's subtree (default True).
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
            their solves in flight and exit before they are terminated; at the time limit they
            are terminated at once (default 1.0).
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
    escalate: bool = True
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
        check_fields(self, non_negative, ("feas_tol", "redundant_tol", "row_tol", "rank_tol", "probe_min_drop",
                     "drain_timeout", "link_min_drop"), prefix="bnb.")  # fmt: skip
        for name in ("probe_after", "probe_budget"):  # inf: never / no budget
            value = getattr(self, name)
            if value != math.inf:
                object.__setattr__(self, name, non_negative(f"bnb.{name}", value))
        for name in ("max_fm_rows", "probe_rounds", "probe_first_rounds", "heur_top",
                     "heur_nodes", "ls_sweeps", "map_depth"):  # fmt: skip
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise InputError(f"bnb.{name}", value, "an integer >= 0")
        for name in ("compact", "links", "staircase", "local_solves", "escalate"):
            if not isinstance(getattr(self, name), bool):
                raise InputError(f"bnb.{name}", getattr(self, name), "True or False")
        if self.map_depth < 1:
            raise InputError("bnb.map_depth", self.map_depth, "an integer >= 1")
        check_fields(self, _pairs, ("clarabel", "clarabel_retry"))
