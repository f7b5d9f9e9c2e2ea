"""The short-horizon footstep MIQP (:mod:`footfall.planning.horizon`): solutions checked against
their constraints and an ALIP integrated by ``solve_ivp``, optima against SCIP on the same problem
written independently (:func:`horizon_problem`), the warm start, the statuses, input errors, the
benchmark and its command."""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from footfall._io import json_ready
from footfall.errors import InputError
from footfall.experiments.bench_horizon import (
    _pushed_state,
    bench_horizon,
    bench_to_dict,
    format_horizon_table,
    summary_rows,
)
from footfall.models.biped import BipedParams, Side
from footfall.planning.horizon import (
    HorizonInput,
    HorizonOptions,
    HorizonPlanner,
    HorizonSolution,
    horizon_input,
    torque_facets,
)
from footfall.planning.horizon_model import horizon_problem
from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.solvers import SolverOptions, SolveStatus, solve
from footfall.terrain import Scene, builtin_scene, load_scene
from tests.cli import error_line, footfall
from tests.conftest import IVP_ATOL, IVP_RTOL

#: relative tolerance of the checker's recomputed final state and objective
CHECK_RTOL = 1e-6
#: relative optimality gap of the planner when compared with SCIP (tighter than the default)
TIGHT_GAP = 1e-6
#: SCIP's options on horizon_problem
SCIP = SolverOptions(time_limit=30, gap=1e-6)

# two tiny pads 1 m apart (farther than any step) and the goal pad 5 m ahead: a left foot on
# pad_left has nowhere to put the right foot
FAR_PADS = """
name: far_pads
description: two tiny pads a metre apart and a goal pad 5 m ahead
start: {left: [0, 0.5, 0], right: [0, -0.5, 0], heading: 0, stance: left}
goal: {position: [5.0, 0, 0], heading: 0}
regions:
  - {name: pad_left, height: 0.0, vertices: [[-0.03, 0.47], [0.03, 0.47], [0.03, 0.53], [-0.03, 0.53]]}
  - {name: pad_right, height: 0.0, vertices: [[-0.03, -0.53], [0.03, -0.53], [0.03, -0.47], [-0.03, -0.47]]}
  - {name: far, height: 0.0, vertices: [[4.5, -0.5], [5.5, -0.5], [5.5, 0.5], [4.5, 0.5]]}
"""


Rhs = Callable[[float, np.ndarray], np.ndarray]
Displacement = Callable[[float], np.ndarray]
Walks = dict[str, tuple[Scene, FootstepPlan]]
Tick = tuple[HorizonPlanner, HorizonInput, HorizonSolution]


