"""Terrain families of the instance suite (footfall.terrain.suite_families): every documented
range is recomputed from the regions' vertices and plane normals, not read from the generator."""

from __future__ import annotations

import math
import re
from functools import cache
from itertools import pairwise

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.planning import PlannerOptions, reachable_steps_bound
from footfall.terrain.region import Region
from footfall.terrain.scene import (
    Scene,
    load_scene,
    robot_to_dict,
    scene_to_dict,
    scene_to_yaml,
)
from footfall.terrain.suite_families import (
    SUITE_FAMILIES,
    instance_terrain_name,
    suite_terrain,
)
from tests.terrain.shapes import level, rect

FAMILIES = tuple(SUITE_FAMILIES)
SEEDS = range(6)
CASES = [(f, s) for f in FAMILIES for s in SEEDS]
#: a length drawn to the millimetre may lie 0.5 mm outside its range; float sums add ~1e-9
DRAW = 0.0005 + 1e-9
#: a distance between two edges: a difference of two rounded sums (1 mm)
DIFF = 0.001 + 1e-9
#: an angle drawn to the tenth of a degree, then corners rounded to the micrometre [deg]
ANGLE = 0.05 + 0.01
#: corners are rounded to the micrometre: heights and lengths agree to a few of them [m]
MICRO = 1e-5


@cache
def _scene(family: str, seed: int) -> Scene:
    return suite_terrain(family, seed)


def _tilt_deg(r: Region) -> tuple[float, float, float]:
    """(pitch, roll, total slope) [deg] of the plane: dz/dx = tan(pitch), dz/dy = tan(roll)."""
    a, b, c = (float(x) for x in r.normal)
    assert abs(math.hypot(a, b, c) - 1.0) < 1e-12 and c > 0.0
    return (
        math.degrees(math.atan(-a / c)),
        math.degrees(math.atan(-b / c)),
        math.degrees(math.acos(c)),
    )


def _within(value: float, lo: float, hi: float, slack: float) -> bool:
    return lo - slack <= value <= hi + slack


def _numbered(scene: Scene, prefix: str) -> list[Region]:
    """The regions called ``prefix1``, ``prefix2``, ... in order (numbered without holes)."""
    found = [r for r in scene.terrain if re.fullmatch(rf"{prefix}\d+", r.name)]
    assert [r.name for r in found] == [f"{prefix}{k + 1}" for k in range(len(found))]
    return found


def _geometry(scene: Scene) -> list[tuple[str, list[list[float]]]]:
    return [(r.name, np.asarray(r.vertices3d).round(9).tolist()) for r in scene.terrain]


def _strictly_convex_ccw(v: np.ndarray) -> bool:
    e = np.roll(v, -1, axis=0) - v
    f = np.roll(e, -1, axis=0)
    return bool(np.all(e[:, 0] * f[:, 1] - e[:, 1] * f[:, 0] > 1e-12))


# --- every family -------------------------------------------------------------------------------


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_deterministic(family: str, seed: int) -> None:
    """Equal arguments give the same scene file, whatever numpy's global random state."""
    np.random.seed(1)  # noqa: NPY002 (the legacy global state must not matter)
    first = scene_to_yaml(suite_terrain(family, seed))
    np.random.seed(2)  # noqa: NPY002
    np.random.random(17)  # noqa: NPY002
    assert scene_to_yaml(suite_terrain(family, seed)) == first
    scene = _scene(family, seed)
    assert scene.name == instance_terrain_name(family, seed) == f"{family}-{seed:02d}"
    assert f"suite family {family}, terrain {seed}" in scene.description


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_yaml_round_trip_is_exact(family: str, seed: int) -> None:
    """The scene file reads back to a scene that writes the same file."""
    text = scene_to_yaml(_scene(family, seed))
    assert scene_to_yaml(load_scene(text)) == text


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_yaml_round_trip_keeps_the_scene(family: str, seed: int) -> None:
    """What the file holds is the generated scene to the last bits, and a file written from a
    loaded scene is a fixed point (what a suite's scene files are)."""
    scene = _scene(family, seed)
    back = load_scene(scene_to_yaml(scene))
    assert (back.name, back.description) == (scene.name, scene.description)
    assert robot_to_dict(back.robot) == robot_to_dict(scene.robot)
    np.testing.assert_array_equal(back.start.left, scene.start.left)
    np.testing.assert_array_equal(back.start.right, scene.start.right)
    assert (back.start.heading, back.start.stance) == (scene.start.heading, scene.start.stance)
    np.testing.assert_array_equal(back.goal.position, scene.goal.position)
    assert back.goal.heading == scene.goal.heading
    assert back.terrain.names == scene.terrain.names
    for r, q in zip(scene.terrain, back.terrain, strict=True):
        np.testing.assert_array_equal(q.vertices, r.vertices)
        np.testing.assert_allclose(q.normal, r.normal, rtol=0, atol=4e-16)
        assert abs(q.offset - r.offset) <= 4e-16
    again = scene_to_yaml(back)
    assert scene_to_yaml(load_scene(again)) == again


