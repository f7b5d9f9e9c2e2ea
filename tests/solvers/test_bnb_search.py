"""The branch-and-bound search's optimality logic (``_Search.offer``, ``gap_of``, ``evaluate``,
``result`` in :mod:`footfall.solvers.bnb.search`), fast enough to mutate.

References, none of them the search itself: SCIP on the same problem at test time (tiny footstep
instances, each solved by SCIP in well under a second; also SCIP's verdict of infeasibility and
its NaN bound without a solution), the optimum of a hand-built two-disjunction MIQCQP worked out
by hand, and SCIP's definition of the relative gap recomputed here:
``(obj - bound) / min(|obj|, |bound|)``, 0 when ``obj <= bound``, inf without an incumbent or when
the denominator is 0. Faults (a node relaxation that fails) are injected through the relaxation
handed to ``_Search``, and the search then has to report them as the module docstring says.
"""

from __future__ import annotations

import dataclasses
import heapq
import math
import time
from collections.abc import Callable

import numpy as np
import pytest

from footfall.models.biped import BipedParams
from footfall.planning.miqcqp import build_footstep_problem
from footfall.solvers import ProblemBuilder, SolverOptions, SolverResult, SolveStatus, bnb, solve
from footfall.solvers.bnb import branching
from footfall.solvers.bnb.relaxation import HullRelaxation, _Relaxation
from footfall.solvers.bnb.search import _Search
from footfall.solvers.problem import MIQCQP, fix_variables
from footfall.solvers.settings import BnbSettings
from footfall.terrain.scene import random_stepping_stones

#: relative optimality gap of the search
GAP = 1e-5
#: SCIP's gap: its objective is the reference optimum
SCIP_GAP = 1e-9
#: an objective within GAP of the optimum is within this of SCIP's (relative): the gap itself
OBJ_RTOL = GAP
ROBOT = BipedParams(n_nodes=3)
#: no probing: the search is the plain best-first loop
NO_PROBING = BnbSettings(probe_rounds=0)
#: (regions, seed, steps): feasible instances that SCIP solves in about 0.1 s and the search
#: only by branching (more than one node)
FEASIBLE = [(4, 1, 4), (4, 3, 4)]
#: an instance that both solvers find infeasible, the search only after branching
INFEASIBLE = (7, 4, 5)
Allowed = tuple[tuple[int, ...], ...]


def _footstep(regions: int, seed: int, n: int) -> MIQCQP:
    return build_footstep_problem(
        random_stepping_stones(seed, regions, robot=ROBOT), ROBOT, n
    ).problem


def _scip(problem: MIQCQP) -> SolverResult:
    res = solve(problem, "scip", SolverOptions(gap=SCIP_GAP, time_limit=30.0))
    assert res.status in (SolveStatus.OPTIMAL, SolveStatus.INFEASIBLE)
    return res


def _scip_gap(obj: float, bound: float) -> float:
    """SCIP's relative gap, written out here."""
    if not math.isfinite(obj):
        return math.inf
    if obj <= bound:
        return 0.0
    denom = min(abs(obj), abs(bound))
    return math.inf if denom == 0.0 else (obj - bound) / denom


def _search(problem: MIQCQP, options: SolverOptions, relax: object | None = None) -> _Search:
    structure = bnb.analyse(problem, settings=options.bnb)
    return _Search(structure, options, time.perf_counter(), relax)  # type: ignore[arg-type]


def _assert_honest(res: SolverResult, problem: MIQCQP, optimum: float) -> None:
    """A result with a solution: feasible, its objective that of ``x``, a bound at or below the
    true optimum, at or below the objective, and the gap SCIP's of the two."""
    assert res.x is not None
    assert problem.violation(res.x) <= BnbSettings().feas_tol
    assert res.objective == pytest.approx(problem.objective(res.x), rel=1e-12)
    assert res.bound <= optimum * (1 + OBJ_RTOL)
    assert optimum <= res.objective * (1 + OBJ_RTOL)
    assert res.bound <= res.objective
    assert res.gap == pytest.approx(_scip_gap(res.objective, res.bound), rel=1e-9, abs=1e-15)


