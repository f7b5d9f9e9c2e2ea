"""ZMP / support-polygon functions of document 001 (quadruped/stability.py) on cases with known
answers: hulls against scipy's Qhull, moment balance of the CoP, eq. (5)/(7) by hand, errors that
name their field. Written to kill the mutmut survivors listed in benchmarks/MUTATION.md."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from footfall.errors import InputError
from footfall.quadruped.stability import (
    centre_of_pressure,
    clip_convex,
    incentre,
    line_intersection,
    stability_margin,
    stability_margins,
    support_polygon,
    zmp_from_com,
    zmp_from_momentum,
)

#: geometry tolerance [m]
GEOM_TOL = 1e-12
G = 9.81
SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
TRI = np.array([[0.0, 0.0], [2.0, 0.0], [0.0, 1.0]])


def same_cycle(a: np.ndarray, b: np.ndarray) -> bool:
    """Both CCW vertex lists describe the same polygon (any starting vertex)."""
    if a.shape != b.shape:
        return False
    k = int(np.argmin(np.linalg.norm(a - b[0], axis=1)))
    return bool(np.allclose(np.roll(a, -k, axis=0), b, atol=GEOM_TOL))


@pytest.mark.parametrize("seed", range(6))
def test_support_polygon_is_qhull_of_a_point_cloud_with_duplicates(seed: int) -> None:
    rng = np.random.default_rng(seed)
    pts = rng.uniform(-1.0, 1.0, (12, 2))
    pts = np.vstack([pts, pts[:4]])  # repeated feet
    hull = support_polygon(pts)
    ref = pts[ConvexHull(pts).vertices]  # counter-clockwise in 2-D
    assert same_cycle(hull, ref)


def test_collinear_and_repeated_points_are_dropped() -> None:
    mids = np.array([[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]])
    assert same_cycle(support_polygon(np.vstack([SQUARE, mids, SQUARE])), SQUARE)
    np.testing.assert_array_equal(support_polygon([[0.2, 0.3], [0.2, 0.3]]), [[0.2, 0.3]])
    np.testing.assert_array_equal(
        support_polygon([[0, 0], [1, 1], [2, 2], [1, 1]]), [[0, 0], [2, 2]]
    )


def check_field(call: Callable[[], object], field: str, value: object = None) -> None:
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field
    if value is not None:
        assert err.value.value == value


@pytest.mark.parametrize(
    ("points", "shape"), [(np.zeros((0, 2)), (0, 2)), (np.zeros((3, 1)), (3, 1)), ([1.0], (1,))]
)
def test_bad_support_points_name_the_field(points: object, shape: tuple) -> None:
    check_field(lambda: support_polygon(points), "points", shape)


def test_margin_of_a_point_polygon_off_the_origin_and_of_3d_zmps() -> None:
    assert stability_margin([1.0, 2.0], [[4.0, 6.0]]) == pytest.approx(-5.0)
    assert stability_margin([1.0, 2.0, 0.7], [[4.0, 6.0]]) == pytest.approx(-5.0)
    assert stability_margin([0.5, 0.25, 3.0], SQUARE) == pytest.approx(0.25)


def test_vectorised_margins_of_segments_3d_points_and_single_points() -> None:
    pts = np.array([[0.5, 0.2], [3.0, 0.5], [-1.0, -2.0], [0.5, 1.5]])
    want = np.array([stability_margin(p, SQUARE) for p in pts])
    np.testing.assert_allclose(want, [0.2, -2.0, -np.sqrt(5.0), -0.5])
    np.testing.assert_allclose(stability_margins(pts, SQUARE), want, atol=GEOM_TOL)
    pts3 = np.column_stack([pts, [0.1, 0.2, 0.3, 0.4]])
    np.testing.assert_allclose(stability_margins(pts3, SQUARE), want, atol=GEOM_TOL)
    np.testing.assert_allclose(stability_margins([0.5, 0.2], SQUARE), [0.2], atol=GEOM_TOL)
    segment = np.array([[0.0, 0.0], [2.0, 0.0]])
    np.testing.assert_allclose(
        stability_margins(pts, segment),
        [-0.2, -1.118033988749895, -2.2360679774997896, -1.5],
        rtol=1e-12,
    )


def test_zmp_from_com_by_hand_and_batched() -> None:
    """Eq. (7): x_p = x_c - (z_c - z_p) xdd / (zdd + g)."""
    c = np.array([[0.1, 0.2, 0.8], [0.0, -0.1, 0.6]])
    a = np.array([[1.0, -2.0, 0.5], [0.3, 0.0, -1.0]])
    want = [
        [0.1 - 0.7 * 1.0 / (0.5 + G), 0.2 + 0.7 * 2.0 / (0.5 + G)],
        [0.0 - 0.5 * 0.3 / (G - 1.0), -0.1],
    ]
    np.testing.assert_allclose(zmp_from_com(c, a, z_p=0.1), want, rtol=1e-14)
    # just above free fall is still loaded
    assert np.all(np.isfinite(zmp_from_com([0, 0, 1], [1.0, 0.0, -G + 0.5])))


@pytest.mark.parametrize("zdd", [-G, -G - 1.0])
def test_feet_unloaded_raise_naming_the_field(zdd: float) -> None:
    check_field(lambda: zmp_from_com([0, 0, 1], [0, 0, zdd], g=G), "com_acc", "zdd_c <= -g")
    check_field(
        lambda: zmp_from_momentum(2.0, [0, 0, 1], [0, 0, 2.0 * zdd], [0, 0, 0], g=G),
        "p_dot",
        "Pdot_z <= -M g",
    )


def test_zmp_from_momentum_by_hand_default_ground_and_batched() -> None:
    """Eq. (5): x_p = (M g x_c + z_p Pdot_x - Ldot_y) / (M g + Pdot_z), y_p likewise with
    + Ldot_x; the ground height defaults to 0."""
    m = 10.0
    c = np.array([0.1, -0.2, 0.7])
    pd = np.array([3.0, -4.0, 5.0])
    ld = np.array([0.6, -0.8, 0.0])
    den = m * G + 5.0
    want0 = [(m * G * 0.1 + 0.8) / den, (m * G * -0.2 + 0.6) / den]
    np.testing.assert_allclose(zmp_from_momentum(m, c, pd, ld), want0, rtol=1e-14)
    want1 = [(m * G * 0.1 + 0.2 * 3.0 + 0.8) / den, (m * G * -0.2 - 0.2 * 4.0 + 0.6) / den]
    np.testing.assert_allclose(zmp_from_momentum(m, c, pd, ld, z_p=0.2), want1, rtol=1e-14)
    # nearly (not quite) free fall: M g + Pdot_z = 0.5 N is still loaded
    assert np.all(np.isfinite(zmp_from_momentum(1.0, c, [0.0, 0.0, 0.5 - G], ld)))
    batch = zmp_from_momentum(m, np.stack([c, c, c]), np.stack([pd] * 3), np.stack([ld] * 3))
    np.testing.assert_allclose(batch, [want0] * 3, rtol=1e-14)


def test_centre_of_pressure_has_no_horizontal_moment() -> None:
    """Contacts at different heights with horizontal forces: the moment of the contact forces
    about the CoP on z = z_p has zero x and y components."""
    r = np.array([[0.3, 0.2, 0.05], [-0.3, 0.25, 0.0], [0.1, -0.3, 0.12]])
    f = np.array([[5.0, -3.0, 60.0], [-2.0, 4.0, 80.0], [1.0, 2.0, 40.0]])
    for z_p in (0.0, 0.04):
        cop, fz = centre_of_pressure(r, f, z_p) if z_p else centre_of_pressure(r, f)
        assert fz == pytest.approx(180.0)
        arm = r - np.array([cop[0], cop[1], z_p])
        moment = np.cross(arm, f).sum(axis=0)
        np.testing.assert_allclose(moment[:2], 0.0, atol=1e-12)


@pytest.mark.filterwarnings("error")  # unloaded feet return NaN without dividing by zero
def test_centre_of_pressure_of_unloaded_and_lightly_loaded_feet() -> None:
    cop, fz = centre_of_pressure([[0, 0, 0], [1, 0, 0]], [[0, 0, 0], [0, 0, 0]])
    assert fz == 0.0 and cop.shape == (2,) and np.all(np.isnan(cop))
    cop, fz = centre_of_pressure([[0, 0, 0], [1, 0, 0]], [[0, 0, 0.25], [0, 0, 0.75]])
    np.testing.assert_allclose(cop, [0.75, 0.0], rtol=1e-14)


def test_incentre_and_intersection_accept_3d_points() -> None:
    centre, r = incentre(np.column_stack([TRI, [0.3, 0.1, 0.2]]))
    want, r2 = incentre(TRI)
    np.testing.assert_allclose(centre, want)
    assert r == pytest.approx(r2)
    p = line_intersection([0, 0, 1], [2, 2, 1], [0, 2, 5], [2, 0, 5])
    np.testing.assert_allclose(p, [1.0, 1.0])


def test_geometry_errors_name_the_field() -> None:
    check_field(lambda: incentre([[0, 0], [1, 0]]), "triangle", (2, 2))
    check_field(lambda: incentre([[0, 0], [1, 1], [2, 2]]), "triangle", [[0, 0], [1, 1], [2, 2]])
    check_field(
        lambda: line_intersection([0, 0], [1, 0], [0, 1], [1, 1]),
        "lines",
        ([0.0, 0.0], [1.0, 0.0]),
    )


def test_clip_convex_edge_cases() -> None:
    empty = clip_convex(SQUARE, SQUARE + 5.0)
    assert empty.shape == (0, 2)
    assert clip_convex([[5.0, 5.0]], SQUARE).shape == (0, 2)  # a point outside
    np.testing.assert_allclose(clip_convex([[0.5, 0.5]], SQUARE), [[0.5, 0.5]])
    # a triangle with a vertex on a clip edge: no repeated vertex in the result
    tri = np.array([[0.5, 1.0], [0.0, 2.0], [-1.0, 1.0]])
    out = clip_convex(tri, SQUARE * 4.0 - np.array([2.0, -1.0]))  # y in [1, 5]
    assert same_cycle(out, support_polygon(tri))
    # squares sharing an edge meet in that edge
    shared = clip_convex(SQUARE, SQUARE + np.array([1.0, 0.0]))
    assert same_cycle(shared, np.array([[1.0, 0.0], [1.0, 1.0]]))


def expected_text(call: Callable[[], object], field: str, *words: str) -> None:
    """The error names ``field`` and its expected-value text holds each of ``words`` as whole
    words: a user reads these messages, so their content is part of the contract."""
    with pytest.raises(InputError) as err:
        call()
    assert err.value.field == field
    for word in words:
        pattern = rf"(?<!\w){re.escape(word)}(?!\w)"
        assert re.search(pattern, err.value.expected), (word, err.value.expected)
        assert re.search(pattern, str(err.value))


def test_error_messages_say_what_was_expected() -> None:
    expected_text(
        lambda: support_polygon(np.zeros((0, 2))), "points", "an array", "(N, 2) or (N, 3), N >= 1"
    )
    expected_text(
        lambda: zmp_from_com([0, 0, 1], [0, 0, -G], g=G),
        "com_acc",
        "vertical acceleration above -g",
        "(feet loaded)",
    )
    expected_text(
        lambda: zmp_from_momentum(1.0, [0, 0, 1], [0, 0, -G], [0, 0, 0], g=G),
        "p_dot",
        "M g + Pdot_z > 0",
        "(feet loaded)",
    )
    expected_text(lambda: incentre([[0, 0], [1, 0]]), "triangle", "three 2-D vertices", "(3, 2)")
    expected_text(lambda: incentre([[0, 0], [1, 1], [2, 2]]), "triangle", "non-degenerate triangle")
    expected_text(
        lambda: line_intersection([0, 0], [1, 0], [0, 1], [1, 1]), "lines", "two non-parallel lines"
    )


@pytest.mark.parametrize("seed", range(8))
def test_support_polygon_of_feet_on_a_grid_is_qhull(seed: int) -> None:
    """Feet sharing x or y coordinates (a stance rectangle, a grid), given in any order and with
    repeats: the monotone chain needs its points sorted by x *then* y, and ties in x are the
    common case for a quadruped."""
    rng = np.random.default_rng(seed)
    pts = rng.integers(0, 3, (8, 2)).astype(float) * 0.2
    pts = np.vstack([pts, [[0.0, 0.0], [0.4, 0.4]]])  # never all collinear
    ref = pts[ConvexHull(pts).vertices]
    assert same_cycle(support_polygon(pts), ref)
    stance = np.array([[0.3, -0.2], [-0.3, 0.2], [0.3, 0.2], [-0.3, -0.2], [0.3, -0.2]])
    rect = np.array([[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]])
    assert same_cycle(support_polygon(stance), rect)


def test_clip_convex_of_polygons_touching_at_a_vertex_is_that_point() -> None:
    """Closed polygons that meet in one point intersect in that point (vertices on a clip line
    count as inside), returned once, not as three copies from Sutherland-Hodgman."""
    touching = np.array([[1.0, 0.5], [2.0, 0.0], [2.0, 1.0]])
    np.testing.assert_array_equal(clip_convex(touching, SQUARE), [[1.0, 0.5]])
    np.testing.assert_array_equal(clip_convex(SQUARE, touching), [[1.0, 0.5]])