@pytest.mark.parametrize("family", FAMILIES)
def test_distinct_seeds_give_distinct_terrains(family: str) -> None:
    geoms = [_geometry(_scene(family, s)) for s in SEEDS]
    for i in range(len(geoms)):
        for j in range(i + 1, len(geoms)):
            assert geoms[i] != geoms[j], f"{family} seeds {i} and {j} have equal regions"
    # the start is the same for every family and seed: feet 0.2 m apart at x = 0, heading +x
    st = _scene(family, 0).start
    np.testing.assert_array_equal(st.left, [0.0, 0.1, 0.0])
    np.testing.assert_array_equal(st.right, [0.0, -0.1, 0.0])
    assert st.heading == 0.0


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_start_feet_and_goal_on_the_terrain(family: str, seed: int) -> None:
    scene = _scene(family, seed)
    terrain = scene.terrain
    for foot in (scene.start.left, scene.start.right):
        inside = [r for r in terrain if r.contains(foot)]
        assert inside, f"start foot {foot} on no region"
        assert terrain.region_of(foot) in {r.name for r in inside}
    goal = np.asarray(scene.goal.position)
    holding = [r for r in terrain if float(r.signed_distance(goal[:2])) <= 1e-9]
    assert holding, f"goal {goal} above no region"
    # the goal's z is the height of a region that holds it in plan view
    assert any(abs(float(r.height_at(goal[:2])) - goal[2]) <= 1e-9 for r in holding)
    assert terrain.locate(goal)


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_regions_are_convex_planar_and_walkable(family: str, seed: int) -> None:
    scene = _scene(family, seed)
    names = scene.terrain.names
    assert len(set(names)) == len(names)
    for r in scene.terrain:
        v3 = np.asarray(r.vertices3d)
        assert _strictly_convex_ccw(np.asarray(r.vertices)), r.name
        # every corner on the region's plane
        assert np.all(np.abs(v3 @ np.asarray(r.normal) + r.offset) <= 1e-9), r.name
        assert _tilt_deg(r)[2] <= 15.0, r.name  # no family is steeper than ~14 deg
        assert r.area > 0.01, r.name  # room for a foot


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("seed", range(4))
def test_reachability_bound_is_a_short_walk(family: str, seed: int) -> None:
    """The suite holds instances of about 4-9 footsteps: the lower bound on N of each terrain
    is at least 3 and at most 9."""
    scene = _scene(family, seed)
    n = reachable_steps_bound(scene, scene.robot, PlannerOptions(), 20).n_steps
    assert 3 <= n <= 9, n


# --- bad arguments ------------------------------------------------------------------------------


