"""The ``bnb`` backend (the planner's default) solves exactly the direct model's problem.

Objective equality against the direct SCIP model on small seeded instances (N = 4..6, K = 3), the
independent checker on every plan, infeasibility detected by both, and unit checks of the
relaxation (a valid lower bound, exact at a fixed assignment) and of the fallback.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import time
from typing import ClassVar

import numpy as np
import pytest

from footfall.models.biped import BipedParams
from footfall.planning.check import check_plan
from footfall.planning.miqcqp import build_footstep_problem, plan_footsteps
from footfall.planning.plan import PlannerOptions
from footfall.solvers import ProblemBuilder, SolverOptions, SolveStatus, bnb, solve
from footfall.solvers.bnb import branching, links, relaxation, workers
from footfall.solvers.bnb import model as bnb_model
from footfall.solvers.bnb import search as bnb_search
from footfall.solvers.bnb import structure as bnb_structure
from footfall.solvers.problem import MIQCQP, fix_variables
from footfall.solvers.settings import BnbSettings
from footfall.terrain.scene import random_stepping_stones
from tests.conftest import VirtualClock

#: relative optimality gap of both solvers in the equality tests
GAP = 1e-5
#: objectives of two runs optimal within GAP agree to this (relative; both gaps plus slack)
OBJ_RTOL = 3 * GAP
#: relative slack of a lower bound against the value it bounds
BOUND_RTOL = 1e-7

ROBOT = BipedParams(n_nodes=3)
#: the default settings of the search (tolerances, drain timeout)
DEFAULTS = BnbSettings()
#: probing at the root of every search (small searches never reach it), without a budget
PROBING = BnbSettings(probe_after=0, probe_budget=math.inf)
#: no probing
NO_PROBING = BnbSettings(probe_rounds=0)

# (regions, seed, steps): feasible small instances where SCIP finishes in seconds
CASES = [(4, 0, 4), (4, 1, 4), (5, 0, 5), (5, 1, 5), (5, 2, 6), (5, 3, 6), (6, 0, 6)]


def _scene(regions: int, seed: int):  # type: ignore[no-untyped-def]
    return random_stepping_stones(seed, regions, robot=ROBOT)


#: optima of the direct model on SCIP (gap 1e-5, default settings) of the 8-region instances,
#: (seed, N) -> objective: an independent reference for the searches on them, pinned because SCIP
#: takes 6-25 s on each. ``test_pinned_optimum_is_scips`` re-solves one; after a change to the
#: model, re-solve them all with ``_scip_optimum(8, seed, n)``.
SCIP_OPTIMA_8 = {
    (0, 7): 0.8648405505353589,
    (0, 8): 0.7840635343254361,
    (1, 8): 0.8250145788140465,
    (2, 7): 1.1242978327997448,
    (2, 8): 0.8135083097684277,
    (3, 8): 0.7482095069103798,
}


@functools.cache
def _scip_optimum(regions: int, seed: int, n: int) -> float:
    """Optimum of the direct model on SCIP: the reference that a search stopping at its first
    incumbent (and calling it optimal) cannot meet."""
    fp = build_footstep_problem(_scene(regions, seed), ROBOT, n)
    res = solve(fp.problem, "scip", SolverOptions(gap=GAP, time_limit=300.0))
    assert res.status is SolveStatus.OPTIMAL
    return res.objective


def _assert_optimum(res, optimum: float) -> None:  # type: ignore[no-untyped-def]
    """``res`` is optimal with the reference objective, and its bound does not pass it."""
    assert res.status is SolveStatus.OPTIMAL
    assert res.objective == pytest.approx(optimum, rel=OBJ_RTOL)
    assert res.bound <= optimum * (1 + OBJ_RTOL)


@pytest.mark.parametrize(("regions", "seed", "n"), CASES)
def test_fast_objective_equals_direct(regions: int, seed: int, n: int) -> None:
    scene = _scene(regions, seed)
    opts = PlannerOptions(gap=GAP, time_limit=60.0)
    direct = plan_footsteps(scene, ROBOT, n, dataclasses.replace(opts, solver="scip"))
    assert direct.solver == "scip"
    fast = plan_footsteps(scene, ROBOT, n, dataclasses.replace(opts, solver="bnb"))
    # these searches are too small to reach probing: force it at the root (and its heuristics)
    probed = plan_footsteps(scene, ROBOT, n, dataclasses.replace(opts, solver="bnb", bnb=PROBING))
    assert probed.stats["probes"] > 0
    assert direct.status is SolveStatus.OPTIMAL, direct.message
    for plan in (fast, probed):
        assert plan.status is SolveStatus.OPTIMAL, plan.message
        assert plan.solver == "bnb"
        assert plan.objective == pytest.approx(direct.objective, rel=OBJ_RTOL)
    for plan in (direct, fast, probed):
        report = check_plan(plan, scene)
        assert report.ok, report.summary()
    # the fast plan's proven bound is a valid lower bound on the direct optimum
    assert fast.bound <= direct.objective * (1 + OBJ_RTOL)
    # and so is the root relaxation (hull, perspective, tightened member rows, condensed dynamics)
    structure = bnb.analyse(build_footstep_problem(scene, ROBOT, n, opts).problem)
    root = bnb.HullRelaxation(structure).solve(branching._root_allowed(structure))
    assert root.status == "solved"
    assert root.bound <= direct.objective * (1 + BOUND_RTOL)


def test_infeasible_detected_by_both() -> None:
    # 5 steps cannot cross this scene, but the variable bounds alone do not show it: both solvers
    # must prove it.
    scene = _scene(6, 2)
    fp = build_footstep_problem(scene, ROBOT, 5)
    assert not fp.problem.bounds_conflict()
    res_fast = solve(fp.problem, "bnb", SolverOptions(time_limit=60.0))
    res_direct = solve(fp.problem, "scip", SolverOptions(time_limit=60.0))
    assert res_fast.status is SolveStatus.INFEASIBLE
    assert res_direct.status is SolveStatus.INFEASIBLE
    plan = plan_footsteps(scene, ROBOT, 5, PlannerOptions(solver="bnb"))
    assert plan.status is SolveStatus.INFEASIBLE
    assert plan.message.startswith("infeasible")
    assert not check_plan(plan, scene).ok


def test_unsolvable_node_relaxations_are_an_error_that_says_so() -> None:
    """Clarabel stopping early on every node (one iteration allowed, also in the retry) must
    not read as infeasible: the plan says how many nodes failed and with which status."""
    one_step = BnbSettings(
        clarabel=(*DEFAULTS.clarabel, ("max_iter", 1)), clarabel_retry=(("max_iter", 1),)
    )
    scene = _scene(4, 0)
    plan = plan_footsteps(scene, ROBOT, 4, PlannerOptions(time_limit=30.0, bnb=one_step))
    assert plan.status is SolveStatus.ERROR
    assert plan.stats["failed_nodes"] == {"MaxIterations": plan.stats["nodes"]}
    assert "infeasibility not proven" in plan.message
    assert "MaxIterations" in plan.message


def test_relaxation_is_a_lower_bound_and_exact_when_fixed() -> None:
    scene = _scene(5, 0)
    fp = build_footstep_problem(scene, ROBOT, 5)
    res = solve(fp.problem, "bnb", SolverOptions(gap=GAP))
    _assert_optimum(res, _scip_optimum(5, 0, 5))
    assert res.x is not None
    structure = bnb.analyse(fp.problem)
    relax = bnb.HullRelaxation(structure)
    root = relax.solve(branching._root_allowed(structure))
    assert root.status == "solved"
    assert root.bound <= res.objective * (1 + BOUND_RTOL)
    # every group fixed to the optimal member: condensed and full relaxations give the optimum
    chosen = tuple(tuple(z for z in grp.members if res.x[z] > 0.5) for grp in structure.groups)
    for full in (False, True):
        fixed = relax.solve(chosen, full=full)
        assert fixed.status == "solved" and fixed.x is not None
        assert fixed.bound == pytest.approx(res.objective, rel=1e-6)


def test_perspective_and_hull_relaxations_agree_on_the_optimum() -> None:
    scene = _scene(5, 1)
    fp = build_footstep_problem(scene, ROBOT, 5)
    structure = bnb.analyse(fp.problem, perspective=False)
    assert not np.any(structure.assigned)
    with_p = bnb.analyse(fp.problem, perspective=True)
    assert np.any(with_p.assigned)  # the horizontal step terms sit in the heading-segment groups
    plain = bnb.HullRelaxation(structure).solve(branching._root_allowed(structure))
    persp = bnb.HullRelaxation(with_p).solve(branching._root_allowed(with_p))
    # the perspective relaxation is at least as tight
    assert persp.bound >= plain.bound * (1 - BOUND_RTOL)


@pytest.mark.parametrize(
    ("step", "status"), [(3, SolveStatus.OPTIMAL), (5, SolveStatus.INFEASIBLE)]
)
def test_fixed_binaries_are_respected(step: int, status: SolveStatus) -> None:
    """Forbidding the optimal region of a footstep: footstep 3 has another region (a worse
    optimum, the same as SCIP's on the fixed problem), footstep 5 none (infeasible)."""
    fp = build_footstep_problem(_scene(5, 2), ROBOT, 6)
    best = solve(fp.problem, "bnb", SolverOptions(gap=GAP))
    _assert_optimum(best, _scip_optimum(5, 2, 6))
    assert best.x is not None
    live = fp.regions[step][fp.regions[step] >= 0]
    used = int(live[np.argmax(best.x[live])])
    fixed = fix_variables(fp.problem, np.array([used]), np.array([0.0]))
    worse = solve(fixed, "bnb", SolverOptions(gap=GAP))
    direct = solve(fixed, "scip", SolverOptions(gap=GAP, time_limit=300.0))
    assert worse.status is direct.status is status
    if status is SolveStatus.OPTIMAL:
        assert worse.x is not None and worse.x[used] < 0.5
        _assert_optimum(worse, direct.objective)
        assert worse.objective > best.objective * (1 + OBJ_RTOL)


#: an instance whose search has incumbents after a few dozen nodes but needs thousands to prove
#: one optimal: the time limit falls between
_TIME_LIMIT_SCENE = random_stepping_stones(0, 12, robot=ROBOT)
TIME_LIMIT_STEPS = 14
#: the time limit of the gap tests [s] on the tests' virtual clock (1 ms a read: the serial
#: search stops after ~140 nodes, the parallel one after ~240, on any machine, loaded or not)
TIME_LIMIT = 0.5
#: clock reads the search may take past its time limit before it stops (a few nodes' worth)
LIMIT_READS = 0.05


@pytest.mark.parametrize("probe_at_root", [False, True])
def test_time_limit_returns_an_honest_gap(probe_at_root: bool, virtual_clock: VirtualClock) -> None:
    settings = PROBING if probe_at_root else DEFAULTS
    fp = build_footstep_problem(_TIME_LIMIT_SCENE, ROBOT, TIME_LIMIT_STEPS)
    res = solve(fp.problem, "bnb", SolverOptions(time_limit=TIME_LIMIT, gap=0.0, bnb=settings))
    assert res.status is SolveStatus.TIME_LIMIT
    assert res.x is not None, "no incumbent at the time limit: the test checks nothing"
    assert fp.problem.violation(res.x) <= DEFAULTS.feas_tol
    assert res.objective == pytest.approx(fp.problem.objective(res.x))
    assert res.bound <= res.objective * (1 + BOUND_RTOL)
    expected = (res.objective - res.bound) / min(abs(res.objective), abs(res.bound))
    assert res.gap == pytest.approx(max(expected, 0.0), abs=1e-12)
    assert res.gap > 0.0


def test_time_limit_without_an_incumbent_has_an_infinite_gap(virtual_clock: VirtualClock) -> None:
    fp = build_footstep_problem(_TIME_LIMIT_SCENE, ROBOT, TIME_LIMIT_STEPS)
    # one read of the clock: the limit has passed when the search starts
    res = solve(fp.problem, "bnb", SolverOptions(time_limit=virtual_clock.step, gap=0.0))
    assert res.status is SolveStatus.TIME_LIMIT
    assert res.x is None and math.isinf(res.gap)


def test_unsupported_problem_falls_back_to_scip() -> None:
    b = ProblemBuilder()
    x = b.add_vars("x", (2,), lb=-1.0, ub=1.0)
    z = b.add_binaries("z", ())
    b.add_square({int(x[0]): 1.0, int(z): 1.0}, 1.5, 1.0, "binary in the objective")
    b.add_le({int(x[0]): 1.0, int(x[1]): 1.0}, 1.0, "plain")
    prob = b.build()
    with pytest.raises(bnb.UnsupportedProblem):
        bnb.analyse(prob)
    res = solve(prob, "bnb")
    assert "fallback" in res.stats
    assert res.status is SolveStatus.OPTIMAL
    assert res.objective == pytest.approx(0.0, abs=1e-6)


@pytest.mark.parametrize(("seed", "n"), [(1, 8), (0, 7), (2, 7), (3, 8)])
def test_parallel_workers_find_the_same_optimum(seed: int, n: int) -> None:
    scene = random_stepping_stones(seed, 8, robot=ROBOT)
    fp = build_footstep_problem(scene, ROBOT, n)
    serial = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=1))
    parallel = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=2))
    assert serial.status is parallel.status
    assert serial.stats["workers"] == 0
    if serial.status is SolveStatus.INFEASIBLE:
        return
    for res in (serial, parallel):
        _assert_optimum(res, SCIP_OPTIMA_8[seed, n])
    assert fp.problem.violation(parallel.x) <= DEFAULTS.feas_tol
    if parallel.stats["nodes"] > 1:  # the search branched, so the workers were used
        assert parallel.stats["workers"] == 2


