"""Seeded terrain families (footfall.terrain.families): every property recomputed from the
regions' vertices, not from the generator's internals."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np
import pytest

from footfall.errors import InputError
from footfall.terrain.families import (
    DISCRETE_STEPS,
    STAIRS_SLOPE_GAP,
    discrete_steps_terrain,
    family_names,
    family_of,
    family_terrain,
    ranges_dict,
    stairs_slope_gap_terrain,
    terrain_name,
)
from footfall.terrain.region import Region
from footfall.terrain.scene import Scene, load_scene, scene_to_dict, scene_to_yaml
from tests.terrain.shapes import level, rect

FAMILIES = ("discrete_steps", "stairs_slope_gap")
SEEDS = range(40)
#: a length drawn to the millimetre (``_draw`` rounds to 3 decimals) may lie 0.5 mm outside its
#: range; float sums add at most ~1e-9
DRAW = 0.0005 + 1e-9
#: a distance between two edges is a difference of two rounded sums: 1 mm
DIFF = 0.001 + 1e-9


def _inside(p: Any, r: Region) -> bool:
    """A point on a level rectangle, by hand."""
    x0, x1, y0, y1 = rect(r)
    x, y, z = (float(c) for c in p)
    return x0 <= x <= x1 and y0 <= y <= y1 and abs(z - level(r)) <= 1e-12


def _within(value: float, rng: tuple[float, float], slack: float) -> bool:
    return rng[0] - slack <= value <= rng[1] + slack


def _regions_text(scene: Scene) -> str:
    return json.dumps(scene_to_dict(scene)["regions"])


# ---------------------------------------------------------------------------------------------
# determinism and scene files


@pytest.mark.parametrize("family", FAMILIES)
def test_scenes_round_trip_and_repeat(family: str) -> None:
    terrains = set()
    for seed in SEEDS:
        scene = family_terrain(family, seed)
        text = scene_to_yaml(scene)
        assert scene_to_yaml(load_scene(text)) == text
        assert scene_to_yaml(family_terrain(family, seed)) == text  # the same seed: the same file
        terrains.add(_regions_text(scene))
    # different seeds: different terrains (the regions themselves, not only the names)
    assert len(terrains) == len(SEEDS)


def test_family_names_and_direct_generators() -> None:
    assert family_names() == ["discrete_steps", "stairs_slope_gap"]
    for seed in (0, 7):
        assert scene_to_yaml(discrete_steps_terrain(seed)) == scene_to_yaml(
            family_terrain("discrete_steps", seed)
        )
        assert scene_to_yaml(stairs_slope_gap_terrain(seed)) == scene_to_yaml(
            family_terrain("stairs_slope_gap", seed)
        )


@pytest.mark.parametrize("family", FAMILIES)
def test_numpy_seed_and_the_largest_seed(family: str) -> None:
    assert scene_to_yaml(family_terrain(family, np.int64(5))) == scene_to_yaml(
        family_terrain(family, 5)
    )
    big = family_terrain(family, 10**9)
    assert big.name == f"{family}-t1000000000"


# ---------------------------------------------------------------------------------------------
# discrete steps


@pytest.mark.parametrize("seed", SEEDS)
def test_discrete_steps_geometry(seed: int) -> None:
    r = DISCRETE_STEPS
    scene = family_terrain("discrete_steps", seed)
    regions = list(scene.terrain)
    n = len(regions) - 2
    assert scene.name == f"discrete_steps-t{seed:04d}"
    assert [g.name for g in regions] == [
        "start_floor",
        *(f"block{k}" for k in range(1, n + 1)),
        "goal_floor",
    ]
    assert r.blocks[0] <= n <= r.blocks[1]
    rects = [rect(g) for g in regions]
    heights = [level(g) for g in regions]
    assert heights[0] == 0.0 and heights[-1] == 0.0
    for k in range(1, n + 1):
        x0, x1, y0, y1 = rects[k]
        assert _within(x1 - x0, r.block_length, DRAW), (k, x1 - x0)
        assert _within(-y0, r.block_side, DRAW), (k, y0)
        assert _within(y1, r.block_side, DRAW), (k, y1)
        assert r.height[0] - 1e-9 <= heights[k] <= r.height[1] + 1e-9, (k, heights[k])
    for k in range(len(regions) - 1):
        gap = rects[k + 1][0] - rects[k][1]
        assert rects[k][0] < rects[k][1] < rects[k + 1][0]  # ordered along x, not overlapping
        assert _within(gap, r.gap, DIFF), (k, gap)
        rise = abs(heights[k + 1] - heights[k])
        assert rise <= r.max_rise + 1e-9, (k, rise)
    start_floor, goal_floor = regions[0], regions[-1]
    assert _inside(scene.start.left, start_floor)
    assert _inside(scene.start.right, start_floor)
    assert _inside(scene.goal.position, goal_floor)


def test_discrete_steps_use_every_block_count() -> None:
    """The block count's range is inclusive at both ends (3..6 blocks all occur in 40 seeds)."""
    counts = {len(family_terrain("discrete_steps", s).terrain) - 2 for s in SEEDS}
    assert counts == set(range(DISCRETE_STEPS.blocks[0], DISCRETE_STEPS.blocks[1] + 1))