@pytest.mark.parametrize("family", ["nope", "", "Stones", " stones", "stones-00", None, 3])
def test_unknown_family_is_refused(family: object) -> None:
    with pytest.raises(InputError) as err:
        suite_terrain(family, 0)  # type: ignore[arg-type]
    assert err.value.field == "family"
    assert "stones" in err.value.expected and "ramps" in err.value.expected


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("seed", [-1, 1.5, True, 10**10, "1", None, np.float64(1.0)])
def test_bad_seed_is_refused(family: str, seed: object) -> None:
    with pytest.raises(InputError) as err:
        suite_terrain(family, seed)  # type: ignore[arg-type]
    assert err.value.field == "seed"


def test_numpy_integer_and_largest_seed_are_accepted() -> None:
    assert scene_to_yaml(suite_terrain("gaps", np.int64(3))) == scene_to_yaml(_scene("gaps", 3))  # type: ignore[arg-type]
    assert suite_terrain("corridor", 10**9).name == "corridor-1000000000"


# --- the documented ranges of each family ---------------------------------------------------------


@pytest.mark.parametrize("seed", SEEDS)
def test_stones(seed: int) -> None:
    """A start pad, four stones and a goal pad, level, 0.25-0.35 x 0.20-0.28 m stones rising by
    at most 0.10 m from one region to the next, at least 0.03 m apart."""
    import shapely

    scene = _scene("stones", seed)
    assert scene.terrain.names == ["start", "stone1", "stone2", "stone3", "stone4", "goal"]
    heights = [level(r, 1e-12) for r in scene.terrain]
    assert heights[0] == 0.0
    assert all(abs(b - a) <= 0.10 + 1e-12 for a, b in pairwise(heights))
    for r in _numbered(scene, "stone"):
        v = np.asarray(r.vertices)
        sides = np.linalg.norm(np.roll(v, -1, axis=0) - v, axis=1)
        assert abs(sides[0] - sides[2]) < 1e-9 and abs(sides[1] - sides[3]) < 1e-9  # rectangle
        assert abs(float(np.dot(v[1] - v[0], v[2] - v[1]))) < 1e-9
        length, width = sorted(sides[:2], reverse=True)
        assert _within(length, 0.25, 0.35, 1e-9) and _within(width, 0.20, 0.28, 1e-9)
    polys = [shapely.Polygon(np.asarray(r.vertices)) for r in scene.terrain]
    for i in range(1, len(polys)):
        for j in range(i):
            assert polys[i].distance(polys[j]) >= 0.03 - 1e-9, (i, j)


@pytest.mark.parametrize("seed", SEEDS)
def test_cinder_blocks(seed: int) -> None:
    """Two rows of 2-3 blocks, 0.28-0.34 x 0.24-0.30 m, 3-6 cm apart, centre 0-0.12 m high,
    tilted by up to 10 deg in pitch and in roll (so at most ~14 deg in all)."""
    scene = _scene("cinder_blocks", seed)
    names = scene.terrain.names
    cols = (len(names) - 2) // 2
    assert cols in (2, 3)
    expected = [f"block{i + 1}{s}" for i in range(cols) for s in "rl"]
    assert names == ["start_floor", *expected, "goal_floor"]
    floor, goal = scene.terrain["start_floor"], scene.terrain["goal_floor"]
    assert level(floor, 1e-12) == 0.0 and level(goal, 1e-12) == 0.0
    edge = rect(floor)[1]
    max_tilt = math.degrees(
        math.atan(math.hypot(math.tan(math.radians(10)), math.tan(math.radians(10))))
    )
    for i in range(cols):
        right, left = scene.terrain[f"block{i + 1}r"], scene.terrain[f"block{i + 1}l"]
        rx0, rx1, ry0, ry1 = rect(right)
        lx0, lx1, ly0, ly1 = rect(left)
        assert (rx0, rx1) == (lx0, lx1)  # one column
        assert _within(rx0 - edge, 0.03, 0.06, DIFF)  # gap along x to the previous column
        assert _within(rx1 - rx0, 0.28, 0.34, DIFF)
        assert ry1 < 0.0 < ly0  # right of the centre line is -y
        assert _within(ly0 - ry1, 0.03, 0.06, DIFF)  # gap between the two rows
        for block, (y0, y1) in ((right, (ry0, ry1)), (left, (ly0, ly1))):
            assert _within(y1 - y0, 0.24, 0.30, DIFF)
            pitch, roll, total = _tilt_deg(block)
            assert abs(pitch) <= 10.0 + ANGLE and abs(roll) <= 10.0 + ANGLE, block.name
            assert total <= max_tilt + ANGLE, block.name
            centre_z = float(block.height_at([(rx0 + rx1) / 2, (y0 + y1) / 2]))
            assert _within(centre_z, 0.0, 0.12, DRAW + MICRO), block.name
        edge = rx1
    assert _within(rect(goal)[0] - edge, 0.03, 0.06, DIFF)
    # the terrain is not flat: some block is tilted by more than a degree
    assert max(_tilt_deg(r)[2] for r in scene.terrain) > 1.0