def test_search_process_solving_beside_one_worker_finds_the_same_optimum() -> None:
    fp = build_footstep_problem(random_stepping_stones(1, 8, robot=ROBOT), ROBOT, 8)
    serial = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=1))
    local = solve(
        fp.problem, "bnb", SolverOptions(gap=GAP, threads=2, bnb=BnbSettings(local_solves=True))
    )
    for res in (serial, local):
        _assert_optimum(res, SCIP_OPTIMA_8[1, 8])
    assert local.stats["workers"] == 1


class _Recorded(workers._Workers):
    """The worker pool, remembering every instance (to check that its processes are reaped)."""

    made: ClassVar[list[workers._Workers]] = []

    def __init__(self, relax, n: int) -> None:  # type: ignore[no-untyped-def]
        super().__init__(relax, n)
        _Recorded.made.append(self)


@pytest.fixture
def recorded(monkeypatch: pytest.MonkeyPatch) -> list[workers._Workers]:
    """Pools the searches of a test made; afterwards every worker must be reaped."""
    import multiprocessing as mp
    import os

    _Recorded.made = []
    monkeypatch.setattr(bnb_search, "_Workers", _Recorded)
    yield _Recorded.made
    for pool in _Recorded.made:
        assert pool.closed
        for proc in pool.procs:
            assert proc.exitcode is not None  # joined
            assert not os.path.exists(f"/proc/{proc.pid}")  # not even a zombie
    assert not mp.active_children()


