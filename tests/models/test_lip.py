"""Kajita LIP closed form against solve_ivp, orbital energy, and the shared discrete shape."""

from __future__ import annotations

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
