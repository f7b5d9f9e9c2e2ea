"""Full-horizon MIQCQP planner (document 000 eq. 5.11-5.18): model structure, solutions checked by
the independent checker, infeasibility diagnosis, the checker's own ability to fail."""

from __future__ import annotations

import functools
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning import (
    FootstepProblem,
    PlannerOptions,
    build_footstep_problem,
    check_plan,
    make_plan,
    plan_footsteps,
    plan_kinematic,
    plan_reactive,
)
from footfall.solvers import SolveStatus
from footfall.terrain import builtin_scene
from footfall.terrain.scene import random_stepping_stones
from tests.conftest import VirtualClock
from tests.planning.scenes import SHORT_FLAT, SHORT_TURN, TWO_STONES, scene

#: the solver's relative gap in these tests
GAP = 1e-6
OPTS = PlannerOptions(time_limit=120.0, gap=GAP)


@pytest.fixture(scope="module")
def stones_plan():
    sc = scene(TWO_STONES)
    return sc, plan_footsteps(sc, n_steps=5, options=OPTS)


def test_dynamics_and_reset_rows_are_the_alip_matrices() -> None:
    sc = scene(SHORT_FLAT)
    fp = build_footstep_problem(sc, n_steps=3)
    alip = sc.robot.alip()
    ad, bd = alip.discretize(sc.robot.node_dt)
    a_r, b_r = alip.reset_map(sc.robot.t_ds)
    a_eq = fp.problem.a_eq.toarray()
    labels = fp.problem.eq_labels
    row = labels.index("5.12a dynamics step 1 node 2 row 3")
    np.testing.assert_allclose(a_eq[row, fp.x[1, 3]], [0, 0, 0, 1])
    np.testing.assert_allclose(-a_eq[row, fp.x[1, 2]], ad[3])
    np.testing.assert_allclose(-a_eq[row, fp.u[1, 2]], bd[3])
    row = labels.index("5.12b reset 1->2 row 2")
    np.testing.assert_allclose(-a_eq[row, fp.x[1, -1]], a_r[2])
    np.testing.assert_allclose(-a_eq[row, fp.p[2]], b_r[2])
    np.testing.assert_allclose(a_eq[row, fp.p[1]], b_r[2])
    # every torque node has exactly one cone of radius U_max
    assert len(fp.problem.cones) == 3 * (sc.robot.n_nodes - 1)
    assert {r for _, r in fp.problem.cones} == {sc.robot.u_max}


def test_plan_is_optimal_and_passes_the_independent_checker(stones_plan) -> None:
    sc, plan = stones_plan
    assert plan.status is SolveStatus.OPTIMAL
    report = check_plan(plan, sc)
    assert report.ok, report.summary()
    assert report.dynamics_error < 1e-6
    assert plan.regions[1:] == ("stone_a", "stone_b", "slope", "slope", "slope")
    # footsteps on the slope follow its plane: z = 0.1 (x - 0.85) / 0.65
    for i in (3, 4, 5):
        assert plan.footsteps[i, 2] == pytest.approx(
            0.1 * (plan.footsteps[i, 0] - 0.85) / 0.65, abs=1e-6
        )
    assert plan.gap <= GAP + 1e-12
    assert plan.bound <= plan.objective * (1 + 1e-9)


def test_objective_recomputed_from_the_plan(stones_plan) -> None:
    """Eq. (5.11) evaluated directly on the plan's arrays equals the solver's objective."""
    sc, plan = stones_plan
    w = OPTS.weights
    torque = w.torque * float(np.sum(plan.torques**2))
    th = plan.headings
    heading = w.heading * float(np.sum((th[2:] - 2 * th[1:-1] + th[:-2]) ** 2))
    steps = np.diff(plan.footsteps, axis=0)
    step = w.step * float(np.sum(steps**2 * np.array(w.step_matrix)))
    # x_goal: at rest between the final feet, relative to the last footstep
    x_goal = np.zeros(4)
    x_goal[:2] = sc.goal.position[:2] - plan.footsteps[-1, :2]
    q = w.terminal_diag(sc.robot)
    terminal = w.terminal * float(np.sum(q * (plan.final_state - x_goal) ** 2))
    assert torque + heading + step + terminal == pytest.approx(plan.objective, rel=1e-6)


