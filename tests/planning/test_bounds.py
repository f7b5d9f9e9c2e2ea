"""The reachable-set lower bound on N (planning/bounds.py): hand-checked, never above a feasible N,
and its sets contain every footstep of the planner's plans."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from footfall._geometry import (
    clip_rows,
    convex_hull,
    distance_to_convex,
    minkowski_sum,
    signed_area,
)
from footfall.errors import InputError
from footfall.planning import PlannerOptions, make_plan, plan_min_steps
from footfall.planning.bounds import (
    SLACK,
    BackwardSets,
    ForwardSets,
    bucket_bounds,
    footstep_sets,
    live_members,
    reachable_steps_bound,
)
from footfall.planning.diagnose import min_steps_lower_bound
from footfall.solvers import SolveStatus
from footfall.terrain import builtin_scene, load_scene
from tests.planning.scenes import SHORT_FLAT, TWO_STONES

#: geometry helpers agree with brute force to this [m]
GEOM_TOL = 1e-9

# --- the polygon helpers --------------------------------------------------------------------


@st.composite
def _convex(draw: st.DrawFn) -> np.ndarray:
    n = draw(st.integers(3, 10))
    pts = draw(
        st.lists(st.tuples(st.floats(-2, 2), st.floats(-2, 2)), min_size=n, max_size=n, unique=True)
    )
    hull = convex_hull(np.array(pts))
    assume(hull.shape[0] >= 3 and signed_area(hull) > 1e-3)
    return hull


def _inside(poly: np.ndarray, pts: np.ndarray, tol: float) -> bool:
    return all(distance_to_convex(p, poly) <= tol for p in pts)


@settings(max_examples=200, deadline=None)
@given(_convex(), _convex())
def test_minkowski_sum_is_the_hull_of_vertex_sums(p: np.ndarray, q: np.ndarray) -> None:
    m = minkowski_sum(p, q)
    brute = (p[:, None, :] + q[None, :, :]).reshape(-1, 2)
    # every pairwise sum is inside, and every vertex of the sum is a pairwise sum
    assert _inside(m, brute, 1e-7)
    assert all(np.min(np.linalg.norm(brute - v, axis=1)) <= 1e-7 for v in m)


@settings(max_examples=200, deadline=None)
@given(_convex(), st.floats(0, 2 * math.pi), st.floats(-1.5, 1.5))
# a cut through a vertex leaves a near-repeated vertex: its 4e-19 m edge must not make the
# polygon's inside look outside (distance_to_convex)
@example(p=np.array([[-2.0, 2.0], [1.0, 0.0], [-3.92315089e-19, 1.0]]), phi=0.0, off=0.0)
def test_clip_rows_keeps_exactly_the_part_inside(p: np.ndarray, phi: float, off: float) -> None:
    a = np.array([[math.cos(phi), math.sin(phi)]])
    cut = clip_rows(p, a, np.array([off]))
    rng = np.random.default_rng(0)
    w = rng.dirichlet(np.ones(p.shape[0]), size=300)
    samples = w @ p  # points of the polygon
    keep = samples @ a[0] <= off
    if cut.shape[0] == 0:
        assert not keep.any()
        return
    assert _inside(cut, samples[keep], 1e-7)
    assert np.all(cut @ a[0] <= off + GEOM_TOL)
    assert _inside(p, cut, 1e-7)


# --- a scene whose bound is counted by hand -------------------------------------------------

#: four 6 cm stones 0.25 m apart, alternately left and right: a step reaches the next stone
#: (0.25 m ahead, 0.2 m across, inside the reach trapezoid) but never the one after it (0.44 m
#: away at least, beyond the trapezoid's farthest vertex, 0.406 m); the start and goal floors are
#: more than 0.406 m from stones 2 and 3. So footstep i is at best on stone i, footstep 5 on the
#: goal floor, and the goal needs footsteps N - 1 = 5 and N = 6.
STONES = """
name: stones_in_a_row
description: four small stones between two floors
robot: {n_nodes: 4}
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [1.25, 0, 0], heading: 0}
regions:
  - {name: start, height: 0.0, vertices: [[-0.4, -0.4], [0.05, -0.4], [0.05, 0.4], [-0.4, 0.4]]}
  - {name: s1, height: 0.0, vertices: [[0.22, 0.07], [0.28, 0.07], [0.28, 0.13], [0.22, 0.13]]}
  - {name: s2, height: 0.0, vertices: [[0.47, -0.13], [0.53, -0.13], [0.53, -0.07], [0.47, -0.07]]}
  - {name: s3, height: 0.0, vertices: [[0.72, 0.07], [0.78, 0.07], [0.78, 0.13], [0.72, 0.13]]}
  - {name: s4, height: 0.0, vertices: [[0.97, -0.13], [1.03, -0.13], [1.03, -0.07], [0.97, -0.07]]}
  - {name: goal, height: 0.0, vertices: [[1.2, -0.4], [1.7, -0.4], [1.7, 0.4], [1.2, 0.4]]}