# --------------------------------------------------------------------------- independent checker
def _rot(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def _alip_rhs(robot: BipedParams, u: np.ndarray, d_of_t: Displacement | None = None) -> Rhs:
    """ALIP about the stance contact (eq. 5.1-5.4): x' = L_y / (m z_H), y' = -L_x / (m z_H),
    L_x' = -m g (y - d_y) + u_x, L_y' = m g (x - d_x) + u_y, where ``d(t)`` is how far the
    contact has moved from the point the state is measured from (zero in single support)."""
    m, zh, g = robot.mass, robot.com_height, robot.g

    def rhs(t: float, s: np.ndarray) -> np.ndarray:
        d = np.zeros(2) if d_of_t is None else d_of_t(t)
        return np.array(
            [
                s[3] / (m * zh),
                -s[2] / (m * zh),
                -m * g * (s[1] - d[1]) + u[0],
                m * g * (s[0] - d[0]) + u[1],
            ]
        )

    return rhs


def _integrate(rhs: Rhs, x0: np.ndarray, duration: float) -> np.ndarray:
    out = solve_ivp(rhs, (0.0, duration), x0, method="DOP853", rtol=IVP_RTOL, atol=IVP_ATOL)
    assert out.success, out.message
    return np.asarray(out.y[:, -1])


def simulate(
    robot: BipedParams, inp: HorizonInput, footsteps: np.ndarray, torques: np.ndarray
) -> np.ndarray:
    """x_H from ``inp.alip_state``: H single supports with piecewise-constant torque (the first
    one's K - 1 blocks last time_left / (K - 1), later ones node_dt), each followed by a double
    support in which the contact point moves linearly from p_j to p_{j+1} over T_ds, after which
    the CoM position is re-expressed relative to p_{j+1} (the reset map, integrated here)."""
    blocks = robot.n_nodes - 1
    x = np.array(inp.alip_state, dtype=float)
    prev = np.array(inp.stance_foot, dtype=float)
    for j, p in enumerate(footsteps):
        dt = inp.time_left / blocks if j == 0 else robot.node_dt
        for b in range(blocks):
            x = _integrate(_alip_rhs(robot, torques[j, b]), x, dt)
        delta = (p - prev)[:2]

        def ramp(t: float, delta: np.ndarray = delta) -> np.ndarray:
            return delta * t / robot.t_ds

        x = _integrate(_alip_rhs(robot, np.zeros(2), ramp), x, robot.t_ds)
        x[:2] -= delta
        prev = p
    return x


def check_solution(planner: HorizonPlanner, inp: HorizonInput, sol: HorizonSolution) -> list[str]:
    """Every way ``sol`` breaks the problem of the module docstring (empty: none). Shares no code
    with the solver: the dynamics are integrated, the constraints and the cost written out."""
    robot, opt = planner.robot, planner.options
    h, blocks = planner.h, robot.n_nodes - 1
    bad: list[str] = []
    steps, torques = np.asarray(sol.footsteps), np.asarray(sol.torques)
    if steps.shape != (h, 3) or torques.shape != (h, blocks, 2) or len(sol.regions) != h:
        return [f"shapes {steps.shape} {torques.shape} {len(sol.regions)}"]
    x_h = simulate(robot, inp, steps, torques)
    if not np.allclose(x_h, sol.final_state, rtol=CHECK_RTOL, atol=1e-9):
        bad.append(f"final state {sol.final_state} but the ALIP gives {x_h}")
    side = Side(inp.stance)
    prev = np.asarray(inp.stance_foot, dtype=float)
    for j in range(h):
        p = steps[j]
        region = planner.terrain[sol.regions[j]]
        if not region.contains(p, tol=1e-6):
            bad.append(f"footstep {j + 1} {p} is not in {sol.regions[j]}")
        q = _rot(float(inp.headings[j])).T @ (p - prev)[:2]
        if not robot.reach.contains(q, side):
            bad.append(f"footstep {j + 1}: step {q} out of reach of the {side.value} foot")
        if abs(p[2] - prev[2]) > robot.step_height_max + 1e-9:
            bad.append(f"footstep {j + 1}: height change {p[2] - prev[2]}")
        side = Side.RIGHT if side == Side.LEFT else Side.LEFT
        prev = p
    c8 = math.cos(math.pi / 8)
    normals = np.array(
        [[math.cos(2 * math.pi * k / 8), math.sin(2 * math.pi * k / 8)] for k in range(8)]
    )
    # the torque scaled to the unit disc: u / U_max for the ball (its octagon in the world
    # frame), (v_x / U_x, v_y / U_y) of v = R^T u in stance j's frame for an ellipse
    for j in range(h):
        for b in range(blocks):
            u = torques[j, b]
            if opt.torque_limits is None:
                scaled = u / robot.u_max
            else:
                v = _rot(float(inp.headings[j])).T @ u
                scaled = v / np.asarray(opt.torque_limits)
            if np.linalg.norm(scaled) > 1.0 + 1e-9:
                bad.append(f"torque {j},{b} {u} beyond U_max (or the torque ellipse)")
            if np.any(normals @ scaled > c8 + 1e-9):
                bad.append(f"torque {j},{b} {u} outside the octagon")
    w = opt.weights
    cost = 0.0
    for j in range(h):
        dt = inp.time_left / blocks if j == 0 else robot.node_dt
        cost += w.torque * dt / robot.node_dt * float(np.sum(torques[j] ** 2))
    err = x_h - np.asarray(inp.state_ref)
    cost += w.terminal * float(np.sum(np.asarray(w.terminal_diag(robot)) * err**2))
    prev = np.asarray(inp.stance_foot, dtype=float)
    for j in range(h):
        d = steps[j] - prev
        cost += w.step * float(np.sum(np.asarray(w.step_matrix) * d**2))
        cost += opt.track * float(np.sum((steps[j] - inp.footsteps_ref[j]) ** 2))
        prev = steps[j]
    if not math.isclose(cost, sol.objective, rel_tol=CHECK_RTOL, abs_tol=1e-9):
        bad.append(f"objective {sol.objective} but the cost of the solution is {cost}")
    return bad


# --------------------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def walks() -> Walks:
    """Scene and reactive plan of each scene the tests walk along (a plan takes ~1 s)."""
    out = {}
    for name in ("narrow_stones_gap", "discrete_steps"):
        scene = builtin_scene(name)
        plan = plan_reactive(scene)
        assert plan.reaches_goal
        out[name] = (scene, plan)
    return out


def _tick(plan: FootstepPlan, step: int, t: float, dv: tuple[float, float]) -> HorizonInput:
    x = _pushed_state(plan, step, t, np.array(dv))
    return horizon_input(plan, step, plan.robot.t_ss - t, x)


@pytest.fixture(scope="module")
def stones_tick(walks: Walks) -> Tick:
    """narrow_stones_gap standing on footstep 2, 0.1 s into the step after a push: its planner
    (default options), input and optimal cold solution."""
    scene, plan = walks["narrow_stones_gap"]
    planner = HorizonPlanner(scene, plan.robot)
    inp = _tick(plan, 2, 0.1, (0.2, -0.1))
    sol = planner.solve(inp)
    assert sol.status == "optimal"
    return planner, inp, sol


# --------------------------------------------------------------------------- the checker itself
def test_pushed_state_is_the_integrated_alip(walks: Walks) -> None:
    """The benchmark's measured state: the plan's, velocity changed by dv, integrated with the
    plan's torque blocks (a partial last block)."""
    _, plan = walks["narrow_stones_gap"]
    rb = plan.robot
    dv = np.array([0.25, -0.1])
    step, t = 3, 0.25  # 2.5 blocks
    x = plan.states[step, 0].copy()
    x[2] += -rb.mass * rb.com_height * dv[1]
    x[3] += rb.mass * rb.com_height * dv[0]
    for blk, dur in ((0, 0.1), (1, 0.1), (2, 0.05)):
        x = _integrate(_alip_rhs(rb, plan.torques[step, blk]), x, dur)
    assert _pushed_state(plan, step, t, dv) == pytest.approx(x, rel=1e-8, abs=1e-9)
    assert _pushed_state(plan, step, 0.0, np.zeros(2)) == pytest.approx(plan.states[step, 0])


@pytest.mark.parametrize("name", ["narrow_stones_gap", "discrete_steps"])
def test_checker_alip_replays_the_plan(walks: Walks, name: str) -> None:
    """The checker's integration, fed the full-horizon plan's footsteps and torques from a state
    of the plan, lands on the plan's state three steps later (eq. 5.12a-b, another module)."""
    _, plan = walks[name]
    for step in (1, plan.n_steps - 3):
        inp = _tick(plan, step, 0.0, (0.0, 0.0))
        x = simulate(
            plan.robot, inp, plan.footsteps[step + 1 : step + 4], plan.torques[step : step + 3]
        )
        assert x == pytest.approx(inp.state_ref, rel=1e-7, abs=1e-9)


def test_checker_rejects_tampered_solutions(stones_tick: Tick) -> None:
    planner, inp, sol = stones_tick
    assert check_solution(planner, inp, sol) == []
    moved = sol.footsteps.copy()
    moved[1, 0] += 0.01
    assert any(
        "final state" in v for v in check_solution(planner, inp, replace(sol, footsteps=moved))
    )
    far = sol.footsteps.copy()
    far[0, 1] += 1.0
    found = " ".join(check_solution(planner, inp, replace(sol, footsteps=far)))
    assert "out of reach" in found and "is not in" in found
    big = sol.torques.copy()
    big[0, 0] = [planner.robot.u_max * 0.99, 0.0]  # in the ball, outside the octagon
    found = " ".join(check_solution(planner, inp, replace(sol, torques=big)))
    assert "octagon" in found and "beyond" not in found
    assert any(
        "objective" in v
        for v in check_solution(planner, inp, replace(sol, objective=sol.objective * 1.001))
    )
    other = tuple(reversed(sol.regions))
    assert any("is not in" in v for v in check_solution(planner, inp, replace(sol, regions=other)))


# --------------------------------------------------------------------------- optimality vs SCIP
TICKS = [
    # scene, footstep stood on, time into the step [s], push dv [m/s]
    ("narrow_stones_gap", 0, 0.0, (0.25, 0.1)),
    ("narrow_stones_gap", 4, 0.15, (-0.1, 0.3)),
    ("narrow_stones_gap", 7, 0.3, (0.2, -0.2)),  # last window: the reference is the final state
    ("discrete_steps", 3, 0.05, (0.3, 0.0)),
    ("discrete_steps", 9, 0.25, (0.1, -0.15)),
]


@pytest.mark.parametrize(("name", "step", "t", "dv"), TICKS)
def test_pushed_ticks_are_optimal_feasible_and_agree_with_scip(
    walks: Walks, name: str, step: int, t: float, dv: tuple[float, float]
) -> None:
    scene, plan = walks[name]
    planner = HorizonPlanner(scene, plan.robot, HorizonOptions(gap=TIGHT_GAP))
    inp = _tick(plan, step, t, dv)
    sol = planner.solve(inp)
    assert sol.status == "optimal", sol.message
    assert sol.gap <= TIGHT_GAP
    assert check_solution(planner, inp, sol) == []
    res = solve(horizon_problem(planner, inp), "scip", SCIP)
    assert res.status == SolveStatus.OPTIMAL
    # the true optimum lies in [SCIP's bound, SCIP's objective]; ours is within our gap of it
    assert sol.objective <= res.objective * (1 + TIGHT_GAP) + 1e-9
    assert sol.objective >= res.bound - 1e-6 * abs(res.bound)
    assert sol.bound <= res.objective * (1 + 1e-6)


# --------------------------------------------------------------------------- torque ellipse
#: a sole-shaped torque set: the ball's roll torque, 2.5 times its pitch torque (the G1's sole
#: gives 7.85 and 22.8 N m)
ELLIPSE_SHAPE = (1.0, 2.5)


@pytest.mark.parametrize("heading", [0.0, 0.7, -2.1])
@pytest.mark.parametrize("limits", [None, (2.0, 5.0), (6.0, 1.5)])
def test_torque_facets_are_an_octagon_inscribed_in_the_torque_set(
    heading: float, limits: tuple[float, float] | None
) -> None:
    """Each vertex of the facets' polygon (two consecutive facet lines intersected) lies on the
    ball of radius U_max, or on the ellipse in the stance frame; each facet's middle too, scaled
    by 1 / cos(pi / 8); opposite facets are negated."""
    u_max = 3.0
    normals, bounds = torque_facets(u_max, limits, heading)
    assert normals.shape == (8, 2) and bounds.shape == (8,)
    assert np.allclose(normals[4:], -normals[:4]) and np.allclose(bounds[4:], bounds[:4])
    semi = np.array([u_max, u_max]) if limits is None else np.array(limits)
    c, s_ = math.cos(heading), math.sin(heading)
    to_stance = np.array([[c, s_], [-s_, c]])  # R(heading)^T
    for k in range(8):
        a = np.vstack([normals[k], normals[(k + 1) % 8]])
        vertex = np.linalg.solve(a, np.array([bounds[k], bounds[(k + 1) % 8]]))
        v = to_stance @ vertex
        assert math.hypot(v[0] / semi[0], v[1] / semi[1]) == pytest.approx(1.0, rel=1e-12)
    # the set's support in each facet's direction (its boundary sampled densely, in the world
    # frame) is the facet's bound over cos(pi / 8): the facet is the set's tangent moved in
    t = np.linspace(0.0, 2.0 * math.pi, 20001)
    boundary = np.column_stack([semi[0] * np.cos(t), semi[1] * np.sin(t)]) @ to_stance
    support = np.max(boundary @ normals.T, axis=0)
    assert support == pytest.approx(bounds / math.cos(math.pi / 8), rel=1e-6)


@pytest.mark.parametrize(("name", "step", "t", "dv"), [TICKS[1], TICKS[3]])
def test_torque_ellipse_ticks_agree_with_scip_and_cost_no_more(
    walks: Walks, name: str, step: int, t: float, dv: tuple[float, float]
) -> None:
    """With the walker's torque ellipse (``HorizonOptions.torque_limits``) a pushed tick is
    optimal, feasible for the ellipse's octagon in every stance frame (the checker), agrees with
    SCIP on :func:`horizon_problem`, and costs no more than with the ball: the ellipse holds the
    ball, so the problem only gains torques."""
    scene, plan = walks[name]
    u = plan.robot.u_max
    limits = (ELLIPSE_SHAPE[0] * u, ELLIPSE_SHAPE[1] * u)
    planner = HorizonPlanner(scene, plan.robot, HorizonOptions(gap=TIGHT_GAP, torque_limits=limits))
    ball = HorizonPlanner(scene, plan.robot, HorizonOptions(gap=TIGHT_GAP))
    inp = _tick(plan, step, t, dv)
    sol, sol_ball = planner.solve(inp), ball.solve(inp)
    assert sol.status == sol_ball.status == "optimal", sol.message
    assert check_solution(planner, inp, sol) == []
    assert sol.objective <= sol_ball.objective * (1 + TIGHT_GAP) + 1e-9
    res = solve(horizon_problem(planner, inp), "scip", SCIP)
    assert res.status == SolveStatus.OPTIMAL
    assert sol.objective <= res.objective * (1 + TIGHT_GAP) + 1e-9
    assert sol.objective >= res.bound - 1e-6 * abs(res.bound)


def test_torque_ellipse_lets_the_pitch_torque_exceed_the_ball(stones_tick: Tick) -> None:
    """A torque the ball's octagon refuses (pitch 1.5 U_max) passes the checker with the
    ellipse's, and one beyond the ellipse's pitch semi-axis is refused."""
    planner, inp, sol = stones_tick
    u = planner.robot.u_max
    limits = (ELLIPSE_SHAPE[0] * u, ELLIPSE_SHAPE[1] * u)
    wide = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(torque_limits=limits))
    pitch = _rot(float(inp.headings[0])) @ np.array([0.0, 1.5 * u])
    big = sol.torques.copy()
    big[0, 0] = pitch
    assert any("octagon" in v for v in check_solution(planner, inp, replace(sol, torques=big)))
    assert not any(
        "octagon" in v or "beyond" in v
        for v in check_solution(wide, inp, replace(sol, torques=big))
    )
    big[0, 0] = _rot(float(inp.headings[0])) @ np.array([0.0, 2.6 * u])
    assert any("beyond" in v for v in check_solution(wide, inp, replace(sol, torques=big)))