def test_torque_bound_is_a_disc_not_a_box() -> None:
    """With U_max small enough to bind, both torque axes are used and the 2-norm stays <= U_max."""
    sc = scene(SHORT_TURN)
    robot = replace(sc.robot, u_max=8.0)
    plan = plan_footsteps(sc, robot, n_steps=4, options=OPTS)
    assert plan.has_solution
    norms = np.linalg.norm(plan.torques, axis=-1)
    assert norms.max() <= robot.u_max * (1 + 1e-6)
    assert check_plan(plan, sc, robot).ok
    # a box of the same size would allow |u| up to sqrt(2) U_max; the cone must bind somewhere
    assert norms.max() > 0.99 * robot.u_max


def test_turning_plan_changes_heading_within_the_rate_bound() -> None:
    sc = scene(SHORT_TURN)
    plan = plan_footsteps(sc, n_steps=4, options=OPTS)
    assert plan.status is SolveStatus.OPTIMAL
    assert np.all(np.abs(np.diff(plan.headings)) <= sc.robot.theta_max + 1e-9)
    assert plan.headings[-1] == pytest.approx(math.radians(60))
    assert check_plan(plan, sc).ok
    # reported sin/cos approximations are within the chord error of the true values
    half = math.pi / OPTS.heading_segments
    chord = 1 - math.cos(half)
    np.testing.assert_allclose(plan.sin_cos[:, 0], np.sin(plan.headings), atol=chord + 1e-9)
    np.testing.assert_allclose(plan.sin_cos[:, 1], np.cos(plan.headings), atol=chord + 1e-9)


@functools.cache
def _reach_model() -> FootstepProblem:
    """The planner's model whose reach rows the property test reads: steps 2 -> 3 (right stance)
    and 3 -> 4 (left stance), each in its stance foot's heading segments (footsteps 2..4 are free;
    the last two stand at the goal)."""
    return build_footstep_problem(scene(SHORT_TURN), n_steps=6)


@settings(max_examples=200, deadline=None)
@given(
    step=st.sampled_from([2, 3]),
    pick=st.integers(0, 15),
    frac=st.floats(0.0, 1.0),
    direction=st.floats(-math.pi, math.pi),
    reach=st.one_of(st.just(1.0), st.floats(0.0, 1.0)),
)
def test_segment_reach_rows_are_conservative(
    step: int, pick: int, frac: float, direction: float, reach: float
) -> None:
    """Any step that satisfies the planner's reach rows of a heading segment (eq. 5.12f-h, read
    from the built model) is reachable at every heading of that segment.

    Steps go from the reach trapezoid's centre (turned to the segment's middle heading) along a
    drawn direction, up to the rows' boundary (``reach`` 1, often drawn): the steps the rows
    barely allow are where rows that are not conservative let an unreachable step through."""
    fp = _reach_model()
    pr = fp.problem
    live = [ell for ell in range(fp.segments.shape[1]) if fp.segments[step, ell] >= 0]
    ell = live[pick % len(live)]
    phi_a, phi_b = float(fp.breakpoints[ell]), float(fp.breakpoints[ell + 1])
    side = fp.sides[step]
    mid = 0.5 * (phi_a + phi_b)
    turn = np.array([[math.cos(mid), -math.sin(mid)], [math.sin(mid), math.cos(mid)]])
    centre = turn @ fp.robot.reach.for_stance(side).mean(axis=0)
    # x: footstep `step` at the centre of its box, segment ell chosen, the step d still free
    here, there = fp.p[step, :2], fp.p[step + 1, :2]
    x = np.zeros(len(pr.names))
    x[here] = 0.5 * (pr.lb[here] + pr.ub[here])
    x[int(fp.segments[step, ell])] = 1.0
    prefix = f"5.12f reach {step} frame {step} segment {ell} row "
    rows = [r for r, label in enumerate(pr.le_labels) if label.startswith(prefix)]
    a_d = pr.a_le[rows][:, there].toarray()  # each row is a_d @ d + (the rest of x) <= b
    x[there] = x[here]
    slack = pr.b_le[rows] - pr.a_le[rows] @ x - a_d @ centre
    assert np.all(slack > 0)  # the centre is strictly inside
    v = np.array([math.cos(direction), math.sin(direction)])
    rate = a_d @ v
    up = rate > 1e-12  # the rows bound the trapezoid: some row stops every direction
    t_max = float(np.min(slack[up] / rate[up]))
    d = centre + reach * t_max * v
    x[there] = x[here] + d
    # rows dropped as never binding are so only inside the variable bounds
    assume(bool(np.all(pr.lb[there] <= x[there]) and np.all(x[there] <= pr.ub[there])))
    assert np.all(pr.a_le[rows] @ x <= pr.b_le[rows] + 1e-12)
    theta = phi_a + frac * (phi_b - phi_a)
    local = np.array(
        [
            math.cos(theta) * d[0] + math.sin(theta) * d[1],
            -math.sin(theta) * d[0] + math.cos(theta) * d[1],
        ]
    )
    assert fp.robot.reach.contains(local, side, tol=1e-9)


