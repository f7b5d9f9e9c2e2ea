"""The quadruped's grounds (side slope, varying slope, stairs) against independent references:
numerical quadrature for the varying slope's height, plane geometry for the side slope, and the
stair edges for footholds."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from footfall.errors import InputError
from footfall.quadruped.ground import PlaneGround, Stairs, VaryingSlope

HILL = VaryingSlope((0.5, 2.5, 4.5, 6.5), tuple(math.radians(v) for v in (0.0, 20.0, 0.0, -15.0)))


def _beta(x: float) -> float:
    """The hill's inclination, written out again (linear between knots, constant outside)."""
    xs, bs = (0.5, 2.5, 4.5, 6.5), (0.0, 20.0, 0.0, -15.0)
    if x <= xs[0]:
        return 0.0
    if x >= xs[-1]:
        return math.radians(bs[-1])
    i = max(k for k in range(len(xs)) if xs[k] <= x)
    u = (x - xs[i]) / (xs[i + 1] - xs[i])
    return math.radians(bs[i] + u * (bs[i + 1] - bs[i]))


@pytest.mark.parametrize("x", [-1.0, 0.3, 1.2, 2.5, 3.7, 5.0, 6.5, 8.0])
def test_varying_slope_height_is_the_integral_of_the_tangent(x: float) -> None:
    ref, _ = quad(lambda s: math.tan(_beta(s)), 0.0, x, points=[0.5, 2.5, 4.5, 6.5], limit=200)
    assert HILL.centre_height(x) == pytest.approx(ref, abs=1e-9)
    assert HILL.inclination(x) == pytest.approx(_beta(x), abs=1e-12)


def test_varying_slope_normal_is_perpendicular_to_the_surface() -> None:
    for x in np.linspace(-0.5, 7.0, 31):
        h = 1e-6
        tangent = np.array([2 * h, 0.0, HILL.centre_height(x + h) - HILL.centre_height(x - h)])
        n = HILL.normal(x)
        assert np.linalg.norm(n) == pytest.approx(1.0)
        assert abs(n @ tangent) / np.linalg.norm(tangent) < 1e-6


@pytest.mark.parametrize("x0", [0.0, 1.3, 2.4, 4.4, 6.0])
@pytest.mark.parametrize("step", [0.4, -0.2])
def test_varying_slope_step_is_a_chord_of_the_step_length(x0: float, step: float) -> None:
    foot = np.array([x0, 0.25, HILL.centre_height(x0)])
    land = HILL.advance(foot, step, 0.03)
    assert np.linalg.norm(land - foot) == pytest.approx(abs(step), abs=1e-9)
    assert np.sign(land[0] - x0) == np.sign(step)
    assert land[2] == pytest.approx(HILL.centre_height(float(land[0])))
    assert land[1] == 0.25


def test_side_slope_plane_contains_its_points_and_steps() -> None:
    g = PlaneGround(math.radians(10.0), math.radians(15.0))
    n = g.normal(0.0, 0.0)
    # the plane through the origin rises tan(10 deg) along x and tan(15 deg) along y
    assert n @ np.array([1.0, 0.0, math.tan(math.radians(10.0))]) == pytest.approx(0.0, abs=1e-12)
    assert n @ np.array([0.0, 1.0, math.tan(math.radians(15.0))]) == pytest.approx(0.0, abs=1e-12)
    assert n[2] > 0 and n[1] < 0  # the left side is higher: the normal leans right
    foot = np.array([0.3, -0.25, g.centre_height(0.3, -0.25)])
    land = g.advance(foot, 0.4, 0.03)
    assert np.linalg.norm(land - foot) == pytest.approx(0.4)
    assert land[2] == pytest.approx(g.centre_height(float(land[0]), float(land[1])))
    drop = g.drop(np.array([0.2, 0.25, 1.0]), np.array([0.0, 0.0, -1.0]))
    assert drop[2] == pytest.approx(g.centre_height(0.2, 0.25))


def test_document_plane_normal_is_unchanged() -> None:
    b = math.radians(15.0)
    np.testing.assert_array_equal(PlaneGround(b).normal(1.0, 2.0), [-math.sin(b), 0.0, math.cos(b)])


def test_stairs_heights_and_edges() -> None:
    s = Stairs(rise=0.1, run=0.4, steps=3, start_x=0.8)
    np.testing.assert_allclose(s.edges, [0.8, 1.2, 1.6])
    for x, h in [(0.0, 0.0), (0.79, 0.0), (0.81, 0.1), (1.3, 0.2), (1.7, 0.3), (9.0, 0.3)]:
        assert s.centre_height(x) == pytest.approx(h)


def test_stairs_footholds_keep_clear_of_every_edge() -> None:
    s = Stairs(rise=0.1, run=0.4, steps=4, start_x=0.8, edge_margin=0.04)
    r = 0.03
    for x0 in np.linspace(-0.5, 2.6, 311):
        land = s.advance(np.array([x0, 0.0, 0.0]), 0.4, r)
        gaps = land[0] - s.edges
        # on the lower tread: the sphere keeps edge_margin from the riser face; on the upper
        # tread: its centre keeps edge_margin past the nosing
        assert np.all((gaps <= -(r + 0.04) + 1e-12) | (gaps >= 0.04 - 1e-12)), (x0, land)
        # moved the least: never more than the band's width
        assert abs(land[0] - (x0 + 0.4)) <= r + 2 * 0.04 + 1e-12
        assert land[2] == pytest.approx(s.centre_height(float(land[0])))


def test_stairs_clearance_sees_the_edge() -> None:
    s = Stairs(rise=0.1, run=0.4, steps=2, start_x=0.8)
    r = 0.03
    # a foot centre 5 cm above the floor but 1 cm before the riser cuts the step's corner
    assert s.clearance(np.array([[0.79, 0.0, 0.05]]), r)[0] < 0
    assert s.clearance(np.array([[0.70, 0.0, 0.0]]), r)[0] == pytest.approx(0.0)
    assert s.clearance(np.array([[0.79, 0.0, 0.12]]), r)[0] == pytest.approx(0.02)


@pytest.mark.parametrize(
    ("build", "field"),
    [
        (lambda: PlaneGround(math.radians(70.0)), "slope"),
        (lambda: PlaneGround(0.1, float("nan")), "side_slope"),
        (lambda: VaryingSlope((0.0,), (0.0,)), "knots_x"),
        (lambda: VaryingSlope((0.0, 1.0), (0.0,)), "knots_slope"),
        (lambda: VaryingSlope((0.0, 0.0), (0.0, 0.1)), "knots_x[1]"),
        (lambda: VaryingSlope((0.0, 1.0), (0.0, 1.2)), "knots_slope[1]"),
        (lambda: Stairs(rise=-0.1), "rise"),
        (lambda: Stairs(steps=0), "steps"),
        (lambda: Stairs(steps=True), "steps"),  # type: ignore[arg-type]
        (lambda: Stairs(steps=100_000_000), "steps"),
        (lambda: Stairs(rise=1.0, run=0.4), "rise"),
    ],
)
def test_bad_grounds_name_the_field(build: object, field: str) -> None:
    with pytest.raises(InputError) as err:
        build()  # type: ignore[operator]
    assert err.value.field == field
