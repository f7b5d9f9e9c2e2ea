"""MPC of eq. (5.19) against references that share nothing with the code under test.

The ALIP dynamics (eq. 5.2-5.4), the double-support ramp of the reset map (eq. 5.8-5.10) and the
cost weights (eq. 5.19a with the capture-point term of ``MPCWeights``) are written out here from
the document, not read from ``footfall.models`` or from the condensed model: a wrong
discretisation (e.g. forward Euler) or a wrong sign in the terminal weight makes these fail even
when the code's own matrices are consistent with each other.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from footfall.control import MPC, MPCWeights, build_mpc
from footfall.control.mpc import CondensedMPC
from footfall.errors import InputError
from footfall.models.biped import BipedParams
from tests.conftest import IVP_ATOL, IVP_RTOL

#: condensed prediction vs solve_ivp, relative to the largest state entry
IVP_PREDICTION_RTOL = 1e-7
#: one-tick matrices vs expm of the matrices written out here
EXPM_ATOL = 1e-12
#: cost matrices vs the hand-built ones (relative to their largest entry)
WEIGHT_RTOL = 1e-12
#: MPC optimum vs the minimiser of the written-out quadratic [N m] and [m]
OPT_TORQUE_ATOL = 1e-8
OPT_STEP_ATOL = 1e-10

ROBOT = BipedParams(n_nodes=6)
RATE_DT = 0.004
M_KG, ZH, G = ROBOT.mass, ROBOT.com_height, ROBOT.g
MZH = M_KG * ZH
OMEGA = np.sqrt(G / ZH)


def alip_rhs(x: np.ndarray, u: np.ndarray) -> np.ndarray:
    """ALIP of eq. (5.2)-(5.4): x = [x_c, y_c, L_x, L_y], u = [tau_x, tau_y]."""
    return np.array(
        [x[3] / MZH, -x[2] / MZH, -M_KG * G * x[1] + u[0], M_KG * G * x[0] + u[1]],
    )


#: the same dynamics as matrices, column by column from alip_rhs (written out, not from the code)
A_CONT = np.array(
    [
        [0.0, 0.0, 0.0, 1.0 / MZH],
        [0.0, 0.0, -1.0 / MZH, 0.0],
        [0.0, -M_KG * G, 0.0, 0.0],
        [M_KG * G, 0.0, 0.0, 0.0],
    ]
)
B_CONT = np.vstack([np.zeros((2, 2)), np.eye(2)])


@pytest.fixture(scope="module")
def model() -> CondensedMPC:
    return build_mpc(ROBOT, MPCWeights(), RATE_DT)


def tick_blocks(model: CondensedMPC, k_s: int) -> np.ndarray:
    """Index of the remaining torque block applied at each tick k_s..M-1 (from block_ticks)."""
    return np.repeat(np.arange(model.n_blocks(k_s)), model.block_ticks[k_s])


def ivp_trajectory(model: CondensedMPC, k_s: int, x0: np.ndarray, u: np.ndarray) -> np.ndarray:
    """States at ticks k_s+1..M by solve_ivp, the block torque held over each tick."""
    dt = model.control_dt
    xs, x = [], np.array(x0, dtype=float)
    for b in tick_blocks(model, k_s):
        sol = solve_ivp(
            lambda _t, y, ub=u[b]: alip_rhs(y, ub), (0.0, dt), x, rtol=IVP_RTOL, atol=IVP_ATOL
        )
        x = sol.y[:, -1]
        xs.append(x)
    return np.array(xs)


def random_state(rng: np.random.Generator, speed: float = 0.3) -> np.ndarray:
    return np.array([*rng.normal(0, 0.05, 2), *(rng.normal(0, speed, 2) * MZH)])


def zoh_by_hand(dt: float) -> tuple[np.ndarray, np.ndarray]:
    """A_d = expm(A dt), B_d = int_0^dt expm(A s) ds B (eq. 5.7a-b) from the A, B written here."""
    aug = np.zeros((6, 6))
    aug[:4, :4], aug[:4, 4:] = A_CONT * dt, B_CONT * dt
    e = expm(aug)
    return e[:4, :4], e[:4, 4:]


def test_one_tick_matrices_are_the_exact_zoh_of_the_written_out_alip(model: CondensedMPC) -> None:
    ad, bd = zoh_by_hand(model.control_dt)
    np.testing.assert_allclose(model.ad, ad, rtol=0, atol=EXPM_ATOL)
    # B_d's position rows are ~dt^2 / (2 m z_H): compare each row relative to its own scale
    scale = np.abs(bd).max(axis=1, keepdims=True)
    np.testing.assert_allclose(model.bd / scale, bd / scale, rtol=0, atol=EXPM_ATOL)


@pytest.mark.parametrize("k_s", [0, 13, 57, 99])
def test_predicted_trajectory_matches_solve_ivp_of_the_alip(model: CondensedMPC, k_s: int) -> None:
    rng = np.random.default_rng(7 + k_s)
    x0 = random_state(rng)
    u = rng.uniform(-20.0, 20.0, (model.n_blocks(k_s), 2))
    phi, gamma = model.stacked(k_s)
    predicted = phi @ x0 + gamma @ u.ravel()
    reference = ivp_trajectory(model, k_s, x0, u)
    scale = np.abs(reference).max(axis=0)
    np.testing.assert_array_less(np.abs(predicted - reference) / scale, IVP_PREDICTION_RTOL)


def reset_reference(x_minus: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Double support (eq. 5.8-5.10 as the module doc states it), by solve_ivp.

    The contact point moves linearly from the old foot by d over T_ds with no ankle torque, so
    measured from the old foot the CoM feels the pendulum about the moving point; at the end the
    CoM position is re-expressed relative to the new foot.
    """
    t_ds = ROBOT.t_ds

    def rhs(t: float, x: np.ndarray) -> np.ndarray:
        p = d * t / t_ds  # contact point relative to the old foot
        return np.array(
            [x[3] / MZH, -x[2] / MZH, -M_KG * G * (x[1] - p[1]), M_KG * G * (x[0] - p[0])]
        )

    x = solve_ivp(rhs, (0.0, t_ds), x_minus, rtol=IVP_RTOL, atol=IVP_ATOL).y[:, -1]
    return np.array([x[0] - d[0], x[1] - d[1], x[2], x[3]])