# ------------------------------------------------------------------------ a hand-built MIQCQP
def hand_problem(radius: float = 3.0) -> MIQCQP:
    """min (x0 - 0.3)^2 + (x1 - 4)^2 with |x0| >= 1 (x0 <= -1 or x0 >= 1), x1 <= 0.5 or
    x1 >= 3.5, and ||x|| <= radius.

    Optimum by hand (radius 3): x1 >= 3.5 leaves x0^2 <= 9 - 12.25 < 0, so x1 <= 0.5 and x1 = 0.5
    (12.25); then x0 = 1 (0.49, against 1.69 at x0 = -1), inside the disc (1.25 <= 9): objective
    12.74. With radius 0.9 every branch is empty (|x0| >= 1 > 0.9): infeasible.
    """
    b = ProblemBuilder()
    x = b.add_vars("x", (2,), -5.0, 5.0)
    z = b.add_binaries("z", (2,))
    w = b.add_binaries("w", (2,))
    b.add_eq({int(z[0]): 1.0, int(z[1]): 1.0}, 1.0, "x0 side")
    b.add_le_big_m({int(x[0]): 1.0}, -1.0, int(z[0]), "x0 <= -1")
    b.add_le_big_m({int(x[0]): -1.0}, -1.0, int(z[1]), "x0 >= 1")
    b.add_eq({int(w[0]): 1.0, int(w[1]): 1.0}, 1.0, "x1 side")
    b.add_le_big_m({int(x[1]): 1.0}, 0.5, int(w[0]), "x1 <= 0.5")
    b.add_le_big_m({int(x[1]): -1.0}, -3.5, int(w[1]), "x1 >= 3.5")
    b.add_cone(x, radius)
    b.add_square({int(x[0]): 1.0}, 0.3, 1.0, "a")
    b.add_square({int(x[1]): 1.0}, 4.0, 1.0, "b")
    return b.build()


#: the hand-computed optimum of :func:`hand_problem`: x = (1, 0.5), z = (0, 1), w = (1, 0)
HAND_X = np.array([1.0, 0.5, 0.0, 1.0, 1.0, 0.0])
HAND_OPT = 0.7**2 + 3.5**2


def test_hand_problem_is_what_its_docstring_says() -> None:
    # the hand optimum is feasible and has the stated objective; SCIP agrees
    prob = hand_problem()
    assert prob.violation(HAND_X) == 0.0
    assert prob.objective(HAND_X) == pytest.approx(HAND_OPT, rel=1e-15)
    ref = _scip(prob)
    assert ref.status is SolveStatus.OPTIMAL
    assert ref.objective == pytest.approx(HAND_OPT, rel=1e-6)
    assert _scip(hand_problem(0.9)).status is SolveStatus.INFEASIBLE


@pytest.mark.parametrize("settings", [BnbSettings(), NO_PROBING])
@pytest.mark.parametrize("gap", [GAP, 0.0])
def test_hand_problem_optimum(settings: BnbSettings, gap: float) -> None:
    """Solved to the hand optimum by branching; with gap 0 too (the proof closes exactly)."""
    prob = hand_problem()
    res = solve(prob, "bnb", SolverOptions(gap=gap, bnb=settings))
    assert res.status is SolveStatus.OPTIMAL
    assert res.stats["nodes"] > 1
    assert res.objective == pytest.approx(HAND_OPT, rel=1e-6)
    assert res.x is not None
    np.testing.assert_allclose(res.x, HAND_X, atol=1e-5)
    _assert_honest(res, prob, HAND_OPT)
    assert res.gap <= gap


def test_hand_problem_infeasible() -> None:
    res = solve(hand_problem(0.9), "bnb", SolverOptions(gap=GAP))
    assert res.status is SolveStatus.INFEASIBLE
    assert res.x is None and math.isnan(res.objective) and math.isinf(res.gap)
    assert math.isnan(
        res.bound
    )  # as SCIP reports it (test_hand_problem_is_what_its_docstring_says)
    assert math.isnan(_scip(hand_problem(0.9)).bound)