def _branching_problem() -> MIQCQP:
    return build_footstep_problem(random_stepping_stones(0, 8, robot=ROBOT), ROBOT, 8).problem


def test_workers_are_reaped_after_a_solve(recorded: list[workers._Workers]) -> None:
    res = solve(_branching_problem(), "bnb", SolverOptions(gap=GAP, threads=2))
    assert res.status is SolveStatus.OPTIMAL
    assert len(recorded) == 1 and len(recorded[0].procs) == 2


def test_workers_are_reaped_after_the_time_limit(
    recorded: list[workers._Workers], virtual_clock: VirtualClock
) -> None:
    fp = build_footstep_problem(_TIME_LIMIT_SCENE, ROBOT, TIME_LIMIT_STEPS)
    res = solve(fp.problem, "bnb", SolverOptions(time_limit=0.1, gap=0.0, threads=2))
    assert res.status is SolveStatus.TIME_LIMIT  # with solves in flight, terminated at once
    assert len(recorded) == 1


def _raise_in_worker(task):  # type: ignore[no-untyped-def]
    raise ArithmeticError("node solver exploded")


def _exit_in_worker(task):  # type: ignore[no-untyped-def]
    import os

    os._exit(7)  # a worker that dies without a word (as if killed)


def test_a_failing_worker_stops_the_search_with_its_error(
    recorded: list[workers._Workers], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(workers, "_work", _raise_in_worker)  # the forked workers inherit it
    with pytest.raises(bnb.WorkerError, match="node solver exploded"):
        solve(_branching_problem(), "bnb", SolverOptions(gap=GAP, threads=2))
    assert len(recorded) == 1


def test_a_dead_worker_is_an_error_not_a_hang(
    recorded: list[workers._Workers], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(workers, "_work", _exit_in_worker)
    # an error, not a result: a search that waited for the dead worker's answer would end at
    # its time limit with a time_limit status instead
    with pytest.raises(bnb.WorkerError, match=r"died \(exit code 7\)"):
        solve(_branching_problem(), "bnb", SolverOptions(time_limit=60.0, gap=GAP, threads=2))
    assert len(recorded) == 1


def test_an_error_in_the_search_process_reaps_the_workers(
    recorded: list[workers._Workers], monkeypatch: pytest.MonkeyPatch
) -> None:
    calls = {"n": 0}
    evaluate = bnb_search._Search.evaluate

    def failing(self, *args, **kwargs):  # type: ignore[no-untyped-def]
        calls["n"] += 1
        if calls["n"] > 3:  # after the root, with workers solving
            raise KeyboardInterrupt
        return evaluate(self, *args, **kwargs)

    monkeypatch.setattr(bnb_search._Search, "evaluate", failing)
    with pytest.raises(KeyboardInterrupt):
        solve(_branching_problem(), "bnb", SolverOptions(gap=GAP, threads=2))
    assert len(recorded) == 1


@pytest.mark.parametrize("threads", [0, -1, 1.5, True, "2", None])
def test_bad_thread_counts_are_input_errors(threads: object) -> None:
    from footfall.errors import InputError

    with pytest.raises(InputError, match="threads"):
        SolverOptions(threads=threads)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="threads"):
        PlannerOptions(threads=threads)  # type: ignore[arg-type]


def test_bench_plan_cli_writes_the_table(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import json
    import subprocess
    import sys

    res = subprocess.run(
        [sys.executable, "-m", "footfall", "bench", "plan", "--steps", "5", "--nodes", "3",
         "--seeds", "0", "--regions", "5", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    runs = json.loads((tmp_path / "bench_plan.json").read_text())["runs"]
    assert {r["solver"] for r in runs} == {"scip", "bnb"}
    assert all(r["status"] == "optimal" and r["check_ok"] for r in runs)
    objs = [r["objective"] for r in runs]
    assert objs[0] == pytest.approx(objs[1], rel=2e-3)  # both within the bench's gap of 1e-3
    table = (tmp_path / "bench_plan.md").read_text()
    assert "| 5 | 3 | 5 | 1 |" in table and "all agree" in table and "all plans pass" in table
    fast_only = subprocess.run(
        [sys.executable, "-m", "footfall", "bench", "plan", "--steps", "5", "--nodes", "3",
         "--seeds", "0", "--regions", "5", "--fast-only", "--out", str(tmp_path / "fast")],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert fast_only.returncode == 0, fast_only.stderr
    runs = json.loads((tmp_path / "fast" / "bench_plan.json").read_text())["runs"]
    assert {r["solver"] for r in runs} == {"bnb"}
    bad = subprocess.run(
        [sys.executable, "-m", "footfall", "bench", "plan", "--steps", "0"],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert bad.returncode == 2 and "steps" in bad.stderr


@pytest.mark.parametrize("probe_at_root", [False, True])
def test_parallel_time_limit_returns_an_honest_gap(
    probe_at_root: bool, virtual_clock: VirtualClock
) -> None:
    # the asynchronous search stops with solves (and possibly the dive) in flight; with probing
    # at the root, the time limit falls in probing or its heuristics. The clock is the tests'
    # virtual one: an incumbent and the stop at the limit do not depend on the machine's load
    settings = PROBING if probe_at_root else DEFAULTS
    fp = build_footstep_problem(_TIME_LIMIT_SCENE, ROBOT, TIME_LIMIT_STEPS)
    options = SolverOptions(time_limit=TIME_LIMIT, gap=0.0, threads=2, bnb=settings)
    res = solve(fp.problem, "bnb", options)
    assert res.status is SolveStatus.TIME_LIMIT
    assert res.solve_time < TIME_LIMIT + LIMIT_READS  # stopped at the limit, workers dropped
    assert res.x is not None, "no incumbent at the time limit: the test checks nothing"
    assert fp.problem.violation(res.x) <= settings.feas_tol
    assert res.bound <= res.objective * (1 + BOUND_RTOL)


def test_dropping_redundant_member_rows_keeps_the_member_set() -> None:
    # a member's rows: two upper and two lower bounds on x0 (the loosest as Fourier-Motzkin leaves
    # them), a row implied by the box, and one that cuts; inside the box the set is unchanged
    rng = np.random.default_rng(0)
    lb, ub = np.array([-1.0, -2.0]), np.array([1.0, 2.0])
    a_v = np.array([[1.0, 0.0], [2.0, 0.0], [-1.0, 0.0], [-0.5, 0.0], [0.1, 0.1], [1.0, 1.0]])
    beta = np.array([0.5, 3.0, 0.8, 0.2, 5.0, 1.0])
    a_r, b_r = bnb_structure._drop_redundant(a_v, beta, lb, ub, DEFAULTS.redundant_tol)
    assert len(b_r) == 3  # x0 <= 0.5, x0 >= -0.4, x0 + x1 <= 1
    pts = rng.uniform(lb, ub, size=(2000, 2))
    inside = np.all(pts @ a_v.T <= beta, axis=1)
    assert np.array_equal(inside, np.all(pts @ a_r.T <= b_r, axis=1))


def test_member_violations_are_the_largest_row_violations() -> None:
    scene = _scene(5, 0)
    fp = build_footstep_problem(scene, ROBOT, 5)
    structure = bnb.analyse(fp.problem)
    x = np.random.default_rng(1).uniform(fp.problem.lb, fp.problem.ub)
    for g, grp in enumerate(structure.groups):
        got = branching._violations(structure, x, g, grp.members[::-1])
        for k, z in enumerate(grp.members[::-1]):
            mb = structure.member[z]
            want = float(np.max(mb.a_v @ x[grp.variables] - mb.beta)) if len(mb.beta) else 0.0
            assert got[k] == pytest.approx(want, abs=1e-12)


def _link_structure(
    problem: MIQCQP, staircase: bool = True, min_drop: float = DEFAULTS.link_min_drop
) -> bnb_model._Structure:
    settings = BnbSettings(links=True, staircase=staircase, link_min_drop=min_drop)
    return bnb.analyse(problem, settings=settings)


def test_link_pairs_are_exactly_the_rate_feasible_segment_pairs() -> None:
    scene = random_stepping_stones(0, 8, robot=ROBOT)
    fp = build_footstep_problem(scene, ROBOT, 8)
    structure = _link_structure(fp.problem, min_drop=0.0)
    pr, br, tmax = fp.problem, fp.breakpoints, ROBOT.theta_max
    by_groups = {link.groups: link for link in structure.compat}
    checked = 0
    for i in range(1, fp.n_steps):
        seg_i = [int(z) for z in fp.segments[i] if z >= 0]
        seg_j = [int(z) for z in fp.segments[i + 1] if z >= 0]
        if len(seg_i) < 2 or len(seg_j) < 2:
            continue
        link = by_groups[(structure.group_of[seg_i[0]], structure.group_of[seg_j[0]])]

        def box(step: int, z: int) -> tuple[float, float]:
            ell = int(np.flatnonzero(fp.segments[step] == z)[0])
            t = int(fp.theta[step])
            return max(br[ell], pr.lb[t]), min(br[ell + 1], pr.ub[t])

        want = set()
        for a in seg_i:
            lo_a, hi_a = box(i, a)
            for b in seg_j:
                lo_b, hi_b = box(i + 1, b)
                # some theta_i in a and theta_{i+1} in b with |theta_{i+1} - theta_i| <= theta_max
                if lo_b - hi_a <= tmax + 1e-9 and lo_a - hi_b <= tmax + 1e-9:
                    want.add((a, b))
        assert {(int(a), int(b)) for a, b in link.pairs} == want
        assert len(want) < len(seg_i) * len(seg_j)
        # a staircase: written as prefix rows, not as pair weights
        assert link.groups in {(g, g2) for g, _, g2, _ in structure.prefix_rows}
        assert link.groups not in {lk.groups for lk in structure.links}
        checked += 1
    assert checked >= 3


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_linked_relaxation_is_tighter_and_below_the_optimum(seed: int) -> None:
    scene = random_stepping_stones(seed, 8, robot=ROBOT)
    fp = build_footstep_problem(scene, ROBOT, 8)
    best = solve(fp.problem, "bnb", SolverOptions(gap=GAP))
    _assert_optimum(best, SCIP_OPTIMA_8[seed, 8])
    plain_s = bnb.analyse(fp.problem)
    plain = bnb.HullRelaxation(plain_s).solve(branching._root_allowed(plain_s))
    bounds = []
    for staircase in (True, False):  # prefix rows and pair weights: the same polytope
        linked_s = _link_structure(fp.problem, staircase)
        linked = bnb.HullRelaxation(linked_s).solve(branching._root_allowed(linked_s))
        assert linked.status == plain.status == "solved"
        assert linked.bound >= plain.bound * (1 - BOUND_RTOL)
        assert linked.bound <= best.objective * (1 + BOUND_RTOL)
        bounds.append(linked.bound)
    assert bounds[0] == pytest.approx(bounds[1], rel=1e-5)
    # with every group fixed to the optimum the links change nothing
    chosen = tuple(tuple(z for z in grp.members if best.x[z] > 0.5) for grp in linked_s.groups)
    fixed = bnb.HullRelaxation(linked_s).solve(chosen)
    assert fixed.bound == pytest.approx(best.objective, rel=1e-6)


@pytest.mark.parametrize(("regions", "seed", "n"), CASES[:4])
def test_linked_search_finds_the_same_optimum(regions: int, seed: int, n: int) -> None:
    fp = build_footstep_problem(_scene(regions, seed), ROBOT, n)
    plain = solve(fp.problem, "bnb", SolverOptions(gap=GAP))
    linked = solve(fp.problem, "bnb", SolverOptions(gap=GAP, bnb=BnbSettings(links=True)))
    for res in (plain, linked):
        _assert_optimum(res, _scip_optimum(regions, seed, n))


def test_propagation_drops_only_members_without_a_compatible_partner() -> None:
    fp = build_footstep_problem(random_stepping_stones(0, 8, robot=ROBOT), ROBOT, 10)
    structure = _link_structure(fp.problem)
    root = branching._root_allowed(structure)
    # pin footstep 5 to its first live segment
    z5 = int(fp.segments[5][fp.segments[5] >= 0][0])
    g5 = structure.group_of[z5]
    pinned = tuple((z5,) if g == g5 else mem for g, mem in enumerate(root))
    out = links._propagate(structure, pinned)
    assert out is not None
    assert sum(map(len, out)) < sum(map(len, pinned))
    # partners of each member in the other group of each link, both directions
    partners: dict[tuple[int, int], set[int]] = {}
    for link in structure.compat:
        g1, g2 = link.groups
        for a, b in link.pairs:
            partners.setdefault((int(a), g2), set()).add(int(b))
            partners.setdefault((int(b), g1), set()).add(int(a))
    links_of = {g: [lk.groups[1 - k] for lk in structure.compat for k in (0, 1)
                    if lk.groups[k] == g] for g in range(len(root))}  # fmt: skip
    for g, mem in enumerate(pinned):
        assert set(out[g]) <= set(mem)
        for a in out[g]:  # every member left has a partner left in every linked group
            assert all(partners.get((a, h), set()) & set(out[h]) for h in links_of[g])
        for a in set(mem) - set(out[g]):  # every member dropped has none in some linked group
            assert not all(partners.get((a, h), set()) & set(out[h]) for h in links_of[g])
    # pinning two footsteps to incompatible segments leaves no node
    z6 = int(fp.segments[6][fp.segments[6] >= 0][-1])  # the live segment farthest from z5
    g6 = structure.group_of[z6]
    clash = tuple((z6,) if g == g6 else mem for g, mem in enumerate(pinned))
    link56 = next(lk for lk in structure.compat if lk.groups == (g5, g6))
    assert (z5, z6) not in {(int(a), int(b)) for a, b in link56.pairs}
    assert links._propagate(structure, clash) is None


def test_clarabel_gets_the_same_problem_from_lists() -> None:
    """The node solver hands Clarabel its matrices as lists built straight from COO entries
    (:meth:`relaxation._CscLists.from_coo`): the same arrays as scipy's canonical CSC (duplicates
    summed, rows sorted in each column, explicit zeros kept, empty columns), and the same solution."""
    import clarabel
    import scipy.sparse as sp

    rng = np.random.default_rng(0)
    m, n = 12, 6
    a_dense = rng.normal(size=(m, n))
    a_dense[:, 3] = 0.0  # an empty column
    rows, cols = np.nonzero(a_dense)
    # shuffled entries, two duplicates at (0, 0) and an explicit zero at (5, 3)
    r = np.r_[rows, [0, 0, 5]]
    c = np.r_[cols, [0, 0, 3]]
    v = np.r_[a_dense[rows, cols], [0.5, 0.25, 0.0]]
    perm = rng.permutation(len(r))
    r, c, v = r[perm], c[perm], v[perm]
    got_a = relaxation._CscLists.from_coo(r, c, v, (m, n))
    ref_a = sp.csc_matrix((v, (r, c)), shape=(m, n))
    ref_a.sum_duplicates()
    assert got_a.shape == ref_a.shape
    assert got_a.indptr == ref_a.indptr.tolist()
    assert got_a.indices == ref_a.indices.tolist()
    assert np.allclose(got_a.data, ref_a.data, rtol=0.0, atol=1e-15)
    assert got_a.data[0] == pytest.approx(a_dense[0, 0] + 0.75)
    assert got_a.indptr[4] - got_a.indptr[3] == 1  # the explicit zero is kept
    p_dense = np.triu(rng.normal(size=(n, n)) * 0.1) + np.eye(n) * 2.0
    pi, pj = np.nonzero(p_dense)
    p_ref = sp.csc_matrix(p_dense)
    q, b = rng.normal(size=n), np.abs(rng.normal(size=m)) + 1.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    cones = [clarabel.NonnegativeConeT(m)]
    ref_sol = clarabel.DefaultSolver(p_ref, q, ref_a, b, cones, settings).solve()
    got = clarabel.DefaultSolver(
        relaxation._CscLists.from_coo(pi, pj, p_dense[pi, pj], (n, n)), q.tolist(), got_a,
        b.tolist(), cones, settings,
    ).solve()  # fmt: skip
    assert str(got.status) == str(ref_sol.status) == "Solved"
    assert np.allclose(got.x, ref_sol.x, atol=1e-12)
    assert got.obj_val == pytest.approx(ref_sol.obj_val, abs=1e-12)


def test_compact_node_problems_are_the_same_relaxation() -> None:
    """``BnbSettings.compact`` leaves out free columns, excluded binaries and implied ``z >= 0`` rows and
    projects the separable forms' copies out: the node bounds (condensed and full) and statuses
    stay those of the plain node problems."""
    fp = build_footstep_problem(_scene(5, 0), ROBOT, 5)
    structure = bnb.analyse(fp.problem)
    plain = bnb.HullRelaxation(structure, settings=BnbSettings(compact=False))
    compact = bnb.HullRelaxation(structure, settings=BnbSettings(compact=True))
    assert compact.condensed is not None
    dropped = compact._tpl[id(compact.condensed)].drop_col
    # the private sin/cos of the heading segments (and footstep 0's, fixed by their bounds)
    private = np.concatenate([grp.private for grp in structure.groups])
    assert len(private) and set(compact.condensed.col[private]) <= set(dropped)
    # the heading of every multi-member heading-segment group is separable
    t = compact._tpl[id(compact.condensed)]
    assert int(np.sum(t.s_nrows)) >= 2 * sum(
        1 for grp in structure.groups if len(grp.cost_rows) and len(grp.members) > 1
    )
    rng = np.random.default_rng(3)
    root = branching._root_allowed(structure)
    nodes = [root]
    for _ in range(12):  # random nodes: every group keeps a random non-empty subset
        nodes.append(
            tuple(
                tuple(sorted(rng.choice(mem, size=rng.integers(1, len(mem) + 1), replace=False)))
                for mem in root
            )
        )
    statuses = set()
    for allowed in nodes:
        for full in (False, True):
            ref = plain.solve(allowed, full=full)
            got = compact.solve(allowed, full=full)
            assert got.status == ref.status
            statuses.add(ref.status)
            if ref.status == "solved":
                assert got.bound == pytest.approx(ref.bound, rel=1e-6, abs=1e-7)
                assert got.x is not None
                # the left-out variables get values within their bounds
                v = np.flatnonzero(np.isin(compact.condensed.col, dropped))
                assert np.all(fp.problem.lb[v] <= got.x[v]) and np.all(got.x[v] <= fp.problem.ub[v])
    assert "solved" in statuses


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize(("seed", "n"), [(1, 8), (3, 8)])
def test_probing_and_heuristics_keep_the_optimum(seed: int, n: int, threads: int) -> None:
    fp = build_footstep_problem(random_stepping_stones(seed, 8, robot=ROBOT), ROBOT, n)
    plain = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=threads, bnb=NO_PROBING))
    probed = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=threads, bnb=PROBING))
    for res in (plain, probed):
        _assert_optimum(res, SCIP_OPTIMA_8[seed, n])
    assert plain.stats["probes"] == 0
    assert probed.stats["probes"] > 0 and probed.stats["probe_dropped"] > 0
    assert probed.stats["heuristic_nodes"] + probed.stats["local_search_solves"] > 0
    assert probed.objective == pytest.approx(plain.objective, rel=OBJ_RTOL)
    assert probed.x is not None and fp.problem.violation(probed.x) <= DEFAULTS.feas_tol
    assert probed.bound <= probed.objective * (1 + BOUND_RTOL)


def test_probing_drops_only_members_no_better_plan_uses() -> None:
    """Every member probing kills is checked by SCIP (an independent solver) on the problem with
    that binary fixed to 1: infeasible, or no better than the plan the search returned."""
    fp = build_footstep_problem(_scene(5, 1), ROBOT, 5)
    options = SolverOptions(gap=GAP, bnb=PROBING)
    search = bnb_search._Search(bnb.analyse(fp.problem), options, time.perf_counter())
    res = search.run()
    assert res.status is SolveStatus.OPTIMAL
    dead = sorted(search.dead)
    assert dead, "probing killed nothing: the test checks nothing"
    for z in dead[:: max(1, len(dead) // 6)]:
        fixed = solve(
            fix_variables(fp.problem, np.array([z]), np.array([1.0])),
            "scip",
            SolverOptions(gap=GAP, time_limit=60.0),
        )
        assert fixed.status in (SolveStatus.OPTIMAL, SolveStatus.INFEASIBLE), fp.problem.names[z]
        if fixed.status is SolveStatus.OPTIMAL:
            assert fixed.objective >= res.objective * (1 - OBJ_RTOL), fp.problem.names[z]


def test_worker_map_keeps_many_tasks_flowing_and_stops_at_its_deadline() -> None:
    # all tasks sent at once filled both pipes and deadlocked the search and its workers
    structure = bnb.analyse(_branching_problem())
    relax = bnb.HullRelaxation(structure)
    root = branching._root_allowed(structure)
    pool = workers._Workers(relax, 2)
    try:
        out = pool.map("node", [(root, False)] * 300)
        assert len(out) == 300 and all(r.status == "solved" for r in out)
        assert len({round(r.bound, 9) for r in out}) == 1
        assert pool.map("node", [(root, False)] * 5, deadline=0.0) == [None] * 5
        assert pool.busy == 0
    finally:
        pool.close()


@pytest.mark.parametrize("threads", [1, 2])
def test_probing_in_the_middle_of_a_search_keeps_the_optimum(threads: int) -> None:
    # probing after some nodes: the open nodes lose the killed members and are solved again
    fp = build_footstep_problem(random_stepping_stones(1, 8, robot=ROBOT), ROBOT, 8)
    plain = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=threads, bnb=NO_PROBING))
    middle = BnbSettings(probe_after=0.2, probe_budget=math.inf)
    probed = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=threads, bnb=middle))
    for res in (plain, probed):
        _assert_optimum(res, SCIP_OPTIMA_8[1, 8])
    assert probed.stats["probed_at_node"] > 1 and probed.stats["probes"] > 0
    assert probed.stats["probe_dropped"] > 0
    assert probed.objective == pytest.approx(plain.objective, rel=OBJ_RTOL)
    assert probed.x is not None and fp.problem.violation(probed.x) <= DEFAULTS.feas_tol


