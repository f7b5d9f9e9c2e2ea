"""MPC of eq. (5.19): condensed matrices vs step-by-step simulation, solutions vs an independent
sparse SOCP solved by Clarabel, the torque ball (not a box), fallback and input errors."""

from __future__ import annotations

import dataclasses
import itertools

import clarabel
import numpy as np
import pytest
from scipy import sparse

from footfall.control import MPC, MPCStatus, MPCWeights, build_mpc, solve_ball_qp
from footfall.control.mpc import CondensedMPC
from footfall.errors import InputError
from footfall.models.biped import BipedParams

#: condensed prediction vs tick-by-tick simulation (relative to the state scale)
PREDICTION_TOL = 1e-9
#: condensed cost vs cost summed from a simulation
COST_RTOL = 1e-9
#: optimal cost of the MPC vs the reference interior-point solve (relative)
OPTIMALITY_RTOL = 1e-6
#: torques of the MPC vs the reference solve [N m]
TORQUE_ATOL = 1e-3
#: ball constraint slack [N m]
BALL_TOL = 1e-9

ROBOT = BipedParams(n_nodes=10)
RATE_DT = 0.004  # 250 Hz keeps the reference problems small


@pytest.fixture(scope="module")
def model() -> CondensedMPC:
    return build_mpc(ROBOT, MPCWeights(), RATE_DT)


def blocks_of_ticks(m: int, k_nodes: int) -> np.ndarray:
    """Independent statement of the blocking: tick k belongs to block floor-ish(k (K-1) / M)."""
    edges = [round(j * m / (k_nodes - 1)) for j in range(k_nodes)]
    return np.array([max(j for j in range(k_nodes - 1) if edges[j] <= k) for k in range(m)])


