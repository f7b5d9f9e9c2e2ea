"""The compiled engine of the reduced-order simulation reproduces the Python reference: the dual
Newton ball QP, the MPC tick with its warm starts and fallbacks, and whole closed-loop runs (pushes,
noise, placement error, model mismatch, a fall, failed solves)."""

from __future__ import annotations

import math
from dataclasses import fields, replace

import numpy as np
import pytest

import footfall.sim.reduced.closed_loop as reduced
from footfall.control import MPC, MPCWeights, build_mpc, solve_ball_qp
from footfall.control.ball_qp import DUAL_TOL, MAX_NEWTON_ITER
from footfall.control.mpc import CondensedMPC
from footfall.errors import InputError, SolverUnavailableError
from footfall.models.biped import BipedParams
from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, SimResult, simulate
from footfall.terrain import builtin_scene
from tests.conftest import first_steps

kernel = pytest.importorskip("footfall.sim.reduced._kernel")

#: compiled vs reference trajectories, footsteps and metrics (same arithmetic, other rounding) [SI]
ENGINE_TOL = 1e-9
#: compiled vs reference ball-QP solutions (both converge to DUAL_TOL on the ball norms)
QP_TOL = 1e-9

ROBOT = BipedParams(n_nodes=10)

#: trajectory fields of SimResult compared between the engines
TRAJECTORIES = ("t", "com", "cop", "cop_offset", "torque_cmd", "torque", "footsteps", "headings")
#: exact (discrete) fields
DISCRETE = ("stance", "single", "saturated")
#: metrics that are timings or labels, not outcomes
NOT_OUTCOMES = ("mpc_time_median", "mpc_time_p99", "mpc_time_max", "wall_time", "engine")


@pytest.fixture(scope="module")
def flat_plan() -> FootstepPlan:
    return plan_reactive(builtin_scene("flat"))


@pytest.fixture(scope="module")
def short_plan(flat_plan: FootstepPlan) -> FootstepPlan:
    """The first 3 steps of the flat walk."""
    return first_steps(flat_plan, 3)


@pytest.fixture(scope="module")
def model() -> CondensedMPC:
    return build_mpc(ROBOT, MPCWeights(), 0.004)


def run_both(plan: FootstepPlan, opts: SimOptions) -> tuple[SimResult, SimResult]:
    ref = simulate(plan, replace(opts, engine="python"))
    fast = simulate(plan, replace(opts, engine="compiled"))
    assert ref.metrics.engine == "python" and fast.metrics.engine == "compiled"
    return ref, fast


def assert_same_run(ref: SimResult, fast: SimResult) -> None:
    for name in TRAJECTORIES:
        a, b = getattr(ref, name), getattr(fast, name)
        assert a.shape == b.shape, name
        np.testing.assert_allclose(b, a, rtol=0, atol=ENGINE_TOL, err_msg=name)
    for name in DISCRETE:
        np.testing.assert_array_equal(getattr(fast, name), getattr(ref, name), err_msg=name)
    for f in fields(ref.metrics):
        if f.name in NOT_OUTCOMES:
            continue
        a, b = getattr(ref.metrics, f.name), getattr(fast.metrics, f.name)
        if isinstance(a, bool | int) or a is None:
            assert a == b, f.name
        else:
            np.testing.assert_allclose(b, a, rtol=0, atol=ENGINE_TOL, err_msg=f.name)
    for m in (ref.metrics, fast.metrics):
        assert 0 < m.mpc_time_median <= m.mpc_time_p99 <= m.mpc_time_max


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_engines_agree_with_pushes_noise_and_mismatch(short_plan: FootstepPlan, seed: int) -> None:
    rng = np.random.default_rng(seed)
    opts = SimOptions(
        noise_pos=0.003,
        noise_vel=0.03,
        placement_error=0.01,
        mass_scale=float(rng.uniform(0.9, 1.1)),
        com_height_scale=float(rng.uniform(0.95, 1.05)),
        # one push switching inside control ticks (sub-steps), one on the tick grid
        pushes=(
            Push.horizontal(0.1234, 9.0, float(rng.uniform(0, 2 * math.pi)), 0.0503),
            Push.horizontal(0.9, 6.0, float(rng.uniform(0, 2 * math.pi)), 0.1),
        ),
        mpc_nodes=10,
        seed=seed,
    )
    ref, fast = run_both(short_plan, opts)
    assert not ref.metrics.fell
    # the torque discs bind (the Newton path runs) and the sole clips the CoP
    assert np.any(np.linalg.norm(ref.torque_cmd, axis=1) >= short_plan.robot.u_max - 1e-9)
    assert ref.saturated.any()
    assert_same_run(ref, fast)


