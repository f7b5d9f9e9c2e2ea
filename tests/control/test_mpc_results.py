"""What an MPC solve (eq. 5.19) hands back besides its optimum: the fields of ``MPCSolution`` for
a normal, a polygon-constrained and a fallback solve, the fallback's reasons, and the errors of
bad arguments with their field, value and expected text (issue 24).

References: the model's own blocking tables (``block_ticks``, ``n_blocks``; checked against an
independent statement in ``test_mpc.py``), a wall clock read around each call for the solve
times, and the inputs given (stance foot, reference height) for the footstep's echoed parts.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from footfall.control import MPC, MPCStatus, MPCWeights, build_mpc
from footfall.control import mpc as mpc_mod
from footfall.control.mpc import CondensedMPC
from footfall.errors import InputError
from footfall.models.biped import BipedParams

ROBOT = BipedParams(n_nodes=10)
RATE_DT = 0.004


@pytest.fixture(scope="module")
def model() -> CondensedMPC:
    return build_mpc(ROBOT, MPCWeights(), RATE_DT)


def _args(seed: int, k_s: int) -> tuple:
    """A solve's arguments with a stance foot off the origin (so its x, y and z differ)."""
    rng = np.random.default_rng(seed)
    mzh = ROBOT.mass * ROBOT.com_height
    x = np.array([*rng.normal(0, 0.05, 2), *(rng.normal(0, 0.3, 2) * mzh)])
    stance = np.array([0.7, -0.3, 0.05])
    ref = stance + np.array([0.25, 0.2, 0.08])
    x_ref = np.array([*rng.normal(0, 0.05, 2), *(rng.normal(0, 0.3, 2) * mzh)])
    return (k_s, x, stance, ref, x_ref)


def _timed(fn, *args):  # type: ignore[no-untyped-def]
    t0 = time.perf_counter()
    out = fn(*args)
    return out, time.perf_counter() - t0


def test_a_solve_reports_its_tick_blocks_and_time(model: CondensedMPC) -> None:
    k_s = 17
    sol, wall = _timed(MPC(model).solve, *_args(1, k_s))
    assert sol.status is MPCStatus.OPTIMAL and sol.fallback is False and sol.message == ""
    assert sol.k_s == k_s
    np.testing.assert_array_equal(sol.block_ticks, model.block_ticks[k_s])
    n_b = model.n_blocks(k_s)
    assert sol.torques.shape == (n_b, 2) and sol.multipliers.shape == (n_b,)
    assert np.all(sol.multipliers >= 0.0)
    assert isinstance(sol.iterations, int) and sol.iterations >= 0
    assert 0.0 < sol.solve_time <= wall
    # the footstep is the stance foot plus the optimised step, at the reference's height
    stance, ref = _args(1, k_s)[2], _args(1, k_s)[3]
    assert sol.next_footstep[2] == ref[2]
    assert abs(sol.next_footstep[1] - stance[1]) < 0.6  # a step from y = -0.3, not from z
    np.testing.assert_array_equal(sol.torque, sol.torques[0])


def test_a_polygon_solve_reports_the_same_fields(model: CondensedMPC) -> None:
    """A polygon that cuts the free footstep off (the constrained Clarabel path)."""
    k_s = 5
    args = _args(2, k_s)
    free = MPC(model).solve(*args)
    a = np.array([[1.0, 0.0]])
    b = np.array([free.next_footstep[0] - 0.05])
    sol, wall = _timed(MPC(model).solve_in_polygon, *args, a, b)
    assert sol.status is MPCStatus.OPTIMAL and sol.fallback is False and sol.message == ""
    assert sol.k_s == k_s
    np.testing.assert_array_equal(sol.block_ticks, model.block_ticks[k_s])
    n_b = model.n_blocks(k_s)
    assert sol.torques.shape == (n_b, 2) and sol.multipliers.shape == (n_b,)
    assert np.all(sol.multipliers >= -1e-9)
    assert isinstance(sol.iterations, int) and sol.iterations > 0
    assert 0.0 < sol.solve_time <= wall
    assert sol.next_footstep[0] == pytest.approx(b[0], abs=1e-6)  # on the cut
    assert sol.next_footstep[2] == args[3][2]
    assert abs(sol.next_footstep[1] - free.next_footstep[1]) < 0.1
    # the torque discs hold, with the torques in newton metres (not scaled)
    lim = model.u_limits
    assert np.all(np.hypot(sol.torques[:, 0] / lim[0], sol.torques[:, 1] / lim[1]) <= 1 + 1e-9)
    assert np.abs(sol.torques).max() > 1.0