# -------------------------------------------------------------------- footstep instances vs SCIP
@pytest.mark.parametrize(("regions", "seed", "n"), FEASIBLE)
@pytest.mark.parametrize("gap", [GAP, 0.0])
def test_optimum_equals_scips(regions: int, seed: int, n: int, gap: float) -> None:
    prob = _footstep(regions, seed, n)
    ref = _scip(prob)
    assert ref.status is SolveStatus.OPTIMAL
    res = solve(prob, "bnb", SolverOptions(gap=gap, bnb=NO_PROBING))
    assert res.status is SolveStatus.OPTIMAL
    assert res.stats["nodes"] > 1
    assert res.stats["raw_status"] == "optimal"
    assert res.stats["failed_nodes"] == {}
    assert res.objective == pytest.approx(ref.objective, rel=OBJ_RTOL)
    _assert_honest(res, prob, ref.objective)
    assert res.gap <= gap


def test_infeasible_instance() -> None:
    prob = _footstep(*INFEASIBLE)
    assert not prob.bounds_conflict()
    assert _scip(prob).status is SolveStatus.INFEASIBLE
    res = solve(prob, "bnb", SolverOptions(gap=GAP))
    assert res.status is SolveStatus.INFEASIBLE
    assert res.stats["nodes"] > 1  # proved by branching, not at the root
    assert res.x is None and math.isnan(res.objective) and math.isnan(res.bound)
    assert math.isinf(res.gap)
    assert res.stats["raw_status"] == "infeasible"


@pytest.mark.parametrize("limit", [2, 4, 6])
def test_node_limit_stops_with_an_honest_gap(limit: int) -> None:
    """Stopped after ``limit`` nodes (as at the time limit): time_limit status, and the bound,
    objective and gap are honest against SCIP's optimum."""
    regions, seed, n = FEASIBLE[0]
    prob = _footstep(regions, seed, n)
    ref = _scip(prob)
    search = _search(prob, SolverOptions(gap=0.0, bnb=NO_PROBING))
    search.node_limit = limit
    res = search.run()
    assert res.stats["nodes"] >= limit
    assert res.status is SolveStatus.TIME_LIMIT
    assert res.x is not None, "no incumbent yet (the dive from the root finds one): test another"
    _assert_honest(res, prob, ref.objective)
    assert res.gap > 0.0
    # the open nodes' bounds: the reported bound is the least of them
    assert res.bound == min(nd.bound for nd in search.heap if nd.bound < res.objective)


def test_time_limit_before_any_node() -> None:
    prob = _footstep(*FEASIBLE[0])
    search = _search(prob, SolverOptions(gap=0.0, time_limit=1e-9, bnb=NO_PROBING))
    time.sleep(1e-3)
    res = search.run()
    assert res.status is SolveStatus.TIME_LIMIT
    assert res.x is None and math.isinf(res.gap) and math.isnan(res.objective)


# --------------------------------------------------------------------------- initial solutions
def _worse_feasible(prob: MIQCQP, best: np.ndarray) -> tuple[np.ndarray, float]:
    """A feasible point worse than ``best``: SCIP's optimum with one used binary forbidden."""
    used = np.flatnonzero(prob.integer & (best > 0.5))
    for z in used:
        res = _scip(fix_variables(prob, np.array([z]), np.array([0.0])))
        if res.status is SolveStatus.OPTIMAL and res.x is not None:
            assert prob.violation(res.x) <= BnbSettings().feas_tol
            return res.x, prob.objective(res.x)
    raise AssertionError("no other feasible assignment")  # pragma: no cover


def test_initial_solution_feasible_worse_is_replaced() -> None:
    prob = _footstep(*FEASIBLE[0])
    ref = _scip(prob)
    assert ref.x is not None
    x0, obj0 = _worse_feasible(prob, ref.x)
    assert obj0 > ref.objective * (1 + OBJ_RTOL)
    options = SolverOptions(gap=GAP, bnb=NO_PROBING, initial_solution=x0)
    search = _search(prob, options)
    assert search.incumbent is not None and search.inc_obj == prob.objective(x0)
    res = search.run()
    assert res.status is SolveStatus.OPTIMAL
    assert res.objective <= obj0
    assert res.objective == pytest.approx(ref.objective, rel=OBJ_RTOL)
    _assert_honest(res, prob, ref.objective)