# --------------------------------------------------------------------------- warm start
def test_warm_start_never_changes_the_optimum(stones_tick: Tick) -> None:
    planner, inp, cold = stones_tick
    gap = planner.options.gap

    def same(a: float, b: float) -> bool:
        return abs(a - b) <= gap * max(abs(a), abs(b)) + 1e-12

    best = planner.solve(inp, warm=cold.regions)
    assert best.status == "optimal" and best.warm_used
    assert same(best.objective, cold.objective)

    # a feasible but worse leaf (stepping back onto the start pad) is the first incumbent only
    # (the root is solved first, then the warm leaf: two QPs)
    worse = ("start_pad", "start_pad", "start_pad")
    assert worse != cold.regions
    leaf = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(node_limit=2))
    first = leaf.solve(inp, warm=worse)
    assert first.warm_used and first.regions == worse
    assert first.objective > cold.objective * (1 + gap)  # truly suboptimal
    sol = planner.solve(inp, warm=worse)
    assert sol.status == "optimal" and sol.warm_used
    assert same(sol.objective, cold.objective)
    assert sol.regions == cold.regions

    # an infeasible leaf among the candidates (stone2 then back to start_pad), and a leaf out of
    # reach (goal_pad first): not used, same optimum
    for bad in (("stone2", "start_pad", "start_pad"), ("goal_pad", "goal_pad", "goal_pad")):
        sol = planner.solve(inp, warm=bad)
        assert sol.status == "optimal" and not sol.warm_used, bad
        assert same(sol.objective, cold.objective)
    for s in (best, sol):
        assert check_solution(planner, inp, s) == []


