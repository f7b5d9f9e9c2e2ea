"""Posture (eq. 9), zero-impact swing (eq. 10-13), OSP planning (sec. 1.3), gait sequencer."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import footfall.quadruped as fq
from footfall.errors import InfeasibleError, InputError
from footfall.quadruped import (
    LEGS,
    BodyPosture,
    GaitParams,
    Leg,
    PhaseKind,
    QuadrupedRobot,
    SlopePosture,
    SwingProfile,
    ZmpStrategy,
    incentre,
    leg_fk,
    leg_heights,
    leg_heights_horizontal,
    optimal_stability_point,
    plan_gait,
    stability_margin,
    suboptimal_triangle,
    swing_in_leg_frame,
)
from footfall.quadruped.kinematics import body_rotation
from footfall.quadruped.zmp_planning import document_point_i

ROBOT = QuadrupedRobot()
#: the document rounds its eq. (9) example to whole millimetres
DOC_ROUNDING = 1e-3
#: finite-difference tolerance relative to the derivative's scale
FD_RTOL = 1e-5
#: planner geometry tolerance [m]
PLAN_TOL = 1e-9
#: CoM placement tolerance of the fixed-point body solve [m]
COM_TOL = 1e-4


def test_public_api_names_resolve() -> None:
    for name in fq.__all__:
        assert getattr(fq, name) is not None


# --- eq. (9) and postures ---------------------------------------------------------------------
def test_eq9_worked_example() -> None:
    """l_B = 1000 mm, h_B = 600 mm, beta_S = 30 deg gives about 311 mm and 888 mm (sec. 2)."""
    h_f, h_h = leg_heights_horizontal(1.0, 0.6, math.radians(30.0))
    assert h_f == pytest.approx(0.311, abs=DOC_ROUNDING)
    assert h_h == pytest.approx(0.888, abs=DOC_ROUNDING)


@given(
    l_b=st.floats(0.3, 1.5),
    h_b=st.floats(0.3, 1.0),
    slope=st.floats(0.0, 0.6),
    frac=st.floats(0.0, 1.0),
)
def test_pitched_body_heights_generalise_eq9(l_b: float, h_b: float, slope: float, frac: float):
    assert leg_heights(l_b, h_b, slope, 0.0) == pytest.approx(
        leg_heights_horizontal(l_b, h_b, slope)
    )
    h_f, h_h = leg_heights(l_b, h_b, slope, slope)
    assert h_f == pytest.approx(h_b) and h_h == pytest.approx(h_b)
    # pitching the body towards the slope shrinks the fore/hind height difference monotonically
    f0, r0 = leg_heights(l_b, h_b, slope, frac * slope * 0.5)
    f1, r1 = leg_heights(l_b, h_b, slope, frac * slope)
    assert r1 - f1 <= r0 - f0 + 1e-12


def test_compromise_posture_has_vertical_legs_and_centred_com() -> None:
    post = SlopePosture(math.radians(15), math.radians(10), 0.6)
    body = post.body_position()
    feet = post.neutral_feet(ROBOT, body)
    rot = body_rotation(post.body_pitch)
    for i, leg in enumerate(LEGS):
        hip = body + rot @ ROBOT.hip_offset(leg)
        np.testing.assert_allclose(feet[i, :2], hip[:2], atol=PLAN_TOL)  # vertical leg
        assert feet[i, 2] == pytest.approx(feet[i, 0] * math.tan(post.slope))  # on the plane
    # CoM (body centre) projection on the midline of the support rectangle
    np.testing.assert_allclose(feet[:, :2].mean(axis=0), body[:2], atol=PLAN_TOL)
    hh = post.hip_heights(ROBOT)
    expected_f, expected_h = leg_heights(ROBOT.hip_spacing_x, 0.6, post.slope, post.body_pitch)
    assert hh[Leg.LF] == pytest.approx(expected_f) and hh[Leg.RH] == pytest.approx(expected_h)


def test_parallel_posture_moves_the_com_projection_rearwards() -> None:
    """Fig. 6: with the body parallel to the slope the CoM projects behind the polygon centre."""
    slope = math.radians(20)
    par = SlopePosture.of(BodyPosture.PARALLEL, slope, 0.6)
    hor = SlopePosture.of(BodyPosture.HORIZONTAL, slope, 0.6)
    for post, behind in ((par, True), (hor, False)):
        body = post.body_position()
        centre = post.neutral_feet(ROBOT, body)[:, 0].mean()
        assert bool(body[0] < centre - 0.05) is behind


def test_body_angle_outside_zero_to_slope_is_rejected() -> None:
    with pytest.raises(InputError) as err:
        GaitParams(slope=math.radians(15), body_pitch=math.radians(20))
    assert err.value.field == "body_pitch"
    with pytest.raises(InputError):
        GaitParams(slope=math.radians(15), body_pitch=-0.01)


def test_too_steep_slope_names_the_slope_limit() -> None:
    with pytest.raises(InputError) as err:
        plan_gait(ROBOT, GaitParams(slope=math.radians(45), body_pitch=0.0, cycles=1))
    assert err.value.field == "slope"
    assert "at most" in err.value.expected


def test_too_long_step_names_the_step_limit() -> None:
    with pytest.raises(InputError) as err:
        plan_gait(ROBOT, GaitParams(math.radians(15), math.radians(10), step=1.2, cycles=1))
    assert err.value.field == "step"
    limit = float(err.value.expected.split("at most ")[1].split(" m")[0])
    # the reported limit is feasible and slightly more is not
    plan_gait(ROBOT, GaitParams(math.radians(15), math.radians(10), step=limit * 0.9, cycles=1))
    assert limit < 1.2


# --- swing trajectory, eq. (10)-(13) ----------------------------------------------------------
@settings(max_examples=30, deadline=None)
@given(step=st.floats(0.05, 0.8), height=st.floats(0.02, 0.3), period=st.floats(0.2, 2.0))
def test_swing_is_zero_impact(step: float, height: float, period: float) -> None:
    prof = SwingProfile(step, height, period)
    np.testing.assert_allclose(prof.position(0.0), [-step / 2, 0.0], atol=1e-12)
    np.testing.assert_allclose(prof.position(period), [step / 2, 0.0], atol=1e-12)
    assert prof.position(period / 2)[1] == pytest.approx(height)
    for t in (0.0, period):
        np.testing.assert_allclose(prof.velocity(t), 0.0, atol=1e-12)
        np.testing.assert_allclose(prof.acceleration(t), 0.0, atol=1e-9)
    # one-sided finite differences at the ends confirm it without the closed forms
    h = period * 1e-4
    v0 = (prof.position(h) - prof.position(0.0)) / h
    assert np.all(np.abs(v0) <= np.array([step, height]) / period * 1e-2)


@settings(max_examples=20, deadline=None)
@given(step=st.floats(0.05, 0.8), height=st.floats(0.02, 0.3), period=st.floats(0.2, 2.0))
def test_swing_derivatives_match_finite_differences(step: float, height: float, period: float):
    prof = SwingProfile(step, height, period)
    # an even count avoids t = T_w/2, where z is C2 but its jerk jumps (eq. 12's sign flip)
    t = np.linspace(0.05, 0.95, 36) * period
    h = period * 1e-5
    vel_fd = (prof.position(t + h) - prof.position(t - h)) / (2 * h)
    acc_fd = (prof.velocity(t + h) - prof.velocity(t - h)) / (2 * h)
    scale_v = max(step, height) / period
    scale_a = scale_v / period
    np.testing.assert_allclose(prof.velocity(t), vel_fd, atol=FD_RTOL * scale_v * 10)
    np.testing.assert_allclose(prof.acceleration(t), acc_fd, atol=FD_RTOL * scale_a * 100)
    # the apex is continuous in acceleration: eq. (12)'s sign flip happens where z'' = 0
    a_left, a_right = prof.acceleration(period / 2 - h), prof.acceleration(period / 2 + h)
    assert abs(a_left[1] - a_right[1]) < 1e-3 * scale_a


def test_eq13_rotation_maps_g_axes_onto_the_slope() -> None:
    """In {W} the rotated swing must run along the slope and lift along its normal."""
    slope, pitch = math.radians(30), math.radians(20)  # fig. 8's angles
    prof = SwingProfile(0.6, 0.2, 0.5)
    origin = np.array([0.05, 0.0, -0.55])
    t = np.linspace(0, 0.5, 41)
    p_leg = swing_in_leg_frame(prof, t, slope - pitch, origin)
    p_w = p_leg @ body_rotation(pitch).T
    o_w = body_rotation(pitch) @ origin
    u = np.array([math.cos(slope), 0, math.sin(slope)])
    n = np.array([-math.sin(slope), 0, math.cos(slope)])
    xz = prof.position(t)
    np.testing.assert_allclose(p_w, o_w + xz[:, :1] * u + xz[:, 1:] * n, atol=1e-12)


# --- OSP in the suboptimal triangle, sec. 1.3 -------------------------------------------------
def _fig4_points() -> tuple[np.ndarray, ...]:
    # A, B, C, D = LF, RF, RH, LH (fig. 4); C1 = RH after a step of 0.4 m
    a, b = np.array([0.5, 0.25]), np.array([0.4, -0.25])
    d = np.array([-0.3, 0.25])
    c1 = np.array([-0.1, -0.25])
    return a, b, c1, d


def test_suboptimal_triangle_is_a_d_i_with_i_from_the_document() -> None:
    a, b, c1, d = _fig4_points()
    tri = suboptimal_triangle(np.array([a, b, d]), np.array([a, c1, d]))
    i = document_point_i(a, b, d, c1)
    found = {tuple(np.round(v, 9)) for v in tri}
    assert found == {tuple(np.round(v, 9)) for v in (a, d, i)}


def test_osp_keeps_a_positive_margin_in_both_swings() -> None:
    a, b, c1, d = _fig4_points()
    first, second = np.array([a, b, d]), np.array([a, c1, d])
    osp, r = optimal_stability_point(first, second)
    assert stability_margin(osp, first) >= r - PLAN_TOL
    assert stability_margin(osp, second) >= r - PLAN_TOL
    # the per-triangle incentres each leave the other triangle's best region
    inc1, r1 = incentre(first)
    assert r1 > r  # the OSP gives up some margin...
    assert stability_margin(inc1, second) < r  # ...but the first incentre is worse in swing 2


def test_transverse_pairs_share_only_a_diagonal() -> None:
    a, b, c1, d = _fig4_points()
    c = c1 - np.array([0.4, 0.0])
    # LF swings then RH: stance RF, RH, LH then LF', RF, LH -> common part is the diagonal RF-LH
    with pytest.raises(InfeasibleError):
        suboptimal_triangle(np.array([b, c, d]), np.array([a + np.array([0.4, 0.0]), b, d]))


# --- gait sequencer ---------------------------------------------------------------------------
@pytest.fixture(scope="module")
def osp_plan() -> fq.GaitPlan:
    return plan_gait(ROBOT, GaitParams(math.radians(15), math.radians(10), cycles=3))


def test_gait_swing_order_and_step_lengths(osp_plan: fq.GaitPlan) -> None:
    swings = [p for p in osp_plan.phases if p.kind is PhaseKind.SWING]
    assert [p.leg for p in swings[:4]] == [Leg.RH, Leg.RF, Leg.LH, Leg.LF]
    u = osp_plan.posture.slope_direction
    for p in swings:
        assert p.leg is not None and p.foot_end is not None
        disp = p.foot_end - p.feet_start[p.leg.idx]
        np.testing.assert_allclose(disp, 0.4 * u, atol=PLAN_TOL)
        assert p.foot_end[2] == pytest.approx(p.foot_end[0] * math.tan(osp_plan.posture.slope))


def test_osp_plan_shifts_once_per_pair_and_places_the_com_on_target(osp_plan: fq.GaitPlan):
    traj = osp_plan.sample(0.01)
    shifts = osp_plan.shifts()
    assert len(shifts) == 2 * 3 + 1  # two per cycle plus the final centring shift
    for sh in shifts[:-1]:
        k = int(np.searchsorted(traj.t, sh.t1 - 1e-9))
        np.testing.assert_allclose(traj.com[k, :2], sh.zmp_target, atol=COM_TOL)
    # the body is still during swings and the stance feet never move
    for k, ph in enumerate(osp_plan.phases):
        sel = traj.phase == k
        if ph.kind is PhaseKind.SWING:
            assert np.ptp(traj.body_pos[sel], axis=0).max() < PLAN_TOL
        stance = traj.contact[sel][0]
        assert np.ptp(traj.feet[sel][:, stance], axis=0).max() < PLAN_TOL
    # during three-legged support the planned ZMP (eq. 5) stays inside the triangle
    three = traj.contact.sum(axis=1) == 3
    assert traj.margin[three].min() > 0.05


def test_sampled_joints_reproduce_the_planned_feet(osp_plan: fq.GaitPlan) -> None:
    traj = osp_plan.sample(0.02, with_zmp=False)
    # on the document's plane the body keeps one pitch
    assert np.all(traj.body_pitch == traj.body_pitch[0])
    rot = body_rotation(float(traj.body_pitch[0]))
    for i, leg in enumerate(LEGS):
        p = (
            traj.body_pos
            + (ROBOT.hip_offset(leg) + leg_fk(ROBOT, traj.joints[:, 3 * i : 3 * i + 3])) @ rot.T
        )
        np.testing.assert_allclose(p, traj.feet[:, i], atol=1e-9)


def test_osp_sways_less_than_per_triangle_incentre() -> None:
    from footfall.sim.quadruped.sim import body_sway

    out = {}
    for strat in (ZmpStrategy.OSP, ZmpStrategy.INCENTRE):
        plan = plan_gait(
            ROBOT, GaitParams(math.radians(15), math.radians(10), cycles=3, strategy=strat)
        )
        tr = plan.sample(0.02, with_zmp=False)
        out[strat] = body_sway(plan, tr.t, tr.body_pos)
    assert out[ZmpStrategy.OSP].shifts_per_cycle == 2
    assert out[ZmpStrategy.INCENTRE].shifts_per_cycle == 4
    assert out[ZmpStrategy.OSP].path_per_cycle_m < out[ZmpStrategy.INCENTRE].path_per_cycle_m