def test_initial_solution_optimal_is_kept() -> None:
    """SCIP's optimum as the start: the result is never worse than it (and optimal)."""
    prob = _footstep(*FEASIBLE[1])
    ref = _scip(prob)
    assert ref.x is not None and prob.violation(ref.x) <= BnbSettings().feas_tol
    res = solve(prob, "bnb", SolverOptions(gap=GAP, bnb=NO_PROBING, initial_solution=ref.x))
    assert res.status is SolveStatus.OPTIMAL
    assert res.objective <= prob.objective(ref.x)
    _assert_honest(res, prob, ref.objective)


def test_initial_solution_infeasible_is_not_taken() -> None:
    """The root relaxation's point: below the optimum, but not feasible; taking it would prune
    everything and call it optimal."""
    prob = _footstep(*FEASIBLE[0])
    ref = _scip(prob)
    structure = bnb.analyse(prob, settings=NO_PROBING)
    root = HullRelaxation(structure, settings=NO_PROBING).solve(branching._root_allowed(structure))
    assert root.x is not None
    assert prob.violation(root.x) > BnbSettings().feas_tol
    assert prob.objective(root.x) < ref.objective
    options = SolverOptions(gap=GAP, bnb=NO_PROBING, initial_solution=root.x)
    search = _search(prob, options)
    assert search.incumbent is None and math.isinf(search.inc_obj)
    res = search.run()
    assert res.status is SolveStatus.OPTIMAL
    assert res.objective == pytest.approx(ref.objective, rel=OBJ_RTOL)
    _assert_honest(res, prob, ref.objective)


def test_initial_solution_of_the_wrong_shape_is_ignored() -> None:
    prob = hand_problem()
    search = _search(prob, SolverOptions(initial_solution=HAND_X[:-1]))
    assert search.incumbent is None


# ------------------------------------------------------------------------------------ offer
def test_offer_takes_only_feasible_better_points() -> None:
    prob = hand_problem()
    search = _search(prob, SolverOptions(bnb=NO_PROBING))
    bad = HAND_X.copy()
    bad[0] = 0.5  # inside the excluded band |x0| < 1 with z1 = 1
    assert prob.violation(bad) > search.settings.feas_tol
    assert search.offer(bad) is False
    assert search.incumbent is None and math.isinf(search.inc_obj)
    worse = np.array([-1.0, 0.5, 1.0, 0.0, 1.0, 0.0])  # x0 = -1: 1.69 + 12.25
    assert prob.violation(worse) == 0.0
    assert search.offer(worse) is True
    assert search.incumbent is worse and search.inc_obj == pytest.approx(1.69 + 12.25)
    best = HAND_X.copy()
    assert search.offer(best) is True
    assert search.incumbent is best and search.inc_obj == pytest.approx(HAND_OPT)
    # a feasible point that is not better is reported feasible but not taken, also on a tie
    assert search.offer(worse.copy()) is True
    tie = HAND_X.copy()
    assert search.offer(tie) is True
    assert search.incumbent is best
    # an infeasible point better than the incumbent is not taken either
    cheat = HAND_X.copy()
    cheat[1] = 2.0  # x1 in the excluded band, objective 0.49 + 4
    assert prob.objective(cheat) < HAND_OPT and prob.violation(cheat) > search.settings.feas_tol
    assert search.offer(cheat) is False
    assert search.incumbent is best


def test_offer_accepts_a_violation_up_to_the_tolerance() -> None:
    prob = hand_problem()
    search = _search(prob, SolverOptions(bnb=BnbSettings(feas_tol=0.25, probe_rounds=0)))
    near = HAND_X.copy()
    near[0] = 0.875  # violates x0 >= 1 by 0.125 (binary fractions: exact)
    assert prob.violation(near) == 0.125
    assert search.offer(near) is True
    edge = HAND_X.copy()
    edge[0] = 0.75  # by exactly the tolerance
    assert prob.violation(edge) == 0.25
    search2 = _search(prob, SolverOptions(bnb=BnbSettings(feas_tol=0.25, probe_rounds=0)))
    assert search2.offer(edge) is True
    far = HAND_X.copy()
    far[0] = 0.5
    assert search2.offer(far) is False