def test_next_regions_shift_after_a_step(stones_tick: Tick) -> None:
    _, _, sol = stones_tick
    abc = replace(sol, regions=("a", "b", "c"))
    assert abc.next_regions(stepped=False) == ("a", "b", "c")
    assert abc.next_regions(stepped=True) == ("b", "c", "c")
    assert replace(sol, regions=("a",)).next_regions(stepped=True) == ("a",)
    assert sol.next_regions(stepped=True) == (*sol.regions[1:], sol.regions[-1])


# --------------------------------------------------------------------------- infeasible, limits
def _far_input(foot: list[float]) -> HorizonInput:
    return HorizonInput(
        stance=Side.LEFT,
        stance_foot=np.array(foot),
        alip_state=np.zeros(4),
        time_left=0.4,
        headings=np.zeros(4),
        footsteps_ref=np.array([[0.2, 0.3, 0.0], [0.4, 0.5, 0.0], [0.6, 0.3, 0.0]]),
        state_ref=np.zeros(4),
    )


@pytest.mark.parametrize(
    ("foot", "nodes"),
    [
        ([0.0, 0.5, 0.0], 1),  # on pad_left: the root QP is infeasible (daqp proves it)
        ([2.5, 0.0, 0.0], 0),  # no region within reach at all: answered before any QP
    ],
)
def test_no_region_within_reach_is_infeasible(foot: list[float], nodes: int) -> None:
    scene = load_scene(FAR_PADS)
    planner = HorizonPlanner(scene)
    inp = _far_input(foot)
    sol = planner.solve(inp)
    assert sol.status == "infeasible" and not sol.has_solution
    assert sol.footsteps.shape == (0, 3) and sol.regions == ()
    assert math.isnan(sol.objective) and sol.bound == math.inf and sol.gap == math.inf
    assert sol.nodes == nodes
    res = solve(horizon_problem(planner, inp), "scip", SCIP)
    assert res.status == SolveStatus.INFEASIBLE