@pytest.mark.parametrize("up", [True, False])
@pytest.mark.parametrize("seed", SEEDS)
def test_stairs(seed: int, up: bool) -> None:
    """2-4 straight stairs: equal risers of 0.08-0.15 m (up or down), treads 0.28-0.34 m,
    0.7-1.0 m wide; a level landing at the top (bottom) holds the goal."""
    family = "stairs_up" if up else "stairs_down"
    scene = _scene(family, seed)
    steps = _numbered(scene, "step")
    assert 2 <= len(steps) <= 4
    assert scene.terrain.names == ["floor", *(r.name for r in steps), "landing"]
    regions = list(scene.terrain)
    heights = [level(r, 1e-12) for r in regions]
    assert heights[0] == 0.0
    risers = np.diff(heights[:-1])
    assert np.ptp(risers) <= 2e-6  # equal risers
    riser = float(risers[0])
    assert (riser > 0) == up
    assert _within(abs(riser), 0.08, 0.15, DRAW)
    assert heights[-1] == heights[-2]  # the landing continues the top (bottom) step
    assert f"{abs(riser) * 1000:.0f} mm risers" in scene.description
    assert f"{len(steps)} stairs {'up' if up else 'down'}" in scene.description
    rects = [rect(r) for r in regions]
    widths = {round(y1 - y0, 9) for _, _, y0, y1 in rects}
    assert len(widths) == 1 and _within(widths.pop(), 0.7, 1.0, 2 * DRAW)
    for (_, x1, _, _), (x0, _, _, _) in pairwise(rects):
        assert abs(x0 - x1) <= 1e-9  # no gap, no overlap
    for x0, x1, _, _ in rects[1:-1]:
        assert _within(x1 - x0, 0.28, 0.34, DIFF)
    assert _within(rects[0][1], 0.15, 0.30, DRAW)  # the first riser, ahead of the feet
    assert scene.terrain.region_of(scene.goal.position) == "landing"
    assert scene.goal.position[2] == heights[-1]


def _line_intersection(p: np.ndarray, q: np.ndarray, r: np.ndarray, s: np.ndarray) -> np.ndarray:
    """The intersection of the line through p, q with the line through r, s (2-D)."""
    d1, d2 = q - p, s - r
    t = np.linalg.solve(np.column_stack([d1, -d2]), r - p)
    return p + t[0] * d1