def simulate_ticks(model: CondensedMPC, k_s: int, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """States at ticks k_s+1..M, torque block held per tick, with the ALIP's own ZOH."""
    ad, bd = ROBOT.alip().discretize(model.control_dt)
    blk = blocks_of_ticks(model.n_ticks, model.n_nodes)
    first = blk[k_s]
    xs, x = [], x0.copy()
    for k in range(k_s, model.n_ticks):
        x = ad @ x + bd @ u[blk[k] - first]
        xs.append(x)
    return np.array(xs)


def random_theta(rng: np.random.Generator, scale: float = 1.0) -> np.ndarray:
    mzh = ROBOT.mass * ROBOT.com_height
    x = np.array([*rng.normal(0, 0.05, 2), *(rng.normal(0, 0.3, 2) * mzh * scale)])
    d_ref = np.array([0.25, 0.2 * rng.choice([-1.0, 1.0])]) + rng.normal(0, 0.02, 2)
    x_ref = np.array([*rng.normal(0, 0.05, 2), *(rng.normal(0, 0.3, 2) * mzh)])
    return np.concatenate([x, d_ref, x_ref])


def test_horizon_shrinks_and_covers_the_remaining_ticks(model: CondensedMPC) -> None:
    assert model.n_ticks == round(ROBOT.t_ss / RATE_DT)
    counts = [model.n_blocks(k) for k in range(model.n_ticks)]
    assert counts[0] == ROBOT.n_nodes - 1 and counts[-1] == 1
    assert all(a >= b for a, b in itertools.pairwise(counts))
    for k in range(model.n_ticks):
        assert model.block_ticks[k].sum() == model.n_ticks - k
        assert np.all(model.block_ticks[k] >= 1)


@pytest.mark.parametrize("k_s", [0, 1, 21, 37, 62, 99])
def test_condensed_prediction_matches_step_by_step_simulation(
    model: CondensedMPC, k_s: int
) -> None:
    rng = np.random.default_rng(k_s)
    x0 = random_theta(rng)[:4]
    u = rng.uniform(-20, 20, (model.n_blocks(k_s), 2))
    phi, gamma = model.stacked(k_s)
    pred = phi @ x0 + gamma @ u.ravel()
    ref = simulate_ticks(model, k_s, x0, u)
    scale = np.abs(ref).max(axis=0)
    np.testing.assert_allclose(pred / scale, ref / scale, atol=PREDICTION_TOL)
    np.testing.assert_allclose(
        (model.a_end[k_s] @ x0 + model.b_end[k_s] @ u.ravel()) / scale,
        ref[-1] / scale,
        atol=PREDICTION_TOL,
    )


@pytest.mark.parametrize("k_s", [0, 13, 50, 98])
def test_condensed_cost_matches_cost_of_a_simulation(model: CondensedMPC, k_s: int) -> None:
    """Eq. (5.19a) evaluated term by term on a simulated trajectory equals the condensed form."""
    rng = np.random.default_rng(100 + k_s)
    theta = random_theta(rng)
    x0, d_ref, x_ref = theta[:4], theta[4:6], theta[6:]
    u = rng.uniform(-20, 20, (model.n_blocks(k_s), 2))
    d = d_ref + rng.normal(0, 0.05, 2)
    dt = model.control_dt
    xs = simulate_ticks(model, k_s, x0, u)
    natural = simulate_ticks(model, k_s, x0, np.zeros_like(u))
    blk = blocks_of_ticks(model.n_ticks, model.n_nodes)[k_s:]
    u_ticks = u[blk - blk[0]]
    a_r, b_r = ROBOT.alip().reset_map(ROBOT.t_ds)
    x_next = a_r @ xs[-1] + b_r @ np.array([d[0], d[1], 0.3])  # z does not enter (eq. 5.10)
    e = xs - natural
    j = dt * np.einsum("ki,ij,kj->", e, model.Q, e)
    j += dt * np.einsum("ki,ij,kj->", u_ticks, model.R, u_ticks)
    j += (d - d_ref) @ model.W @ (d - d_ref) + (x_next - x_ref) @ model.Qf @ (x_next - x_ref)
    z = np.concatenate([u.ravel(), d])
    assert model.cost(k_s, z, theta) == pytest.approx(j, rel=COST_RTOL)


def reference_solve(
    model: CondensedMPC,
    k_s: int,
    theta: np.ndarray,
    limits: tuple[float, float] | None = None,
    polygon: tuple[np.ndarray, np.ndarray] | None = None,
) -> tuple[float, np.ndarray]:
    """Sparse SOCP of eq. (5.19) (states as variables, one per tick) solved by Clarabel.

    Variables: u blocks (2 n_b), d (2), x_{k_s+1..M} (4 T), x_next (4). Written from the
    equations, not from the condensed matrices. ``limits`` = ellipse semi-axes (U_x, U_y);
    default the ball U_max. ``polygon`` = ``(a, b)``: the footstep offset ``d`` (from a stance
    foot at the origin) must satisfy ``a d <= b``.
    """
    lim = (ROBOT.u_max, ROBOT.u_max) if limits is None else limits
    n_b = model.n_blocks(k_s)
    t_n = model.n_ticks - k_s
    n_u, iu_d = 2 * n_b, 2 * n_b
    ix = n_u + 2
    ixn = ix + 4 * t_n
    n = ixn + 4
    x0, d_ref, x_ref = theta[:4], theta[4:6], theta[6:]
    ad, bd, dt = model.ad, model.bd, model.control_dt
    blk = blocks_of_ticks(model.n_ticks, model.n_nodes)[k_s:]
    blk = blk - blk[0]
    # natural trajectory from x0 (5.19a's reference)
    nat, x = [], x0.copy()
    for _ in range(t_n):
        x = ad @ x
        nat.append(x)
    p = np.zeros((n, n))
    q = np.zeros(n)
    for k in range(t_n):
        sl = slice(ix + 4 * k, ix + 4 * k + 4)
        p[sl, sl] += 2 * dt * model.Q
        q[sl] += -2 * dt * model.Q @ nat[k]
        ub = slice(2 * blk[k], 2 * blk[k] + 2)
        p[ub, ub] += 2 * dt * model.R
    p[iu_d : iu_d + 2, iu_d : iu_d + 2] += 2 * model.W
    q[iu_d : iu_d + 2] += -2 * model.W @ d_ref
    p[ixn:, ixn:] += 2 * model.Qf
    q[ixn:] += -2 * model.Qf @ x_ref
    rows_eq, b_eq = [], []
    for k in range(t_n):
        for i in range(4):
            r = np.zeros(n)
            r[ix + 4 * k + i] = 1.0
            if k > 0:
                r[ix + 4 * (k - 1) : ix + 4 * k] -= ad[i]
            r[2 * blk[k] : 2 * blk[k] + 2] -= bd[i]
            rows_eq.append(r)
            b_eq.append(ad[i] @ x0 if k == 0 else 0.0)
    for i in range(4):  # reset map (5.19c)
        r = np.zeros(n)
        r[ixn + i] = 1.0
        r[ix + 4 * (t_n - 1) : ix + 4 * t_n] -= model.ar[i]
        r[iu_d : iu_d + 2] -= model.br[i, :2]
        rows_eq.append(r)
        b_eq.append(0.0)
    rows_c, b_c = [], []
    for j in range(n_b):  # (1, u_jx / U_x, u_jy / U_y) in the second-order cone (5.19e)
        rows_c.append(np.zeros(n))
        b_c.append(1.0)
        for i in range(2):
            r = np.zeros(n)
            r[2 * j + i] = -1.0 / lim[i]
            rows_c.append(r)
            b_c.append(0.0)
    rows_p, b_p = [], []
    if polygon is not None:
        for a_row, b_row in zip(*polygon, strict=True):
            r = np.zeros(n)
            r[iu_d : iu_d + 2] = a_row
            rows_p.append(r)
            b_p.append(b_row)
    a = sparse.csc_matrix(np.array(rows_eq + rows_p + rows_c))
    b = np.array(b_eq + b_p + b_c)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = 1e-10
    settings.tol_feas = 1e-10
    cones = [clarabel.ZeroConeT(len(b_eq))]
    if rows_p:
        cones.append(clarabel.NonnegativeConeT(len(rows_p)))
    cones += [clarabel.SecondOrderConeT(3)] * n_b
    sol = clarabel.DefaultSolver(
        sparse.triu(sparse.csc_matrix(p)).tocsc(), q, a, b, cones, settings
    ).solve()
    assert str(sol.status) == "Solved"
    z = np.asarray(sol.x)[: n_u + 2]
    return model.cost(k_s, z, theta), z


@pytest.mark.parametrize("seed", range(8))
def test_solution_is_feasible_and_optimal_against_a_sparse_reference(
    model: CondensedMPC, seed: int
) -> None:
    rng = np.random.default_rng(seed)
    k_s = int(rng.integers(0, model.n_ticks))
    # large velocity errors so that several torque balls are active
    theta = random_theta(rng, scale=3.0 if seed % 2 else 0.3)
    mpc = MPC(model)
    sol = mpc.solve(k_s, theta[:4], np.zeros(3), np.array([*theta[4:6], 0.1]), theta[6:])
    assert sol.status is MPCStatus.OPTIMAL and not sol.fallback
    norms = np.linalg.norm(sol.torques, axis=1)
    assert np.all(norms <= ROBOT.u_max + BALL_TOL)
    assert sol.next_footstep[2] == pytest.approx(0.1)  # height stays at the reference
    z = np.concatenate([sol.torques.ravel(), sol.next_footstep[:2]])
    ref_cost, z_ref = reference_solve(model, k_s, theta)
    cost = model.cost(k_s, z, theta)
    assert cost <= ref_cost * (1 + OPTIMALITY_RTOL) + 1e-9
    np.testing.assert_allclose(z[:-2], z_ref[:-2], atol=TORQUE_ATOL)


@pytest.mark.parametrize("solver", ["newton", "clarabel"])
def test_elliptic_torque_bound_matches_the_sparse_reference(solver: str) -> None:
    """With semi-axes (U_max, 2.5 U_max) the solution lies in the ellipse, some torques on its
    boundary beyond U_max along u_y, and is the sparse reference's optimum."""
    lim = (ROBOT.u_max, 2.5 * ROBOT.u_max)
    model = build_mpc(ROBOT, MPCWeights(), RATE_DT, torque_limits=lim)
    rng = np.random.default_rng(5)
    beyond_ball = 0
    for seed in range(6):
        theta = random_theta(rng, scale=3.0)
        k_s = int(rng.integers(0, model.n_ticks))
        sol = MPC(model, solver=solver).solve(
            k_s, theta[:4], np.zeros(3), np.array([*theta[4:6], 0.0]), theta[6:]
        )
        assert sol.status is MPCStatus.OPTIMAL, seed
        scaled = np.hypot(sol.torques[:, 0] / lim[0], sol.torques[:, 1] / lim[1])
        assert np.all(scaled <= 1.0 + BALL_TOL / ROBOT.u_max)
        beyond_ball += int(np.sum(np.abs(sol.torques[:, 1]) > ROBOT.u_max * 1.05))
        z = np.concatenate([sol.torques.ravel(), sol.next_footstep[:2]])
        ref_cost, z_ref = reference_solve(model, k_s, theta, lim)
        assert model.cost(k_s, z, theta) <= ref_cost * (1 + OPTIMALITY_RTOL) + 1e-9
        np.testing.assert_allclose(z[:-2], z_ref[:-2], atol=TORQUE_ATOL * 2.5)
    assert beyond_ball > 0, "no torque used the longer axis of the ellipse"


def test_footstep_polygon_that_holds_the_free_optimum_changes_nothing(
    model: CondensedMPC,
) -> None:
    rng = np.random.default_rng(21)
    theta = random_theta(rng, scale=1.0)
    args = (12, theta[:4], np.zeros(3), np.array([*theta[4:6], 0.0]), theta[6:])
    free = MPC(model).solve(*args)
    # a 1 m square around the free footstep
    a = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
    c = free.next_footstep[:2]
    b = np.array([c[0] + 0.5, 0.5 - c[0], c[1] + 0.5, 0.5 - c[1]])
    inside = MPC(model).solve_in_polygon(*args, a, b)
    np.testing.assert_array_equal(inside.torques, free.torques)
    np.testing.assert_array_equal(inside.next_footstep, free.next_footstep)


@pytest.mark.parametrize("seed", range(4))
def test_footstep_polygon_is_respected_and_torques_compensate(seed: int) -> None:
    """A polygon that cuts the free footstep off: the result lies in it, in the torque ellipse,
    is the sparse reference's optimum, and its torques differ from the free solution's."""
    lim = (ROBOT.u_max, 2.0 * ROBOT.u_max)
    model = build_mpc(ROBOT, MPCWeights(), RATE_DT, torque_limits=lim)
    rng = np.random.default_rng(100 + seed)
    theta = random_theta(rng, scale=1.5)
    k_s = int(rng.integers(0, model.n_ticks // 2))
    stance = np.array([0.3, -0.2, 0.05])
    ref = np.array([stance[0] + theta[4], stance[1] + theta[5], 0.1])
    args = (k_s, theta[:4], stance, ref, theta[6:])
    free = MPC(model).solve(*args)
    # half-planes through a point 3 cm short of the free footstep, plus a far box
    normal = rng.normal(size=2)
    normal /= np.linalg.norm(normal)
    cut = free.next_footstep[:2] - 0.03 * normal
    a = np.vstack([normal, np.eye(2), -np.eye(2)])
    b = np.concatenate([[normal @ cut], stance[:2] + 2.0, 2.0 - stance[:2]])
    sol = MPC(model).solve_in_polygon(*args, a, b)
    assert sol.status is MPCStatus.OPTIMAL and not sol.fallback and sol.message == ""
    assert np.all(a @ sol.next_footstep[:2] <= b + 1e-6)
    assert normal @ sol.next_footstep[:2] == pytest.approx(normal @ cut, abs=1e-6)  # active
    scaled = np.hypot(sol.torques[:, 0] / lim[0], sol.torques[:, 1] / lim[1])
    assert np.all(scaled <= 1.0 + 1e-9)
    assert sol.next_footstep[2] == pytest.approx(0.1)
    z = np.concatenate([sol.torques.ravel(), sol.next_footstep[:2] - stance[:2]])
    ref_cost, z_ref = reference_solve(model, k_s, theta, lim, (a, b - a @ stance[:2]))
    assert model.cost(k_s, z, theta) <= ref_cost * (1 + OPTIMALITY_RTOL) + 1e-9
    # the cost is the strict check; two interior-point solutions of a problem this flat in the
    # torques (R = 1e-3) agree to ~1e-4 of U_y in them
    np.testing.assert_allclose(z[:-2], z_ref[:-2], atol=1e-4 * lim[1])
    np.testing.assert_allclose(z[-2:], z_ref[-2:], atol=1e-5)
    assert np.abs(sol.torques[0] - free.torques[0]).max() > 1e-3


def test_empty_footstep_polygon_returns_the_free_solution_with_a_message(
    model: CondensedMPC,
) -> None:
    rng = np.random.default_rng(4)
    theta = random_theta(rng)
    args = (0, theta[:4], np.zeros(3), np.array([*theta[4:6], 0.0]), theta[6:])
    free = MPC(model).solve(*args)
    a = np.array([[1.0, 0.0], [-1.0, 0.0]])
    b = np.array([-1.0, -1.0])  # x <= -1 and x >= 1
    sol = MPC(model).solve_in_polygon(*args, a, b)
    np.testing.assert_array_equal(sol.next_footstep, free.next_footstep)
    assert "polygon" in sol.message
    for bad_a, bad_b in ((np.zeros((2, 3)), np.zeros(2)), (np.zeros((2, 2)), np.zeros(3))):
        with pytest.raises(InputError):
            MPC(model).solve_in_polygon(*args, bad_a, bad_b)


def test_torque_bound_is_a_disc_not_a_box(model: CondensedMPC) -> None:
    """A large diagonal disturbance saturates torques on the circle, below U_max per axis."""
    rng = np.random.default_rng(7)
    found = False
    for _ in range(40):
        theta = random_theta(rng, scale=3.0)
        sol = MPC(model).solve(0, theta[:4], np.zeros(3), np.array([*theta[4:6], 0]), theta[6:])
        norms = np.linalg.norm(sol.torques, axis=1)
        on_circle = np.abs(norms - ROBOT.u_max) < 1e-6
        both_axes = np.all(np.abs(sol.torques) > 0.2 * ROBOT.u_max, axis=1)
        if np.any(on_circle & both_axes):
            # a box |u_x|, |u_y| <= U_max would allow norms up to sqrt(2) U_max here
            assert np.all(np.abs(sol.torques[on_circle]) < ROBOT.u_max - 1e-3)
            found = True
            break
    assert found, "no instance with a torque on the circle away from the axes"


def test_unconstrained_solution_satisfies_stationarity(model: CondensedMPC) -> None:
    rng = np.random.default_rng(3)
    theta = random_theta(rng, scale=0.05)
    k_s = 40
    sol = MPC(model).solve(k_s, theta[:4], np.zeros(3), np.array([*theta[4:6], 0]), theta[6:])
    assert sol.iterations == 0 and np.all(np.linalg.norm(sol.torques, axis=1) < ROBOT.u_max)
    z = np.concatenate([sol.torques.ravel(), sol.next_footstep[:2]])
    grad = model.H[k_s] @ z + model.F[k_s] @ theta
    assert np.abs(grad).max() < 1e-8 * (1 + np.abs(model.F[k_s] @ theta).max())


def test_clarabel_backend_agrees_with_newton(model: CondensedMPC) -> None:
    rng = np.random.default_rng(11)
    for _ in range(5):
        theta = random_theta(rng, scale=3.0)
        k_s = int(rng.integers(0, model.n_ticks))
        args = (k_s, theta[:4], np.zeros(3), np.array([*theta[4:6], 0]), theta[6:])
        a, b = MPC(model).solve(*args), MPC(model, solver="clarabel").solve(*args)
        np.testing.assert_allclose(a.torques, b.torques, atol=TORQUE_ATOL)
        np.testing.assert_allclose(a.next_footstep, b.next_footstep, atol=1e-5)


def test_ball_qp_matches_kkt_conditions() -> None:
    """solve_ball_qp on a random strictly convex problem: stationarity and complementarity."""
    rng = np.random.default_rng(5)
    a = rng.normal(size=(8, 8))
    p = a @ a.T + 0.5 * np.eye(8)
    q = rng.normal(0, 10, 8)
    v, lam, _, ok = solve_ball_qp(p, q)
    assert ok
    vb = v.reshape(4, 2)
    norms = np.linalg.norm(vb, axis=1)
    assert np.all(norms <= 1 + 1e-12) and np.all(lam >= 0)
    assert np.all((lam < 1e-9) | (np.abs(norms - 1) < 1e-8))
    stat = p @ v + q + np.repeat(lam, 2) * v
    assert np.abs(stat).max() < 1e-6


def test_failed_solve_returns_the_last_good_solution_shifted(model: CondensedMPC) -> None:
    rng = np.random.default_rng(9)
    theta = random_theta(rng)
    mpc = MPC(model)
    args = (np.zeros(3), np.array([*theta[4:6], 0]), theta[6:])
    good = mpc.solve(10, theta[:4], *args)
    k_s = 30  # one block later (blocks of ~11 ticks at 250 Hz)
    bad = mpc.solve(k_s, np.array([np.nan, 0, 0, 0]), *args)
    assert bad.fallback and bad.status is MPCStatus.FALLBACK
    assert mpc.n_fallbacks == 1 and mpc.n_solves == 2
    shift = model.first_block[k_s] - model.first_block[10]
    assert shift > 0
    np.testing.assert_array_equal(bad.torques, good.torques[shift:])
    np.testing.assert_array_equal(bad.next_footstep, good.next_footstep)
    # a failure at the start of a new single support has nothing to shift: zero torque, reference
    first = mpc.solve(0, np.full(4, np.inf), *args)
    assert first.fallback and np.all(first.torques == 0)
    np.testing.assert_array_equal(first.next_footstep[:2], theta[4:6])


def test_bad_inputs_raise_input_errors(model: CondensedMPC) -> None:
    mpc = MPC(model)
    ok = (np.zeros(4), np.zeros(3), np.array([0.25, 0.2, 0]), np.zeros(4))
    with pytest.raises(InputError, match="k_s"):
        mpc.solve(model.n_ticks, *ok)
    with pytest.raises(InputError, match="k_s"):
        mpc.solve(1.5, *ok)  # type: ignore[arg-type]
    with pytest.raises(InputError, match="x_measured"):
        mpc.solve(0, np.zeros(3), *ok[1:])
    with pytest.raises(InputError, match="solver"):
        MPC(model, solver="osqp")
    with pytest.raises(InputError, match=r"weights\.r"):
        MPCWeights(r=0.0)
    with pytest.raises(InputError, match=r"weights\.w"):
        MPCWeights(w=-1.0)
    with pytest.raises(InputError, match="control_dt"):
        build_mpc(ROBOT, control_dt=-0.002)
    with pytest.raises(InputError, match="n_nodes"):
        build_mpc(ROBOT, n_nodes=1)
    for bad in ((1.0,), (1.0, -2.0), (1.0, float("nan")), "ab"):
        with pytest.raises(InputError, match="torque_limits"):
            build_mpc(ROBOT, torque_limits=bad)  # type: ignore[arg-type]


def test_padded_matrices_hold_the_per_tick_matrices(model: CondensedMPC) -> None:
    pad = model.padded
    assert pad is model.padded  # built once
    nu = 2 * (model.n_nodes - 1)
    assert pad.p_scaled.shape == (model.n_ticks, nu, nu) and np.all(pad.u_limits == ROBOT.u_max)
    for k in range(model.n_ticks):
        n = 2 * model.n_blocks(k)
        assert pad.n_b[k] == model.n_blocks(k) and pad.first_block[k] == model.first_block[k]
        for padded, exact in (
            (pad.p_scaled[k], model._p_scaled[k]),
            (pad.q_map[k], model._q_map[k]),
            (pad.gain[k], model._gain[k]),
            (pad.d_u[k].T, model._d_u[k].T),
        ):
            np.testing.assert_array_equal(padded[:n, : exact.shape[1]], exact)
            assert not padded[n:].any() and not padded[:, exact.shape[1] :].any()
        np.testing.assert_array_equal(pad.d_theta[k], model._d_theta[k])


@pytest.mark.parametrize("factor", [0.5, 3.0])
def test_a_heavier_robot_gets_the_same_centre_of_pressure_plan(factor: float) -> None:
    """The ALIP in (position, velocity, CoP = u / (m g)) does not depend on the mass: a robot
    ``factor`` times heavier, measured with ``factor`` times the momentum, must get the same
    footstep and ``factor`` times the torques (the same CoP) when R is scaled by the mass
    (``r_mass``), with the torque balls active or not (U_max scaled alike). The document's
    literal R (the default, ``r_mass=None``) breaks this where the balls are not all active:
    the heavier robot moves its footstep instead."""
    heavy = dataclasses.replace(ROBOT, mass=ROBOT.mass * factor, u_max=ROBOT.u_max * factor)
    rng = np.random.default_rng(7)
    scaled = MPCWeights(r_mass=ROBOT.mass)
    for weights, invariant in ((scaled, True), (MPCWeights(), False)):
        light_mpc = MPC(build_mpc(ROBOT, weights, RATE_DT))
        heavy_mpc = MPC(build_mpc(heavy, weights, RATE_DT))
        worst_step, worst_cop = 0.0, 0.0
        for j in range(6):
            theta = random_theta(rng, scale=3.0 if j % 2 else 0.3)
            k_s = int(rng.integers(0, light_mpc.model.n_ticks))
            momentum = np.array([1.0, 1.0, factor, factor])
            args = (np.zeros(3), np.array([*theta[4:6], 0.0]))
            a = light_mpc.solve(k_s, theta[:4], *args, theta[6:])
            b = heavy_mpc.solve(k_s, theta[:4] * momentum, *args, theta[6:] * momentum)
            assert a.status is MPCStatus.OPTIMAL and b.status is MPCStatus.OPTIMAL
            worst_step = max(worst_step, float(np.max(np.abs(a.next_footstep - b.next_footstep))))
            worst_cop = max(worst_cop, float(np.max(np.abs(a.torques * factor - b.torques))))
        if invariant:
            assert worst_step < 1e-7 and worst_cop < 1e-6 * ROBOT.u_max * factor
        else:
            assert worst_step > 1e-3


@pytest.mark.parametrize("value", [0.0, -30.0, float("nan"), float("inf")])
def test_r_mass_must_be_a_positive_mass(value: float) -> None:
    with pytest.raises(InputError) as err:
        MPCWeights(r_mass=value)
    assert err.value.field == "weights.r_mass"