def test_node_limit_is_not_optimal_and_reports_an_honest_gap(stones_tick: Tick) -> None:
    planner, inp, cold = stones_tick
    one = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(node_limit=1))
    sol = one.solve(inp)
    # the root relaxation alone: no footsteps, its bound is a valid lower bound
    assert sol.status == "node_limit" and not sol.has_solution
    assert sol.nodes == 1
    assert math.isnan(sol.objective) and sol.gap == math.inf
    assert math.isfinite(sol.bound) and sol.bound <= cold.objective
    # with a (suboptimal) warm leaf and room for it (the root, then the leaf): an incumbent,
    # not claimed optimal, gap from its numbers
    two = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(node_limit=2))
    warm = two.solve(inp, warm=("start_pad", "start_pad", "start_pad"))
    assert warm.status == "node_limit" and warm.has_solution
    assert warm.nodes == 2 and warm.warm_used
    assert check_solution(two, inp, warm) == []
    assert warm.bound <= cold.objective <= warm.objective
    expected = (warm.objective - warm.bound) / min(abs(warm.objective), abs(warm.bound))
    assert warm.gap == pytest.approx(expected) and warm.gap > 0.0


def test_node_limit_bounds_the_qp_solves(stones_tick: Tick) -> None:
    planner, inp, cold = stones_tick
    for limit in (1, 2, 3):
        lim = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(node_limit=limit))
        assert lim.solve(inp).nodes <= limit
        assert lim.solve(inp, warm=cold.regions).nodes <= limit


