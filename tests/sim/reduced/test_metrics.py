"""Closed-loop metrics (``SimMetrics``, section 5.5 ZMP measure) recomputed from the written
trajectories of a run with numpy, and on a hand-made trace whose values are known in closed form."""

from __future__ import annotations

import math
import time
from types import SimpleNamespace

import numpy as np
import pytest

from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, simulate
from footfall.sim.reduced.closed_loop import _result, compiled_available
from footfall.terrain import builtin_scene
from tests.conftest import first_steps

#: metrics vs their recomputation from the trajectories (same numbers, summation order aside)
METRIC_RTOL = 1e-12

ENGINES = [
    "python",
    pytest.param(
        "compiled", marks=pytest.mark.skipif(not compiled_available(), reason="numba not installed")
    ),
]


@pytest.fixture(scope="module")
def short_plan() -> FootstepPlan:
    return first_steps(plan_reactive(builtin_scene("flat")), 3)


@pytest.mark.parametrize("engine", ENGINES)
def test_metrics_match_a_recomputation_from_the_trajectories(
    short_plan: FootstepPlan, engine: str
) -> None:
    # a narrow sole, a sideways push and placement errors: every metric is non-trivial
    opts = SimOptions(
        foot_width=0.04,
        pushes=(Push.horizontal(0.1, 6.0, math.pi / 2),),
        placement_error=0.01,
        seed=3,
        engine=engine,
    )
    res = simulate(short_plan, opts)
    met = res.metrics
    assert met.engine == engine and not met.fell

    ss = res.single
    assert 0 < ss.sum() < ss.size  # double-support samples exist and must be left out
    offs = np.hypot(res.cop_offset[ss, 0], res.cop_offset[ss, 1])
    assert met.zmp_offset_mean == pytest.approx(np.mean(offs), rel=METRIC_RTOL)
    assert met.zmp_offset_rms == pytest.approx(math.sqrt(np.mean(offs**2)), rel=METRIC_RTOL)
    assert met.zmp_offset_max == pytest.approx(np.max(offs), rel=METRIC_RTOL)

    phases = np.unique(res.stance[ss])
    np.testing.assert_array_equal(phases, np.arange(short_plan.n_steps))
    for p in phases:
        in_p = ss & (res.stance == p)
        o = np.hypot(res.cop_offset[in_p, 0], res.cop_offset[in_p, 1])
        assert met.zmp_offset_phase_mean[p] == pytest.approx(o.mean(), rel=METRIC_RTOL)
        assert met.zmp_offset_phase_max[p] == pytest.approx(o.max(), rel=METRIC_RTOL)

    sat = res.saturated[ss]
    assert 0 < sat.sum() < sat.size
    dt = np.diff(res.t[ss])
    dt_ctrl = np.median(dt)  # single-support samples are one control period apart
    assert met.saturated_time == pytest.approx(sat.sum() * dt_ctrl, rel=1e-9)
    assert met.saturated_fraction == pytest.approx(sat.sum() / ss.sum(), rel=METRIC_RTOL)

    n = res.footsteps.shape[0] - 1
    assert met.steps_taken == n == short_plan.n_steps
    dev = np.hypot(*(res.footsteps[1:, :2] - res.plan_footsteps[1 : n + 1, :2]).T)
    assert dev.min() > 0.0  # placement errors
    assert met.footstep_dev_mean == pytest.approx(dev.mean(), rel=METRIC_RTOL)
    assert met.footstep_dev_max == pytest.approx(dev.max(), rel=METRIC_RTOL)


