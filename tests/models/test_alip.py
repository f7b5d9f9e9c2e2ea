"""ALIP model (document 000 eq. 5.1-5.10) against an independent integration of the CoM dynamics.

The reference integrates the CoM position/velocity under gravity with the centre of pressure
(CoP) as the pivot, ``c'' = g / z_H (c - cop)``, which is the physics the ALIP linearises, and
converts to the ALIP state only at the end with ``L = m z_H (-v_y, v_x)``.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from footfall.errors import InputError
from footfall.models import ALIP, zoh
from tests.conftest import INTEGRATION_TOL, IVP_ATOL, IVP_RTOL

M, ZH, G = 32.0, 0.6, 9.81


def to_alip(pos: np.ndarray, vel: np.ndarray) -> np.ndarray:
    return np.array([pos[0], pos[1], -M * ZH * vel[1], M * ZH * vel[0]])


def from_alip(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return x[:2].copy(), np.array([x[3], -x[2]]) / (M * ZH)


def cop_of_torque(u: np.ndarray) -> np.ndarray:
    """Independent statement of the sign convention: torque (m g d_y, -m g d_x) from CoP offset d."""
    return np.array([-u[1], u[0]]) / (M * G)


def integrate(pos, vel, cop_fn, t_end):
    """CoM relative to a fixed origin, pivoting on the CoP cop_fn(t) (2,)."""

    def f(t, s):
        return np.concatenate([s[2:], G / ZH * (s[:2] - cop_fn(t))])

    sol = solve_ivp(f, (0.0, t_end), np.concatenate([pos, vel]), rtol=IVP_RTOL, atol=IVP_ATOL)
    assert sol.success
    return sol.y[:2, -1], sol.y[2:, -1]


@pytest.fixture
def alip() -> ALIP:
    return ALIP(mass=M, com_height=ZH, g=G)


def test_continuous_matrices_match_eq_5_2_and_5_4(alip: ALIP) -> None:
    x = np.array([0.03, -0.02, 1.5, -2.0])
    u = np.array([4.0, -7.0])
    pos, vel = from_alip(x)
    cop = cop_of_torque(u)
    acc = G / ZH * (pos - cop)
    # d/dt of L = m z_H (-v_y, v_x)
    ldot = M * ZH * np.array([-acc[1], acc[0]])
    np.testing.assert_allclose(alip.A @ x + alip.B @ u, np.concatenate([vel, ldot]), rtol=1e-12)


def test_zoh_matches_integration_with_piecewise_constant_torque(alip: ALIP) -> None:
    rng = np.random.default_rng(0)
    k_nodes, t_ss = 6, 0.4
    dt = t_ss / (k_nodes - 1)
    ad, bd = alip.discretize(dt)
    x = np.array([-0.05, 0.08, -3.0, 4.0])
    for _ in range(k_nodes - 1):
        u = rng.uniform(-30.0, 30.0, 2)
        pos, vel = from_alip(x)
        cop = cop_of_torque(u)
        pos_end, vel_end = integrate(pos, vel, lambda t, c=cop: c, dt)
        x_next = ad @ x + bd @ u
        np.testing.assert_allclose(x_next, to_alip(pos_end, vel_end), atol=INTEGRATION_TOL)
        x = x_next


def test_zoh_equals_document_formula_5_7(alip: ALIP) -> None:
    from scipy.linalg import expm

    dt = 0.1
    ad, bd = alip.discretize(dt)
    a = alip.A
    np.testing.assert_allclose(ad, expm(a * dt), rtol=1e-12)
    bd_doc = np.linalg.inv(a) @ (expm(a * dt) - np.eye(4)) @ alip.B
    np.testing.assert_allclose(bd, bd_doc, atol=1e-12)


def test_zoh_handles_singular_state_matrix() -> None:
    # Double integrator: A singular, Ad = [[1, dt], [0, 1]], Bd = [dt^2/2, dt].
    a = np.array([[0.0, 1.0], [0.0, 0.0]])
    b = np.array([[0.0], [1.0]])
    ad, bd = zoh(a, b, 0.3)
    np.testing.assert_allclose(ad, [[1.0, 0.3], [0.0, 1.0]], atol=1e-14)
    np.testing.assert_allclose(bd, [[0.045], [0.3]], atol=1e-14)


@pytest.mark.parametrize("dp", [(0.3, -0.2, 0.0), (0.25, 0.22, 0.1), (-0.1, 0.25, -0.15)])
def test_reset_map_matches_integration_with_moving_contact(alip: ALIP, dp: tuple) -> None:
    """Eq. (5.8)-(5.10): contact moves linearly from p- to p+ during T_ds; state ends relative to p+."""
    t_ds = 0.1
    dp_arr = np.array(dp)
    x_minus = np.array([0.1, -0.04, 2.0, 9.0])
    pos, vel = from_alip(x_minus)  # relative to p- = origin
    pos_end, vel_end = integrate(pos, vel, lambda t: dp_arr[:2] * t / t_ds, t_ds)
    expected = to_alip(pos_end - dp_arr[:2], vel_end)

    a_r, b_r = alip.reset_map(t_ds)
    np.testing.assert_allclose(a_r @ x_minus + b_r @ dp_arr, expected, atol=INTEGRATION_TOL)
    # The z column of B_r is zero: the ALIP neglects the pivot height change (as the document).
    np.testing.assert_array_equal(b_r[:, 2], 0.0)


def test_document_eq_5_10_needs_minus_identity(alip: ALIP) -> None:
    """The document's eq. (5.10) with +I disagrees with the integration; with -I it agrees."""
    t_ds = 0.1
    a = alip.A
    a_r = expm(a * t_ds)
    ainv = np.linalg.inv(a)
    arinv = np.linalg.inv(a_r)
    first = a_r @ ainv @ (ainv @ (np.eye(4) - arinv) / t_ds - arinv) @ alip.E
    ident = np.zeros((4, 3))
    ident[:2, :2] = np.eye(2)
    br_doc = first + ident
    _, b_r = alip.reset_map(t_ds)
    np.testing.assert_allclose(b_r, first - ident, atol=1e-9)

    dp = np.array([0.3, -0.2, 0.0])
    x_minus = np.array([0.1, -0.04, 2.0, 9.0])
    pos, vel = from_alip(x_minus)
    pos_end, vel_end = integrate(pos, vel, lambda t: dp[:2] * t / t_ds, t_ds)
    truth = to_alip(pos_end - dp[:2], vel_end)
    doc_error = np.abs(a_r @ x_minus + br_doc @ dp - truth)[:2]
    np.testing.assert_allclose(doc_error, 2 * np.abs(dp[:2]), atol=1e-6)