def test_reported_bound_is_a_lower_bound_with_a_loose_gap(stones_tick: Tick) -> None:
    planner, inp, cold = stones_tick
    loose = HorizonPlanner(planner.terrain, planner.robot, HorizonOptions(gap=0.1))
    sol = loose.solve(inp, warm=("stone1", "stone2", "stone2"))
    assert sol.status == "optimal"
    assert sol.objective <= cold.objective * 1.1  # within the gap, as claimed
    assert sol.bound <= cold.objective * (1 + 1e-9)  # a proven lower bound, pruned nodes too


def test_solve_time_is_read_from_the_injected_clock(stones_tick: Tick) -> None:
    planner, inp, _ = stones_tick
    reads = iter([0.0, 0.25])  # a third read would raise StopIteration
    timed = HorizonPlanner(
        planner.terrain, planner.robot, planner.options, clock=lambda: next(reads)
    )
    sol = timed.solve(inp)
    assert sol.status == "optimal"
    assert sol.solve_time == 0.25


# --------------------------------------------------------------------------- input errors
def _raises(field: str, fn: Callable[..., object], *args: object, **kwargs: object) -> None:
    with pytest.raises(InputError) as exc:
        fn(*args, **kwargs)
    assert exc.value.field == field, exc.value
    assert field in str(exc.value)


