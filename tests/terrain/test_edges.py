"""Per-edge riser insets (footfall.terrain.edges) on hand-made scenes with answers worked by hand.

Region vertices are counter-clockwise from the lower-left corner, so edge 0 is the side at the
smallest y, edge 1 the side at the largest x, edge 2 the side at the largest y, edge 3 the side
at the smallest x.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from footfall._geometry import clip_halfplane, signed_area
from footfall.errors import InputError
from footfall.terrain import Region, Terrain, builtin_scene
from footfall.terrain.edges import inset_region_edges, inset_riser_edges, riser_edge_insets

TOL = 0.04
#: exact-arithmetic answers up to float round-off [m]
EPS = 1e-12


def box(name: str, z: float, x0: float, x1: float, y0: float = 0.0, y1: float = 1.0) -> Region:
    return Region.from_height(name, z, [[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def test_step_up_next_to_an_edge_moves_only_that_edge() -> None:
    # the low tread's +x edge meets a 0.1 m riser: a foot landing long would put its toe on top
    low, high = box("low", 0.0, 0.0, 1.0), box("high", 0.1, 1.0, 2.0)
    ins = riser_edge_insets(Terrain((low, high)), TOL)
    np.testing.assert_allclose(ins["low"], [0.0, TOL, 0.0, 0.0], atol=EPS)
    # seen from the high tread the neighbour is a step down: an overhang, like an open edge
    np.testing.assert_allclose(ins["high"], [0.0, 0.0, 0.0, 0.0], atol=EPS)


def test_a_gap_counts_against_the_tolerance() -> None:
    # the higher block begins 0.01 m beyond the edge: the sole may come 0.03 m closer
    ins = riser_edge_insets(Terrain((box("low", 0.0, 0.0, 1.0), box("high", 0.1, 1.01, 2.0))), TOL)
    assert ins["low"][1] == pytest.approx(TOL - 0.01, abs=EPS)
    # a gap wider than the tolerance: out of reach of a landing error
    far = Terrain((box("low", 0.0, 0.0, 1.0), box("high", 0.1, 1.05, 2.0)))
    np.testing.assert_allclose(riser_edge_insets(far, TOL)["low"], 0.0, atol=EPS)


def test_small_steps_ramps_and_corner_contacts_are_not_risers() -> None:
    low = box("low", 0.0, 0.0, 1.0)
    # a 4 mm step is below min_rise (5 mm)
    tiny = Terrain((low, box("tiny", 0.004, 1.0, 2.0)))
    np.testing.assert_allclose(riser_edge_insets(tiny, TOL)["low"], 0.0, atol=EPS)
    # a ramp leaving the floor along the edge (z = 0.2 (x - 1)): the surfaces meet, no step,
    # although the ramp is 8 mm up at the strip's far side
    ramp = Region.from_3d(
        "ramp", [[1.0, 0.0, 0.0], [2.0, 0.0, 0.2], [2.0, 1.0, 0.2], [1.0, 1.0, 0]]
    )
    np.testing.assert_allclose(riser_edge_insets(Terrain((low, ramp)), TOL)["low"], 0.0, atol=EPS)
    # the same ramp starting 0.05 m up is a riser
    raised = Region.from_3d(
        "raised", [[1.0, 0.0, 0.05], [2.0, 0.0, 0.25], [2.0, 1.0, 0.25], [1.0, 1.0, 0.05]]
    )
    ins = riser_edge_insets(Terrain((low, raised)), TOL)["low"]
    np.testing.assert_allclose(ins, [0.0, TOL, 0.0, 0.0], atol=EPS)
    # a higher block touching only at the corner (1, 1) covers no area of any edge's strip
    corner = Terrain((low, box("corner", 0.1, 1.0, 2.0, 1.0, 2.0)))
    np.testing.assert_allclose(riser_edge_insets(corner, TOL)["low"], 0.0, atol=EPS)


def test_partly_covered_edge_and_stairs() -> None:
    # a higher block beside only part of the +x edge still makes it a riser edge
    part = Terrain((box("low", 0.0, 0.0, 1.0), box("part", 0.2, 1.0, 2.0, 0.5, 1.5)))
    np.testing.assert_allclose(riser_edge_insets(part, TOL)["low"], [0.0, TOL, 0.0, 0.0])
    # stairs down in +x: each lower tread's -x edge is a riser edge, its +x edge is not
    stairs = Terrain(
        (box("top", 0.24, 0.0, 0.5), box("s1", 0.16, 0.5, 0.8), box("s2", 0.08, 0.8, 1.1))
    )
    ins = riser_edge_insets(stairs, TOL)
    np.testing.assert_allclose(ins["top"], 0.0, atol=EPS)
    np.testing.assert_allclose(ins["s1"], [0.0, 0.0, 0.0, TOL], atol=EPS)
    np.testing.assert_allclose(ins["s2"], [0.0, 0.0, 0.0, TOL], atol=EPS)
    shrunk = inset_riser_edges(stairs, TOL)
    assert shrunk["top"] is stairs["top"]
    v = shrunk["s1"].vertices
    assert (v[:, 0].min(), v[:, 0].max()) == pytest.approx((0.5 + TOL, 0.8))
    assert (v[:, 1].min(), v[:, 1].max()) == pytest.approx((0.0, 1.0))
    assert shrunk["s1"].height_at([0.6, 0.5]) == pytest.approx(0.16)


def test_inset_keeps_a_tilted_plane_and_drops_an_emptied_region() -> None:
    ramp = Region.from_3d(
        "ramp", [[0.0, 0.0, 0.0], [1.0, 0.0, 0.2], [1.0, 1.0, 0.2], [0.0, 1.0, 0]]
    )
    out = inset_region_edges(ramp, [0.0, 0.1, 0.0, 0.0])
    assert out is not None
    np.testing.assert_allclose(out.normal, ramp.normal)
    assert out.offset == pytest.approx(ramp.offset)
    assert float(out.vertices[:, 0].max()) == pytest.approx(0.9)
    assert out.height_at([0.9, 0.5]) == pytest.approx(0.18)
    # a 0.03 m sliver between two higher blocks has nothing left for a 0.04 m tolerance
    sliver = Terrain(
        (box("a", 0.1, 0.0, 1.0), box("sliver", 0.0, 1.0, 1.03), box("b", 0.1, 1.03, 2.0))
    )
    assert inset_riser_edges(sliver, TOL).names == ["a", "b"]


def test_stairs_slope_gap_insets_the_treads_below_the_risers() -> None:
    terrain = builtin_scene("stairs_slope_gap").terrain
    ins = riser_edge_insets(terrain, TOL)
    moved = {name for name, d in ins.items() if np.any(d > 0.0)}
    # top (0.24) -> stair1 (0.16) -> stair2 (0.08) -> ledge (0.0); the slope meets top without a
    # step and the gap to the landing is at the same height
    assert moved == {"stair1", "stair2", "ledge"}
    for name in moved:
        r = terrain[name]
        back = int(np.argmin(r.halfspaces()[0][:, 0]))  # the edge whose normal points to -x
        assert ins[name][back] == pytest.approx(TOL)
        assert np.count_nonzero(ins[name]) == 1


def test_zero_tolerance_changes_nothing() -> None:
    terrain = builtin_scene("stairs_slope_gap").terrain
    shrunk = inset_riser_edges(terrain, 0.0)
    assert all(a is b for a, b in zip(shrunk.regions, terrain.regions, strict=True))


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"tolerance": -0.01}, "tolerance"),
        ({"tolerance": float("nan")}, "tolerance"),
        ({"tolerance": "0.04"}, "tolerance"),
        ({"tolerance": 0.04, "min_rise": 0.0}, "min_rise"),
        ({"tolerance": 0.04, "min_rise": float("inf")}, "min_rise"),
    ],
)
def test_bad_numbers_are_input_errors(kwargs: dict[str, object], field: str) -> None:
    terrain = Terrain((box("low", 0.0, 0.0, 1.0),))
    with pytest.raises(InputError) as err:
        riser_edge_insets(terrain, **kwargs)  # type: ignore[arg-type]
    assert err.value.field == field


def test_bad_terrain_and_insets_are_input_errors() -> None:
    with pytest.raises(InputError) as err:
        riser_edge_insets([box("low", 0.0, 0.0, 1.0)], TOL)  # type: ignore[arg-type]
    assert err.value.field == "terrain"
    low = box("low", 0.0, 0.0, 1.0)
    for bad in ([0.0, 0.1], [0.0, -0.1, 0.0, 0.0], [0.0, float("nan"), 0.0, 0.0]):
        with pytest.raises(InputError) as err:
            inset_region_edges(low, bad)
        assert "low" in err.value.field


@settings(max_examples=60, deadline=None)
@given(
    st.floats(0.0, 2.0 * np.pi),
    st.floats(-1.5, 1.5),
)
def test_clip_halfplane_keeps_exactly_the_inside(angle: float, b: float) -> None:
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    a = np.array([np.cos(angle), np.sin(angle)])
    part = clip_halfplane(square, a, b)
    if part.shape[0] >= 3:
        assert np.all(part @ a <= b + 1e-9)
        assert signed_area(part) > 0.0
    # independent area: Monte Carlo-free, a fine grid of the square
    g = np.linspace(-1.0, 1.0, 401)
    xx, yy = np.meshgrid(g, g)
    share = float(np.mean(a[0] * xx + a[1] * yy <= b))
    area = signed_area(part) if part.shape[0] >= 3 else 0.0
    assert area == pytest.approx(4.0 * share, abs=0.03)