@pytest.mark.parametrize("seed", SEEDS)
def test_spiral_stairs(seed: int) -> None:
    """3-5 treads, each the chord quadrilateral of an annular sector of 25-35 deg between radii
    0.3 and 1.0 m around one centre, rising by equal steps of 0.05-0.10 m, turning one way; the
    start floor is level at 0 and the goal on the top tread."""
    scene = _scene("spiral_stairs", seed)
    treads = _numbered(scene, "tread")
    assert 3 <= len(treads) <= 5
    assert scene.terrain.names == ["floor", *(r.name for r in treads)]
    regions = list(scene.terrain)
    centres, angles = [], []
    for r in regions:
        v = np.asarray(r.vertices)
        assert v.shape == (4, 2)
        nxt = np.roll(v, -1, axis=0)
        lengths = np.linalg.norm(nxt - v, axis=1)
        radial = [k for k in range(4) if abs(lengths[k] - 0.7) <= MICRO]
        assert len(radial) == 2, (r.name, lengths)  # the two radial edges, 1.0 - 0.3 m long
        a, b = radial
        centre = _line_intersection(v[a], nxt[a], v[b], nxt[b])
        radii = sorted(np.linalg.norm(v - centre, axis=1))
        np.testing.assert_allclose(radii, [0.3, 0.3, 1.0, 1.0], atol=MICRO)
        ends = [v[k] if np.linalg.norm(v[k] - centre) > 0.5 else nxt[k] for k in radial]
        span = math.degrees(
            math.acos(np.clip(np.dot(ends[0] - centre, ends[1] - centre) / 1.0, -1.0, 1.0))
        )
        if r.name != "floor":
            assert _within(span, 25.0, 35.0, ANGLE), (r.name, span)
        centres.append(centre)
        c = np.asarray(r.centroid)[:2] - centre
        angles.append(math.atan2(c[1], c[0]))
    for c in centres[1:]:
        np.testing.assert_allclose(c, centres[0], atol=1e-4)  # one staircase
    turns = np.diff(np.unwrap(angles))
    assert np.all(turns > 0) or np.all(turns < 0)
    left = bool(turns[0] > 0)
    assert f"turning {'left' if left else 'right'}" in scene.description
    # walking +x from the origin, a left turn has its centre on the left (+y)
    assert (centres[0][1] > 0) == left
    heights = [level(r, 1e-12) for r in regions]
    assert heights[0] == 0.0
    rises = np.diff(heights)
    assert np.ptp(rises) <= 2e-6 and _within(float(rises[0]), 0.05, 0.10, DRAW)
    # neighbouring treads share their radial edge
    for r0, r1 in pairwise(regions):
        shared = {tuple(p) for p in np.asarray(r0.vertices).round(6).tolist()} & {
            tuple(p) for p in np.asarray(r1.vertices).round(6).tolist()
        }
        assert len(shared) == 2, (r0.name, r1.name)
    goal = np.asarray(scene.goal.position)
    assert scene.terrain.region_of(goal) == treads[-1].name and goal[2] == heights[-1]
    # the goal heading is the walking direction along the circle through the goal
    g = goal[:2] - centres[0]
    tangent = math.atan2(g[1], g[0]) + (math.pi / 2 if left else -math.pi / 2)
    assert abs(math.remainder(scene.goal.heading - tangent, 2 * math.pi)) < 1e-4


@pytest.mark.parametrize("seed", SEEDS)
def test_gaps(seed: int) -> None:
    """2-3 level floor pieces 0.30-0.40 m long, centred within 0.10 m of the centre line and
    within 0.05 m of the floor height, across gaps of 0.08-0.18 m along x."""
    scene = _scene("gaps", seed)
    pieces = _numbered(scene, "piece")
    assert 2 <= len(pieces) <= 3
    assert scene.terrain.names == ["start_floor", *(r.name for r in pieces), "goal_floor"]
    regions = list(scene.terrain)
    assert level(regions[0], 1e-12) == 0.0 and level(regions[-1], 1e-12) == 0.0
    rects = [rect(r) for r in regions]
    for (_, x1, _, _), (x0, _, _, _) in pairwise(rects):
        assert _within(x0 - x1, 0.08, 0.18, DIFF), (x1, x0)
    for r, (x0, x1, y0, y1) in zip(pieces, rects[1:-1], strict=True):
        assert _within(x1 - x0, 0.30, 0.40, DIFF)
        assert abs((y1 - y0) - 0.6) <= 1e-9
        assert _within((y0 + y1) / 2, -0.10, 0.10, DRAW)
        assert _within(level(r, 1e-12), -0.05, 0.05, DRAW)
    # the start feet on the start floor, the goal on the goal floor
    assert scene.terrain.region_of(scene.goal.position) == "goal_floor"