def test_probing_stays_within_its_budget() -> None:
    fp = build_footstep_problem(random_stepping_stones(1, 8, robot=ROBOT), ROBOT, 8)
    settings = BnbSettings(probe_after=1.0)
    res = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=1, bnb=settings))
    assert res.status is SolveStatus.OPTIMAL
    at = res.stats["probed_at_node"]
    assert at is not None, "the search ended before probing: the test checks nothing"
    for key in ("probes", "local_search_solves", "heuristic_nodes"):
        assert res.stats[key] <= settings.probe_budget * at, key
    assert res.stats["settings"] == dataclasses.asdict(settings)
    assert res.stats["probes"] > 0


@pytest.mark.parametrize(
    ("field", "value"),
    [("probe_rounds", -1), ("heur_nodes", 1.5), ("compact", 1), ("feas_tol", -1e-6),
     ("probe_budget", "inf"), ("clarabel", (("max_iter", "many"),)), ("map_depth", 0)],
)  # fmt: skip
def test_bad_bnb_settings_are_input_errors(field: str, value: object) -> None:
    from footfall.errors import InputError

    with pytest.raises(InputError, match=f"bnb.{field}"):
        BnbSettings(**{field: value})  # type: ignore[arg-type]


def test_bnb_settings_travel_with_the_options_and_serialise() -> None:
    import json

    from footfall.errors import InputError

    settings = BnbSettings(probe_budget=math.inf, clarabel={"max_iter": 50})
    assert settings.clarabel == (("max_iter", 50),)
    assert PlannerOptions(bnb=settings).solver_options().bnb is settings
    assert json.loads(json.dumps(dataclasses.asdict(settings)))["clarabel"] == [["max_iter", 50]]
    for bad in ({"probe_rounds": 0}, None):
        with pytest.raises(InputError, match="bnb"):
            SolverOptions(bnb=bad)  # type: ignore[arg-type]
        with pytest.raises(InputError, match="bnb"):
            PlannerOptions(bnb=bad)  # type: ignore[arg-type]


