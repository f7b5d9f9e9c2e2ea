"""The heading-window search (a primal heuristic beyond the document): on a gap longer than the
forward reach, the only plans turn; the search finds one that the independent checker accepts,
and it runs only where the solve found no plan."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

import footfall.planning.miqcqp as miqcqp
from footfall.errors import InputError
from footfall.planning import PlannerOptions, build_footstep_problem, check_plan, plan_footsteps
from footfall.planning.cache import plan_key
from footfall.planning.windows import (
    heading_window_search,
    pin_headings,
    window_order,
    window_schedule,
)
from footfall.solvers import SolverResult, SolveStatus, solve
from footfall.solvers.base import SolveProgress
from tests.conftest import VirtualClock
from tests.planning.scenes import SHORT_FLAT, scene

#: two floors with a 0.35 m gap across the path; the document robot's reach trapezoid reaches
#: 0.35 m forward at its inner edge only (0.12 m to the side), so facing the goal no step crosses
TURNED_GAP = """
name: turned_gap
description: a gap longer than the forward reach, crossed only turned
robot: {n_nodes: 3}
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [1.8, 0, 0], heading: 0}
regions:
  - {name: near, height: 0.0, vertices: [[-0.5, -1], [0.9, -1], [0.9, 1], [-0.5, 1]]}
  - {name: far, height: 0.0, vertices: [[1.25, -1], [3, -1], [3, 1], [1.25, 1]]}
"""
N = 8
OPTS = PlannerOptions(time_limit=600.0, gap=1e-6)
#: a window that leaves no heading free: every footstep is pinned
NOWHERE = -100


@pytest.fixture(scope="module")
def gap():
    sc = scene(TURNED_GAP)
    return sc, build_footstep_problem(sc, None, N, OPTS)


def _solve(problem):
    return solve(problem, "bnb", OPTS.solver_options())


def test_facing_the_goal_the_gap_cannot_be_crossed(gap) -> None:
    """The search has something to find: with every heading pinned the model is infeasible,
    with them free it has plans."""
    _, fp = gap
    assert _solve(pin_headings(fp, NOWHERE, 0).problem).status is SolveStatus.INFEASIBLE
    assert _solve(fp.problem).status is SolveStatus.OPTIMAL


def test_pinning_changes_only_heading_bounds_and_segments_outside_the_window(gap) -> None:
    _, fp = gap
    centre, width = 4, 1
    pinned = pin_headings(fp, centre, width)
    seg_width = 2.0 * math.pi / OPTS.heading_segments
    changed = np.flatnonzero(
        (pinned.problem.lb != fp.problem.lb) | (pinned.problem.ub != fp.problem.ub)
    )
    allowed = set(fp.theta.tolist()) | set(fp.segments[fp.segments >= 0].tolist())
    assert set(changed.tolist()) <= allowed
    for i in range(1, N + 1):
        t = int(fp.theta[i])
        lo, hi = pinned.problem.lb[t], pinned.problem.ub[t]
        if abs(i - centre) <= width:  # the window keeps the model's bounds
            assert (lo, hi) == (fp.problem.lb[t], fp.problem.ub[t])
        else:  # start and goal heading 0: the band is a quarter segment either side
            assert lo >= -0.25 * seg_width - 1e-12 and hi <= 0.25 * seg_width + 1e-12
        for ell, z in enumerate(fp.segments[i]):
            if z < 0:
                continue
            a, b = fp.breakpoints[ell], fp.breakpoints[ell + 1]
            meets = b >= lo - 1e-12 and a <= hi + 1e-12
            assert (pinned.problem.ub[z] == 0.0) == (not meets) or fp.problem.ub[z] == 0.0


def _plan_of(fp, found):
    """The search's point as a plan (for the independent checker)."""
    return miqcqp.extract_plan(
        fp,
        found.x,
        status=SolveStatus.TIME_LIMIT,
        objective=found.objective,
        bound=math.nan,
        gap=math.inf,
        solve_time=found.seconds,
        solver="bnb",
        stats={},
    )


def test_the_search_finds_a_turned_plan_the_checker_accepts(gap) -> None:
    sc, fp = gap
    found = heading_window_search(fp, sc, OPTS, 600.0)
    assert found is not None and found.feasible >= 1
    plan = _plan_of(fp, found)
    report = check_plan(plan, sc)  # the independent checker, not the solver's rows
    assert report.ok, report.summary()
    # the crossing step is turned (more than a segment) and only the window turns
    seg_width = 2.0 * math.pi / OPTS.heading_segments
    turned = np.flatnonzero(np.abs(plan.headings) > 0.25 * seg_width + 1e-9)
    assert len(turned) > 0
    assert np.all(np.abs(turned - found.centre) <= found.width)
    # no plan of the whole model is better than the optimum the full solve proves
    best = _solve(fp.problem)
    assert found.objective >= best.objective * (1.0 - 1e-6)


