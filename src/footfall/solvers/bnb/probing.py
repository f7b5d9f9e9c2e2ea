"""Probing at the root and the primal heuristics that follow it.

A search still open after ``probe_after`` nodes per undecided root member solves the root once
with each member fixed and kills the members whose bound reaches the incumbent (or that are
infeasible): no better point uses them, so every open node drops them (a node that loses any is
solved again before it is branched), and the node problems shrink. One round ranks the members;
two primal heuristics then look for a better incumbent (a search of at most ``heur_nodes`` nodes
over each group's ``heur_top`` members of the lowest probe bound, and a one-group-at-a-time local
search), and further rounds probe with it until a round kills nothing.

Written against :class:`SearchState`, the part of the search these functions use, so that this
module does not import :mod:`footfall.solvers.bnb.search`.
"""

from __future__ import annotations

import math
import time
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from footfall._typing import FloatArray
from footfall.solvers.bnb.branching import _choice, _finish, _root_allowed, _without
from footfall.solvers.bnb.relaxation import _Relaxation
from footfall.solvers.bnb.workers import _Workers

if TYPE_CHECKING:
    from footfall.solvers.base import SolverOptions
    from footfall.solvers.bnb.model import _Structure
    from footfall.solvers.bnb.relaxation import HullRelaxation
    from footfall.solvers.settings import BnbSettings

#: a node's allowed members: per group, the binaries it may still use
Allowed = tuple[tuple[int, ...], ...]


class SearchState(Protocol):
    """The part of a search (:class:`footfall.solvers.bnb.search._Search`) that probing and the
    primal heuristics read and update."""

    s: _Structure
    settings: BnbSettings
    options: SolverOptions
    relax: HullRelaxation
    deadline: float
    node_limit: float
    nodes: int
    heap: list[Any]
    incumbent: FloatArray | None
    inc_obj: float
    tried: set[Allowed]
    #: the root node's allowed members and relaxation point
    root: tuple[Allowed, FloatArray] | None
    probes: int
    probe_dropped: int
    probe_time: float
    probe_budget: float
    probed_at: int | None
    probe_gap: float
    dead: set[int]
    dead_at: float
    heur_nodes: int
    ls_solves: int
    heur_from: float
    probe_bound: dict[int, float]

    def offer(self, cand: FloatArray) -> bool:
        """Take ``cand`` as incumbent if it is feasible and better; True if feasible."""
        ...

    def solve_fixed(self, fixed: Allowed) -> None:
        """One convex solve with every group fixed."""
        ...

    def dive(self, x: FloatArray, allowed: Allowed) -> None:
        """Dive from a relaxation point and solve the assignment it ends at."""
        ...

    def gap_of(self, bound: float) -> float:
        """Relative gap of the incumbent against ``bound``."""
        ...

    def evaluate(
        self,
        allowed: Allowed,
        parent_bound: float,
        depth: int,
        full: bool,
        res: _Relaxation | None = None,
    ) -> _Relaxation | None:
        """Solve a node and keep it when it may hold a better plan than the incumbent."""
        ...

    def subsearch(self) -> SearchState:
        """A new search over the same structure and relaxation, not started."""
        ...

    def loop(self, pool: _Workers | None) -> bool:
        """The best-first loop over the open nodes; True when stopped by a limit."""
        ...


