"""The MPC's step timing (:attr:`footfall.control.adjusters.MPCAdjuster.step_timing`).

After a push the MPC may end the single support sooner: eq. (5.19) is solved as if it had fewer
ticks left, and the touchdown moves when that costs less by the margin. Checked: on the plan's
own state nothing moves and the adjuster answers bit for bit as without the timing; after a
forward push the touchdown moves, within its bounds, to a tick whose optimal cost (recomputed
by the sparse reference SOCP of test_mpc, written from the equations) is lower by more than the
margin, and the footstep it commands is nearer the plan's than the fixed timing's (the capture
point had less time to grow: an independent, physical consequence); nothing moves late in the
support or on the last stopping step; the probing solves leave no warm start or counter behind.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from footfall.control.adjusters import (
    TIMING_MARGIN,
    TIMING_MIN_SHARE,
    TIMING_UNTIL,
    MPCAdjuster,
)
from footfall.control.region_mpc import RegionMPC
from footfall.errors import InputError
from footfall.experiments.bench_horizon import _pushed_state
from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.terrain import Scene, builtin_scene
from tests.control.test_horizon_regions import DT
from tests.control.test_horizon_regions import _adjuster as walker_adjuster
from tests.control.test_mpc import reference_solve

#: the pushed single support and the push: forward, at its start
STEP, PUSH = 4, (0.6, 0.0)
#: the reference SOCP's optimal cost against the adjuster's (relative), as in test_mpc
COST_RTOL = 1e-6


@pytest.fixture(scope="module")
def flat() -> tuple[Scene, FootstepPlan]:
    scene = builtin_scene("flat_long")
    plan = plan_reactive(scene)
    assert plan.n_steps > STEP + 2
    return scene, plan


def _adjuster(scene: Scene, plan: FootstepPlan, **kw: object) -> MPCAdjuster:
    return walker_adjuster(plan, scene, "planned", **kw)


def _theta(adj: MPCAdjuster, x: np.ndarray, step: int) -> np.ndarray:
    """The MPC's parameter vector in the stance heading's frame (where the adjuster solves)."""
    plan = adj.plan
    c, s = math.cos(float(plan.headings[step])), math.sin(float(plan.headings[step]))
    rot = np.array([[c, -s], [s, c]])
    rot4 = np.kron(np.eye(2), rot)
    d_ref = plan.footsteps[step + 1, :2] - plan.footsteps[step, :2]
    return np.concatenate([rot4.T @ x, rot.T @ d_ref, rot4.T @ plan.states[step + 1, 0]])


def _world(adj: MPCAdjuster, d: np.ndarray, step: int) -> np.ndarray:
    """A footstep offset (2,) of the stance frame in the world's."""
    c, s = math.cos(float(adj.plan.headings[step])), math.sin(float(adj.plan.headings[step]))
    return np.array([[c, -s], [s, c]]) @ d


def test_on_the_plan_nothing_moves_and_the_answer_is_unchanged(flat) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat
    on, off = _adjuster(scene, plan, step_timing=True), _adjuster(scene, plan)
    stance = plan.footsteps[STEP]
    for k in range(0, 40, 3):
        t = k * DT
        x = _pushed_state(plan, STEP, t, np.zeros(2))
        a, b = on.update(t, x, stance, STEP), off.update(t, x, stance, STEP)
        assert on.take_advance() == 0.0
        assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])
    assert on.saved_ticks == {}
    assert on.mpc.n_solves == off.mpc.n_solves  # the probes are not counted
    assert off.take_advance() == 0.0  # without the timing: always nothing


def test_a_push_moves_the_touchdown_to_a_cheaper_tick(flat) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat
    adj = _adjuster(scene, plan, step_timing=True)
    mdl = adj.mpc.model
    m = mdl.n_ticks
    t = 0.05
    k_s = round(t / DT)
    x = _pushed_state(plan, STEP, t, np.array(PUSH))
    target, _ = adj.update(t, x, plan.footsteps[STEP], STEP)
    adv = adj.take_advance()
    assert adv > 0.0 and adj.take_advance() == 0.0  # taken once
    k_new = k_s + round(adv / DT)
    assert adj.saved_ticks == {STEP: k_new - k_s}
    # within the bounds: at least timing_min_share of the ticks the support had left remain
    assert m - k_new >= TIMING_MIN_SHARE * (m - k_s) - 1e-9
    # the cheaper tick, by the reference SOCP written from the equations
    theta = _theta(adj, x, STEP)
    lim = tuple(float(v) for v in mdl.u_limits)
    fixed, _ = reference_solve(mdl, k_s, theta, limits=lim)
    moved, z = reference_solve(mdl, k_new, theta, limits=lim)
    assert moved < fixed - TIMING_MARGIN
    # the commanded footstep is the reference optimum at the moved tick
    d = z[2 * mdl.n_blocks(k_new) : 2 * mdl.n_blocks(k_new) + 2]
    assert np.allclose(target[:2] - plan.footsteps[STEP, :2], _world(adj, d, STEP), atol=1e-5)
    # physically: landing sooner, the capture point grew less, so the footstep needs less
    # correction than the fixed timing's
    d_fixed = reference_solve(mdl, k_s, theta, limits=lim)[1][2 * mdl.n_blocks(k_s) :][:2]
    d_ref = theta[4:6]
    assert np.linalg.norm(d - d_ref) < np.linalg.norm(d_fixed - d_ref) - 0.02
    # and no tick allowed is cheaper by the reference than the one chosen, beyond the stride
    k_hi = m - math.ceil(TIMING_MIN_SHARE * (m - k_s) - 1e-9)
    best = min(reference_solve(mdl, k, theta, limits=lim)[0] for k in range(k_s, k_hi + 1))
    assert moved <= best + 0.05 * fixed