# ----------------------------------------------------------------------------------- gap_of
@pytest.mark.parametrize(
    ("inc", "bound"),
    [
        (math.inf, 1.0),  # no incumbent
        (1.0, 1.0),  # incumbent at the bound
        (1.0, 2.0),  # incumbent below the bound
        (0.0, 0.0),  # both zero: obj <= bound comes first
        (3.0, 2.0),
        (2.0, 0.5),
        (1.0, 0.0),  # zero denominator
        (0.0, -1.0),  # zero denominator
        (-1.0, -3.0),  # negative: min of the absolute values
        (1.0, -1.0),
        (-2.0, -2.5),
        (4.0, -math.inf),
    ],
)
def test_gap_of_is_scips_gap(inc: float, bound: float) -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    search.inc_obj = inc
    got = search.gap_of(bound)
    want = _scip_gap(inc, bound)
    if math.isinf(want):
        assert math.isinf(got) and got > 0
    else:
        assert got == pytest.approx(want, rel=1e-15, abs=0.0)


def test_gap_of_values_by_hand() -> None:
    # the same definition, values written out (a check of _scip_gap too)
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    search.inc_obj = 3.0
    assert search.gap_of(2.0) == 0.5
    search.inc_obj = -1.0
    assert search.gap_of(-3.0) == 2.0
    assert search.gap_of(-1.0) == 0.0
    search.inc_obj = 0.0
    assert search.gap_of(0.0) == 0.0
    assert search.gap_of(-1.0) == math.inf


# --------------------------------------------------------------------------------- evaluate
def _root(search: _Search) -> tuple[Allowed, _Relaxation]:
    allowed = branching._root_allowed(search.s)
    res = search.relax.solve(allowed)
    assert res.status == "solved" and res.x is not None
    return allowed, res


def test_evaluate_keeps_a_fractional_node_with_the_larger_bound() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, res = _root(search)
    assert res.bound < HAND_OPT
    assert search.evaluate(allowed, -math.inf, 0, False, res) is res
    assert search.nodes == 1
    assert [nd.bound for nd in search.heap] == [res.bound]
    # a parent's bound above the node's relaxation is the node's bound
    parent = res.bound + 1.0
    assert search.evaluate(allowed, parent, 1, False, res) is res
    assert search.nodes == 2
    assert sorted(nd.bound for nd in search.heap) == [res.bound, parent]
    assert search.incumbent is None and not search.failed


def test_evaluate_prunes_a_node_that_cannot_beat_the_incumbent() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, res = _root(search)
    search.inc_obj = res.bound  # a node at the incumbent's value holds nothing better
    assert search.evaluate(allowed, -math.inf, 0, False, res) is None
    assert search.heap == [] and search.nodes == 1
    search.inc_obj = res.bound + 1.0
    assert search.evaluate(allowed, res.bound + 1.0, 0, False, res) is None  # by the parent
    assert search.heap == [] and search.nodes == 2


def test_evaluate_takes_an_integral_node_as_incumbent() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    z, w = search.s.groups[0].members, search.s.groups[1].members
    fixed = ((z[1],), (w[0],))  # x0 >= 1, x1 <= 0.5: the optimal branch
    for full in (False, True):
        assert search.evaluate(fixed, -math.inf, 2, full) is None
    assert search.nodes == 2
    assert search.incumbent is not None
    assert search.inc_obj == pytest.approx(HAND_OPT, rel=1e-6)
    np.testing.assert_allclose(search.incumbent, HAND_X, atol=1e-5)
    assert search.heap == []
    res = search.result(False)
    assert res.status is SolveStatus.OPTIMAL and res.bound == res.objective == search.inc_obj
    assert res.gap == 0.0