def test_bad_input_names_the_field(stones_tick: Tick, walks: Walks) -> None:
    planner, inp, _ = stones_tick
    good: dict[str, Any] = {
        "stance": inp.stance,
        "stance_foot": inp.stance_foot,
        "alip_state": inp.alip_state,
        "time_left": inp.time_left,
        "headings": inp.headings,
        "footsteps_ref": inp.footsteps_ref,
        "state_ref": inp.state_ref,
    }
    for field, value in [
        ("stance", "up"),
        ("stance_foot", np.zeros(2)),
        ("alip_state", np.zeros(5)),
        ("alip_state", np.array([0.0, math.nan, 0.0, 0.0])),
        ("time_left", 0.0),
        ("time_left", -0.1),
        ("headings", np.zeros((4, 1))),
        ("footsteps_ref", np.zeros((2, 3))),
        ("state_ref", np.zeros(3)),
    ]:
        _raises(field, HorizonInput, **{**good, field: value})
    # checked against the planner when solving (and when writing the MIQCQP)
    late = replace(inp, time_left=planner.robot.t_ss + 0.01)
    _raises("time_left", planner.solve, late)
    short = HorizonInput(
        **{**good, "headings": inp.headings[:3], "footsteps_ref": inp.footsteps_ref[:2]}
    )
    _raises("headings", planner.solve, short)
    _raises("headings", horizon_problem, planner, short)
    _raises("warm", planner.solve, inp, warm=("stone1", "stone2", "nope"))
    _raises("warm", planner.solve, inp, warm=("stone1", "stone2"))
    _raises("input", planner.solve, "not an input")
    _raises("horizon", HorizonOptions, horizon=0)
    _raises("horizon", HorizonOptions, horizon=True)
    _raises("track", HorizonOptions, track=-1.0)
    _raises("gap", HorizonOptions, gap=-1e-3)
    _raises("node_limit", HorizonOptions, node_limit=0)
    for bad in [(1.0,), (0.0, 1.0), (1.0, -2.0), (math.nan, 1.0), (1.0, math.inf), "ab", 3.0]:
        _raises("torque_limits", HorizonOptions, torque_limits=bad)
    assert HorizonOptions(torque_limits=[2, 3]).torque_limits == (2.0, 3.0)
    _, plan = walks["narrow_stones_gap"]
    x = plan.states[0, 0]
    _raises("step", horizon_input, plan, plan.n_steps - 2, 0.2, x)  # needs n - H
    _raises("step", horizon_input, plan, -1, 0.2, x)
    assert horizon_input(plan, plan.n_steps - 3, 0.2, x).horizon == 3