@pytest.mark.slow
def test_pinned_optimum_is_scips() -> None:
    """The pinned SCIP optima still belong to the model (the cheapest one, 6 s, re-solved)."""
    assert _scip_optimum(8, 0, 7) == pytest.approx(SCIP_OPTIMA_8[0, 7], rel=GAP)


#: a robot whose ankle-torque bound U_max (eq. 5.12d), not the reach, decides what is feasible:
#: on 5-region stones seed 0, N = 6 has kinematic plans but none within 5 N m; N = 7 has plans
#: whose torque reaches the bound
WEAK_ANKLE = BipedParams(n_nodes=3, u_max=5.0)


def _weak_ankle_problem(n: int):  # type: ignore[no-untyped-def]
    return build_footstep_problem(random_stepping_stones(0, 5, robot=WEAK_ANKLE), WEAK_ANKLE, n)


def test_a_condensed_point_past_the_torque_bound_is_resolved_in_full() -> None:
    """The condensed relaxation drops the torque cone (its torques are the cost-optimal ones);
    a point that breaks it is solved again with the full model, whose bound is tighter there.
    The violation is checked here from the planner's own torque indices, not the relaxation's."""
    fp = _weak_ankle_problem(7)
    structure = bnb.analyse(fp.problem)
    root = branching._root_allowed(structure)
    plain = bnb.HullRelaxation(structure, settings=BnbSettings(escalate=False)).solve(root)
    assert plain.status == "solved" and plain.x is not None and not plain.full
    torque = np.linalg.norm(plain.x[fp.u], axis=-1)  # (N, K-1)
    assert torque.max() > WEAK_ANKLE.u_max + 1e-3, "the bound does not bind: nothing to test"
    relax = bnb.HullRelaxation(structure)
    assert relax.dropped_violation(plain.x) == pytest.approx(
        torque.max() - WEAK_ANKLE.u_max, rel=1e-9
    )
    res = relax.solve(root)
    assert res.full and relax.escalations == 1
    assert res.status == "solved" and res.x is not None
    assert res.bound == pytest.approx(relax.solve(root, full=True).bound, rel=1e-9)
    assert res.bound > plain.bound
    assert np.linalg.norm(res.x[fp.u], axis=-1).max() <= WEAK_ANKLE.u_max + 1e-6


