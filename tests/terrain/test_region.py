"""Region geometry (document 000, eq. 5.15-5.18), against independent computations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from matplotlib.path import Path as MplPath

from footfall.errors import SceneError
from footfall.terrain import Region

SQUARE = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])


def winding_number(pt: np.ndarray, poly: np.ndarray) -> int:
    """Independent point-in-polygon test (Sunday's winding number)."""
    wn = 0
    n = len(poly)
    for i in range(n):
        a, b = poly[i], poly[(i + 1) % n]
        is_left = (b[0] - a[0]) * (pt[1] - a[1]) - (pt[0] - a[0]) * (b[1] - a[1])
        if a[1] <= pt[1] < b[1] and is_left > 0:
            wn += 1
        elif b[1] <= pt[1] < a[1] and is_left < 0:
            wn -= 1
    return wn


def test_ccw_kept_and_cw_reordered() -> None:
    r = Region.from_height("a", 0.0, SQUARE)
    assert not r.reordered
    np.testing.assert_array_equal(r.vertices, SQUARE)
    cw = SQUARE[::-1]
    r2 = Region.from_height("b", 0.0, cw)
    assert r2.reordered
    assert r2.area == pytest.approx(1.0)
    # Same polygon, same half-spaces (as sets of rows).
    a1, b1 = r.halfspaces()
    a2, b2 = r2.halfspaces()
    rows1 = sorted(map(tuple, np.round(np.column_stack([a1, b1]), 12)))
    rows2 = sorted(map(tuple, np.round(np.column_stack([a2, b2]), 12)))
    assert rows1 == rows2


def test_non_convex_rejected_naming_region() -> None:
    dart = np.array([[0.0, 0.0], [2.0, 0.0], [0.6, 0.6], [0.0, 2.0]])
    with pytest.raises(SceneError, match="convex") as exc:
        Region.from_height("block7", 0.1, dart)
    assert "block7" in str(exc.value)


def test_self_intersecting_star_rejected() -> None:
    ang = np.radians(90 + 144 * np.arange(5))
    star = np.column_stack([np.cos(ang), np.sin(ang)])
    with pytest.raises(SceneError, match=r"winds|convex"):
        Region.from_height("star", 0.0, star)


@pytest.mark.parametrize(
    ("vertices", "message"),
    [
        ([[0, 0], [1, 0]], "at least 3"),
        ([[0, 0], [1, 0], [1, 0], [0, 1]], "distinct consecutive"),
        ([[0, 0], [1, 0], [2, 0]], "area"),
        ([[0, 0], [1, 0], [float("nan"), 1]], "finite"),
    ],
)
def test_degenerate_rejected(vertices: list[list[float]], message: str) -> None:
    with pytest.raises(SceneError, match=message) as exc:
        Region.from_height("r", 0.0, np.array(vertices, dtype=float))
    assert "'r'" in exc.value.field


def test_vertical_plane_rejected() -> None:
    # A wall x = 1: normal (1, 0, 0).
    with pytest.raises(SceneError, match=r"vertical|horizontal") as exc:
        Region.from_plane("wall", [1.0, 0.0, 0.0], -1.0, SQUARE)
    assert "wall" in str(exc.value)
    # 80 deg is too steep, 70 deg is accepted.
    for deg, ok in ((80.0, False), (70.0, True)):
        n = [math.sin(math.radians(deg)), 0.0, math.cos(math.radians(deg))]
        if ok:
            assert Region.from_plane("s", n, 0.0, SQUARE).slope_deg == pytest.approx(deg)
        else:
            with pytest.raises(SceneError):
                Region.from_plane("s", n, 0.0, SQUARE)


def test_normal_normalised_with_positive_c() -> None:
    # -2 z + 0.4 = 0 is the plane z = 0.2, written with a downward, non-unit normal.
    r = Region.from_plane("r", [0.0, 0.0, -2.0], 0.4, SQUARE)
    np.testing.assert_allclose(r.normal, [0, 0, 1])
    assert r.offset == pytest.approx(-0.2)
    assert r.height_at([0.3, 0.3]) == pytest.approx(0.2)


def test_plane_fit_from_3d_vertices() -> None:
    # Plane z = 0.1 + 0.2 x - 0.05 y, corners of a quadrilateral (clockwise in plan view).
    xy = np.array([[0.0, 0.0], [0.0, 1.0], [1.5, 1.2], [1.2, -0.1]])
    z = 0.1 + 0.2 * xy[:, 0] - 0.05 * xy[:, 1]
    r = Region.from_3d("tilt", np.column_stack([xy, z]))
    assert r.reordered
    expected = np.array([-0.2, 0.05, 1.0]) / math.sqrt(0.2**2 + 0.05**2 + 1.0)
    np.testing.assert_allclose(r.normal, expected, atol=1e-12)
    np.testing.assert_allclose(
        r.vertices3d[:, 2], 0.1 + 0.2 * r.vertices[:, 0] - 0.05 * r.vertices[:, 1]
    )


def test_non_planar_3d_rejected() -> None:
    p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0.01], [0, 1, 0]], dtype=float)
    with pytest.raises(SceneError, match="coplanar") as exc:
        Region.from_3d("warped", p)
    assert "warped" in str(exc.value)