def test_evaluate_drops_an_infeasible_node() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    z, w = search.s.groups[0].members, search.s.groups[1].members
    assert search.evaluate(((z[1],), (w[1],)), -math.inf, 2, False) is None  # x1 >= 3.5: empty
    assert search.nodes == 1 and search.heap == [] and search.incumbent is None
    assert not search.failed
    res = search.result(False)
    assert res.status is SolveStatus.INFEASIBLE


def test_evaluate_records_a_failed_node() -> None:
    """The parent's bound of an unsolved node stays in the reported bound; its status is
    counted."""
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, _ = _root(search)
    failed = _Relaxation("failed", raw="InsufficientProgress")
    assert search.evaluate(allowed, 7.0, 1, True, failed) is None
    assert search.evaluate(allowed, 9.0, 1, True, failed) is None
    failed2 = _Relaxation("failed", raw="MaxIterations")
    assert search.evaluate(allowed, 5.0, 1, True, failed2) is None
    assert search.failed and search.nodes == 3
    assert search.failures == {"InsufficientProgress": 2, "MaxIterations": 1}
    assert search.lost_bound == 5.0
    res = search.result(False)
    assert res.status is SolveStatus.ERROR  # no incumbent, infeasibility not proven
    assert res.stats["failed_nodes"] == {"InsufficientProgress": 2, "MaxIterations": 1}
    assert res.x is None and math.isinf(res.gap)
    # with a solution, the lost bound is the reported bound and the result is not optimal
    assert search.offer(HAND_X.copy())
    res = search.result(False)
    assert res.status is SolveStatus.FEASIBLE
    assert res.bound == 5.0
    assert res.gap == pytest.approx(_scip_gap(HAND_OPT, 5.0), rel=1e-12)
    assert search.result(True).status is SolveStatus.TIME_LIMIT


def test_evaluate_retries_a_failed_condensed_node_on_the_full_model() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, res = _root(search)
    kept = search.evaluate(allowed, -math.inf, 0, False, _Relaxation("failed", raw="X"))
    assert not search.failed and search.failures == {}
    assert kept is not None and kept.status == "solved"
    assert search.nodes == 1
    assert [nd.full for nd in search.heap] == [True]
    assert search.heap[0].bound == pytest.approx(res.bound, rel=1e-6)


class _Recording:
    """The real node relaxation, recording every solve as ``(allowed, full)``."""

    def __init__(self, relax: HullRelaxation) -> None:
        self.inner = relax
        self.calls: list[tuple[Allowed, bool]] = []

    def solve(self, allowed: Allowed, full: bool = False) -> _Relaxation:
        self.calls.append((allowed, full))
        return self.inner.solve(allowed, full=full)

    def __getattr__(self, name: str) -> object:
        return getattr(self.inner, name)


def _off_the_disc(res: _Relaxation) -> _Relaxation:
    """``res`` with x0 = 3: the member rows of the optimal branch (x0 >= 1, x1 <= 0.5) still hold,
    the disc ||x|| <= 3 does not (as when a condensed model drops a cone): a condensed result."""
    assert res.x is not None
    x = res.x.copy()
    x[0] = 3.0
    return dataclasses.replace(res, x=x, full=False)


def test_evaluate_solves_an_integral_node_again_on_the_full_model() -> None:
    """A condensed relaxation point whose member choice is integral but infeasible: the node is
    solved again on the full model, once, and its point is the incumbent."""
    prob = hand_problem()
    structure = bnb.analyse(prob, settings=NO_PROBING)
    rec = _Recording(HullRelaxation(structure, settings=NO_PROBING))
    search = _Search(structure, SolverOptions(bnb=NO_PROBING), time.perf_counter(), rec)  # type: ignore[arg-type]
    z, w = structure.groups[0].members, structure.groups[1].members
    fixed = ((z[1],), (w[0],))
    bad = _off_the_disc(rec.inner.solve(fixed))
    assert bad.x is not None and prob.violation(bad.x) > search.settings.feas_tol
    assert search.evaluate(fixed, -math.inf, 2, False, bad) is None
    assert rec.calls == [(fixed, True)]
    assert search.inc_obj == pytest.approx(HAND_OPT, rel=1e-6)
    assert search.heap == []