# ---------------------------------------------------------------------------------------------
# stairs, slope and gap


@pytest.mark.parametrize("seed", SEEDS)
def test_stairs_slope_gap_geometry(seed: int) -> None:
    r = STAIRS_SLOPE_GAP
    scene = family_terrain("stairs_slope_gap", seed)
    regions = list(scene.terrain)
    by = {g.name: g for g in regions}
    n_stairs = len(regions) - 5
    assert scene.name == f"stairs_slope_gap-t{seed:04d}"
    assert [g.name for g in regions] == [
        "start_floor",
        "slope",
        "top",
        *(f"stair{k}" for k in range(1, n_stairs + 1)),
        "ledge",
        "landing",
    ]
    # the slope: its angle from the 3-D corners at its two ends
    slope = by["slope"]
    sx0, sx1, _, _ = rect(slope)
    corners = np.asarray(slope.vertices3d)
    low = corners[corners[:, 0] == sx0]
    high = corners[corners[:, 0] == sx1]
    assert len(low) == 2 and len(high) == 2
    assert np.ptp(low[:, 2]) <= 1e-9 and np.ptp(high[:, 2]) <= 1e-9  # level across y
    z_low, z_high = float(low[0, 2]), float(high[0, 2])
    angle = math.degrees(math.atan2(z_high - z_low, sx1 - sx0))
    assert _within(angle, r.slope_angle, 0.05), angle
    assert _within(sx1 - sx0, r.slope_length, DRAW)
    assert abs(z_low) <= 1e-9  # it starts at the floor...
    top = level(by["top"])
    assert abs(z_high - top) <= 1e-9  # ...and ends at the top landing
    # the stairs: from the top to the ledge in equal risers
    steps = ["top", *(f"stair{k}" for k in range(1, n_stairs + 1)), "ledge"]
    heights = np.array([level(by[s]) for s in steps])
    assert heights[-1] == 0.0 and level(by["landing"]) == 0.0
    risers = -np.diff(heights)
    assert np.all(risers > 0)
    assert np.all(risers <= r.riser[1] + 1e-4), risers
    # each stored height is rounded to 0.1 mm, so each riser is within 0.1 mm of the mean one
    assert np.max(np.abs(risers - top / len(risers))) <= 1e-4 + 1e-12, risers
    # lengths along x
    rects = [rect(g) for g in regions]
    assert _within(rects[2][1] - rects[2][0], r.top_length, DRAW)
    for k in range(3, 3 + n_stairs):
        assert _within(rects[k][1] - rects[k][0], r.tread, DRAW), (k, rects[k])
    assert _within(rects[-2][1] - rects[-2][0], r.ledge_length, DRAW)
    gap = rects[-1][0] - rects[-2][1]
    assert _within(gap, r.gap, DIFF), gap
    # contiguous along x except the gap, all the same width
    for k in range(len(regions) - 2):
        assert abs(rects[k + 1][0] - rects[k][1]) <= 1e-9, (k, rects[k], rects[k + 1])
    for x0, x1, y0, y1 in rects:
        assert x0 < x1 and (y0, y1) == (-0.5, 0.5)
    assert _inside(scene.start.left, by["start_floor"])
    assert _inside(scene.start.right, by["start_floor"])
    assert _inside(scene.goal.position, by["landing"])