@pytest.mark.parametrize("seed", SEEDS)
def test_corridor(seed: int) -> None:
    """A level corridor 0.45-0.70 m wide, 0.4-0.8 m ahead of the feet, a square corner, then
    0.4-0.7 m to the left or right, with the goal heading along the second leg."""
    scene = _scene("corridor", seed)
    assert scene.terrain.names == ["leg1", "corner", "leg2"]
    assert all(level(r, 1e-12) == 0.0 for r in scene.terrain)
    ax0, ax1, ay0, ay1 = rect(scene.terrain["leg1"])
    cx0, cx1, cy0, cy1 = rect(scene.terrain["corner"])
    bx0, bx1, by0, by1 = rect(scene.terrain["leg2"])
    w = ay1 - ay0
    assert _within(w, 0.45, 0.70, DRAW)
    assert abs(ay0 + ay1) <= 1e-9  # centred on the feet
    assert _within(ax1, 0.4, 0.8, DRAW) and ax0 < -0.1  # room behind the feet
    assert (cx0, cy0, cy1) == (ax1, ay0, ay1) and abs((cx1 - cx0) - w) <= 1e-9  # square corner
    assert (bx0, bx1) == (cx0, cx1)
    left = by0 >= cy1
    if left:
        assert by0 == cy1 and _within(by1 - by0, 0.4, 0.7, DIFF)
    else:
        assert by1 == cy0 and _within(by1 - by0, 0.4, 0.7, DIFF)
    assert f"turning {'left' if left else 'right'}" in scene.description
    # the corner overlaps neither leg: their plan-view areas add up to the union's
    import shapely

    polys = [shapely.Polygon(np.asarray(r.vertices)) for r in scene.terrain]
    assert abs(shapely.union_all(polys).area - sum(p.area for p in polys)) < 1e-9
    assert scene.terrain.region_of(scene.goal.position) == "leg2"
    assert abs(scene.goal.heading - (math.pi / 2 if left else -math.pi / 2)) < 1e-12


@pytest.mark.parametrize("seed", SEEDS)
def test_ramps(seed: int) -> None:
    """Two ramps of 0.4-0.6 m pitched by 5-12 deg (up or down) and rolled by at most 6 deg,
    joined without a step along the centre line to the level start and goal floors."""
    scene = _scene("ramps", seed)
    assert scene.terrain.names == ["start_floor", "ramp1", "ramp2", "goal_floor"]
    regions = list(scene.terrain)
    assert level(regions[0], 1e-12) == 0.0
    level(regions[-1], 1e-12)
    for r in regions[1:3]:
        x0, x1, y0, y1 = rect(r)
        assert _within(x1 - x0, 0.4, 0.6, DIFF)
        assert (y0, y1) == (-0.5, 0.5)
        pitch, roll, _ = _tilt_deg(r)
        assert _within(abs(pitch), 5.0, 12.0, ANGLE), (r.name, pitch)
        assert abs(roll) <= 6.0 + ANGLE, (r.name, roll)
    for r0, r1 in pairwise(regions):
        x1, x0 = rect(r0)[1], rect(r1)[0]
        assert abs(x0 - x1) <= 1e-9, (r0.name, r1.name)
        z0, z1 = float(r0.height_at([x1, 0.0])), float(r1.height_at([x0, 0.0]))
        assert abs(z0 - z1) <= MICRO, (r0.name, r1.name, z0, z1)
    goal = np.asarray(scene.goal.position)
    assert scene.terrain.region_of(goal) == "goal_floor" and goal[2] == level(regions[-1], 1e-12)


def test_families_are_the_documented_eight() -> None:
    assert FAMILIES == (
        "stones",
        "cinder_blocks",
        "stairs_up",
        "stairs_down",
        "spiral_stairs",
        "gaps",
        "corridor",
        "ramps",
    )
    # a scene file carries the default biped of every family
    robots = {str(scene_to_dict(_scene(f, 0))["robot"]) for f in FAMILIES}
    assert len(robots) == 1