def test_fallbacks_say_why_and_report_their_fields(
    model: CondensedMPC, monkeypatch: pytest.MonkeyPatch
) -> None:
    mpc = MPC(model)
    k0 = 3
    good = mpc.solve(*_args(3, k0))
    # non-finite measurement, nothing to shift at the first solve of a fresh MPC
    fresh = MPC(model)
    args = _args(3, 0)
    first, wall = _timed(fresh.solve, 0, np.full(4, np.nan), *args[2:])
    assert first.fallback is True and first.status is MPCStatus.FALLBACK
    assert first.message == "non-finite measurement or reference"
    assert first.k_s == 0 and fresh.n_fallbacks == 1
    np.testing.assert_array_equal(first.block_ticks, model.block_ticks[0])
    n_b = model.n_blocks(0)
    np.testing.assert_array_equal(first.torques, np.zeros((n_b, 2)))
    np.testing.assert_array_equal(first.multipliers, np.zeros(n_b))
    np.testing.assert_array_equal(first.next_footstep, args[3])
    assert 0.0 < first.solve_time <= wall
    # a non-finite reference footstep falls back to the stance foot
    nan_ref = fresh.solve(0, args[1], args[2], np.full(3, np.nan), args[4])
    np.testing.assert_array_equal(nan_ref.next_footstep, args[2])
    assert fresh.n_fallbacks == 2

    # a solver that does not converge, later in the phase: the good solution shifted
    def no_convergence(p, q, lam0=None, *a, **k):  # type: ignore[no-untyped-def]
        n = q.shape[0]
        return np.zeros(n), np.zeros(n // 2), 7, False

    monkeypatch.setattr(mpc_mod, "solve_ball_qp", no_convergence)
    k_s = 30
    big = _args(3, k_s)
    big = (k_s, big[1] * 50.0, *big[2:])  # torque bounds active: the ball QP is called
    late = mpc.solve(*big)
    assert late.fallback is True and late.message == "solver did not converge"
    assert late.k_s == k_s and mpc.n_fallbacks == 1
    shift = model.first_block[k_s] - model.first_block[k0]
    assert shift > 0
    np.testing.assert_array_equal(late.torques, good.torques[shift:])
    np.testing.assert_array_equal(late.multipliers, good.multipliers[shift:])
    np.testing.assert_array_equal(late.block_ticks, model.block_ticks[k_s])

    def broken(*a, **k):  # type: ignore[no-untyped-def]
        raise np.linalg.LinAlgError("singular dual Hessian (info 3)")

    monkeypatch.setattr(mpc_mod, "solve_ball_qp", broken)
    err = mpc.solve(*big)
    assert err.fallback is True and mpc.n_fallbacks == 2
    assert err.message == "solver error: singular dual Hessian (info 3)"
    assert err.k_s == k_s


def test_bad_arguments_name_field_value_and_expected(model: CondensedMPC) -> None:
    with pytest.raises(InputError) as e:
        MPC("not a model")  # type: ignore[arg-type]
    assert (e.value.field, e.value.value) == ("condensed", "not a model")
    assert e.value.expected == "a CondensedMPC from build_mpc"
    with pytest.raises(InputError) as e:
        MPC(model, solver="osqp")
    assert (e.value.field, e.value.value) == ("solver", "osqp")
    assert e.value.expected == "one of newton, clarabel"
    mpc = MPC(model)
    ok = _args(4, 0)[1:]
    with pytest.raises(InputError) as e:
        mpc.solve(model.n_ticks, *ok)
    assert (e.value.field, e.value.value) == ("k_s", model.n_ticks)
    assert e.value.expected == f"an integer tick in [0, {model.n_ticks})"
    for i, (name, n) in enumerate(
        (("x_measured", 4), ("p_stance", 3), ("p_next_ref", 3), ("x_next_ref", 4))
    ):
        bad = list(ok)
        bad[i] = np.zeros(n + 1)
        with pytest.raises(InputError) as e:
            mpc.solve(0, *bad)
        assert e.value.field == name
        assert e.value.value == [0.0] * (n + 1)
        assert e.value.expected == f"shape ({n},)"


def test_weights_errors_and_stored_values() -> None:
    for name in ("q_pos", "q_vel", "qf_pos", "qf_vel", "qf_dcm"):
        with pytest.raises(InputError) as e:
            MPCWeights(**{name: -1.0})
        assert (e.value.field, e.value.value) == (f"weights.{name}", -1.0)
        assert e.value.expected == "a finite number >= 0"
        with pytest.raises(InputError) as e:
            MPCWeights(**{name: float("inf")})
        assert e.value.field == f"weights.{name}"
    for name in ("r", "w"):
        with pytest.raises(InputError) as e:
            MPCWeights(**{name: 0.0})
        assert (e.value.field, e.value.value) == (f"weights.{name}", 0.0)
    w = MPCWeights(r=2, w=3)  # integers are stored as the floats they are
    assert (w.r, w.w) == (2.0, 3.0) and isinstance(w.r, float) and isinstance(w.w, float)


def test_torque_limit_errors_and_small_valid_limits() -> None:
    with pytest.raises(InputError) as e:
        build_mpc(ROBOT, torque_limits="ab")  # type: ignore[arg-type]
    assert (e.value.field, e.value.value) == ("torque_limits", "ab")
    assert e.value.expected == "two numbers (U_x, U_y) [N m]"
    for bad in ((0.0, 1.0), (1.0, -2.0), (1.0, float("nan")), (1.0,)):
        with pytest.raises(InputError) as e:
            build_mpc(ROBOT, torque_limits=bad)  # type: ignore[arg-type]
        assert (e.value.field, e.value.value) == ("torque_limits", bad)
        assert e.value.expected == "two finite numbers (U_x, U_y) > 0 [N m]"
    small = build_mpc(ROBOT, MPCWeights(), RATE_DT, torque_limits=(0.5, 0.25))
    np.testing.assert_array_equal(small.u_limits, [0.5, 0.25])
    with pytest.raises(InputError) as e:
        build_mpc(ROBOT, n_nodes=1)
    assert (e.value.field, e.value.value) == ("n_nodes", 1)
    assert e.value.expected == "an integer >= 2"
    for bad_n in (3.0, True):  # a float or a bool is not a node count, even when integral
        with pytest.raises(InputError) as e:
            build_mpc(ROBOT, n_nodes=bad_n)  # type: ignore[arg-type]
        assert e.value.field == "n_nodes"


def test_block_of_tick_follows_the_node_grid(model: CondensedMPC) -> None:
    """Tick k belongs to the last block whose first tick ``round(j M / (K - 1))`` is <= k (the
    blocking of eq. 5.12b's node intervals on the control ticks, stated independently)."""
    m, k_nodes = model.n_ticks, model.n_nodes
    edges = [round(j * m / (k_nodes - 1)) for j in range(k_nodes)]
    for k in range(m):
        expected = max(j for j in range(k_nodes - 1) if edges[j] <= k)
        assert model.block_of_tick(k) == expected, k
        assert isinstance(model.block_of_tick(k), int)


def test_a_non_integer_tick_is_named_with_its_value(model: CondensedMPC) -> None:
    with pytest.raises(InputError) as e:
        MPC(model).solve(1.5, *_args(5, 0)[1:])  # type: ignore[arg-type]
    assert (e.value.field, e.value.value) == ("k_s", 1.5)
    assert e.value.expected == f"an integer tick in [0, {model.n_ticks})"


def test_free_and_bounded_solves_report_their_multipliers_and_iterations(
    model: CondensedMPC,
) -> None:
    """The unconstrained optimum scales linearly with the state (eq. 5.19 without the discs), so
    a state scaled until the free torques reach 1.2 x their disc must come back on the disc
    (not accepted as it is), with at least one Newton iteration and a positive multiplier; a
    state small enough to stay inside gives zero multipliers, one per block, and 0 iterations."""
    k_s = 40
    args = _args(6, k_s)
    wide = build_mpc(ROBOT, MPCWeights(), RATE_DT, torque_limits=(1e6, 1e6))
    free = MPC(wide).solve(*args)  # the discs never bind: the unconstrained optimum
    lim = model.u_limits
    scaled = np.hypot(free.torques[:, 0] / lim[0], free.torques[:, 1] / lim[1]).max()
    n_b = model.n_blocks(k_s)
    for factor, active in ((1.2 / scaled, True), (0.5 / scaled, False)):
        x = args[1] * factor
        ref = args[4] * factor
        p_ref = args[2] + (args[3] - args[2]) * factor
        sol = MPC(model).solve(k_s, x, args[2], p_ref, ref)
        norms = np.hypot(sol.torques[:, 0] / lim[0], sol.torques[:, 1] / lim[1])
        assert sol.multipliers.shape == (n_b,)
        if active:
            assert norms.max() == pytest.approx(1.0, abs=1e-6)
            assert sol.iterations >= 1 and sol.multipliers.max() > 0.0
        else:
            assert norms.max() <= 0.5 + 1e-9
            assert sol.iterations == 0
            np.testing.assert_array_equal(sol.multipliers, np.zeros(n_b))


def test_clarabel_backend_answers_each_new_state_and_prints_nothing(
    model: CondensedMPC, capfd: pytest.CaptureFixture[str]
) -> None:
    """The Clarabel backend keeps one solver per tick and updates its linear term: a second
    state at the same tick must get its own answer (a fresh MPC's), and its ball multipliers
    are the Newton backend's (both are the duals of the same scaled discs)."""
    k_s = 12
    a1 = _args(7, k_s)
    a2 = (k_s, a1[1] * 40.0, *a1[2:])  # torque discs active
    cached = MPC(model, solver="clarabel")
    cached.solve(*a1)
    second = cached.solve(*a2)
    fresh = MPC(model, solver="clarabel").solve(*a2)
    np.testing.assert_allclose(second.torques, fresh.torques, atol=1e-3)  # interior-point tol
    newton = MPC(model).solve(*a2)
    np.testing.assert_allclose(second.torques, newton.torques, atol=1e-3)
    assert newton.multipliers.max() > 0.0
    np.testing.assert_allclose(second.multipliers, newton.multipliers, rtol=1e-3, atol=1e-6)
    assert capfd.readouterr().out == ""


def test_the_last_solution_after_a_polygon_solve_and_a_reset(model: CondensedMPC) -> None:
    """A fallback returns the last good solution shifted by the blocks that passed (here from
    block 1 to block 2): after a polygon solve that solution is the polygon one; after
    ``reset`` there is none (zero torques)."""
    k0, k_s = 15, 25
    assert (model.first_block[k0], model.first_block[k_s]) == (1, 2)
    mpc = MPC(model)
    args = _args(8, k0)
    free = mpc.solve(*args)
    a = np.array([[1.0, 0.0]])
    b = np.array([free.next_footstep[0] - 0.05])
    poly = mpc.solve_in_polygon(*args, a, b)
    assert poly.next_footstep[0] == pytest.approx(b[0], abs=1e-6)
    bad = mpc.solve(k_s, np.full(4, np.nan), *args[2:])
    assert bad.fallback
    np.testing.assert_array_equal(bad.next_footstep, poly.next_footstep)
    np.testing.assert_array_equal(bad.torques, poly.torques[1:])
    mpc.reset()
    after = mpc.solve(k_s, np.full(4, np.nan), *args[2:])
    np.testing.assert_array_equal(after.torques, np.zeros((model.n_blocks(k_s), 2)))
    good = mpc.solve(*_args(8, k_s))
    assert not good.fallback


def test_a_solver_failure_at_the_first_solve_falls_back_to_zero_torque_and_the_reference(
    model: CondensedMPC, monkeypatch: pytest.MonkeyPatch
) -> None:
    """With no earlier solution there is nothing to shift: zero torques, the reference
    footstep, and the reason (non-convergence or a solver error)."""

    def no_convergence(p, q, lam0=None, *a, **k):  # type: ignore[no-untyped-def]
        return np.zeros(q.shape[0]), np.zeros(q.shape[0] // 2), 7, False

    def broken(*a, **k):  # type: ignore[no-untyped-def]
        raise np.linalg.LinAlgError("singular dual Hessian (info 3)")

    k_s = 30
    base = _args(9, k_s)
    args = (k_s, base[1] * 50.0, *base[2:])  # torque discs active: the ball QP is called
    for fake, reason in ((no_convergence, "solver did not converge"), (broken, "solver error")):
        monkeypatch.setattr(mpc_mod, "solve_ball_qp", fake)
        sol = MPC(model).solve(*args)
        assert sol.fallback is True and sol.message.startswith(reason)
        np.testing.assert_array_equal(sol.torques, np.zeros((model.n_blocks(k_s), 2)))
        np.testing.assert_array_equal(sol.next_footstep, args[3])


def test_warm_starts_from_the_last_solution_save_iterations(model: CondensedMPC) -> None:
    """Consecutive ticks of one single support with the torque discs active: the multipliers of
    the last solution, shifted by the blocks that passed, start the next dual solve. Over 8
    seeded phases the warm-started solves need fewer Newton iterations in total than the same
    solves started cold (fresh MPCs), with the same torques."""
    warm_total = cold_total = 0
    for seed in range(8):
        base = _args(20 + seed, 0)
        x0, x_ref = base[1] * 30.0, base[4]
        ticks = list(range(0, 40, 3))  # crosses block boundaries (blocks of ~11 ticks)
        mpc = MPC(model)
        ad, bd = ROBOT.alip().discretize(model.control_dt)
        x = x0
        for k in ticks:
            warm = mpc.solve(k, x, base[2], base[3], x_ref)
            cold = MPC(model).solve(k, x, base[2], base[3], x_ref)
            np.testing.assert_allclose(warm.torques, cold.torques, atol=1e-6)
            if k > 0:
                warm_total += warm.iterations
                cold_total += cold.iterations
            for _ in range(3):  # the ALIP moves on under the applied torque
                x = ad @ x + bd @ warm.torque
    assert cold_total > 0
    assert warm_total < cold_total, (warm_total, cold_total)