def test_height_at_tilted_plane_by_hand() -> None:
    # n = (1, 2, 4)/|.|, d = -1/|.|: x + 2 y + 4 z = 1 -> z = (1 - x - 2 y) / 4.
    r = Region.from_plane("t", [1.0, 2.0, 4.0], -1.0, SQUARE)
    for x, y in [(0.0, 0.0), (0.5, 0.25), (1.0, 1.0), (0.2, 0.9)]:
        assert r.height_at([x, y]) == pytest.approx((1 - x - 2 * y) / 4, abs=1e-12)
    zs = r.height_at(np.array([[0.0, 0.0], [1.0, 1.0]]))
    np.testing.assert_allclose(zs, [0.25, -0.5])


def test_plane_rows_eq_5_17() -> None:
    r = Region.from_plane("t", [1.0, 2.0, 4.0], -1.0, SQUARE)
    a, b = r.plane_rows()
    on = np.array([0.5, 0.25, (1 - 0.5 - 0.5) / 4])
    assert np.all(a @ on <= b + 1e-12)
    assert np.any(a @ (on + np.array([0, 0, 1e-3])) > b)
    assert np.any(a @ (on - np.array([0, 0, 1e-3])) > b)


def test_contains_needs_plane_and_polygon() -> None:
    r = Region.from_height("r", 0.3, SQUARE)
    assert r.contains([0.5, 0.5, 0.3])
    assert not r.contains([0.5, 0.5, 0.31])
    assert not r.contains([1.1, 0.5, 0.3])
    assert r.contains([1.0, 0.5, 0.3])  # on the edge


def test_halfspaces_vs_winding_number_and_signed_distance() -> None:
    hexagon = np.array([[0, 0], [1, -0.2], [1.8, 0.3], [1.7, 1.1], [0.8, 1.4], [-0.2, 0.8]])
    r = Region.from_height("hex", 0.0, hexagon)
    a, b = r.halfspaces()
    np.testing.assert_allclose(np.linalg.norm(a, axis=1), 1.0)
    # eq. 5.18: row j is n_j . xy <= n_j . v_j with n_j normal to edge j and pointing away from
    # the interior.
    edges = np.roll(hexagon, -1, axis=0) - hexagon
    np.testing.assert_allclose(np.einsum("ij,ij->i", a, edges), 0.0, atol=1e-12)
    np.testing.assert_allclose(b, np.einsum("ij,ij->i", a, hexagon))
    assert np.all(a @ hexagon.mean(axis=0) < b)
    rng = np.random.default_rng(1)
    pts = rng.uniform(-0.5, 2.0, size=(3000, 2))
    sd = r.signed_distance(pts)
    inside = np.array([winding_number(p, hexagon) != 0 for p in pts])
    clear = np.abs(sd) > 1e-6
    assert np.array_equal((sd <= 0)[clear], inside[clear])
    # Signed distance equals the true distance when the nearest feature is an edge interior:
    # check the point straight out from an edge midpoint.
    mid = 0.5 * (hexagon[0] + hexagon[1])
    assert r.signed_distance(mid + 0.1 * a[0]) == pytest.approx(0.1)