def test_too_few_steps_is_infeasible_with_a_diagnosis() -> None:
    sc = scene(TWO_STONES)
    plan = plan_footsteps(sc, n_steps=2, options=OPTS)
    assert plan.status is SolveStatus.INFEASIBLE
    assert not plan.has_solution
    assert "at least" in plan.message


def test_unreachable_goal_region_is_diagnosed() -> None:
    text = TWO_STONES.replace(
        "[[0.85, -0.4, 0.0], [1.5, -0.4, 0.1], [1.5, 0.4, 0.1], [0.85, 0.4, 0.0]]",
        "[[1.85, -0.4, 0.0], [2.5, -0.4, 0.1], [2.5, 0.4, 0.1], [1.85, 0.4, 0.0]]",
    ).replace("[1.1, 0, 0.038462]", "[2.1, 0, 0.038462]")
    sc = scene(text)
    plan = plan_footsteps(sc, n_steps=8, options=OPTS)
    assert plan.status is SolveStatus.INFEASIBLE
    assert "cannot be reached" in plan.message or "no goal region" in plan.message


def test_checker_reports_each_kind_of_violation(stones_plan) -> None:
    sc, plan = stones_plan
    bad_region = plan.footsteps.copy()
    bad_region[2, :2] += [0.0, 0.5]  # off stone_b
    report = check_plan(replace(plan, footsteps=bad_region), sc)
    assert {"region", "reach", "dynamics"} <= report.kinds()

    bad_torque = plan.torques.copy()
    bad_torque[1, 0] = [sc.robot.u_max, sc.robot.u_max]
    assert "torque" in check_plan(replace(plan, torques=bad_torque), sc).kinds()

    bad_heading = plan.headings.copy()
    bad_heading[2] += 1.0
    assert "heading_rate" in check_plan(replace(plan, headings=bad_heading), sc).kinds()

    bad_state = plan.states.copy()
    bad_state[2, 1, 3] += 0.5
    assert "dynamics" in check_plan(replace(plan, states=bad_state), sc).kinds()

    short = replace(plan, footsteps=plan.footsteps.copy())
    short.footsteps[-1, 0] += 0.05
    assert "goal" in check_plan(short, sc).kinds()