def probe_now(search: SearchState, pool: _Workers | None) -> None:
    """Probe the root (:meth:`probe`, ``settings.probe_first_rounds`` rounds) with the
    incumbent, run the primal heuristics (:meth:`restricted_search`, :meth:`local_search`),
    then probe on (up to ``settings.probe_rounds`` rounds) with their incumbent. The members
    probing drops are dead for the rest of the search: an open node
    loses them when it is next taken from the queue (:meth:`narrowed`), and one that loses
    any is solved again before it is branched. Called with no node solve in flight."""
    search.probed_at = search.nodes
    if search.root is None:
        return
    search.probe_budget = search.settings.probe_budget * search.nodes
    search.probe_gap = search.gap_of(search.heap[0].bound) if search.heap else 0.0
    start, root_x = search.root
    # one round ranks the members for the heuristics; the rest use their incumbent
    t0 = time.perf_counter()
    allowed = probe(search, start, root_x, pool, search.settings.probe_first_rounds)
    search.probe_time += time.perf_counter() - t0
    if all(allowed) and search.heap and search.gap_of(search.heap[0].bound) > search.options.gap:
        search.heur_from = search.inc_obj
        restricted_search(search, allowed, pool)
        local_search(search, allowed, pool)
    t0 = time.perf_counter()
    allowed = probe(search, allowed, None, pool, search.settings.probe_rounds)
    search.probe_time += time.perf_counter() - t0
    kept = {z for mem in allowed for z in mem}
    search.dead |= {z for mem in start for z in mem if z not in kept}
    search.dead_at = search.inc_obj


def narrowed(
    search: SearchState, allowed: tuple[tuple[int, ...], ...]
) -> tuple[tuple[int, ...], ...] | None:
    """``allowed`` without the dead members (see :meth:`probe_now`); None when a group loses
    all of its members (no point of the node beats the incumbent). A better incumbent since
    the last call first kills every member whose probe bound reaches it."""
    if search.inc_obj < search.dead_at:
        search.dead |= _beaten(search)
        search.dead_at = search.inc_obj
    if not search.dead:
        return allowed
    out = tuple(tuple(z for z in mem if z not in search.dead) for mem in allowed)
    return out if all(out) else None


def _beaten(search: SearchState) -> set[int]:
    """The probed members whose probe bound reaches the incumbent."""
    return {z for z, b in search.probe_bound.items() if b >= search.inc_obj}