def test_zmp_sign_convention_worked_example(alip: ALIP) -> None:
    # m g = 32 * 9.81 = 313.92 N. A ZMP 0.1 m ahead and 0.02 m left of the stance point needs
    # tau_x = m g d_y = 6.2784 N m and tau_y = -m g d_x = -31.392 N m.
    stance = np.array([1.0, 2.0, 0.3])
    u = np.array([6.2784, -31.392])
    np.testing.assert_allclose(alip.zmp(stance, u), [1.1, 2.02], atol=1e-12)
    np.testing.assert_allclose(alip.torque_for_zmp([0.1, 0.02]), u, atol=1e-12)
    # That torque pushes the CoM backwards (dL_y/dt = m g x_c + tau_y < 0 at x_c = 0).
    assert (alip.A @ np.zeros(4) + alip.B @ u)[3] < 0.0


def test_velocity_and_state_round_trip(alip: ALIP) -> None:
    x = alip.state_from_velocity([0.01, -0.02], [0.4, -0.1])
    np.testing.assert_allclose(alip.velocity(x), [0.4, -0.1], atol=1e-14)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"mass": -1.0, "com_height": 0.6}, "mass"),
        ({"mass": 30.0, "com_height": float("nan")}, "com_height"),
        ({"mass": 30.0, "com_height": 0.6, "g": 0.0}, "g"),
        ({"mass": "heavy", "com_height": 0.6}, "mass"),
    ],
)
def test_bad_parameters_name_the_field(kwargs: dict, field: str) -> None:
    with pytest.raises(InputError) as err:
        ALIP(**kwargs)
    assert err.value.field == field


def test_bad_periods_are_rejected(alip: ALIP) -> None:
    with pytest.raises(InputError, match="dt"):
        alip.discretize(0.0)
    with pytest.raises(InputError, match="t_ds"):
        alip.reset_map(-0.1)


def test_state_from_velocity_is_position_and_momentum(alip: ALIP) -> None:
    """x = [c_x, c_y, -m z_H v_y, m z_H v_x] (eq. 5.1 with L = m z_H (-v_y, v_x))."""
    mzh = alip.mass * alip.com_height
    x = alip.state_from_velocity([0.01, -0.02], [0.4, -0.1])
    np.testing.assert_allclose(x, [0.01, -0.02, 0.1 * mzh, 0.4 * mzh], rtol=1e-15)


def test_state_from_velocity_checks_both_vectors(alip: ALIP) -> None:
    for pos, vel, field in (([0.0, 0.0, 0.0], [0.0, 0.0], "pos"), ([0.0, 0.0], [1.0], "vel")):
        with pytest.raises(InputError) as err:
            alip.state_from_velocity(pos, vel)
        assert err.value.field == field


def test_batched_maps_keep_the_leading_axis(alip: ALIP) -> None:
    """velocity, zmp and torque_for_zmp act on the last axis of a batch (N, .)."""
    rng = np.random.default_rng(0)
    xs = rng.normal(size=(3, 4))
    np.testing.assert_allclose(alip.velocity(xs), [alip.velocity(x) for x in xs], rtol=1e-15)
    us = rng.normal(size=(3, 2))
    stance = np.array([1.0, 2.0])
    np.testing.assert_allclose(alip.zmp(stance, us), [alip.zmp(stance, u) for u in us])
    np.testing.assert_allclose(alip.torque_for_zmp(us), [alip.torque_for_zmp(u) for u in us])


def test_parameters_are_stored_as_floats() -> None:
    alip = ALIP(30, 1, g=10)
    assert all(type(v) is float for v in (alip.mass, alip.com_height, alip.g))
    assert alip.omega == pytest.approx(np.sqrt(10.0))


def test_bad_double_support_names_t_ds(alip: ALIP) -> None:
    with pytest.raises(InputError) as err:
        alip.reset_map(0.0)
    assert err.value.field == "t_ds"