"""


def test_hand_counted_bound_on_stones_in_a_row() -> None:
    sc = load_scene(STONES)
    assert sc.robot.reach.radius == pytest.approx(math.hypot(0.25, 0.32))
    assert min_steps_lower_bound(sc, sc.robot) == 4  # distance alone: 1.27 m / 0.406 m
    bound = reachable_steps_bound(sc, sc.robot, PlannerOptions(), 20)
    assert bound.n_steps == 6 and not bound.exhausted
    # footstep i can only be on stone i (or behind it): the sets say so region by region
    names = sc.terrain.names
    for i, sets, _ in footstep_sets(sc, sc.robot, PlannerOptions(), 5):
        regions = {names[r] for (_, r) in sets}
        assert f"s{i}" in regions and not {f"s{k}" for k in range(i + 1, 5)} & regions
        assert ("goal" in regions) == (i >= 5)
    # the bound is tight here: the planner's smallest N is 6
    plan = plan_min_steps(sc, "kinematic", PlannerOptions(time_limit=60))
    assert plan.has_solution and plan.n_steps == 6
    assert plan.stats["tried"] == [] and plan.stats["skipped"]["to"] == 5


def test_a_goal_out_of_step_height_is_ruled_out_for_every_n() -> None:
    # the only way to the goal is up a 0.4 m block (step_height_max 0.25 m)
    text = STONES.replace("{name: goal, height: 0.0", "{name: goal, height: 0.4").replace(
        "position: [1.25, 0, 0]", "position: [1.25, 0, 0.4]"
    )
    sc = load_scene(text)
    bound = reachable_steps_bound(sc, sc.robot, PlannerOptions(), 12)
    assert bound.exhausted and bound.n_steps == 13
    plan = plan_min_steps(sc, "kinematic", n_max=12)
    assert plan.status.value == "infeasible" and not plan.has_solution
    assert plan.stats["tried"] == [] and plan.stats["skipped"]["to"] == 12
    assert "infeasible in the planner's model for N = 4..12" in plan.message


def test_n_max_below_the_distance_bound_is_bad_input() -> None:
    sc = load_scene(STONES)
    with pytest.raises(InputError, match="n_max"):
        plan_min_steps(sc, "kinematic", n_max=3)


# --- never above a feasible N; the sets hold every planned footstep -------------------------


def _check_plan_in_sets(sc, options: PlannerOptions, plan) -> None:  # type: ignore[no-untyped-def]
    """Every footstep i of ``plan`` lies in the set of its heading bucket and region."""
    lo, hi = bucket_bounds(options, float(sc.start.heading))
    names = list(sc.terrain.names)
    n = plan.n_steps
    for i, sets, goal in footstep_sets(sc, plan.robot, options, n + 1):
        if i > n:
            break
        r = names.index(plan.regions[i])
        theta = plan.headings[i]
        buckets = [b for b in range(len(lo)) if lo[b] - 1e-6 <= theta <= hi[b] + 1e-6]
        dist = min(
            (
                distance_to_convex(plan.footsteps[i, :2], sets[(b, r)])
                for b in buckets
                if (b, r) in sets
            ),
            default=math.inf,
        )
        assert dist <= SLACK, f"footstep {i} at {plan.footsteps[i]} is {dist} m outside its set"
        if i == n - 1:
            assert goal(n)


@pytest.mark.parametrize(
    ("name", "options"),
    [
        ("discrete_steps", PlannerOptions(heading_segments=16)),
        ("turn", PlannerOptions(heading_segments=16, reach_both_frames=True)),
        ("stairs_slope_gap", PlannerOptions(heading_segments=64, region_margin=0.1)),
        ("flat", PlannerOptions(heading_segments=32, swing_max=0.5)),
    ],
)
def test_builtin_bound_is_below_the_smallest_n_and_holds_its_plan(
    name: str, options: PlannerOptions
) -> None:
    """The kinematic planner's rows are the miqcqp's without the dynamics, so its smallest N is
    at most the miqcqp's: the bound must not exceed it, and N = bound - 1 must have no plan."""
    sc = builtin_scene(name)
    options = replace(options, time_limit=60.0)
    bound = reachable_steps_bound(sc, sc.robot, options, 40)
    below = make_plan(sc, "kinematic", bound.n_steps - 1, options)
    assert below.status is SolveStatus.INFEASIBLE
    plan = plan_min_steps(sc, "kinematic", options, n_max=bound.n_steps + 3)
    assert plan.has_solution and plan.n_steps >= bound.n_steps
    _check_plan_in_sets(sc, options, plan)


