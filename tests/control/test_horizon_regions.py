"""The walker's MPC in ``horizon`` mode (:class:`footfall.control.horizon_regions.HorizonRegions`
inside :class:`footfall.control.adjusters.MPCAdjuster`): after a push, the region it puts the next
footstep in is the one SCIP puts footstep 1 in when it solves the same short-horizon problem
written independently (:func:`footfall.planning.horizon_model.horizon_problem`); the commanded footstep
stands in that region with the sole inside it (shapely); the solves follow the 50 Hz schedule."""

from __future__ import annotations

import math

import numpy as np
import pytest
from shapely.geometry import Point, Polygon

from footfall._geometry import rot2
from footfall.control.adjusters import MPCAdjuster, sole_torque_limits
from footfall.control.horizon_regions import HORIZON_PERIOD, HorizonRegions
from footfall.errors import InputError
from footfall.experiments.bench_horizon import _pushed_state
from footfall.planning.horizon import HorizonOptions, HorizonPlanner, horizon_input
from footfall.planning.horizon_model import horizon_problem
from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.solvers import SolverOptions, SolveStatus, solve
from footfall.terrain import Scene, builtin_scene

#: the walker's control period [s]
DT = 0.01
#: standing on footstep 4 of stepping_stones, 0.05 s after a backward push of 0.3 m/s: the
#: short-horizon MIQP steps back onto the previous stone (found by a sweep of pushes)
STEP, T, DV = 4, 0.05, (-0.3, 0.0)


@pytest.fixture(scope="module")
def stones() -> tuple[Scene, FootstepPlan]:
    scene = builtin_scene("stepping_stones")
    plan = plan_reactive(scene)
    assert plan.reaches_goal
    return scene, plan


def _adjuster(plan: FootstepPlan, scene: Scene, mode: str, **kw: object) -> MPCAdjuster:
    """The walker's MPC adjuster (its control period and sole torque ellipse) in ``mode``."""
    regions = {r.name: r for r in scene.terrain.regions}
    return MPCAdjuster(
        plan,
        regions,
        control_dt=DT,
        torque_limits=sole_torque_limits(plan.robot),
        region_aware=mode,
        **kw,  # type: ignore[arg-type]
    )


def _scip_region(scene: Scene, plan: FootstepPlan, x: np.ndarray) -> str:
    """The region holding SCIP's footstep 1 of the independently written problem, with the
    walker MPC's torque ellipse (the adjuster hands it to its short-horizon MIQP)."""
    options = HorizonOptions(torque_limits=sole_torque_limits(plan.robot))
    planner = HorizonPlanner(scene, plan.robot, options)
    inp = horizon_input(plan, STEP, plan.robot.t_ss - T, x)
    prob = horizon_problem(planner, inp)
    res = solve(prob, "scip", SolverOptions(time_limit=60, gap=1e-6))
    assert res.status == SolveStatus.OPTIMAL and res.x is not None
    p1 = np.array([res.x[prob.names.index(f"p[0,{k}]")] for k in range(3)])
    holding = [
        r.name
        for r in scene.terrain.regions
        if Polygon(r.vertices).buffer(1e-6).covers(Point(p1[:2]))
        and abs(float(r.height_at(p1[:2])) - p1[2]) <= 1e-5
    ]
    assert len(holding) == 1, holding
    return holding[0]