def test_warm_start_from_a_solution_without_footsteps(stones_tick: Tick) -> None:
    planner, inp, sol = stones_tick
    far = HorizonPlanner(load_scene(FAR_PADS)).solve(_far_input([2.5, 0.0, 0.0]))
    assert far.status == "infeasible" and far.next_regions(stepped=True) is None
    empty = replace(sol, status="infeasible", regions=())
    assert planner.solve(inp, warm=empty.next_regions(stepped=True)).status == "optimal"


# --------------------------------------------------------------------------- benchmark and CLI
def test_bench_horizon_small_run_agrees_with_scip() -> None:
    bench = bench_horizon(scenes=("narrow_stones_gap",), seeds=(0,), ticks=2, scip=True)
    assert len(bench.ticks) == 2 * (10 - 3 + 1)  # 10 footsteps, H = 3, 2 ticks a step
    for t in bench.ticks:
        assert t.status == "optimal" and t.cold_status == "optimal", t
        assert abs(t.objective - t.cold_objective) <= 2e-4 * abs(t.cold_objective)
    scip_ticks = [t for t in bench.ticks if t.scip_status]
    assert len(scip_ticks) == 8 and all(t.time_left == pytest.approx(0.4) for t in scip_ticks)
    for t in scip_ticks:  # our own reading of agreement, besides the module's
        assert t.scip_status == "optimal"
        assert t.scip_bound * (1 - 1e-6) <= t.objective <= t.scip_objective * (1 + 1e-4) + 1e-9
    rows = summary_rows(bench)
    assert [r["scene"] for r in rows] == ["narrow_stones_gap", "all"]
    assert rows[-1]["optimal"] == rows[-1]["ticks"] == 16
    assert rows[-1]["scip_agree"] == rows[-1]["scip_ticks"] == 8
    table = format_horizon_table(bench)
    assert "| narrow_stones_gap | 16 | 16 / 16 |" in table and "| all |" in table
    doc = bench_to_dict(bench)
    json.dumps(doc)
    back = json.loads(json.dumps(json_ready(doc), allow_nan=False))
    assert len(back["ticks"]) == 16 and back["summary"][-1]["scip_ticks"] == 8


def test_cli_bench_plan_horizon_writes_json_and_table(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    from footfall.cli import app

    args = ["bench", "plan", "--horizon", "3", "--scenes", "narrow_stones_gap", "--seeds", "0"]
    res = CliRunner().invoke(app, [*args, "--ticks", "1", "--fast-only", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    doc = json.loads(
        (tmp_path / "bench_horizon.json").read_text(),
        parse_constant=lambda c: pytest.fail(f"non-strict JSON token {c}"),
    )
    assert doc["horizon"] == 3 and len(doc["ticks"]) == 8
    assert all(t["status"] == "optimal" and t["scip_status"] == "" for t in doc["ticks"])
    md = (tmp_path / "bench_horizon.md").read_text()
    assert "| narrow_stones_gap | 8 |" in md
    assert not (tmp_path / "bench_plan.json").exists()


@pytest.mark.parametrize(
    ("extra", "field"), [(["--push", "-1"], "push"), (["--scenes", "nope"], "scenes")]
)
def test_cli_bench_plan_horizon_refuses_bad_input(
    tmp_path: Path, extra: list[str], field: str
) -> None:
    args = ["bench", "plan", "--horizon", "3", "--seeds", "0", "--ticks", "1", "--fast-only"]
    if "--scenes" not in extra:
        args += ["--scenes", "narrow_stones_gap"]
    r = footfall(*args, *extra, "--out", str(tmp_path), timeout=120)
    assert f"{field}: got" in error_line(r, field)
    assert not (tmp_path / "bench_horizon.json").exists()