def test_miqcqp_plan_lies_in_the_sets() -> None:
    sc = load_scene(TWO_STONES)
    options = PlannerOptions(time_limit=60.0)
    plan = plan_min_steps(sc, "miqcqp", options)
    assert plan.has_solution
    assert plan.n_steps >= reachable_steps_bound(sc, sc.robot, options, 20).n_steps
    _check_plan_in_sets(sc, options, plan)


def _fixed(x: float) -> float:
    """``x`` rounded to what a fixed-point YAML number holds: YAML 1.1 (PyYAML) reads ``1e-07``,
    which Python prints for small floats, as a string."""
    return round(x, 6)


@st.composite
def _stones_scene(draw: st.DrawFn) -> str:
    """A start floor, one to three stones of random size, place and height, a goal floor."""
    lines = [
        "  - {name: start, height: 0.0, vertices: [[-0.4, -0.4], [0.1, -0.4], [0.1, 0.4], [-0.4, 0.4]]}"
    ]
    x, z = 0.1, 0.0
    for k in range(draw(st.integers(1, 3))):
        x0 = _fixed(x + draw(st.floats(0.05, 0.3)))
        x1 = _fixed(x0 + draw(st.floats(0.05, 0.4)))
        y0 = _fixed(draw(st.floats(-0.4, 0.1)))
        y1 = _fixed(y0 + draw(st.floats(0.08, 0.6)))
        z = round(z + draw(st.floats(-0.2, 0.2)), 3)
        lines.append(
            f"  - {{name: s{k}, height: {z}, vertices: [[{x0}, {y0}], [{x1}, {y0}], [{x1}, {y1}], "
            f"[{x0}, {y1}]]}}"
        )
        x = x1
    g0 = _fixed(x + draw(st.floats(0.05, 0.3)))
    heading = draw(st.sampled_from([0, 20, -30]))
    return (
        f"""
name: random_stones
description: random stones
robot: {{n_nodes: 3}}
start: {{left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}}
goal: {{position: [{g0 + 0.3}, 0, 0], heading_deg: {heading}}}
regions:
"""
        + "\n".join(lines)
        + f"""
  - {{name: goal, height: 0.0, vertices: [[{g0}, -0.5], [{g0 + 0.8}, -0.5], [{g0 + 0.8}, 0.5], [{g0}, 0.5]]}}
"""
    )


@settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    _stones_scene(),
    st.sampled_from([8, 16, 64]),
    st.booleans(),
    st.sampled_from([None, 0.5]),
    st.sampled_from([0.0, 0.03]),
)
def test_bound_never_exceeds_a_feasible_n_on_random_stones(
    text: str, segments: int, both: bool, swing: float | None, margin: float
) -> None:
    sc = load_scene(text)
    options = PlannerOptions(
        heading_segments=segments,
        reach_both_frames=both,
        swing_max=swing,
        region_margin=margin,
        time_limit=20.0,
    )
    bound = reachable_steps_bound(sc, sc.robot, options, 14)
    distance = min_steps_lower_bound(sc, sc.robot, swing)
    if bound.n_steps - 1 >= max(2, distance):
        # the N just below the bound: the solver must not find a plan there
        below = make_plan(sc, "kinematic", bound.n_steps - 1, options)
        assert not below.has_solution, f"bound {bound.n_steps} but N = {below.n_steps} has a plan"
    if bound.exhausted:
        return
    plan = make_plan(sc, "kinematic", bound.n_steps + 1, options)
    if plan.has_solution:
        _check_plan_in_sets(sc, options, plan)
        _check_plan_uses_live_members(sc, options, plan)