def test_time_limit_is_honest(virtual_clock: VirtualClock) -> None:
    """A plan stopped by the time limit holds its incumbent, says so, and passes the checker.

    The instance (12 random stones, N = 14) has incumbents after a few dozen nodes and needs
    thousands to prove one optimal; on the tests' virtual clock (1 ms a read) a 0.5 s limit
    falls between on any machine (a wall-clock 1.5 s limit found no incumbent under load)."""
    robot = BipedParams(n_nodes=3)
    sc = random_stepping_stones(0, 12, robot=robot)
    plan = plan_footsteps(sc, robot, 14, PlannerOptions(time_limit=0.5, gap=GAP))
    assert plan.status is SolveStatus.TIME_LIMIT
    assert plan.has_solution, plan.message
    assert plan.gap > GAP and "time limit" in plan.message
    report = check_plan(plan, sc, robot)
    assert report.ok, report.summary()


def test_kinematic_baseline_meets_geometry_and_needs_more_torque(stones_plan) -> None:
    sc, full = stones_plan
    kin = plan_kinematic(sc, n_steps=5, options=OPTS)
    assert kin.has_solution
    report = check_plan(kin, sc)
    assert report.kinds() <= {"torque"}, report.summary()
    # Same footstep count; the full-horizon plan needs no more torque effort (it optimises it).
    assert np.sum(full.torques**2) <= np.sum(kin.torques**2) * (1 + 1e-6)


def test_reactive_baseline_reaches_goal_and_passes_checker() -> None:
    sc = scene(SHORT_FLAT)
    plan = plan_reactive(sc)
    assert plan.status is SolveStatus.FEASIBLE, plan.message
    assert check_plan(plan, sc).ok


def test_reactive_baseline_comes_nearly_to_rest_on_the_goal() -> None:
    """The last step spends the stance's ankle torque on stopping: CoM speed after the final reset
    well below walking speed, CoM near the goal midpoint."""
    sc = builtin_scene("flat")
    plan = plan_reactive(sc)
    assert plan.status is SolveStatus.FEASIBLE
    mzh = sc.robot.mass * sc.robot.com_height
    speed = float(np.hypot(plan.final_state[2], plan.final_state[3])) / mzh
    com = plan.footsteps[-1, :2] + plan.final_state[:2]
    assert speed < 0.2
    assert np.linalg.norm(com - sc.goal.position[:2]) < 0.1


@pytest.mark.parametrize("name", ["discrete_steps", "stairs_slope_gap"])
def test_reactive_baseline_ends_capturable_with_a_weak_ankle(name: str) -> None:
    """With the MuJoCo biped's numbers (ankle torque bound 11.8 N m: the ZMP within 4 cm of the
    sole centre) the reactive walk must brake before the goal: one final stance cannot stop a
    0.5 m/s walk. The final state's divergent component of motion ``c + v / omega`` (computed
    here from the ALIP definitions, eq. 5.1: v_x = L_y / (m z_H), v_y = -L_x / (m z_H)) must lie
    near the midpoint of the final feet, where the robot can shift its CoM and stand. Before
    the reactive planner braked, it ended 25 cm behind (discrete_steps) and 28 cm ahead
    (stairs_slope_gap) of it, and every MuJoCo walk of the plan fell while stopping."""
    sc = builtin_scene(name)
    robot = replace(sc.robot, mass=30.1, com_height=0.6725, u_max=11.8)
    plan = plan_reactive(sc, robot)
    assert plan.status is SolveStatus.FEASIBLE, plan.message
    assert check_plan(plan, sc).ok
    x = plan.final_state
    mzh = robot.mass * robot.com_height
    omega = math.sqrt(robot.g / robot.com_height)
    dcm = plan.footsteps[-1, :2] + x[:2] + np.array([x[3], -x[2]]) / mzh / omega
    mid = 0.5 * (plan.footsteps[-1, :2] + plan.footsteps[-2, :2])
    assert np.linalg.norm(dcm - mid) < 0.04, (dcm, mid)
    assert np.linalg.norm(mid - sc.goal.position[:2]) < 1e-6


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [({"n_steps": 0}, "n_steps"), ({"n_steps": 2.5}, "n_steps"), ({"planner": "astar"}, "planner")],
)
def test_bad_arguments(kwargs: dict, field: str) -> None:
    sc = scene(SHORT_FLAT)
    args = {"planner": "miqcqp", "n_steps": 3} | kwargs
    with pytest.raises(InputError) as err:
        make_plan(sc, **args)
    assert err.value.field == field