def test_evaluate_solves_a_full_integral_node_with_every_group_fixed() -> None:
    """The same on the full model: the assignment is solved with every group fixed."""
    prob = hand_problem()
    search = _search(prob, SolverOptions(bnb=NO_PROBING))
    z, w = search.s.groups[0].members, search.s.groups[1].members
    fixed = ((z[1],), (w[0],))
    bad = _off_the_disc(search.relax.solve(fixed, full=True))
    assert search.evaluate(fixed, -math.inf, 2, True, bad) is None
    assert fixed in search.tried
    assert search.inc_obj == pytest.approx(HAND_OPT, rel=1e-6)
    assert search.heap == []


def test_evaluate_keeps_nodes_of_equal_bound_in_order() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, res = _root(search)
    for depth in range(5):
        assert search.evaluate(allowed, -math.inf, depth, False, res) is res
    assert search.nodes == 5
    # best first, ties in the order they came (five nodes: a heap of equal keys pops them
    # out of order)
    assert [heapq.heappop(search.heap).depth for _ in range(5)] == [0, 1, 2, 3, 4]


def test_evaluate_keeps_a_node_solved_again_at_its_depth() -> None:
    """A root whose condensed point looks integral but breaks the disc: solved again on the full
    model, where it is fractional, it is kept with its depth, on the full model, at the full
    relaxation's bound."""
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    allowed, res = _root(search)
    full = search.relax.solve(allowed, full=True)
    # a condensed result (this problem has no condensed model: ``res`` comes from the full one)
    fake = dataclasses.replace(res, bound=res.bound - 1.0, x=HAND_X.copy(), full=False)
    assert fake.x is not None
    fake.x[0] = 3.0  # x0 >= 1 and x1 <= 0.5 hold, ||x|| <= 3 does not
    kept = search.evaluate(allowed, -math.inf, 4, False, fake)
    assert kept is not None and kept.status == "solved"
    assert search.incumbent is None
    assert [(nd.depth, nd.full) for nd in search.heap] == [(4, True)]
    assert search.heap[0].bound == full.bound


# ------------------------------------------------------------------- faults in the relaxation
class _Faulty:
    """A node relaxation whose solves fail (Clarabel status "Injected") when ``fail(allowed,
    full)`` says so; otherwise the real one."""

    def __init__(self, relax: HullRelaxation, fail: Callable[[Allowed, bool], bool]) -> None:
        self.inner = relax
        self.fail = fail
        self.injected = 0

    def solve(self, allowed: Allowed, full: bool = False) -> _Relaxation:
        if self.fail(allowed, full):
            self.injected += 1
            return _Relaxation("failed", raw="Injected")
        return self.inner.solve(allowed, full=full)

    def __getattr__(self, name: str) -> object:
        return getattr(self.inner, name)


def _faulty_search(
    prob: MIQCQP, options: SolverOptions, fail: Callable[[Allowed, bool], bool]
) -> tuple[_Search, _Faulty]:
    structure = bnb.analyse(prob, settings=options.bnb)
    faulty = _Faulty(HullRelaxation(structure, settings=options.bnb), fail)
    return _Search(structure, options, time.perf_counter(), faulty), faulty  # type: ignore[arg-type]


@pytest.mark.parametrize(("regions", "seed", "n"), FEASIBLE)
def test_condensed_failures_are_retried_on_the_full_model(regions: int, seed: int, n: int) -> None:
    prob = _footstep(regions, seed, n)
    ref = _scip(prob)
    search, faulty = _faulty_search(
        prob, SolverOptions(gap=GAP, bnb=NO_PROBING), lambda allowed, full: not full
    )
    assert search.relax.condensed is not None  # the condensed model is the one that fails
    res = search.run()
    assert res.stats["condensed"] is True
    assert faulty.injected > 0
    assert res.status is SolveStatus.OPTIMAL
    assert res.stats["failed_nodes"] == {}
    assert res.stats["nodes"] > 1
    _assert_honest(res, prob, ref.objective)
    assert res.objective == pytest.approx(ref.objective, rel=OBJ_RTOL)