def test_a_pushed_walker_steps_where_scip_puts_the_footstep(
    stones: tuple[Scene, FootstepPlan],
) -> None:
    scene, plan = stones
    x = _pushed_state(plan, STEP, T, np.array(DV))
    stance = np.asarray(plan.footsteps[STEP], dtype=float)
    expected = _scip_region(scene, plan, x)
    planned = plan.regions[STEP + 1]
    assert expected != planned, "the push must make the short horizon leave the plan's stone"

    adj = _adjuster(plan, scene, "horizon")
    target, u = adj.update(T, x, stance, STEP)
    choice = adj.choices[STEP]
    assert choice.region == expected and choice.planned == planned
    assert choice.candidates == (expected,)
    assert adj.horizon is not None and adj.horizon.solves == 1
    # the MIQP judges the regions with the torques the walker's MPC will use
    assert adj.horizon._planner.options.torque_limits == sole_torque_limits(plan.robot)
    # the commanded footstep stands on that stone, the whole sole inside it at its heading
    region = {r.name: r for r in scene.terrain.regions}[expected]
    half = np.array([plan.robot.foot_length, plan.robot.foot_width]) / 2.0
    corners = np.array([[sx * half[0], sy * half[1]] for sx in (-1, 1) for sy in (-1, 1)])
    heading = float(plan.headings[STEP + 1])
    sole = corners @ rot2(heading).T + target[:2]
    stone = Polygon(region.vertices).buffer(1e-6)
    assert all(stone.covers(Point(c)) for c in sole), sole
    assert target[2] == pytest.approx(float(region.height_at(target[:2])), abs=1e-9)
    assert np.all(np.isfinite(u))

    # the same tick with the plan's region: the footstep stays on the planned stone
    kept = _adjuster(plan, scene, "planned")
    target_p, _ = kept.update(T, x, stance, STEP)
    own = {r.name: r for r in scene.terrain.regions}[planned]
    assert Polygon(own.vertices).buffer(1e-6).covers(Point(target_p[:2]))
    assert kept.choices[STEP].region == planned


def test_solves_follow_the_50_hz_schedule(stones: tuple[Scene, FootstepPlan]) -> None:
    """A solve at the phase's first tick and every HORIZON_PERIOD / DT ticks; between solves the
    last choice holds; no solve where fewer than H footsteps are left."""
    scene, plan = stones
    adj = _adjuster(plan, scene, "horizon")
    assert adj.horizon is not None
    every = round(HORIZON_PERIOD / DT)
    ticks = round(plan.robot.t_ss / DT)
    stance = np.asarray(plan.footsteps[STEP], dtype=float)
    for k in range(ticks - 5):  # before the footstep freezes
        t = k * DT
        x = _pushed_state(plan, STEP, t, np.zeros(2))
        adj.update(t, x, stance, STEP)
    assert adj.horizon.solves == math.ceil((ticks - 5) / every)
    assert adj.horizon.failures == 0
    # unpushed, the short horizon keeps the plan's stone
    assert adj.choices[STEP].region == plan.regions[STEP + 1]

    # the adjuster's plan has its stopping steps appended: the last phases with H footsteps
    # ahead ask, the ones after do not
    n = adj.plan.n_steps
    late = HorizonRegions(adj.plan, tuple(scene.terrain.regions), DT)
    last = n - late.horizon
    foot = np.asarray(adj.plan.footsteps[last + 1], dtype=float)
    assert late.choose(last + 1, 0, 0.3, np.zeros(4), foot) is None
    assert late.solves == 0


def test_bad_input_names_the_field(stones: tuple[Scene, FootstepPlan]) -> None:
    scene, plan = stones
    for dt in (0.0, -0.01, math.nan):
        with pytest.raises(InputError, match="control_dt"):
            HorizonRegions(plan, tuple(scene.terrain.regions), dt)
    with pytest.raises(InputError, match="region_aware"):
        _adjuster(plan, scene, "horizons")


def test_one_region_leaves_nothing_to_choose() -> None:
    """On a terrain of one region the MIQP is not solved and the adjuster's footstep, pushed, is
    the ``planned`` mode's to the bit."""
    scene = builtin_scene("flat")
    plan = plan_reactive(scene)
    assert len(scene.terrain.regions) == 1
    step = 2
    x = _pushed_state(plan, step, T, np.array([-0.3, 0.2]))
    stance = np.asarray(plan.footsteps[step], dtype=float)
    adj = _adjuster(plan, scene, "horizon")
    target, u = adj.update(T, x, stance, step)
    target_p, u_p = _adjuster(plan, scene, "planned").update(T, x, stance, step)
    assert adj.horizon is not None and adj.horizon.solves == 0
    assert np.array_equal(target, target_p) and np.array_equal(u, u_p)
    assert adj.choices[step].region == plan.regions[step + 1]
