"""Closed-loop reduced-order simulation: plant vs solve_ivp, CoP clipping, falls, reproducibility."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from footfall.errors import InputError
from footfall.planning.plan import FootstepPlan, goal_feet
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, simulate
from footfall.sim.reduced.closed_loop import viability_bounds
from footfall.terrain import builtin_scene
from tests.conftest import IVP_ATOL, IVP_RTOL, first_steps

#: plant CoM vs the solve_ivp integration of the CoM dynamics [m]
PLANT_TOL = 1e-7
#: landed footsteps vs the plan on a walk without disturbances [m]
NOMINAL_STEP_TOL = 0.03


@pytest.fixture(scope="module")
def flat_plan() -> FootstepPlan:
    plan = plan_reactive(builtin_scene("flat"))
    assert plan.n_steps >= 4
    return plan


@pytest.fixture(scope="module")
def short_plan(flat_plan: FootstepPlan) -> FootstepPlan:
    """The first 3 steps of the flat walk (fast to simulate)."""
    return first_steps(flat_plan, 3)


def test_plant_matches_solve_ivp_of_the_com_dynamics(short_plan: FootstepPlan) -> None:
    robot = short_plan.robot
    push = Push.horizontal(0.15, 6.0, 1.0, 0.05)
    opts = SimOptions(pushes=(push,), mass_scale=1.1, com_height_scale=0.95, substeps=4)
    res = simulate(short_plan, opts)
    m, zh, g = robot.mass * 1.1, robot.com_height * 0.95, robot.g
    x0 = short_plan.states[0, 0]
    vel0 = np.array([x0[3], -x0[2]]) / (m * zh)
    f = push.force[:2]
    t, cop = res.t, res.cop
    n = t.shape[0]
    dt_ss = t[1] - t[0]

    def cop_at(s: float) -> np.ndarray:
        j = min(int(np.searchsorted(t, s, side="right") - 1), n - 1)
        if res.single[j] or j + 1 >= n:
            return cop[j]
        # double support: the contact moves linearly; interpolate to the next recorded point
        # (or to the landed foot at the end of the phase)
        nxt = cop[j + 1] if not res.single[j + 1] else res.footsteps[res.stance[j] + 1, :2]
        return cop[j] + (s - t[j]) / (t[j + 1] - t[j]) * (nxt - cop[j])

    def rhs(s: float, y: np.ndarray) -> np.ndarray:
        acc = g / zh * (y[:2] - cop_at(s))
        if push.start <= s < push.start + push.duration:
            acc = acc + f / m
        return np.concatenate([y[2:], acc])

    # integrate sample by sample so that the piecewise inputs are resolved exactly
    y = np.concatenate([res.com[0], vel0])
    edges = [*t.tolist(), t[-1] + (t[-1] - t[-2])]
    breaks = sorted({push.start, push.start + push.duration})
    for j in range(n - 1):
        np.testing.assert_allclose(y[:2], res.com[j], atol=PLANT_TOL)
        pts = [edges[j], *[b for b in breaks if edges[j] < b < edges[j + 1]], edges[j + 1]]
        for a, b in itertools.pairwise(pts):
            sol = solve_ivp(rhs, (a, b), y, rtol=IVP_RTOL, atol=IVP_ATOL, method="DOP853")
            y = sol.y[:, -1]
    assert dt_ss == pytest.approx(0.002)


def test_cop_is_clipped_to_the_sole(short_plan: FootstepPlan) -> None:
    # a narrow sole and a sideways push: the ankle cannot make the commanded torque
    opts = SimOptions(foot_width=0.02, pushes=(Push.horizontal(0.1, 8.0, math.pi / 2),))
    res = simulate(short_plan, opts)
    ss = res.single
    assert np.all(np.abs(res.cop_offset[ss, 0]) <= 0.1 + 1e-12)
    assert np.all(np.abs(res.cop_offset[ss, 1]) <= 0.01 + 1e-12)
    assert res.saturated.any() and res.metrics.saturated_time > 0
    mg = short_plan.robot.mass * short_plan.robot.g
    # commanded CoP outside the sole where saturated, applied torque = clipped CoP times weight
    cmd_off = np.stack([-res.torque_cmd[:, 1], res.torque_cmd[:, 0]], axis=1) / mg
    sat = res.saturated & ss
    assert np.all(np.abs(cmd_off[sat, 1]) > 0.01)
    off_w = res.cop[ss] - res.footsteps[res.stance[ss], :2]  # world frame
    np.testing.assert_allclose(
        res.torque[ss], np.stack([mg * off_w[:, 1], -mg * off_w[:, 0]], axis=1), atol=1e-9
    )
    assert res.metrics.zmp_offset_max <= math.hypot(0.1, 0.01) + 1e-12


def test_walk_on_flat_reaches_the_goal_without_falling(flat_plan: FootstepPlan) -> None:
    scene = builtin_scene("flat")
    res = simulate(flat_plan, SimOptions(), goal=scene.goal.position)
    m = res.metrics
    assert not m.fell and m.steps_taken == flat_plan.n_steps and m.mpc_fallbacks == 0
    feet = goal_feet(flat_plan.robot, scene.goal.position[:2], scene.goal.heading)
    for k in (-1, -2):
        target = feet[flat_plan.sides[k]]
        assert np.linalg.norm(res.footsteps[k, :2] - target) < NOMINAL_STEP_TOL
    assert m.footstep_dev_max < NOMINAL_STEP_TOL
    # without disturbances the CoP never reaches the sole edge (the reactive plan's last step
    # brakes with up to ~6 cm of forward CoP offset, inside the 10 cm half-length)
    assert m.saturated_time == 0.0
    assert m.zmp_offset_max < 0.75 * 0.5 * flat_plan.robot.foot_length
    # the CoM ends where the plan's final state puts it
    plan_final = flat_plan.footsteps[-1, :2] + flat_plan.final_state[:2]
    assert np.linalg.norm(res.com[-1] - plan_final) < NOMINAL_STEP_TOL
    assert m.goal_error == pytest.approx(
        np.linalg.norm(plan_final - scene.goal.position[:2]), abs=NOMINAL_STEP_TOL
    )


def test_huge_push_is_a_fall_not_an_exception(short_plan: FootstepPlan) -> None:
    res = simulate(short_plan, SimOptions(pushes=(Push.horizontal(0.1, 150.0, 0.0),)))
    m = res.metrics
    assert m.fell and not m.success and math.isnan(m.goal_error)
    assert 0.1 < m.fall_time <= 0.2 + 1e-9
    # the recorded trajectory stops at the fall
    assert res.t[-1] <= m.fall_time


def test_moderate_push_is_recovered(flat_plan: FootstepPlan) -> None:
    res = simulate(flat_plan, SimOptions(pushes=(Push.horizontal(1.0, 10.0, math.pi / 2),)))
    assert not res.metrics.fell
    assert res.metrics.footstep_dev_max > NOMINAL_STEP_TOL  # recovered by stepping


def test_fall_bound_is_the_fixed_point_of_the_capturability_recursion(
    flat_plan: FootstepPlan,
) -> None:
    robot = flat_plan.robot
    omega = robot.alip().omega
    d0, span = viability_bounds(robot, omega, 0.2, 0.1)
    e = math.exp(-omega * (robot.t_ss + robot.t_ds))
    reach = np.array([0.35, 0.20, 0.32, 0.32])  # DEFAULT_REACH bounding box
    d = d0.copy()
    for _ in range(200):
        d = d0 + (d + reach - d0) * e
    np.testing.assert_allclose(span, d + reach - d0, rtol=1e-12)


def test_seeded_runs_are_reproducible(short_plan: FootstepPlan) -> None:
    opts = SimOptions(noise_pos=0.003, noise_vel=0.03, placement_error=0.01, seed=4)
    a, b = simulate(short_plan, opts), simulate(short_plan, opts)
    np.testing.assert_array_equal(a.com, b.com)
    np.testing.assert_array_equal(a.footsteps, b.footsteps)
    c = simulate(short_plan, replace(opts, seed=5))
    assert not np.array_equal(a.com, c.com)


def test_bad_inputs_raise_input_errors(short_plan: FootstepPlan) -> None:
    with pytest.raises(InputError, match="control_rate"):
        SimOptions(control_rate=-500.0)
    with pytest.raises(InputError, match="control_rate"):
        SimOptions(control_rate="fast")  # type: ignore[arg-type]
    with pytest.raises(InputError, match=r"push\.impulse"):
        Push.horizontal(1.0, -3.0)
    with pytest.raises(InputError, match="substeps"):
        SimOptions(substeps=0)
    with pytest.raises(InputError, match="seed"):
        SimOptions(seed=1.5)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="pushes"):
        SimOptions(pushes=(3.0,))  # type: ignore[arg-type]
    with pytest.raises(InputError, match="plan"):
        simulate("plan.json")  # type: ignore[arg-type]
    empty = FootstepPlan.empty("miqcqp", short_plan.status, short_plan.robot, "infeasible")
    with pytest.raises(InputError, match="plan"):
        simulate(empty)