def test_centroid_and_area_of_triangle() -> None:
    tri = np.array([[0.0, 0.0], [3.0, 0.0], [0.0, 3.0]])
    r = Region.from_plane("t", [0.0, 0.5, 1.0], 0.0, tri)
    np.testing.assert_allclose(r.centroid[:2], [1.0, 1.0])
    assert r.centroid[2] == pytest.approx(-0.5)
    assert r.area == pytest.approx(4.5)


@st.composite
def convex_polygons(draw: st.DrawFn) -> np.ndarray:
    """Random convex polygons: sorted angles on a random ellipse, rotated and shifted."""
    n = draw(st.integers(3, 9))
    angles = np.sort(
        np.array(draw(st.lists(st.floats(0, 2 * np.pi, exclude_max=True), min_size=n, max_size=n)))
    )
    if np.min(np.diff(np.append(angles, angles[0] + 2 * np.pi))) < 0.05:
        angles = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ax, ay = draw(st.floats(0.2, 3.0)), draw(st.floats(0.2, 3.0))
    rot = draw(st.floats(-np.pi, np.pi))
    cx, cy = draw(st.floats(-10, 10)), draw(st.floats(-10, 10))
    local = np.column_stack([ax * np.cos(angles), ay * np.sin(angles)])
    c, s = np.cos(rot), np.sin(rot)
    return local @ np.array([[c, s], [-s, c]]) + [cx, cy]


@settings(max_examples=60, deadline=None)
@given(
    poly=convex_polygons(),
    flip=st.booleans(),
    slope=st.tuples(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5)),
)
def test_property_convex_polygons(poly: np.ndarray, flip: bool, slope: tuple[float, float]) -> None:
    given_poly = poly[::-1] if flip else poly
    r = Region.from_plane("p", [-slope[0], -slope[1], 1.0], -0.2, given_poly)
    assert r.reordered == flip
    # Centroid inside.
    assert r.signed_distance(r.centroid[:2]) < 0
    assert r.contains(r.centroid, tol=1e-9)
    assert MplPath(r.vertices).contains_point(r.centroid[:2])
    # Vertices on the boundary: max of the edge functions is 0 there.
    for v in r.vertices:
        assert abs(r.signed_distance(v)) < 1e-9
    # Far points outside, in every direction.
    span = np.ptp(r.vertices, axis=0).max()
    for t in np.linspace(0, 2 * np.pi, 12, endpoint=False):
        far = r.centroid[:2] + 3 * span * np.array([np.cos(t), np.sin(t)])
        assert r.signed_distance(far) > 0
    # Every vertex lies on the plane (eq. 5.15).
    np.testing.assert_allclose(r.vertices3d @ r.normal + r.offset, 0.0, atol=1e-9)
    # Region from its own 3-D corners reproduces the plane.
    r3 = Region.from_3d("q", r.vertices3d)
    np.testing.assert_allclose(r3.normal, r.normal, atol=1e-9)
    assert r3.offset == pytest.approx(r.offset, abs=1e-9)


def test_region_is_immutable() -> None:
    r = Region.from_height("r", 0.0, SQUARE)
    with pytest.raises(ValueError, match="read-only"):
        r.vertices[0, 0] = 5.0
    with pytest.raises(AttributeError):
        r.name = "x"  # type: ignore[misc]