def test_the_walker_gets_the_moved_tick_on_its_next_call(flat) -> None:  # type: ignore[no-untyped-def]
    """On the moved clock the adjuster solves the moved tick's problem, and the touchdown can
    move only within what the support had left at its real elapsed time."""
    scene, plan = flat
    adj = _adjuster(scene, plan, step_timing=True)
    t = 0.05
    x = _pushed_state(plan, STEP, t, np.array(PUSH))
    adj.update(t, x, plan.footsteps[STEP], STEP)
    adv = adj.take_advance()
    t2 = t + adv + DT  # the walker's next tick on the moved clock
    x2 = _pushed_state(plan, STEP, t + DT, np.array(PUSH))
    adj.update(t2, x2, plan.footsteps[STEP], STEP)
    adv2 = adj.take_advance()
    m = adj.mpc.model.n_ticks
    k2 = round(t2 / DT) + round(adv2 / DT)
    elapsed = round((t + DT) / DT)  # ticks really spent in the support
    assert m - k2 >= TIMING_MIN_SHARE * (m - elapsed) - 1e-9


def test_nothing_moves_late_in_the_support_or_on_the_last_step(flat) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat
    adj = _adjuster(scene, plan, step_timing=True, capture_stop=True)  # as the walker has it
    t_ss = plan.robot.t_ss
    t = math.ceil(TIMING_UNTIL * t_ss / DT) * DT
    x = _pushed_state(plan, STEP, t, np.array(PUSH))
    adj.update(t, x, plan.footsteps[STEP], STEP)
    assert adj.take_advance() == 0.0
    # the last stopping step is the capture stop's (the walker's default): its touchdown keeps
    # its time
    last = adj.plan.n_steps - 1
    x = _pushed_state(plan, STEP, 0.05, np.array(PUSH))
    adj.update(0.05, x, adj.plan.footsteps[last], last)
    assert adj.take_advance() == 0.0
    # an early push, same state: it moves (the two checks above are not vacuous)
    adj.update(0.05, x, plan.footsteps[STEP], STEP)
    assert adj.take_advance() > 0.0


def test_probing_solves_leave_no_trace(flat) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat
    adj = _adjuster(scene, plan)
    rmpc: RegionMPC = adj.region_mpc
    x = _pushed_state(plan, STEP, 0.05, np.array(PUSH))
    adj.update(0.05, x, plan.footsteps[STEP], STEP)
    before = (dict(rmpc._warm), rmpc.mpc._last, rmpc.mpc.n_solves, rmpc.mpc.n_fallbacks)
    theta = _theta(adj, x, STEP)
    ps, pr = np.array(plan.footsteps[STEP]), np.array(plan.footsteps[STEP + 1])
    with rmpc.probe():
        for k in (10, 20, 30):
            rmpc.mpc.solve_theta(k, theta, ps, pr)
        assert rmpc.mpc.n_solves == before[2] + 3
    after = (rmpc._warm, rmpc.mpc._last, rmpc.mpc.n_solves, rmpc.mpc.n_fallbacks)
    assert after[0] == before[0] and after[1] is before[1] and after[2:] == before[2:]


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("timing_min_share", 0.0),
        ("timing_min_share", 1.5),
        ("timing_min_share", math.nan),
        ("timing_until", -0.1),
        ("timing_until", math.inf),
        ("timing_margin", -1.0),
        ("timing_margin", math.nan),
        ("timing_stride", 0),
        ("timing_stride", 2.0),
        ("timing_stride", True),
    ],
)
def test_bad_timing_settings_name_the_field(flat, field: str, value: object) -> None:  # type: ignore[no-untyped-def]
    scene, plan = flat
    with pytest.raises(InputError, match=field):
        _adjuster(scene, plan, **{field: value})