def hand_made_run() -> tuple[SimpleNamespace, SimpleNamespace]:
    """Two single supports of three ticks with a two-tick double support between them.

    Single-support CoP offsets [m]: phase 0: (0.03, 0.04), (0, 0), (0.06, 0.08) -> 0.05, 0, 0.1;
    phase 1: (0.01, 0), (0, -0.02), (-0.03, 0) -> 0.01, 0.02, 0.03. The double-support rows hold
    (1, 1), which must not count. Saturated single-support ticks: 3 of 6.
    """
    single = np.array([1, 1, 1, 0, 0, 1, 1, 1], dtype=bool)
    stance = np.array([0, 0, 0, 0, 0, 1, 1, 1])
    cop_off = np.array(
        [[0.03, 0.04], [0, 0], [0.06, 0.08], [1, 1], [1, 1], [0.01, 0], [0, -0.02], [-0.03, 0]]
    )
    sat = np.array([1, 0, 1, 1, 1, 0, 0, 1], dtype=bool)
    plan_feet = np.array([[0, 0.1, 0], [0.3, -0.1, 0], [0.6, 0.1, 0], [0.9, -0.1, 0]])
    # landed: the first step 5 cm off (3, 4 cm), the second on the plan
    feet = np.array([[0, 0.1, 0], [0.33, -0.06, 0], [0.6, 0.1, 0]])
    n = single.size
    # the engines preallocate: rows past `samples` are never written and must be ignored
    pad = 3
    single, stance = np.r_[single, [True] * pad], np.r_[stance, [1] * pad]
    cop_off, sat = np.vstack([cop_off, np.full((pad, 2), 9.0)]), np.r_[sat, [True] * pad]
    plan = SimpleNamespace(
        footsteps=plan_feet,
        headings=np.zeros(4),
        robot=SimpleNamespace(u_max=30.0),
        planner="hand",
    )
    walk = SimpleNamespace(
        plan=plan,
        dt=0.01,
        goal_xy=np.array([0.9, 0.5]),
        mzh=20.0,
        omega=4.0,
        f_len=0.2,
        f_wid=0.1,
        regions=(),
    )
    trace = SimpleNamespace(
        samples=n,
        t=np.arange(n + pad) * 0.01,
        stance=stance,
        single=single,
        com=np.arange(2 * (n + pad)).reshape(-1, 2) * 0.1,
        cop=np.arange(2 * (n + pad)).reshape(-1, 2) * 0.2,
        cop_off=cop_off,
        tau_cmd=np.arange(2 * (n + pad)).reshape(-1, 2) * 0.3,
        tau=np.arange(2 * (n + pad)).reshape(-1, 2) * 0.4,
        sat=sat,
        solve_times=np.array([1e-4, 2e-4, 3e-4]),
        feet=feet,
        x=np.array([0.0, 0.0, 0.0, 0.0]),  # CoM on the last foot, at rest
        time=0.08,
        fell=False,
        fall_time=math.nan,
        n_solves=3,
        n_fallbacks=0,
    )
    return walk, trace