def test_torque_limited_infeasibility_is_proven_in_few_nodes() -> None:
    """SCIP, the search without re-solving in full, and the default search all find no plan;
    without the full model the search must enumerate nearly every assignment to see it."""
    fp = _weak_ankle_problem(6)
    assert not fp.problem.bounds_conflict()
    direct = solve(fp.problem, "scip", SolverOptions(time_limit=120.0))
    assert direct.status is SolveStatus.INFEASIBLE
    options = SolverOptions(time_limit=60.0)
    blind = solve(fp.problem, "bnb", dataclasses.replace(options, bnb=BnbSettings(escalate=False)))
    res = solve(fp.problem, "bnb", options)
    assert blind.status is res.status is SolveStatus.INFEASIBLE
    assert res.stats["nodes"] * 10 < blind.stats["nodes"]


@pytest.mark.parametrize("threads", [1, 2])
def test_torque_limited_optimum_is_scips(threads: int) -> None:
    fp = _weak_ankle_problem(7)
    res = solve(fp.problem, "bnb", SolverOptions(gap=GAP, threads=threads))
    _assert_optimum(res, _weak_ankle_optimum())
    assert res.x is not None and fp.problem.violation(res.x) <= DEFAULTS.feas_tol
    # the optimum uses the whole torque bound: the cone the condensed model drops binds
    assert np.linalg.norm(res.x[fp.u], axis=-1).max() == pytest.approx(WEAK_ANKLE.u_max, abs=1e-6)


@functools.cache
def _weak_ankle_optimum() -> float:
    res = solve(_weak_ankle_problem(7).problem, "scip", SolverOptions(gap=GAP, time_limit=300.0))
    assert res.status is SolveStatus.OPTIMAL
    return res.objective
