"""The best-first search: :func:`solve` and the state of one run (:class:`_Search`).

Best-first on the bound; incumbents come from nodes whose relaxation point is integral by
geometry, from a dive from the root and from the heuristics after probing. Serial, or with the
node solves in forked workers answering asynchronously. The search stops when
``(incumbent - bound) / min(|incumbent|, |bound|) <= gap`` (SCIP's definition) or at the time
limit, returning the best point and an honest gap; a node whose solve fails numerically makes
the result ``feasible`` at best, never ``optimal``.
"""

from __future__ import annotations

import dataclasses
import heapq
import math
import time
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.solvers.base import (
    SolveProgress,
    SolverOptions,
    SolverResult,
    SolveStatus,
    relative_gap,
)
from footfall.solvers.bnb import probing
from footfall.solvers.bnb.branching import _branch, _choice, _dive, _finish, _Node, _root_allowed
from footfall.solvers.bnb.model import _Structure
from footfall.solvers.bnb.relaxation import HullRelaxation, _Relaxation
from footfall.solvers.bnb.structure import UnsupportedProblem, analyse
from footfall.solvers.bnb.workers import _Workers
from footfall.solvers.problem import MIQCQP

NAME = "bnb"
#: least time [s] between two calls of ``SolverOptions.progress``
PROGRESS_PERIOD = 1.0


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
        #: when ``options.progress`` was last called (the first call comes after one period)
        self.reported_at = start
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
        return relative_gap(self.inc_obj, bound)

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
        full = full or res.full
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
        if time.perf_counter() > self.deadline:  # the set-up took the whole time limit
            return self.result(True)
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
                # at the time limit the solves in flight are dropped at once (their results
                # would be dropped anyway); otherwise the workers get their drain time
                pool.close(grace=0.0 if timed_out else None)
        return self.result(timed_out)

    @property
    def probe_due(self) -> bool:
        """Probing is due (see :meth:`run`) and has not run yet."""
        return self.probed_at is None and self.nodes >= self.probe_at

    def subsearch(self) -> _Search:
        """A new search over the same structure, options and relaxation, not started."""
        # a sub-search reports nothing: its nodes are not the search's
        options = dataclasses.replace(self.options, progress=None)
        return _Search(self.s, options, self.start, self.relax)

    def loop(self, pool: _Workers | None) -> bool:
        """The best-first loop over the open nodes, serial or with ``pool`` (without a dive);
        returns True when stopped by the time or node limit."""
        return self._loop() if pool is None else self._loop_async(pool, None)

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
                probing.probe_now(self, None)
                continue
            for child, node in self._take_two():
                self.evaluate(child, node.bound, node.depth + 1, node.full)
        return False

    def _record(self, top: float) -> None:
        """Append ``(nodes, seconds, incumbent, bound)`` to the trace every 25 nodes; report
        progress (``options.progress``) at most every ``PROGRESS_PERIOD``."""
        if not self.trace or self.nodes >= self.trace[-1][0] + 25:
            inc = self.inc_obj if math.isfinite(self.inc_obj) else None  # JSON-safe
            self.trace.append((self.nodes, time.perf_counter() - self.start, inc, top))
        hook = self.options.progress
        now = time.perf_counter()
        if hook is not None and now >= self.reported_at + PROGRESS_PERIOD:
            self.reported_at = now
            inc = self.inc_obj if math.isfinite(self.inc_obj) else None
            hook(SolveProgress(self.nodes, now - self.start, inc, top, self.gap_of(top)))

    def _take_two(self) -> list[tuple[tuple[tuple[int, ...], ...], _Node]]:
        """Up to two node problems to solve next, with their parents: the children of the best
        open node, or an open node that lost dead members (solved again before it is branched)."""
        tasks: list[tuple[tuple[tuple[int, ...], ...], _Node]] = []
        while self.heap and len(tasks) < 2:
            node = heapq.heappop(self.heap)
            if node.bound >= self.inc_obj:
                continue
            assert node.x is not None
            narrowed = probing.narrowed(self, node.allowed)
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
                probing.probe_now(self, pool)
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
            allowed = probing.narrowed(self, node.allowed)
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
            # an empty wait is the time limit only once the clock says so (a wait may return a
            # little early, and the clock is the search's, not the wait's timer)
            answered = []
            while not answered:
                left = self.deadline - time.perf_counter()
                if left <= 0.0:
                    return []
                answered = pool.wait(left)
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
                "escalations": self.relax.escalations,
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
