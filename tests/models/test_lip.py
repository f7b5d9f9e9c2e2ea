"""Kajita LIP closed form against solve_ivp, orbital energy, and the shared discrete shape."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import solve_ivp

from footfall.errors import InputError
from footfall.models import LIP
from tests.conftest import INTEGRATION_TOL, IVP_ATOL, IVP_RTOL


def integrate(z_c, g, x0, v0, p, t):
    sol = solve_ivp(
        lambda _, s: [s[1], g / z_c * (s[0] - p)],
        (0.0, t[-1]),
        [x0, v0],
        t_eval=t,
        rtol=IVP_RTOL,
        atol=IVP_ATOL,
    )
    assert sol.success
    return sol.y[0], sol.y[1]


@settings(max_examples=25, deadline=None)
@given(
    z_c=st.floats(0.2, 1.5),
    x0=st.floats(-0.3, 0.3),
    v0=st.floats(-1.0, 1.0),
    p=st.floats(-0.3, 0.3),
)
def test_closed_form_matches_integration(z_c: float, x0: float, v0: float, p: float) -> None:
    lip = LIP(z_c)
    t = np.linspace(0.0, 0.8, 9)
    pos, vel = lip.state_at([x0], [v0], [p], t)
    ref_pos, ref_vel = integrate(z_c, lip.g, x0, v0, p, t)
    np.testing.assert_allclose(pos[:, 0], ref_pos, atol=INTEGRATION_TOL * 10)
    np.testing.assert_allclose(vel[:, 0], ref_vel, atol=INTEGRATION_TOL * 10)


def test_orbital_energy_is_conserved() -> None:
    lip = LIP(0.8)
    t = np.linspace(0.0, 1.0, 50)
    pos, vel = lip.state_at([0.1, -0.05], [0.2, 0.4], [0.0, 0.02], t)
    e = lip.orbital_energy(pos, vel, [0.0, 0.02])
    np.testing.assert_allclose(e, np.broadcast_to(e[0], e.shape), atol=1e-12)


def test_scalar_time_returns_both_axes() -> None:
    pos, vel = LIP(0.8).state_at([0.1, 0.2], [0.0, 0.0], [0.0, 0.0], 0.5)
    assert pos.shape == (2,) and vel.shape == (2,)
    assert pos[1] == pytest.approx(2 * pos[0])


def test_discrete_matrices_match_closed_form() -> None:
    lip = LIP(0.8)
    ad, bd = lip.discretize(0.3)
    x0 = np.array([0.1, -0.05, 0.2, 0.4])
    p = np.array([0.03, 0.01])
    pos, vel = lip.state_at(x0[:2], x0[2:], p, 0.3)
    np.testing.assert_allclose(ad @ x0 + bd @ p, np.concatenate([pos, vel]), atol=1e-12)


def test_sample_step_includes_both_ends() -> None:
    t, pos, _ = LIP(0.8).sample_step([0.0], [0.1], [0.0], 0.8, 0.1)
    assert t[0] == 0.0 and t[-1] == pytest.approx(0.8) and t.size == 9
    assert pos[0, 0] == 0.0


@pytest.mark.parametrize("z_c", [0.0, -0.8, float("nan"), float("inf")])
def test_bad_height(z_c: float) -> None:
    with pytest.raises(InputError, match="z_c"):
        LIP(z_c)


def test_orbital_energy_value_and_the_capture_state() -> None:
    """E = v^2 / 2 - g / (2 z_c) (x - p)^2 (Kajita eq. 4.21) at a point, and E = 0 on the stable
    manifold v = -(x - p) / Tc."""
    lip = LIP(0.8)
    e = lip.orbital_energy([0.1, -0.2], [0.5, 0.3], [0.0, -0.1])
    np.testing.assert_allclose(
        e, [0.125 - 9.81 / 1.6 * 0.01, 0.045 - 9.81 / 1.6 * 0.01], rtol=1e-14
    )
    x, p = np.array([0.3]), np.array([0.1])
    assert lip.orbital_energy(x, -(x - p) / lip.Tc, p)[0] == pytest.approx(0.0, abs=1e-15)


def test_sample_step_shorter_than_dt_is_its_two_ends() -> None:
    t, pos, vel = LIP(0.8).sample_step([0.0], [0.1], [0.0], 0.05, 0.1)
    np.testing.assert_array_equal(t, [0.0, 0.05])
    assert pos.shape == vel.shape == (2, 1)


def test_parameters_are_stored_as_floats() -> None:
    lip = LIP(1, g=10)
    assert type(lip.z_c) is float and type(lip.g) is float
    assert lip.Tc == pytest.approx(np.sqrt(0.1))


@pytest.mark.parametrize(
    ("call", "field"),
    [
        (lambda: LIP(0.0), "z_c"),
        (lambda: LIP(0.8, g=-9.81), "g"),
        (lambda: LIP(0.8).sample_step([0.0], [0.0], [0.0], 0.0, 0.1), "t_sup"),
        (lambda: LIP(0.8).sample_step([0.0], [0.0], [0.0], 0.4, float("nan")), "dt"),
    ],
)
def test_input_errors_name_the_field(call: Callable[[], object], field: str) -> None:
    with pytest.raises(InputError) as exc:
        call()
    assert exc.value.field == field