def test_engines_agree_on_a_whole_walk(flat_plan: FootstepPlan) -> None:
    opts = SimOptions(pushes=(Push.horizontal(1.0, 10.0, math.pi / 2),), noise_pos=0.001, seed=3)
    ref, fast = run_both(flat_plan, opts)
    assert ref.metrics.success and ref.metrics.steps_taken == flat_plan.n_steps
    assert_same_run(ref, fast)


def test_engines_agree_on_a_fall(short_plan: FootstepPlan) -> None:
    ref, fast = run_both(short_plan, SimOptions(pushes=(Push.horizontal(0.1, 150.0, 0.0),)))
    assert ref.metrics.fell and math.isfinite(ref.metrics.fall_time)
    assert_same_run(ref, fast)


def test_engines_agree_on_failed_solves(short_plan: FootstepPlan) -> None:
    # a non-finite reference state for the second step: every solve of that phase fails and
    # falls back to zero torque and the reference footstep
    states = short_plan.states.copy()
    states[2, 0, 0] = math.nan
    # FootstepPlan refuses non-finite states, so the failure is planted past its validation
    plan = replace(short_plan)
    object.__setattr__(plan, "states", states)
    ref, fast = run_both(plan, SimOptions())
    m_ticks = int(np.sum(ref.single & (ref.stance == 1)))
    assert ref.metrics.mpc_fallbacks == m_ticks > 0
    assert np.all(ref.torque_cmd[ref.stance == 1] == 0.0)
    assert_same_run(ref, fast)


