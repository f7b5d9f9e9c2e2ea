"""Swing apex, swing timing and the CoM height planes of the MuJoCo walker (issue 7).

The constraint-plane claim (a CoM on a plane through ``z_H`` above the stance foot moves
horizontally exactly as the pendulum of height ``z_H``) is checked against an independent
integration of a point mass pushed only along the leg (scipy ``solve_ivp``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from footfall.sim.biped.references import (
    QUINTIC_PEAK_ACC,
    SWING_ACC_MAX,
    SWING_SHARES,
    CoMHeight,
    smoothstep,
    swing_bow,
    swing_reference,
    swing_shares,
    terrain_height_along,
)
from footfall.terrain.region import Region

G = 9.81
#: integration tolerance of the point-mass check [m]
IVP_TOL = 1e-6
Z_H = 0.67


def _block(name: str, z: float, x0: float, x1: float) -> Region:
    return Region.from_height(name, z, [[x0, -0.4], [x1, -0.4], [x1, 0.4], [x0, 0.4]])


def test_swing_apex_counts_only_blocks_the_sole_sweeps_over() -> None:
    # discrete_steps: block1 (0.10) ends at x = 0.80, block2 (0.25) starts at 0.88
    blocks = (_block("b1", 0.10, 0.40, 0.80), _block("b2", 0.25, 0.88, 1.20))
    half_length, half_width = 0.10, 0.05
    # a step on block1 ending at x = 0.70: the toe reaches 0.80, 0.08 short of block2
    on_b1 = terrain_height_along(
        blocks, np.array([0.40, 0.0, 0.1]), np.array([0.70, 0.0, 0.1]), half_length, half_width
    )
    assert on_b1 == pytest.approx(0.10)
    # a step from block1 to x = 1.40 passes over block2
    over_b2 = terrain_height_along(
        blocks, np.array([0.70, 0.0, 0.1]), np.array([1.40, 0.0, 0.1]), half_length, half_width
    )
    assert over_b2 == pytest.approx(0.25)
    # a block beside the path within half the sole width counts, one farther away does not
    beside = (Region.from_height("side", 0.3, [[0.5, 0.02], [0.6, 0.02], [0.6, 0.2], [0.5, 0.2]]),)
    start, target = np.array([0.3, -0.02, 0.0]), np.array([0.8, -0.02, 0.0])
    assert terrain_height_along(beside, start, target, half_length, half_width) == pytest.approx(
        0.3
    )
    far = (Region.from_height("far", 0.3, [[0.5, 0.1], [0.6, 0.1], [0.6, 0.2], [0.5, 0.2]]),)
    assert terrain_height_along(far, start, target, half_length, half_width) == pytest.approx(0.0)


def test_swing_shares_bound_the_vertical_acceleration() -> None:
    t_ss = 0.4
    lo, hi = SWING_SHARES
    assert swing_shares(0.05, 0.05, t_ss) == pytest.approx((lo, 1.0 - lo))
    assert swing_shares(0.3, 0.3, t_ss) == pytest.approx((hi, 1.0 - hi))
    for h in (0.08, 0.1, 0.12):
        rise, descend = swing_shares(h, 0.05, t_ss)
        if lo < rise < hi:
            # the quintic's peak acceleration over the rise is the bound
            assert QUINTIC_PEAK_ACC * h / (rise * t_ss) ** 2 == pytest.approx(SWING_ACC_MAX)
        assert descend == pytest.approx(1.0 - lo)
    # the swing reference starts and ends at rest at the given points and passes the apex
    start, target, apex = np.array([0.0, 0.1, 0.0]), np.array([0.3, 0.1, 0.05]), 0.1
    rise, descend = swing_shares(apex - start[2], apex - target[2], t_ss)
    assert lo < rise < hi
    p0, s0 = swing_reference(0.0, start, target, apex, rise, descend)
    p1, s1 = swing_reference(1.0, start, target, apex, rise, descend)
    pm, _ = swing_reference(0.5 * (rise + descend), start, target, apex, rise, descend)
    np.testing.assert_allclose(p0, start, atol=1e-12)
    np.testing.assert_allclose(p1, target, atol=1e-12)
    assert (s0, s1) == (0.0, 1.0)
    assert pm[2] == pytest.approx(apex)
    # numerically: the peak vertical acceleration of the rise
    tau = np.linspace(0.0, rise, 2001)
    z = np.array([swing_reference(t, start, target, apex, rise, descend)[0][2] for t in tau])
    acc = np.diff(z, 2) / (tau[1] - tau[0]) ** 2 / t_ss**2
    assert np.max(np.abs(acc)) <= SWING_ACC_MAX * 1.01


def test_swing_bows_out_around_the_stance_foot() -> None:
    # stance sole at the origin; the swing foot passes 0.10 m beside it (the soles, 0.10 m wide,
    # touch); with a 0.13 m clearance the path must pass 0.03 m further out, on its own side
    stance = np.array([0.0, 0.0, 0.0])
    start, target = np.array([-0.3, 0.1, 0.0]), np.array([0.3, 0.1, 0.0])
    clearance = 0.13
    bow, s_pass = swing_bow(start, target, stance, clearance)
    np.testing.assert_allclose(bow, [0.0, 0.03], atol=1e-12)
    assert s_pass == pytest.approx(0.5)
    # the mirror case (a right swing foot) bows to -y
    bow_r, _ = swing_bow(start * [1, -1, 1], target * [1, -1, 1], stance, clearance)
    np.testing.assert_allclose(bow_r, [0.0, -0.03], atol=1e-12)
    # a swing foot far enough away, or one that does not pass the stance foot, does not bow
    side = np.array([0.0, 0.05, 0.0])
    assert not np.any(swing_bow(start + side, target + side, stance, clearance)[0])
    ahead = np.array([0.5, 0.0, 0.0])
    assert not np.any(swing_bow(start, start + 0.4 * ahead, stance + ahead, clearance)[0])
    # along the whole reference: the ends are unchanged, the path never comes closer than the
    # straight one, and where it passes the stance foot (x = 0) it is the clearance away
    apex, rise, descend = 0.05, 0.35, 0.65
    tau = np.linspace(0.0, 1.0, 401)
    path = np.array(
        [swing_reference(t, start, target, apex, rise, descend, stance, clearance)[0] for t in tau]
    )
    straight = np.array([swing_reference(t, start, target, apex, rise, descend)[0] for t in tau])
    np.testing.assert_allclose(path[[0, -1]], straight[[0, -1]], atol=1e-12)
    np.testing.assert_allclose(path[:, [0, 2]], straight[:, [0, 2]], atol=1e-12)
    assert np.all(path[:, 1] >= straight[:, 1] - 1e-12)
    passing = int(np.argmin(np.abs(path[:, 0])))
    assert abs(path[passing, 0]) < 0.01
    assert path[passing, 1] == pytest.approx(clearance, abs=1e-3)
    # the lateral path is smooth: no jump between samples larger than the straight path's steps
    assert np.max(np.abs(np.diff(path[:, 1]))) < 0.01


def _steps() -> np.ndarray:
    # up 0.1, up 0.15, down 0.1, level: the discrete steps' profile, alternating feet
    return np.array(
        [
            [0.0, -0.1, 0.0],
            [0.3, 0.1, 0.1],
            [0.6, -0.1, 0.25],
            [0.9, 0.1, 0.15],
            [1.2, -0.1, 0.15],
        ]
    )


def test_com_height_is_z_h_above_every_footstep_and_continuous_between_supports() -> None:
    p = _steps()
    h = CoMHeight(p, Z_H)
    for j in range(p.shape[0]):
        assert h(j, p[j, :2]) == pytest.approx(p[j, 2] + Z_H, abs=1e-12)
    # between footsteps j and j + 1 (away from the rounded kinks) both supports use one plane
    rng = np.random.default_rng(0)
    for j in range(p.shape[0] - 1):
        for _ in range(20):
            s = rng.uniform(0.25, 0.75)
            c = p[j, :2] + s * (p[j + 1, :2] - p[j, :2]) + rng.uniform(-0.03, 0.03, 2)
            assert h(j, c) == pytest.approx(h(j + 1, c), abs=1e-12)
            # and the plane passes through both footstep heights
            line = p[j, 2] + s * (p[j + 1, 2] - p[j, 2]) + Z_H
            assert h(j, p[j, :2] + s * (p[j + 1, :2] - p[j, :2])) == pytest.approx(line)
    # flat footsteps: level everywhere
    flat = CoMHeight(p * np.array([1.0, 1.0, 0.0]), Z_H)
    assert flat(2, np.array([5.0, -3.0])) == pytest.approx(Z_H)


@pytest.mark.parametrize("rise", [0.15, -0.1, 0.0])
def test_com_on_the_plane_moves_as_the_pendulum_of_height_z_h(rise: float) -> None:
    """A point mass pushed only along the leg (stance point -> CoM), constrained to the plane
    through z_H above the stance point, integrated by scipy: its horizontal motion is the LIP
    x(t) = x0 cosh(w t) + v0 / w sinh(w t) of eq. (5.1) with zero ankle torque."""
    stance = np.array([0.0, 0.0, 0.0])
    nxt = np.array([0.32, 0.0, rise])
    h = CoMHeight(np.array([stance, nxt]), Z_H, kink=1e-6)
    grad = (rise / 0.32**2) * np.array([0.32, 0.0])  # the plane ahead of the stance foot

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        c, v = y[:3], y[3:]
        r = c - stance
        # leg force f r (per unit mass) keeps z - grad . c_xy constant: its second derivative
        # f (r_z - grad . r_xy) - g = 0
        f = G / (r[2] - grad @ r[:2])
        return np.concatenate([v, f * r - np.array([0.0, 0.0, G])])

    x0, v0 = 0.02, 0.5  # just ahead of the stance foot, moving forward
    c0 = np.array([x0, 0.0, h(0, np.array([x0, 0.0]))])
    vz0 = grad[0] * v0
    t_end = 0.4
    sol = solve_ivp(
        rhs,
        (0.0, t_end),
        np.concatenate([c0, [v0, 0.0, vz0]]),
        rtol=1e-10,
        atol=1e-12,
        dense_output=True,
    )
    assert sol.success
    w = math.sqrt(G / Z_H)
    for t in np.linspace(0.0, t_end, 9):
        c = sol.sol(t)[:3]
        assert c[0] == pytest.approx(x0 * math.cosh(w * t) + v0 / w * math.sinh(w * t), abs=IVP_TOL)
        # and the CoMHeight reference is where the mass is
        assert h(0, c[:2]) == pytest.approx(c[2], abs=IVP_TOL)
    assert smoothstep(1.0) == 1.0