def reset_by_hand(x_minus: np.ndarray, d: np.ndarray) -> np.ndarray:
    """:func:`reset_reference` in closed form: the contact point p is a ramp (p' = d / T_ds), so
    the state [x, p, p'] is linear and time invariant and one expm integrates it exactly."""
    mg = M_KG * G
    a = np.zeros((8, 8))
    a[:4, :4] = A_CONT
    a[2, 5], a[3, 4] = mg, -mg  # the pendulum about the moving contact point p
    a[4:6, 6:8] = np.eye(2)
    y = expm(a * ROBOT.t_ds) @ np.concatenate([x_minus, np.zeros(2), d / ROBOT.t_ds])
    return np.array([y[0] - d[0], y[1] - d[1], y[2], y[3]])


def test_closed_form_reset_matches_solve_ivp() -> None:
    rng = np.random.default_rng(3)
    for _ in range(3):
        x, d = random_state(rng), rng.normal(0.0, 0.2, 2)
        np.testing.assert_allclose(reset_by_hand(x, d), reset_reference(x, d), rtol=1e-9, atol=1e-9)


def weights_by_hand(w: MPCWeights) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Q, R, W, Q_f from the MPCWeights docstring: velocity weights act on v = (L_y, -L_x)/(m z_H)
    and Q_f adds qf_dcm |xi|^2 with the capture point xi = c + v / omega."""
    qv = w.q_vel / MZH**2
    q = np.diag([w.q_pos, w.q_pos, qv, qv])
    qf = np.diag([w.qf_pos, w.qf_pos, w.qf_vel / MZH**2, w.qf_vel / MZH**2])
    # xi_x = x_c + L_y / (m z_H omega), xi_y = y_c - L_x / (m z_H omega)
    k = 1.0 / (MZH * OMEGA)
    for row in (np.array([1.0, 0.0, 0.0, k]), np.array([0.0, 1.0, -k, 0.0])):
        qf = qf + w.qf_dcm * np.outer(row, row)
    return q, w.r * np.eye(2), w.w * np.eye(2), qf


@pytest.mark.parametrize(
    "weights",
    [MPCWeights(), MPCWeights(q_pos=2.0, q_vel=0.3, r=0.01, w=4.0, qf_pos=3, qf_vel=7, qf_dcm=50)],
)
def test_cost_matrices_match_the_documented_definition(weights: MPCWeights) -> None:
    mdl = build_mpc(ROBOT, weights, RATE_DT)
    for got, want in zip((mdl.Q, mdl.R, mdl.W, mdl.Qf), weights_by_hand(weights), strict=True):
        np.testing.assert_allclose(got, want, rtol=0, atol=WEIGHT_RTOL * np.abs(want).max())


def test_capture_point_term_penalises_the_divergent_component_only() -> None:
    """A next-step state with xi = 0 (pure convergent component) costs nothing in the DCM term."""
    only_dcm = MPCWeights(qf_pos=0.0, qf_vel=0.0, qf_dcm=1.0)
    qf = build_mpc(ROBOT, only_dcm, RATE_DT).Qf
    # c = 0.1, v = -omega c: xi = c + v / omega = 0 along both axes
    c = np.array([0.1, -0.05])
    v = -OMEGA * c
    x_conv = np.array([c[0], c[1], -MZH * v[1], MZH * v[0]])
    assert x_conv @ qf @ x_conv == pytest.approx(0.0, abs=1e-15)
    x_div = np.array([c[0], c[1], MZH * v[1], -MZH * v[0]])  # v = +omega c: xi = 2 c
    assert x_div @ qf @ x_div == pytest.approx(4.0 * c @ c, rel=1e-12)


def written_out_cost(
    model: CondensedMPC,
    k_s: int,
    x0: np.ndarray,
    d_ref: np.ndarray,
    x_next_ref: np.ndarray,
    z: np.ndarray,
) -> float:
    """Eq. (5.19a) with the weights built by hand, the ticks by the expm of the written-out ALIP
    (the prediction itself is checked against solve_ivp above) and the reset in closed form."""
    q, r, w, qf = weights_by_hand(model.weights)
    n_u = 2 * model.n_blocks(k_s)
    u, d = z[:n_u].reshape(-1, 2), z[n_u:]
    u_ticks = u[tick_blocks(model, k_s)]
    ad, bd = zoh_by_hand(model.control_dt)
    xs, natural = [], []
    x, xn = np.array(x0, dtype=float), np.array(x0, dtype=float)
    for uk in u_ticks:
        x, xn = ad @ x + bd @ uk, ad @ xn
        xs.append(x)
        natural.append(xn)
    xs, natural = np.array(xs), np.array(natural)
    dt = model.control_dt
    e = xs - natural
    j = dt * np.einsum("ki,ij,kj->", e, q, e) + dt * np.einsum("ki,ij,kj->", u_ticks, r, u_ticks)
    x_next = reset_by_hand(xs[-1], d)
    return float(
        (d - d_ref) @ w @ (d - d_ref) + j + (x_next - x_next_ref) @ qf @ (x_next - x_next_ref)
    )


@pytest.mark.parametrize("k_s", [40, 85])
def test_unconstrained_optimum_minimises_the_written_out_cost(
    model: CondensedMPC, k_s: int
) -> None:
    """The MPC's torques and footstep equal the minimiser of eq. (5.19a) written out here.

    The cost is quadratic in z = [u; d], so its Hessian and gradient are recovered exactly from
    cost evaluations (second differences) and the minimiser is one linear solve.
    A small disturbance keeps every torque inside its ball (eq. 5.19e inactive).
    """
    rng = np.random.default_rng(k_s)
    x0 = random_state(rng, speed=0.05)
    d_ref = np.array([0.25, -0.2])
    # near the natural next-step state, so that small torques suffice (no ball active)
    ad, _ = zoh_by_hand(model.control_dt)
    x_end = np.linalg.matrix_power(ad, model.n_ticks - k_s) @ x0
    x_next_ref = reset_by_hand(x_end, d_ref) + np.array([0.01, -0.01, 0.05 * MZH, -0.05 * MZH])
    n_z = 2 * model.n_blocks(k_s) + 2
    step = np.concatenate([np.full(n_z - 2, 10.0), [0.1, 0.1]])  # N m and m

    def cost(z: np.ndarray) -> float:
        return written_out_cost(model, k_s, x0, d_ref, x_next_ref, z)

    j0 = cost(np.zeros(n_z))
    ji = [cost(step[i] * np.eye(n_z)[i]) for i in range(n_z)]
    hess = np.empty((n_z, n_z))
    for i in range(n_z):
        for k in range(i, n_z):
            zik = step[i] * np.eye(n_z)[i] + step[k] * np.eye(n_z)[k]
            # J(h_i e_i + h_k e_k) - J(h_i e_i) - J(h_k e_k) + J(0) = H_ik h_i h_k (also i = k)
            hess[i, k] = hess[k, i] = (cost(zik) - ji[i] - ji[k] + j0) / (step[i] * step[k])
    grad = (np.array(ji) - j0) / step - 0.5 * np.diag(hess) * step
    z_ref = np.linalg.solve(hess, -grad)

    sol = MPC(model).solve(k_s, x0, np.zeros(3), np.array([d_ref[0], d_ref[1], 0.0]), x_next_ref)
    # no torque bound active, so the unconstrained reference is the same problem
    assert np.all(sol.multipliers == 0.0)
    assert np.linalg.norm(sol.torques, axis=1).max() < ROBOT.u_max
    np.testing.assert_allclose(sol.torques.ravel(), z_ref[:-2], rtol=0, atol=OPT_TORQUE_ATOL)
    np.testing.assert_allclose(sol.next_footstep[:2], z_ref[-2:], rtol=0, atol=OPT_STEP_ATOL)


def test_end_state_maps_and_blocking_are_exact() -> None:
    """x_M = a_end x + b_end u from the hand-built ZOH, and integer tick counts per block."""
    # built here, not by the module fixture, so mutation testing attributes build_mpc to it
    model = build_mpc(ROBOT, MPCWeights(), RATE_DT)
    ad, bd = zoh_by_hand(model.control_dt)
    for k_s in (0, 57, 99):
        n_b = model.n_blocks(k_s)
        np.testing.assert_allclose(
            model.a_end[k_s], np.linalg.matrix_power(ad, model.n_ticks - k_s), rtol=0, atol=1e-12
        )
        u = np.random.default_rng(k_s).uniform(-20.0, 20.0, (n_b, 2))
        x = np.zeros(4)
        for b in tick_blocks(model, k_s):
            x = ad @ x + bd @ u[b]
        np.testing.assert_allclose(model.b_end[k_s] @ u.ravel(), x, rtol=1e-12, atol=1e-15)
        assert model.block_ticks[k_s].dtype.kind == "i"
    assert model.block_edges.dtype.kind == "i"
    assert model.robot is ROBOT and model.weights == MPCWeights()


def test_coarsest_control_rate_and_two_nodes_are_accepted() -> None:
    """M = K - 1 ticks (one tick per block) and K = 2 (one block) are valid."""
    robot = BipedParams(n_nodes=5)
    assert build_mpc(robot, control_dt=robot.t_ss / 4).n_ticks == 4
    assert build_mpc(robot, control_dt=0.02, n_nodes=2).n_blocks(0) == 1


@pytest.mark.parametrize(
    ("kwargs", "field", "value"),
    [
        ({"weights": "heavy"}, "weights", "heavy"),
        ({"control_dt": -0.01}, "control_dt", -0.01),
        ({"control_dt": 0.4 / 3}, "control_dt", 0.4 / 3),  # M = 3 < K - 1 = 4
        ({"n_nodes": 1}, "n_nodes", 1),
    ],
)
def test_build_mpc_errors_name_the_field(kwargs: dict, field: str, value: object) -> None:
    with pytest.raises(InputError) as err:
        build_mpc(BipedParams(n_nodes=5), **kwargs)
    assert err.value.field == field and err.value.value == value