def test_compiled_ball_qp_matches_the_reference() -> None:
    rng = np.random.default_rng(7)
    iters = []
    for trial in range(40):
        n = 2 * int(rng.integers(1, 10))
        a = rng.normal(size=(n, n))
        p = a @ a.T + rng.uniform(0.05, 2.0) * np.eye(n)
        q = rng.normal(0, float(rng.uniform(1, 20)), n)
        warm = trial % 2 == 1
        lam0 = rng.uniform(0, 3, n // 2) * (rng.uniform(size=n // 2) < 0.5) if warm else None
        v_ref, lam_ref, it_ref, ok_ref = solve_ball_qp(p, q, lam0)
        lam = np.zeros(n // 2) if lam0 is None else lam0.copy()
        v = np.zeros(n)
        code, it = kernel.ball_qp(p, q, n, lam, warm, DUAL_TOL, MAX_NEWTON_ITER, v)
        assert ok_ref and code == kernel.QP_CONVERGED
        assert it == it_ref
        iters.append(it)
        np.testing.assert_allclose(v, v_ref, rtol=0, atol=QP_TOL)
        np.testing.assert_allclose(lam, lam_ref, rtol=1e-9, atol=QP_TOL)
    assert max(iters) >= 3  # real Newton iterations, not just the cold-start guess


def test_compiled_ball_qp_reports_an_iteration_limit() -> None:
    rng = np.random.default_rng(3)
    a = rng.normal(size=(8, 8))
    p, q = a @ a.T + 0.1 * np.eye(8), rng.normal(0, 30, 8)
    _, _, it_ref, ok_ref = solve_ball_qp(p, q, max_iter=1)
    code, it = kernel.ball_qp(p, q, 8, np.zeros(4), False, DUAL_TOL, 1, np.zeros(8))
    assert not ok_ref and code == kernel.QP_MAX_ITER and it == it_ref == 1


class CompiledMPC:
    """The kernel's MPC tick driven like :class:`MPC` (memory kept across calls)."""

    def __init__(self, mdl: CondensedMPC) -> None:
        self.pad = mdl.padded
        nu = self.pad.gain.shape[1]
        self.mem = np.zeros(kernel.MEM_SIZE, dtype=np.int64)
        self.mem[kernel.MEM_LAST_K] = -1
        self.last_u, self.last_lam, self.last_foot = np.zeros(nu), np.zeros(nu // 2), np.zeros(3)

    def solve(
        self, k_s: int, theta: np.ndarray, ps: np.ndarray, pr: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray, bool]:
        pad, torque, foot = self.pad, np.zeros(2), np.zeros(3)
        failed = kernel.mpc_step(
            k_s,
            theta,
            ps,
            pr,
            pad.n_b,
            pad.first_block,
            pad.gain,
            pad.q_map,
            pad.p_scaled,
            pad.d_theta,
            pad.d_u,
            pad.u_limits,
            DUAL_TOL,
            MAX_NEWTON_ITER,
            self.mem,
            self.last_u,
            self.last_lam,
            self.last_foot,
            torque,
            foot,
        )
        return torque, foot, bool(failed)


@pytest.mark.parametrize("ellipse", [False, True])
def test_compiled_mpc_tick_matches_solve_theta_with_warm_starts_and_fallbacks(
    model: CondensedMPC, ellipse: bool
) -> None:
    if ellipse:  # the torque ellipse of the MuJoCo walker (U_y = 2 U_x)
        model = build_mpc(ROBOT, MPCWeights(), 0.004, torque_limits=(ROBOT.u_max, 2 * ROBOT.u_max))
    rng = np.random.default_rng(2)
    mzh = ROBOT.mass * ROBOT.com_height
    ps = np.array([0.1, -0.05, 0.02])
    ref, fast = MPC(model), CompiledMPC(model)
    active = 0
    for phase in range(3):
        pr = np.array([0.35, 0.15 * (-1) ** phase, 0.04])
        theta = np.concatenate(
            [[0.02, -0.01, 0.4 * mzh, 0.5 * mzh], pr[:2] - ps[:2], [-0.1, 0.05, 0.0, 0.2 * mzh]]
        )
        for k in range(0, model.n_ticks, 3):
            th = theta.copy()
            th[:4] += rng.normal(0, 0.01, 4) * np.array([1, 1, mzh, mzh]) * (1 + k / 20)
            p_ref = pr
            if phase == 1 and k in (30, 33):  # failures mid-phase: the last solution, shifted
                th[2] = math.nan
            if phase == 2 and k == 0:  # failure at a phase start: zero torque, reference foot
                th[0] = math.inf
            if phase == 2 and k == 3:  # ... and with a non-finite reference: the stance foot
                th[0], p_ref = math.inf, np.array([math.nan, 0.0, 0.0])
            sol = ref.solve_theta(k, th, ps, p_ref)
            torque, foot, failed = fast.solve(k, th, ps, p_ref)
            assert failed == sol.fallback
            active += int(fast.mem[kernel.MEM_ITERATIONS] > 0)
            np.testing.assert_allclose(torque, sol.torques[0], rtol=0, atol=1e-9 * ROBOT.u_max)
            np.testing.assert_allclose(foot, sol.next_footstep, rtol=0, atol=ENGINE_TOL)
    assert ref.n_fallbacks == fast.mem[kernel.MEM_FALLBACKS] == 4
    assert ref.n_solves == fast.mem[kernel.MEM_SOLVES]
    assert active >= 5


def test_kernel_clock_is_monotonic() -> None:
    a = kernel.monotonic_ns()
    b = kernel.monotonic_ns()
    assert 0 < a <= b


def test_engine_option_is_validated_and_resolved(
    short_plan: FootstepPlan, monkeypatch: pytest.MonkeyPatch
) -> None:
    with pytest.raises(InputError, match="engine"):
        SimOptions(engine="cuda")
    with pytest.raises(InputError, match="engine"):
        SimOptions(engine="compiled", solver="clarabel")
    assert reduced.resolve_engine(SimOptions()) == "compiled"
    assert reduced.resolve_engine(SimOptions(solver="clarabel")) == "python"
    monkeypatch.setattr(reduced, "compiled_available", lambda: False)
    assert reduced.resolve_engine(SimOptions()) == "python"
    with pytest.raises(SolverUnavailableError, match="numba"):
        simulate(short_plan, SimOptions(engine="compiled"))