def test_bad_options() -> None:
    with pytest.raises(InputError, match="time_limit"):
        PlannerOptions(time_limit=-1)
    with pytest.raises(InputError, match="heading_segments"):
        PlannerOptions(heading_segments=2)
    with pytest.raises(InputError, match="threads"):
        PlannerOptions(threads=0)
    with pytest.raises(InputError, match="solver"):
        PlannerOptions(solver="cplex")


def test_region_margin_keeps_footsteps_inside() -> None:
    sc = scene(TWO_STONES)
    margin = 0.05
    opts = PlannerOptions(time_limit=120.0, gap=GAP, region_margin=margin)
    plan = plan_footsteps(sc, n_steps=5, options=opts)
    assert plan.status is SolveStatus.OPTIMAL
    assert check_plan(plan, sc).ok
    for i in range(1, plan.n_steps + 1):
        a, b = sc.terrain[plan.regions[i]].halfspaces()
        assert np.max(a @ plan.footsteps[i, :2] - b) <= -margin + 1e-6
    # the same footsteps claimed with a larger margin are flagged by the checker
    assert "region" in check_plan(replace(plan, region_margin=0.2), sc).kinds()
    reactive = plan_reactive(sc, region_margin=margin)
    assert reactive.status is SolveStatus.FEASIBLE and check_plan(reactive, sc).ok


def test_reactive_step_limit_counts_the_last_step() -> None:
    """A limit equal to the steps the walk needs still reaches the goal (the limit is inclusive)."""
    sc = scene(SHORT_FLAT)
    free = plan_reactive(sc)
    exact = plan_reactive(sc, max_steps=free.n_steps)
    assert exact.status is SolveStatus.FEASIBLE and exact.n_steps == free.n_steps
    short = plan_reactive(sc, max_steps=free.n_steps - 1)
    assert short.status is SolveStatus.INCOMPLETE


def test_reach_both_frames_holds_each_step_in_both_feet_frames() -> None:
    """With ``reach_both_frames`` every step lies in the reach set seen from either foot."""
    sc = scene(SHORT_TURN)
    one = plan_footsteps(sc, n_steps=5, options=OPTS)
    both = plan_footsteps(sc, n_steps=5, options=replace(OPTS, reach_both_frames=True))
    assert one.status is SolveStatus.OPTIMAL and both.status is SolveStatus.OPTIMAL
    assert both.reach_both_frames and not one.reach_both_frames
    assert check_plan(both, sc).ok

    def outside_in_landing_frame(plan) -> list[int]:  # type: ignore[no-untyped-def]
        bad = []
        for i in range(plan.n_steps):
            d = plan.footsteps[i + 1, :2] - plan.footsteps[i, :2]
            th = plan.headings[i + 1]
            q = np.array(
                [
                    math.cos(th) * d[0] + math.sin(th) * d[1],
                    -math.sin(th) * d[0] + math.cos(th) * d[1],
                ]
            )
            if not sc.robot.reach.contains(q, plan.sides[i], tol=1e-6):
                bad.append(i + 1)
        return bad

    # the document's plan turns by moving the trailing foot beside the new stance foot
    assert outside_in_landing_frame(one)
    assert "reach" in check_plan(replace(one, reach_both_frames=True), sc).kinds()
    assert outside_in_landing_frame(both) == []
    # a restriction of the document's problem: never a better objective
    assert both.objective >= one.objective - 1e-6
    # the direct model on SCIP has the same optimum (the rows are built once, for every backend)
    direct = plan_footsteps(
        sc, n_steps=5, options=replace(OPTS, reach_both_frames=True, solver="scip")
    )
    assert direct.status is SolveStatus.OPTIMAL
    assert direct.objective == pytest.approx(both.objective, rel=1e-4)
    with pytest.raises(InputError, match="reach_both_frames"):
        PlannerOptions(reach_both_frames="yes")  # type: ignore[arg-type]
    with pytest.raises(InputError, match="reach_both_frames"):
        make_plan(sc, "reactive", options=replace(OPTS, reach_both_frames=True))