def test_n_the_bound_allows_is_proven_infeasible_before_the_miqcqp() -> None:
    # both reach frames on SHORT_FLAT: the bound allows N = 3; the live members (forward and
    # backward reachable sets) leave a footstep no position, and so do the rows without dynamics
    from footfall.planning.run import _kinematic_proof

    sc = load_scene(SHORT_FLAT)
    options = PlannerOptions(reach_both_frames=True, time_limit=60.0)
    assert reachable_steps_bound(sc, sc.robot, options, 10).n_steps == 3
    plan = plan_min_steps(sc, "miqcqp", options)
    assert plan.has_solution and plan.n_steps == 4
    (tried,) = plan.stats["tried"]
    assert tried["n_steps"] == 3 and tried["status"] == "infeasible"
    assert tried["proof"] == "reachable sets" and tried["seconds"] >= 0.0
    assert "proven infeasible: N = 3 (reachable sets)" in plan.message
    # the kinematic relaxation alone proves it too, and so does the full model
    kin = _kinematic_proof(sc, sc.robot, 3, options)
    assert kin is not None and kin.status is SolveStatus.INFEASIBLE
    assert "rows without the ALIP dynamics" in kin.message
    full = make_plan(sc, "miqcqp", 3, options)
    assert full.status is SolveStatus.INFEASIBLE


# --- live members: what each footstep of an N-step plan can use ---------------------------


def _check_plan_uses_live_members(sc, options: PlannerOptions, plan) -> None:  # type: ignore[no-untyped-def]
    """Every free footstep of ``plan`` (made without the live members) lies in a live region and
    in a live heading segment (either segment when its heading sits on a breakpoint)."""
    n = plan.n_steps
    live = live_members(sc, plan.robot, options, n)
    names = list(sc.terrain.names)
    n_seg = options.heading_segments
    width = 2.0 * math.pi / n_seg
    start = float(sc.start.heading) - math.pi
    for i in range(1, n - 1):
        assert live.regions[i, names.index(plan.regions[i])], f"footstep {i}: region not live"
        pos = (plan.headings[i] - start) / width
        candidates = {min(max(math.floor(pos + d), 0), n_seg - 1) for d in (-1e-6, 1e-6)}
        assert any(live.segments[i, seg] for seg in candidates), f"footstep {i}: segment not live"


@pytest.mark.parametrize(
    ("name", "n", "options"),
    [
        ("turn", 11, PlannerOptions(reach_both_frames=True)),
        ("discrete_steps", 13, PlannerOptions(heading_segments=16, region_margin=0.05)),
    ],
)
def test_fixing_out_dead_members_keeps_the_optimum(
    name: str, n: int, options: PlannerOptions
) -> None:
    from footfall.planning.miqcqp import plan_footsteps

    sc = builtin_scene(name)
    options = replace(options, time_limit=120.0)
    live = live_members(sc, sc.robot, options, n)
    plain = plan_footsteps(sc, None, n, options)
    pruned = plan_footsteps(sc, None, n, options, members=live)
    assert plain.status is pruned.status is SolveStatus.OPTIMAL
    assert pruned.stats["members_fixed_out"] > 0, "nothing fixed out: the test checks nothing"
    assert pruned.objective == pytest.approx(plain.objective, rel=1e-6)
    _check_plan_uses_live_members(sc, options, plain)