def probe(
    search: SearchState,
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
    known = _beaten(search)
    if known:
        narrowed = _narrow(search, allowed, known)
        if narrowed != allowed:
            allowed = narrowed
            root_x = None
    for rnd in range(rounds):
        if not all(allowed) or time.perf_counter() > search.deadline:
            break
        if rnd and not math.isfinite(search.inc_obj):
            # no incumbent yet: the smaller root may lead the dive to a plan
            if root_x is None:
                top = search.relax.solve(allowed)
                root_x = top.x if top.status == "solved" else None
            if root_x is not None:
                search.dive(root_x, allowed)
        before = search.inc_obj
        tasks = [(g, z) for g, mem in enumerate(allowed) if len(mem) > 1 for z in mem]
        if not tasks or search.probes + len(tasks) > search.probe_budget:
            break
        fixed = []
        for g, z in tasks:
            one = list(allowed)
            one[g] = (z,)
            fixed.append(tuple(one))
        results = _probe_solves(search, fixed, pool)
        search.probes += sum(res is not None for res in results)
        for (_, z), a, res in zip(tasks, fixed, results, strict=True):
            if res is None:
                continue  # not solved before the time limit: kept
            if res.status == "solved":
                search.probe_bound[z] = res.bound
            elif res.status == "infeasible":
                search.probe_bound[z] = math.inf
            if res.status == "solved" and res.x is not None:
                chosen = _choice(search.s, res.x, a, search.settings.row_tol)
                if chosen is not None:
                    search.offer(_finish(search.s, res.x, chosen))
        # against the best incumbent now (a probe may have found a better one)
        drop = {z for _, z in tasks if search.probe_bound.get(z, -math.inf) >= search.inc_obj}
        root_x = None
        if drop:
            allowed = _narrow(search, allowed, drop)
        few = len(drop) < search.settings.probe_min_drop * len(tasks)
        if not drop or (few and search.inc_obj >= before and math.isfinite(search.inc_obj)):
            break
    return allowed


def _narrow(
    search, allowed: tuple[tuple[int, ...], ...], drop: set[int]
) -> tuple[tuple[int, ...], ...]:
    """:func:`_without`, counting the dropped members."""
    out = _without(allowed, drop)
    search.probe_dropped += sum(map(len, allowed)) - sum(map(len, out))
    return out


def _probe_solves(
    search, fixed: list[tuple[tuple[int, ...], ...]], pool: _Workers | None
) -> list[_Relaxation | None]:
    """The relaxations of the probes ``fixed``, in the workers when there are any; None for a
    probe not solved before the time limit."""
    if pool is not None:
        return pool.map("node", [(a, False) for a in fixed], search.deadline)
    out: list[_Relaxation | None] = []
    for a in fixed:
        if time.perf_counter() > search.deadline:
            out.append(None)
            continue
        res = search.relax.solve(a)
        if res.status == "failed":  # as in _work
            res = search.relax.solve(a, full=True)
        out.append(res)
    return out


def restricted_search(search, allowed: tuple[tuple[int, ...], ...], pool: _Workers | None) -> None:
    """Primal heuristic: branch and bound (at most ``settings.heur_nodes`` nodes, cut off at the
    incumbent) over ``allowed`` restricted to each group's ``settings.heur_top`` members of the lowest
    probe bound; its best point is offered as incumbent. The restricted problem is small, and
    its optimum is often the full problem's (the probe bounds rank the members well)."""
    top, nodes = search.settings.heur_top, search.settings.heur_nodes
    if not (top and nodes):
        return
    rank = search.probe_bound
    small = tuple(
        mem if len(mem) <= top
        else tuple(sorted(mem, key=lambda z: (rank.get(z, -math.inf), z))[:top])
        for mem in allowed
    )  # fmt: skip
    if small == allowed:
        return  # the restricted problem is the search itself
    limit = min(nodes, search.probe_budget)
    sub = search.subsearch()
    sub.deadline = search.deadline
    sub.node_limit = limit
    sub.incumbent, sub.inc_obj = search.incumbent, search.inc_obj
    sub.tried = search.tried
    sub.evaluate(small, -math.inf, 0, False)
    try:
        sub.loop(pool)
    finally:
        if pool is not None:
            pool.drain()  # the restricted search may leave solves in flight
        search.heur_nodes += sub.nodes
    if sub.incumbent is not None:
        search.offer(sub.incumbent)


def local_search(
    search: SearchState, allowed: tuple[tuple[int, ...], ...], pool: _Workers | None
) -> None:
    """Primal heuristic: from the incumbent's members, solve every assignment that moves one
    group to another allowed member (all groups fixed: one convex solve each) and take the
    best improvement; repeat for at most ``settings.ls_sweeps`` sweeps."""
    if search.incumbent is None or not search.settings.ls_sweeps:
        return
    x = search.incumbent
    cur = [mem[int(np.argmax(x[list(mem)]))] for mem in _root_allowed(search.s)]
    for _ in range(search.settings.ls_sweeps):
        if time.perf_counter() > search.deadline:
            return
        moves: list[tuple[tuple[int, ...], ...]] = []
        for g, mem in enumerate(allowed):
            for z in mem:
                if z != cur[g]:
                    one: list[tuple[int, ...]] = [(m,) for m in cur]
                    one[g] = (z,)
                    moves.append(tuple(one))
        moves = [a for a in moves if a not in search.tried]
        if not moves or search.ls_solves + len(moves) > search.probe_budget:
            return
        results = _probe_solves(search, moves, pool)
        search.ls_solves += sum(res is not None for res in results)
        order = sorted(
            (res.bound, k)
            for k, res in enumerate(results)
            if res is not None and res.status == "solved" and res.x is not None
        )
        before = search.inc_obj
        for bound, k in order:
            if bound >= search.inc_obj:
                break
            a, res = moves[k], results[k]
            assert res is not None and res.x is not None
            search.tried.add(a)
            if not search.offer(_finish(search.s, res.x, a)):
                # the condensed point broke a dropped bound: the full model decides
                search.tried.discard(a)
                search.solve_fixed(a)
            if search.inc_obj < before:
                cur = [m[0] for m in a]
                break
        else:
            return
        if search.inc_obj >= before:
            return