def _swings(plan, sc) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Horizontal swing of every footstep from the same foot's previous foothold [m]."""
    start = sc.start.foot(plan.sides[1])[None, :2]
    prev = np.vstack([start, plan.footsteps[:-2, :2]])
    return np.linalg.norm(plan.footsteps[1:, :2] - prev, axis=1)


def test_swing_max_bounds_every_swing_for_bnb_and_scip() -> None:
    """The swing bound (beyond the document) is built once, so both backends find the same
    optimum; the checker holds the plan to the true disc, and refuses a plan that breaks it."""
    sc = scene(SHORT_FLAT)
    free = plan_footsteps(sc, n_steps=4, options=OPTS)
    assert free.status is SolveStatus.OPTIMAL and free.swing_max is None
    longest = float(_swings(free, sc).max())
    limit = round(0.9 * longest, 3)  # binds: the document's optimum swings further
    opts = replace(OPTS, swing_max=limit)
    bnb = plan_footsteps(sc, n_steps=4, options=opts)
    direct = plan_footsteps(sc, n_steps=4, options=replace(opts, solver="scip"))
    assert bnb.status is SolveStatus.OPTIMAL and direct.status is SolveStatus.OPTIMAL
    assert bnb.swing_max == limit
    assert direct.objective == pytest.approx(bnb.objective, rel=1e-4)
    for plan in (bnb, direct):
        assert _swings(plan, sc).max() <= limit + 1e-6
        report = check_plan(plan, sc)
        assert report.ok, report.summary()
        assert "swing" in report.checked
    # a restriction of the document's problem: never a better objective
    assert bnb.objective >= free.objective - 1e-6
    # the document's plan held to the bound: the checker names the long swing
    report = check_plan(replace(free, swing_max=limit), sc)
    bad = [v for v in report.violations if v.kind == "swing"]
    assert bad and max(v.amount for v in bad) == pytest.approx(longest - limit, abs=1e-9)
    # the kinematic planner builds the same rows
    kin = plan_kinematic(sc, n_steps=4, options=opts)
    assert kin.swing_max == limit and _swings(kin, sc).max() <= limit + 1e-6


def test_swing_max_raises_the_step_lower_bound() -> None:
    # 0.6 m to the goal: with 0.35 m swings each foot needs two, so the stance (right) foot,
    # which swings at footsteps 2 and 4, needs N >= 4; N = 3 is refused before any search
    from footfall.planning.diagnose import min_steps_lower_bound

    sc = scene(SHORT_FLAT)
    assert min_steps_lower_bound(sc, sc.robot) < 4
    assert min_steps_lower_bound(sc, sc.robot, swing_max=0.35) == 4
    plan = plan_footsteps(sc, n_steps=3, options=replace(OPTS, swing_max=0.35))
    assert plan.status is SolveStatus.INFEASIBLE and "at least 4 footsteps" in plan.message


@pytest.mark.parametrize("value", [-0.1, 0.0, math.nan, math.inf, "0.5", True])
def test_swing_max_must_be_a_positive_length(value: object) -> None:
    with pytest.raises(InputError) as err:
        PlannerOptions(swing_max=value)  # type: ignore[arg-type]
    assert err.value.field == "swing_max"


def test_reactive_planner_refuses_the_swing_bound() -> None:
    sc = scene(SHORT_FLAT)
    with pytest.raises(InputError) as err:
        make_plan(sc, "reactive", options=replace(OPTS, swing_max=0.5))
    assert err.value.field == "swing_max"