def test_dead_members_have_no_plan_by_scip() -> None:
    """An independent solver on the rows the live members come from (the model without the
    ALIP dynamics, where the turn has plans with 11 steps): with any sampled dead member forced
    in, SCIP proves that there is no plan."""
    from footfall.planning.miqcqp import build_footstep_problem
    from footfall.solvers import SolverOptions, solve
    from footfall.solvers.problem import fix_variables

    sc = builtin_scene("turn")
    options = PlannerOptions(heading_segments=16, reach_both_frames=True, time_limit=60.0)
    n = 11
    assert make_plan(sc, "kinematic", n, options).has_solution
    kin = build_footstep_problem(sc, sc.robot, n, options, dynamics=False)
    live = live_members(sc, sc.robot, options, n)
    dead_s = kin.segments[(kin.segments >= 0) & ~live.segments]
    dead_r = kin.regions[(kin.regions >= 0) & ~live.regions]
    assert len(dead_s) > 10 and len(dead_r) > 3
    rng = np.random.default_rng(0)
    for z in [*rng.choice(dead_s, 5, replace=False), *rng.choice(dead_r, 3, replace=False)]:
        forced = fix_variables(kin.problem, np.array([z]), np.array([1.0]))
        res = solve(forced, "scip", SolverOptions(gap=1.0, time_limit=120.0))
        assert res.status is SolveStatus.INFEASIBLE, kin.problem.names[z]


def test_shared_reachable_sets_give_the_same_bound_and_members() -> None:
    sc = builtin_scene("discrete_steps")
    options = PlannerOptions(heading_segments=16, reach_both_frames=True)
    shared = ForwardSets(sc, sc.robot, options, 30)
    bound = reachable_steps_bound(sc, sc.robot, options, 20, shared)
    assert bound == reachable_steps_bound(sc, sc.robot, options, 20)
    for n in (bound.n_steps, bound.n_steps + 2):
        a = live_members(sc, sc.robot, options, n, shared)
        b = live_members(sc, sc.robot, options, n)
        np.testing.assert_array_equal(a.segments, b.segments)
        np.testing.assert_array_equal(a.regions, b.regions)
        assert not a.segments[1 : n - 1].all() and not a.regions[1 : n - 1].all()


def test_backward_sets_shared_between_n_and_cut_short_by_a_deadline_give_the_same_members() -> None:
    """The smallest-N search keeps the backward sets of every N it tried (two chains, one per
    side of the goal foot) and may stop computing them at a deadline: the members of each N are
    those computed from scratch for it alone."""
    import time

    sc = builtin_scene("stairs_slope_gap")
    options = PlannerOptions()
    backward = BackwardSets(sc, sc.robot, options)
    with pytest.raises(TimeoutError):
        live_members(
            sc, sc.robot, options, 13, deadline=time.perf_counter() - 1.0, backward=backward
        )
    for n in (11, 12, 13, 14):
        shared = live_members(sc, sc.robot, options, n, backward=backward)
        alone = live_members(sc, sc.robot, options, n)
        np.testing.assert_array_equal(shared.segments, alone.segments)
        np.testing.assert_array_equal(shared.regions, alone.regions)
    assert {len(chain) for chain in backward.chains.values()} == {12, 13}  # levels 0..N - 2


def test_members_of_another_problem_are_bad_input() -> None:
    from footfall.planning.miqcqp import build_footstep_problem, restrict_members

    sc = load_scene(SHORT_FLAT)
    fp = build_footstep_problem(sc, sc.robot, 4)
    other = live_members(sc, sc.robot, PlannerOptions(), 5)
    with pytest.raises(InputError, match="members"):
        restrict_members(fp, other)
    for bad in ("5", 2.5, 0, -1, float("nan"), True):
        with pytest.raises(InputError, match="n_steps"):
            live_members(sc, sc.robot, PlannerOptions(), bad)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="options"):
        live_members(sc, sc.robot, "fast", 5)  # type: ignore[arg-type]
    # sets cut short by their horizon would read as footsteps with no place: refused
    short = ForwardSets(sc, sc.robot, PlannerOptions(), 3)
    with pytest.raises(InputError, match="forward"):
        live_members(sc, sc.robot, PlannerOptions(), 5, short)
    with pytest.raises(InputError, match="forward"):
        reachable_steps_bound(sc, sc.robot, PlannerOptions(), 10, short)
    mine = live_members(sc, sc.robot, PlannerOptions(), 4)
    for planner, n in (("kinematic", 4), ("miqcqp", None)):
        with pytest.raises(InputError, match="members"):
            make_plan(sc, planner, n, members=mine)
