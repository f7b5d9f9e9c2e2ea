"""The legs' momentum forecast in the walker's ALIP prediction (footfall.sim.biped.leg_momentum).

The state shift is checked against the ALIP integrated by ``solve_ivp`` with the forecast
disturbance as a torque (``dL/dt = m g (x, y) + u - dL_G/dt``), not against the matrices it uses.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.sim.biped.leg_momentum import (
    LegMomentumForecast,
    forecast_shift,
    inverse_powers,
)
from footfall.sim.biped.options import LEG_MOMENTUM, WalkOptions

DT = 0.01
M = 40  # ticks of a 0.4 s single support


def _end_state_ivp(alip, x0, torques, disturbance, dt):
    """Integrate the continuous ALIP over len(torques) ticks, each tick's torque and disturbance
    held (4,) -> (4,)."""
    a, b = np.asarray(alip.A), np.asarray(alip.B)
    x = np.array(x0, dtype=float)
    for u, w in zip(torques, disturbance, strict=True):
        out = solve_ivp(
            lambda _t, s, u=u, w=w: a @ s + b @ (u + w),
            (0.0, dt),
            x,
            method="DOP853",
            rtol=1e-12,
            atol=1e-12,
        )
        x = out.y[:, -1]
    return x


@pytest.mark.parametrize("heading", [0.0, 0.7, -2.1])
@pytest.mark.parametrize("k", [0, 13, M - 2, M - 1])
def test_shift_carries_the_disturbance_to_the_end_of_the_step(heading, k):
    alip = BipedParams().alip()
    ad, bd = alip.discretize(DT)
    rng = np.random.default_rng(7)
    tau = np.arange(M) * DT
    profile = 1.5 + 0.8 * np.sin(2 * np.pi * tau / (M * DT)) + 0.05 * rng.standard_normal(M)
    x0 = np.array([0.02, -0.05, 3.0, 8.0])
    torques = rng.uniform(-2.0, 2.0, size=(M - k, 2))
    axis = np.array([-math.sin(heading), math.cos(heading)])
    # the disturbance of tick j: -(L_G[j+1] - L_G[j]) / dt about the heading's lateral axis,
    # none in the last tick (the profile ends there)
    w = np.zeros((M - k, 2))
    w[:-1] = (-np.diff(profile[k:]) / DT)[:, None] * axis[None, :]
    expected = _end_state_ivp(alip, x0, torques, w, DT)

    d = forecast_shift(profile, k, DT, inverse_powers(ad, bd, M), heading)
    x = x0 + d
    for u in torques:
        x = ad @ x + bd @ u
    np.testing.assert_allclose(x, expected, rtol=1e-8, atol=1e-9)
    if k == M - 1:
        assert not d.any()


def test_forecast_uses_the_previous_whole_support_only():
    alip = BipedParams().alip()
    ad, bd = alip.discretize(DT)
    fc = LegMomentumForecast(ad, bd, DT, M * DT, gain=0.5)
    l_g = np.array([0.0, 0.0, 0.0])
    # first support: nothing to forecast from
    for k in range(M):
        l_g[1] = 1.0 + 0.01 * k
        assert not fc.shift(0, k * DT, l_g, 0.0).any()
    # second support: the first one's profile, half of its shift
    profile = 1.0 + 0.01 * np.arange(M)
    full = forecast_shift(profile, 0, DT, inverse_powers(ad, bd, M), 0.0)
    np.testing.assert_allclose(fc.shift(1, 0.0, l_g, 0.0), 0.5 * full)
    assert np.abs(full).max() > 1e-3
    # the second support stops early (a fall, say): the third has no forecast
    assert not fc.shift(2, 0.0, l_g, 0.0).any()
    # a skipped support has none either
    fc2 = LegMomentumForecast(ad, bd, DT, M * DT, gain=1.0)
    for k in range(M):
        fc2.shift(0, k * DT, l_g, 0.0)
    assert not fc2.shift(2, 0.0, l_g, 0.0).any()


def test_shift_rejects_a_tick_outside_the_support():
    alip = BipedParams().alip()
    ad, bd = alip.discretize(DT)
    with pytest.raises(ValueError, match="tick"):
        forecast_shift(np.zeros(M), M, DT, inverse_powers(ad, bd, M), 0.0)


@pytest.mark.parametrize("value", [-0.1, 1.5, math.nan, math.inf])
def test_leg_momentum_share_is_checked(value):
    with pytest.raises(InputError, match="leg_momentum"):
        WalkOptions(leg_momentum=value)


def test_leg_momentum_needs_the_com_velocity_estimate():
    with pytest.raises(InputError, match="leg_momentum"):
        WalkOptions(leg_momentum=0.5, true_momentum=True)
    with pytest.raises(InputError, match="leg_momentum"):
        WalkOptions(controller="servo", leg_momentum=0.5)
    assert WalkOptions(leg_momentum=0.5).leg_momentum == 0.5


def test_default_share_follows_the_momentum_the_adjuster_gets():
    # on with the CoM-velocity estimate (wbc), off where the adjuster gets the true momentum,
    # which holds the legs' momentum already (servo, or true_momentum asked for)
    assert WalkOptions(controller="wbc").leg_momentum == LEG_MOMENTUM == 0.5
    assert WalkOptions(controller="servo").leg_momentum == 0.0
    assert WalkOptions(controller="wbc", true_momentum=True).leg_momentum == 0.0
    assert WalkOptions(controller="servo", true_momentum=False).leg_momentum == LEG_MOMENTUM
    assert WalkOptions(leg_momentum=0.0).legs_share == 0.0


def test_forecast_lowers_the_zmp_offset_of_a_flat_walk():
    # measured on this 8-step walk: ZMP offset mean 24.8 mm without, 16.6 mm with half the
    # forecast, and the MPC's footstep corrections 33 -> 21 mm (the ankle no longer brakes a CoM
    # that runs ahead of the point-mass prediction). A forecast with the wrong sign or the wrong
    # tick would not lower both.
    pytest.importorskip("mujoco")
    from footfall.planning import make_plan
    from footfall.sim.biped.model import planner_params
    from footfall.sim.biped.walk import walk
    from footfall.terrain import builtin_scene

    scene = builtin_scene("flat")
    plan = make_plan(scene, "miqcqp", robot=planner_params(base=scene.robot))
    res_off = walk(scene, plan, WalkOptions(controller="wbc", leg_momentum=0.0))
    res_on = walk(scene, plan, WalkOptions(controller="wbc", leg_momentum=0.5))
    off, on = res_off.metrics, res_on.metrics
    assert off.reached_goal and on.reached_goal
    assert on.zmp.mean < 0.85 * off.zmp.mean
    assert on.correction_m.mean < 0.85 * off.correction_m.mean
    # the whole-body controller still puts the measured CoP where the MPC's torque asks, as
    # closely as without the forecast (RMS [m] per axis, the bounds of test_walk_wbc.py;
    # measured 11.9 / 3.7 mm with it, 12.6 / 3.2 mm without)
    tr = res_on.trace
    ok = ~np.isnan(tr.zmp_offset[:, 0]) & ~np.isnan(tr.zmp_planned[:, 0])
    assert ok.sum() > 300
    rms = np.sqrt(np.mean((tr.zmp_offset[ok] - tr.zmp_planned[ok]) ** 2, axis=0))
    assert rms[0] < 0.02 and rms[1] < 0.006


def test_walk_command_records_the_share(tmp_path):
    pytest.importorskip("mujoco")
    import json

    from typer.testing import CliRunner

    from footfall.cli import app

    args = ["walk", "--scene", "flat", "--planner", "reactive", "--no-video", "--quiet"]
    res = CliRunner().invoke(app, [*args, "--leg-momentum", "0.25", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    walked = json.loads((tmp_path / "walk.json").read_text())
    assert walked["walker"] == {
        "region_aware": "horizon",
        "leg_momentum": 0.25,
        "capture_stop": True,
        "walk_on": 4,
        "torque_weight_mass": 30.1,
        "step_timing": True,
    }
    assert walked["metrics"]["reached_goal"]