def test_windows_are_tried_nearest_the_hole_first() -> None:
    """Hand count: the hole spans 0.9..1.25 m of the 1.8 m line, fractions 0.5..0.694; footstep
    k sits at k / 7: k = 4 (0.571) is in it, k = 5 (0.714) 0.020 away, k = 3 (0.429) 0.071, k = 2
    (0.286) 0.214. Without a hole: from the middle (0.5) outward, ties to the lower k."""
    assert window_order(scene(TURNED_GAP), N, 1) == [4, 5, 3, 2]
    assert window_order(scene(TURNED_GAP), N, 2) == [4, 3]
    assert window_order(scene(SHORT_FLAT), N, 1) == [3, 4, 2, 5]


def test_nothing_found_when_no_window_has_a_plan() -> None:
    """N = 6 is too short to cross at any heading: every window is infeasible."""
    sc = scene(TURNED_GAP)
    fp = build_footstep_problem(sc, None, 6, OPTS)
    assert heading_window_search(fp, sc, OPTS, 600.0) is None


def test_the_search_stops_at_its_time(gap, virtual_clock: VirtualClock) -> None:
    sc, fp = gap
    assert heading_window_search(fp, sc, OPTS, 0.0) is None


def _no_plan_solve(monkeypatch: pytest.MonkeyPatch, bound: float) -> list[int]:
    """The planner's main solve replaced by one that ends at its time limit with no plan (as the
    branch and bound does on the G1's stairs_slope_gap); the window solves stay real."""
    calls: list[int] = []

    def stopped(problem, backend, options):
        calls.append(problem.n)
        return SolverResult(
            SolveStatus.TIME_LIMIT, None, math.nan, bound, math.inf, options.time_limit, backend
        )

    monkeypatch.setattr(miqcqp, "solve", stopped)
    return calls


def test_a_solve_without_a_plan_hands_over_to_the_search(
    gap, monkeypatch: pytest.MonkeyPatch
) -> None:
    sc, _ = gap
    calls = _no_plan_solve(monkeypatch, bound=1.0)
    plan = plan_footsteps(sc, n_steps=N, options=OPTS)
    assert len(calls) == 1
    assert plan.status is SolveStatus.TIME_LIMIT and plan.has_solution
    assert "heading-window search" in plan.message
    # the gap is against the solve's bound, which holds for the whole model
    assert plan.bound == 1.0
    assert plan.gap == pytest.approx((plan.objective - 1.0) / 1.0)
    assert plan.stats["heading_windows"]["found"] is True
    assert check_plan(plan, sc).ok


def test_without_the_search_a_solve_without_a_plan_says_so(
    gap, monkeypatch: pytest.MonkeyPatch
) -> None:
    sc, _ = gap
    _no_plan_solve(monkeypatch, bound=1.0)
    plan = plan_footsteps(sc, n_steps=N, options=replace(OPTS, heading_windows=0))
    assert not plan.has_solution
    assert "no feasible plan found" in plan.message
    assert "heading-window" not in plan.message


def test_a_search_that_finds_nothing_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    sc = scene(TURNED_GAP)
    _no_plan_solve(monkeypatch, bound=math.nan)
    plan = plan_footsteps(sc, n_steps=6, options=OPTS)
    assert not plan.has_solution and plan.status is SolveStatus.TIME_LIMIT
    assert "nor did the heading-window search" in plan.message


@pytest.mark.parametrize("value", [-1, 1.5, True, "2", None])
def test_heading_windows_must_be_a_count(value: object) -> None:
    with pytest.raises(InputError, match="heading_windows"):
        PlannerOptions(heading_windows=value)  # type: ignore[arg-type]


def test_the_default_leaves_cached_plans_keys_unchanged() -> None:
    """Plans cached before the option existed keep their key at its default (the search never
    changes a plan the solve found, and only plans are cached); another value gets its own."""
    sc = scene(SHORT_FLAT)
    default = plan_key(sc, "miqcqp", 4, PlannerOptions())
    assert plan_key(sc, "miqcqp", 4, PlannerOptions(heading_windows=2)) == default
    assert plan_key(sc, "miqcqp", 4, PlannerOptions(heading_windows=0)) != default


