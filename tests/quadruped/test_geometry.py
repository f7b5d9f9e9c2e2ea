"""Kinematics and stability geometry of document 001 (eq. 1-8) against independent checks."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from footfall.errors import InputError
from footfall.quadruped import (
    LEGS,
    QuadrupedRobot,
    centre_of_pressure,
    incentre,
    leg_fk,
    leg_ik,
    stability_margin,
    support_polygon,
    whole_body_com,
    whole_body_ik,
    zmp_from_com,
    zmp_from_momentum,
)
from footfall.quadruped.stability import clip_convex, stability_margins

ROBOT = QuadrupedRobot()
#: round-trip tolerance of closed-form kinematics [m] / [rad]
KIN_TOL = 1e-9
#: tolerance of geometric identities [m]
GEOM_TOL = 1e-9

coord = st.floats(-2.0, 2.0, allow_nan=False)


def _triangle_area(t: np.ndarray) -> float:
    d1, d2 = t[1] - t[0], t[2] - t[0]
    return 0.5 * abs(d1[0] * d2[1] - d1[1] * d2[0])


triangles = (
    st.lists(st.tuples(coord, coord), min_size=3, max_size=3)
    .map(np.array)
    .filter(lambda t: _triangle_area(t) > 0.05)
)


def _line_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    d = b - a
    return abs(d[0] * (p[1] - a[1]) - d[1] * (p[0] - a[0])) / np.linalg.norm(d)


@given(
    q1=st.floats(-0.5, 0.5),
    q2=st.floats(-1.2, 1.2),
    q3=st.floats(0.55, 2.65),
)
def test_ik_inverts_fk(q1: float, q2: float, q3: float) -> None:
    q = np.array([q1, q2, q3])
    foot = leg_fk(ROBOT, q)
    # the closed form covers feet below the hip (the ab/ad angle is read from the leg's plane)
    assume(math.hypot(foot[1], foot[2]) > 0.05 and foot[2] < 0.0)
    np.testing.assert_allclose(leg_ik(ROBOT, foot), q, atol=KIN_TOL)


def test_fk_matches_geometry_at_known_poses() -> None:
    l1, l2 = ROBOT.thigh_length, ROBOT.shank_length
    # straight leg hangs down; a right-angle knee puts the foot l2 forward of the knee
    np.testing.assert_allclose(leg_fk(ROBOT, [0, 0, 0]), [0, 0, -(l1 + l2)], atol=KIN_TOL)
    np.testing.assert_allclose(leg_fk(ROBOT, [0, 0, math.pi / 2]), [-l2, 0, -l1], atol=KIN_TOL)
    # positive ab/ad swings the foot to +y (left) by the same angle
    p = leg_fk(ROBOT, [0.3, 0, 0])
    assert math.atan2(p[1], -p[2]) == pytest.approx(0.3)


def test_fk_knee_column_is_a_rotation_about_the_knee_axis() -> None:
    """Finite-difference dFK/dq3 must be axis x (foot - knee): normal to both, length l2."""
    from footfall.quadruped.kinematics import leg_link_points

    rng = np.random.default_rng(0)
    h = 1e-6
    for _ in range(20):
        q = rng.uniform([-0.4, -1.0, 0.4], [0.4, 1.0, 2.4])
        dq = np.array([0.0, 0.0, h])
        col = (leg_fk(ROBOT, q + dq) - leg_fk(ROBOT, q - dq)) / (2 * h)
        _, knee, foot = leg_link_points(ROBOT, q)
        axis = np.array([0.0, math.cos(q[0]), math.sin(q[0])])  # y axis turned by ab/ad
        np.testing.assert_allclose(col, np.cross(axis, foot - knee), atol=1e-7)


def test_ik_rejects_unreachable_target_naming_the_leg() -> None:
    with pytest.raises(InputError) as err:
        leg_ik(ROBOT, [0.0, 0.0, -1.2], LEGS[2])
    assert err.value.field == "foot[RH]"
    assert "reach" in err.value.expected


def test_ik_rejects_joint_limit() -> None:
    # within reach, but the thigh would have to pitch forward beyond its limit
    with pytest.raises(InputError, match="hip_pitch"):
        leg_ik(ROBOT, [0.85, 0.0, -0.05])


def test_whole_body_ik_puts_feet_where_asked() -> None:
    body = np.array([0.1, 0.02, 0.65])
    pitch = math.radians(10)
    rot = np.array(
        [
            [math.cos(-pitch), 0, math.sin(-pitch)],
            [0, 1, 0],
            [-math.sin(-pitch), 0, math.cos(-pitch)],
        ]
    )
    below = np.array([0.05, 0.0, -0.6])
    feet = np.array([body + rot @ ROBOT.hip_offset(leg) + below for leg in LEGS])
    q = whole_body_ik(ROBOT, body, pitch, feet)
    for i, leg in enumerate(LEGS):
        back = body + rot @ (ROBOT.hip_offset(leg) + leg_fk(ROBOT, q[3 * i : 3 * i + 3]))
        np.testing.assert_allclose(back, feet[i], atol=KIN_TOL)
    com = whole_body_com(ROBOT, body, pitch, q)
    # legs hang below the body, so the CoM is below the body centre but within the leg mass share
    assert body[2] - 0.6 * ROBOT.leg_mass * 4 / ROBOT.total_mass < com[2] < body[2]


def test_support_polygon_hull_and_margin_of_a_square() -> None:
    pts = np.array([[0, 0], [1, 0], [1, 1], [0, 1], [0.5, 0.5], [0.2, 0.7]], dtype=float)
    hull = support_polygon(pts)
    assert hull.shape == (4, 2)
    area = 0.5 * np.sum(hull[:, 0] * np.roll(hull[:, 1], -1) - np.roll(hull[:, 0], -1) * hull[:, 1])
    assert area == pytest.approx(1.0)  # positive: counter-clockwise
    assert stability_margin([0.5, 0.5], hull) == pytest.approx(0.5)
    assert stability_margin([0.9, 0.5], hull) == pytest.approx(0.1)
    assert stability_margin([2.0, 0.5], hull) == pytest.approx(-1.0)
    assert stability_margin([2.0, 2.0], hull) == pytest.approx(-math.sqrt(2.0))
    assert stability_margin([0.3, 0.0], hull) == pytest.approx(0.0)


def test_margin_of_degenerate_polygons_is_minus_the_distance() -> None:
    assert stability_margin([0.5, 1.0], [[0, 0], [1, 0]]) == pytest.approx(-1.0)
    assert stability_margin([3.0, 4.0], [[0, 0]]) == pytest.approx(-5.0)


@settings(max_examples=60, deadline=None)
@given(tri=triangles, w=st.lists(st.floats(0.01, 1.0), min_size=3, max_size=3))
def test_incentre_is_equidistant_and_maximises_the_margin(tri: np.ndarray, w: list[float]) -> None:
    centre, radius = incentre(tri)
    for i in range(3):
        assert _line_distance(centre, tri[i], tri[(i + 1) % 3]) == pytest.approx(radius, abs=1e-9)
    assert stability_margin(centre, tri) == pytest.approx(radius, abs=GEOM_TOL)
    # any interior point (positive barycentric weights) has a positive margin no larger
    bary = np.array(w) / np.sum(w)
    p = bary @ tri
    m = stability_margin(p, tri)
    assert 0.0 < m <= radius + GEOM_TOL
    # reflecting it through a vertex puts it outside: negative margin
    outside = 2.0 * tri[0] - p + (tri[0] - centre)
    assert stability_margin(outside, tri) < 0.0


@settings(max_examples=40, deadline=None)
@given(tri=triangles, pts=st.lists(st.tuples(coord, coord), min_size=1, max_size=8))
def test_vectorised_margin_matches_scalar(tri: np.ndarray, pts: list[tuple[float, float]]) -> None:
    arr = np.array(pts)
    expected = [stability_margin(p, tri) for p in arr]
    np.testing.assert_allclose(stability_margins(arr, tri), expected, atol=GEOM_TOL)


def test_clip_convex_of_two_squares() -> None:
    a = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    b = a + 1.0
    inter = clip_convex(a, b)
    np.testing.assert_allclose(np.sort(inter, axis=0), [[1, 1], [1, 1], [2, 2], [2, 2]])
    assert clip_convex(a, a + 5.0).shape[0] == 0


def test_zmp_eq7_equals_eq5_for_a_point_mass() -> None:
    """Eq. (7) is eq. (5) with P = M c', L = c x M c' (eq. 6): check on random motions."""
    rng = np.random.default_rng(1)
    mass = 100.0
    for _ in range(50):
        c = rng.uniform([-1, -1, 0.3], [1, 1, 1.0])
        a = rng.uniform(-3, 3, size=3)
        z_p = rng.uniform(-0.2, 0.2)
        p_dot = mass * a
        l_dot = np.cross(c, mass * a)  # d/dt (c x M c') = c x M c''
        np.testing.assert_allclose(
            zmp_from_momentum(mass, c, p_dot, l_dot, z_p), zmp_from_com(c, a, z_p), atol=1e-12
        )


def test_zmp_of_a_static_robot_is_the_com_projection() -> None:
    np.testing.assert_allclose(zmp_from_com([0.3, -0.2, 0.7], [0, 0, 0]), [0.3, -0.2])
    # accelerating forwards moves the ZMP backwards by z a / g
    zmp = zmp_from_com([0, 0, 0.6], [1.0, 0, 0], g=9.81)
    assert zmp[0] == pytest.approx(-0.6 / 9.81)


def test_centre_of_pressure_balances_a_static_tripod_on_a_slope() -> None:
    """Contact forces that hold a point mass still give a CoP at the CoM's vertical projection."""
    mass, g = 100.0, 9.81
    slope = math.radians(15.0)
    com = np.array([0.1, 0.05, 0.8])
    xy = np.array([[0.5, 0.3], [0.4, -0.3], [-0.45, 0.0]])
    pts = np.column_stack([xy, xy[:, 0] * math.tan(slope)])  # feet on the slope
    # vertical forces from moment balance about the CoM projection; friction carries nothing
    a_mat = np.vstack([np.ones(3), xy[:, 0], xy[:, 1]])
    fz = np.linalg.solve(a_mat, [mass * g, mass * g * com[0], mass * g * com[1]])
    forces = np.column_stack([np.zeros(3), np.zeros(3), fz])
    cop, total = centre_of_pressure(pts, forces, z_p=float(pts[:, 2].mean()))
    assert total == pytest.approx(mass * g)
    np.testing.assert_allclose(cop, com[:2], atol=1e-12)