def test_metrics_of_a_hand_made_trace_have_their_closed_form_values() -> None:
    walk, trace = hand_made_run()
    t0 = time.perf_counter()
    res = _result(walk, trace, "python", t0)  # type: ignore[arg-type]
    elapsed = time.perf_counter() - t0
    met = res.metrics
    assert met.zmp_offset_mean == pytest.approx(0.21 / 6, rel=1e-12)
    assert met.zmp_offset_rms == pytest.approx(math.sqrt(0.0139 / 6), rel=1e-12)
    assert met.zmp_offset_max == pytest.approx(0.1, rel=1e-12)
    assert met.zmp_offset_phase_mean == pytest.approx((0.05, 0.02), rel=1e-12)
    assert met.zmp_offset_phase_max == pytest.approx((0.1, 0.03), rel=1e-12)
    assert met.saturated_time == pytest.approx(0.03, rel=1e-12)
    assert met.saturated_fraction == 0.5
    assert met.footstep_dev_mean == pytest.approx(0.025, rel=1e-12)
    assert met.footstep_dev_max == pytest.approx(0.05, rel=1e-12)
    assert met.steps_taken == 2
    # final CoM on the last foot (0.6, 0.1), goal (0.9, 0.5): a 3-4-5 triangle
    assert met.goal_error == pytest.approx(0.5, rel=1e-12)
    # at rest on the last foot: the capture point is inside the final soles
    assert met.stopped and met.success
    assert met.mpc_time_max == 3e-4 and met.mpc_time_median == 2e-4
    assert met.mpc_time_p99 == pytest.approx(2.98e-4, rel=1e-12)  # linear interpolation
    assert (met.mpc_solves, met.mpc_fallbacks, met.sim_time) == (3, 0, 0.08)
    assert not met.fell and math.isnan(met.fall_time) and met.engine == "python"
    assert 0.0 <= met.wall_time <= elapsed  # the run's own clock, read within ours
    # the trajectories are the written samples, trimmed; the rest is echoed
    n = trace.samples
    for got, want in (
        (res.t, trace.t[:n]),
        (res.com, trace.com[:n]),
        (res.cop, trace.cop[:n]),
        (res.cop_offset, trace.cop_off[:n]),
        (res.torque_cmd, trace.tau_cmd[:n]),
        (res.torque, trace.tau[:n]),
        (res.saturated, trace.sat[:n]),
        (res.single, trace.single[:n]),
        (res.stance, trace.stance[:n]),
        (res.footsteps, trace.feet),
        (res.plan_footsteps, walk.plan.footsteps),
        (res.headings, np.zeros(3)),
        (res.goal, walk.goal_xy),
    ):
        np.testing.assert_array_equal(got, want)
    assert (res.u_max, res.foot_length, res.foot_width, res.planner) == (30.0, 0.2, 0.1, "hand")


@pytest.mark.parametrize(
    ("x", "goal", "stopped"),
    [
        # CoM 1 m off, momentum bringing the capture point back between the two soles:
        # xi = (-0.4, -0.9) + (L_y, -L_x) / (m z_H omega) = (0.47, 0.0), inside neither sole
        # but inside their hull
        ([-1.0, -1.0, -72.0, 69.6], [-0.1, -0.5], True),
        # the same CoM at rest: the capture point is the CoM, far outside
        ([-1.0, -1.0, 0.0, 0.0], [-0.1, -0.5], False),
    ],
)
def test_stopped_is_the_capture_point_in_the_final_soles(
    x: list[float], goal: list[float], stopped: bool
) -> None:
    walk, trace = hand_made_run()
    trace.x, walk.goal_xy = np.array(x), np.array(goal)
    met = _result(walk, trace, "python", 0.0).metrics  # type: ignore[arg-type]
    assert met.stopped is stopped and met.success is stopped
    assert met.goal_error == pytest.approx(0.5, rel=1e-12)  # CoM (-0.4, -0.9)


def test_a_fall_is_neither_stopped_nor_successful() -> None:
    walk, trace = hand_made_run()
    trace.fell, trace.fall_time = True, 0.05
    met = _result(walk, trace, "python", 0.0).metrics  # type: ignore[arg-type]
    assert met.fell and met.fall_time == 0.05
    assert met.stopped is False and met.success is False and math.isnan(met.goal_error)


@pytest.mark.filterwarnings("error")  # no mean of an empty array behind the NaNs
def test_metrics_of_a_run_without_single_support_or_steps() -> None:
    walk, trace = hand_made_run()
    trace.single = np.zeros_like(trace.single)
    trace.feet = trace.feet[:1]
    trace.solve_times = np.zeros(0)
    trace.fell, trace.fall_time = True, 0.0  # e.g. non-finite from the start
    met = _result(walk, trace, "python", 0.0).metrics  # type: ignore[arg-type]
    assert math.isnan(met.zmp_offset_mean) and math.isnan(met.zmp_offset_rms)
    assert math.isnan(met.zmp_offset_max)
    assert met.zmp_offset_phase_mean == () and met.zmp_offset_phase_max == ()
    assert met.saturated_time == 0.0 and met.saturated_fraction == 0.0
    assert met.footstep_dev_mean == 0.0 and met.footstep_dev_max == 0.0
    assert met.steps_taken == 0
    assert met.mpc_time_median == met.mpc_time_p99 == met.mpc_time_max == 0.0