def test_progress_goes_on_from_the_solve_with_its_bound(
    gap, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The window solves report as one search that continues the unrestricted solve: nodes and
    seconds counted on, the unrestricted bound kept (a restriction's bound is not the model's)."""
    import footfall.planning.windows as windows

    sc, fp = gap
    real = windows.solve

    def reporting(problem, backend, options):  # each window solve reports once, then solves
        options.progress(SolveProgress(nodes=5, seconds=0.1, incumbent=9.0, bound=8.0, gap=0.1))
        return real(problem, backend, replace(options, progress=None))

    monkeypatch.setattr(windows, "solve", reporting)
    heard: list[SolveProgress] = []
    after = SolveProgress(nodes=100, seconds=60.0, incumbent=None, bound=1.0, gap=math.inf)
    found = heading_window_search(fp, sc, OPTS, 600.0, heard.append, after)
    assert found is not None and len(heard) == found.tried
    first = heard[0]
    assert first.nodes == 105 and first.seconds >= 60.0
    assert first.bound == 1.0 and first.incumbent == 9.0 and first.gap == pytest.approx(8.0)
    for later in heard[1:]:  # once a window has a plan, the best plan so far is the incumbent
        assert later.bound == 1.0 and later.nodes > 105
        assert later.incumbent is not None and later.incumbent <= 9.0


def test_the_walks_plans_take_the_option(monkeypatch: pytest.MonkeyPatch) -> None:
    """``plan_for_walk(heading_windows=0)`` reaches the planner's options (``footfall walk
    --heading-windows``), so a walk's planning can be kept to its time limit."""
    import footfall.sim.biped.plans as plans

    seen: list[PlannerOptions] = []

    def record(scene, planner, n_steps, options, robot, cache, monitor):
        seen.append(options)
        raise RuntimeError("stop here")

    monkeypatch.setattr(plans, "cached_plan", record)
    with pytest.raises(RuntimeError, match="stop here"):
        plans.plan_for_walk(scene(SHORT_FLAT), "miqcqp", 4, 60.0, heading_windows=0)
    assert seen[0].heading_windows == 0


def test_windows_widen_when_none_has_a_plan() -> None:
    """Hand count, N = 21 (free footsteps 1..19): width 2 has centres 3..17 (15 windows), width 4
    centres 5..15 (11), width 8 centres 9..11 (3); width 16 would free all 19 (2 x 16 + 1 >= 19),
    the unrestricted model, so it is not tried."""
    sched = window_schedule(scene(TURNED_GAP), 21, 2)
    widths = [w for w, _ in sched]
    assert widths == [2] * 15 + [4] * 11 + [8] * 3
    for w in (2, 4, 8):
        assert [k for ww, k in sched if ww == w] == window_order(scene(TURNED_GAP), 21, w)
    # a model too short for any window still gets its one window
    assert window_schedule(scene(TURNED_GAP), 6, 2) == [(2, 3)]


def test_the_search_widens_until_a_window_has_a_plan(gap, monkeypatch: pytest.MonkeyPatch) -> None:
    """Narrow windows made plan-less (an injected solver refuses width 1): the search goes on to
    width 2 and returns its plan, and tries no width beyond it."""
    import footfall.planning.windows as windows

    sc, fp = gap
    real, widths = windows.solve, []
    pinned_at = windows.pin_headings

    def pin(fp_, centre, width):
        widths.append(width)
        return pinned_at(fp_, centre, width)

    def narrow_fails(problem, backend, options):
        if widths[-1] == 1:
            return SolverResult(
                SolveStatus.INFEASIBLE, None, math.nan, math.nan, math.inf, 0.0, backend
            )
        return real(problem, backend, options)

    monkeypatch.setattr(windows, "pin_headings", pin)
    monkeypatch.setattr(windows, "solve", narrow_fails)
    found = heading_window_search(fp, sc, replace(OPTS, heading_windows=1), 600.0)
    assert found is not None and found.width == 2
    assert set(widths) == {1, 2} and widths == sorted(widths)
    assert check_plan(_plan_of(fp, found), sc).ok


def test_a_plan_after_a_solve_without_a_bound_claims_no_gap(
    gap, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A solve stopped before it had any bound (nan): the window plan's gap is inf, not nan."""
    sc, _ = gap
    _no_plan_solve(monkeypatch, bound=math.nan)
    plan = plan_footsteps(sc, n_steps=N, options=OPTS)
    assert plan.has_solution and plan.gap == math.inf
    assert check_plan(plan, sc).ok


@pytest.mark.parametrize("command", ["plan", "walk"])
def test_the_command_lines_default_is_the_options(command: str) -> None:
    import inspect

    from footfall.cli import planning, simulation

    fn = planning.plan if command == "plan" else simulation.walk_cmd
    default = inspect.signature(fn).parameters["heading_windows"].default.default
    assert default == PlannerOptions.heading_windows