# ---------------------------------------------------------------------------------------------
# bad input and names


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("seed", [-1, True, 1.5, 10**9 + 1, "3", None])
def test_bad_seed_names_the_seed(family: str, seed: Any) -> None:
    with pytest.raises(InputError) as e:
        family_terrain(family, seed)
    assert e.value.field == "seed" and "seed" in str(e.value)
    gen = discrete_steps_terrain if family == "discrete_steps" else stairs_slope_gap_terrain
    with pytest.raises(InputError) as e:
        gen(seed)
    assert e.value.field == "seed"


@pytest.mark.parametrize("family", ["nope", "", "Discrete_steps", "flat"])
def test_unknown_family_names_the_family(family: str) -> None:
    with pytest.raises(InputError) as e:
        family_terrain(family, 0)
    assert e.value.field == "family" and "family" in str(e.value)
    with pytest.raises(InputError) as e:
        ranges_dict(family)
    assert e.value.field == "family"


def test_ranges_dict_is_the_documented_ranges() -> None:
    assert ranges_dict("discrete_steps") == {
        "blocks": [3, 6],
        "block_length": [0.32, 0.50],
        "block_side": [0.25, 0.40],
        "height": [0.05, 0.30],
        "max_rise": 0.20,
        "gap": [0.05, 0.10],
    }
    assert ranges_dict("stairs_slope_gap") == {
        "slope_angle": [6.0, 14.0],
        "slope_length": [0.8, 1.4],
        "top_length": [0.40, 0.60],
        "riser": [0.06, 0.10],
        "tread": [0.28, 0.34],
        "ledge_length": [0.35, 0.50],
        "gap": [0.06, 0.14],
    }


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("seed", [0, 7, 42, 9999, 10**9])
def test_family_of_inverts_terrain_name(family: str, seed: int) -> None:
    name = terrain_name(family, seed)
    assert name == f"{family}-t{seed:04d}"
    assert family_of(name) == family


@pytest.mark.parametrize(
    "name",
    [
        "discrete_steps",
        "x-t0001",
        "../discrete_steps-t0001",
        "discrete_steps-t",
        "discrete_steps-t-1",
        "discrete_steps-tabc",
        "discrete_steps-t1",  # terrain_name pads to 4 digits: not a generated name
        "discrete_steps-t\u00b2",  # a superscript 2 is a digit to str.isdigit, not to us
        "terrains/stairs_slope_gap-t0001",
        "flat",
        "",
    ],
)
def test_family_of_other_names_is_none(name: str) -> None:
    assert family_of(name) is None


# ---------------------------------------------------------------------------------------------
# the planner walks them


@pytest.mark.parametrize("family", FAMILIES)
def test_reactive_plans_for_the_biped_stand_on_the_terrain(family: str) -> None:
    from footfall.sim.biped.plans import plan_for_walk, robot_model

    model = robot_model("biped")
    for seed in (0, 1):
        scene = family_terrain(family, seed)
        plan = plan_for_walk(scene, "reactive", None, 30.0, None, model, threads=1)
        assert plan.has_solution, (seed, plan.status, plan.message)
        # a reactive plan always holds footstep 0: it reached the goal only when feasible
        assert plan.status.value == "feasible" and plan.n_steps > 0, (seed, plan.message)
        for i, p in enumerate(plan.footsteps):
            on = [g.name for g in scene.terrain if g.contains(p)]
            assert on, (seed, i, p.tolist())
            assert plan.regions[i] in on, (seed, i, plan.regions[i], on)
        # the last two footsteps are the goal stance: their midpoint is the goal
        mid = (plan.footsteps[-1] + plan.footsteps[-2]) / 2
        assert np.allclose(mid, scene.goal.position, atol=1e-6), (mid, scene.goal.position)