def test_a_node_that_fails_for_good_keeps_its_parents_bound() -> None:
    """The root's first child fails on both models: the search goes on, but its result is
    feasible at best and its bound is the root's (the failed node's parent)."""
    prob = _footstep(*FEASIBLE[0])
    ref = _scip(prob)
    doomed: list[Allowed] = []
    root_allowed: list[Allowed] = []

    def fail(allowed: Allowed, full: bool) -> bool:
        if not root_allowed:
            root_allowed.append(allowed)
        if not doomed and search.nodes == 1 and not search.heap and allowed != root_allowed[0]:
            doomed.append(allowed)
        return bool(doomed) and allowed == doomed[0]

    search, faulty = _faulty_search(prob, SolverOptions(gap=GAP, bnb=NO_PROBING), fail)
    root = search.relax.solve(branching._root_allowed(search.s))
    root_allowed.append(branching._root_allowed(search.s))
    res = search.run()
    assert doomed and faulty.injected == 2  # condensed, then full
    assert res.stats["failed_nodes"] == {"Injected": 1}
    assert res.status is SolveStatus.FEASIBLE
    assert res.bound == root.bound
    _assert_honest(res, prob, ref.objective)


def test_every_node_failing_is_an_error() -> None:
    prob = _footstep(*FEASIBLE[0])
    search, faulty = _faulty_search(
        prob, SolverOptions(gap=GAP, bnb=NO_PROBING), lambda allowed, full: True
    )
    res = search.run()
    assert res.status is SolveStatus.ERROR
    assert res.stats["failed_nodes"] == {"Injected": 1}  # the root, on both models
    assert faulty.injected == 2
    assert res.x is None and math.isinf(res.gap)


# ----------------------------------------------------------------------------------- result
def test_result_of_a_search_that_found_nothing() -> None:
    search = _search(hand_problem(), SolverOptions(bnb=NO_PROBING))
    stopped = search.result(True)
    assert stopped.status is SolveStatus.TIME_LIMIT
    ended = search.result(False)
    assert ended.status is SolveStatus.INFEASIBLE
    for res in (stopped, ended):
        assert res.x is None and math.isnan(res.objective) and math.isnan(res.bound)
        assert math.isinf(res.gap)
        assert res.stats["raw_status"] == res.status.value


def test_result_stats_describe_the_search() -> None:
    prob = hand_problem()
    settings = NO_PROBING
    counted: list[int] = []
    evaluate = _Search.evaluate

    class Counting(_Search):
        def evaluate(self, *args, **kwargs):  # type: ignore[no-untyped-def]
            counted.append(1)
            return evaluate(self, *args, **kwargs)

    t0 = time.perf_counter()
    structure = bnb.analyse(prob, settings=settings)
    search = Counting(structure, SolverOptions(gap=GAP, bnb=settings), time.perf_counter())
    res = search.run()
    wall = time.perf_counter() - t0
    stats = res.stats
    assert res.solver == "bnb"
    assert 0.0 <= res.solve_time <= wall
    assert stats["nodes"] == len(counted) > 1  # one per node evaluated
    assert stats["raw_status"] == "optimal"
    assert stats["failed_nodes"] == {}
    assert stats["variables"] == 6 and stats["integer_variables"] == 4
    assert stats["groups"] == 2 and stats["members"] == 4
    assert stats["workers"] == 0
    assert stats["relaxations"] >= stats["nodes"]
    assert stats["relaxation_time_s"] > 0.0
    assert stats["settings"] == dataclasses.asdict(settings)
    # no probing, so nothing probed and no heuristics after it
    assert stats["probes"] == 0 and stats["probe_dropped"] == 0 and stats["probe_time_s"] == 0.0
    assert stats["probed_at_node"] is None and math.isnan(stats["gap_when_probed"])
    assert stats["heuristic_nodes"] == 0 and stats["local_search_solves"] == 0
    assert math.isnan(stats["incumbent_before_heuristics"])
    assert isinstance(stats["condensed"], bool)
    assert stats["trace"] and stats["trace"][0][0] <= stats["nodes"]
