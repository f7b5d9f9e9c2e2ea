"""Seeded terrain families: many terrains shaped like each of document 000's two study scenes.

Document 000 evaluates its planner (section 5.5) on one terrain of each kind: discrete step blocks
(fig. 5.5, the built-in ``discrete_steps``) and a slope, stairs and a gap (fig. 5.6, the built-in
``stairs_slope_gap``). A claim about a planner on *such terrain* needs many terrains of each kind,
so a family is a generator: ``family_terrain(family, seed)`` draws one terrain from the family's
documented ranges (:data:`DISCRETE_STEPS`, :data:`STAIRS_SLOPE_GAP`); equal arguments give an
identical :class:`~footfall.terrain.scene.Scene` (numpy's PCG64 from the seed alone, no global
state), which :func:`~footfall.terrain.scene.scene_to_yaml` writes as an ordinary scene file.

Every terrain runs along +x from a start floor (feet at x = 0, 0.2 m apart) to a goal floor, as
the document's two figures do. The ranges keep every terrain walkable by footfall's MuJoCo biped
(0.20 m sole, about 0.35 m forward reach, 0.25 m step height): blocks at least 0.32 m and treads
at least 0.28 m long (a sole and its margins), gaps at most 0.10 m between blocks and 0.14 m
before the landing (stepped over with about 0.34 m between the footsteps), neighbouring heights
within ``max_rise``. Whether a planner finds a plan on a given terrain is for the
planner to say (a study records a failed plan as such).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import Any

import numpy as np

from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.terrain.region import Region
from footfall.terrain.scene import Goal, Scene, Start
from footfall.terrain.terrain import Terrain

Range = tuple[float, float]


@dataclass(frozen=True)
class DiscreteStepsRanges:
    """Ranges of the discrete-steps family (document 000 fig. 5.5); lengths [m].

    Attributes:
        blocks: smallest and largest number of step blocks (integers).
        block_length: block size along the walking direction x.
        block_side: distance of each block side from the centre line (y), drawn per side.
        height: block height above the floors.
        max_rise: largest height change between neighbours (floor -> block, block -> block,
            block -> floor).
        gap: gap between neighbours along x.
    """

    blocks: tuple[int, int] = (3, 6)
    block_length: Range = (0.32, 0.50)
    block_side: Range = (0.25, 0.40)
    height: Range = (0.05, 0.30)
    max_rise: float = 0.20
    gap: Range = (0.05, 0.10)


@dataclass(frozen=True)
class StairsSlopeGapRanges:
    """Ranges of the stairs + slope + gap family (document 000 fig. 5.6); lengths [m].

    Attributes:
        slope_angle: slope angle [deg] (up, in the walking direction).
        slope_length: horizontal length of the slope.
        top_length: length of the landing at the top of the slope.
        riser: largest riser height of the stairs down; the stairs take the walker from the top
            back to the floor height in equal risers, as many as this needs.
        tread: tread length of each stair.
        ledge_length: length of the floor-height ledge before the gap.
        gap: width of the gap to step over.
    """

    slope_angle: Range = (6.0, 14.0)
    slope_length: Range = (0.8, 1.4)
    top_length: Range = (0.40, 0.60)
    riser: Range = (0.06, 0.10)
    tread: Range = (0.28, 0.34)
    ledge_length: Range = (0.35, 0.50)
    gap: Range = (0.06, 0.14)


#: the ranges of the built-in families
DISCRETE_STEPS = DiscreteStepsRanges()
STAIRS_SLOPE_GAP = StairsSlopeGapRanges()
#: the families by name (their names are the built-in scenes they generalise)
FAMILIES: dict[str, DiscreteStepsRanges | StairsSlopeGapRanges] = {
    "discrete_steps": DISCRETE_STEPS,
    "stairs_slope_gap": STAIRS_SLOPE_GAP,
}
#: largest seed accepted (seeds name files: keep them short)
MAX_SEED = 10**9
#: half width of the floors, the slope, the stairs and the ledge [m] (as the built-in scenes)
HALF_WIDTH = 0.5
#: the feet at the start, each this far from the centre line [m]
START_HALF_STANCE = 0.1
#: goal floor length [m] and the goal's distance past the floor's near edge [m]
GOAL_FLOOR, GOAL_IN = 0.8, 0.4


def family_names() -> list[str]:
    """The terrain families (``footfall terrain generate --family``)."""
    return list(FAMILIES)


def terrain_name(family: str, seed: int) -> str:
    """The scene name of terrain ``seed`` of ``family`` (a study's rows name it)."""
    return f"{family}-t{int(seed):04d}"


def _seed(seed: object) -> int:
    if (
        isinstance(seed, bool)
        or not isinstance(seed, int | np.integer)
        or not 0 <= seed <= MAX_SEED
    ):
        raise InputError("seed", seed, f"an integer in [0, {MAX_SEED}]")
    return int(seed)


def _draw(rng: np.random.Generator, r: Range) -> float:
    """A uniform draw from ``r``, to the millimetre (scene files stay readable)."""
    return round(float(rng.uniform(*r)), 3)


def _box(name: str, z: float, x0: float, x1: float, y0: float, y1: float) -> Region:
    """A level rectangle at height ``z`` (corners to the micrometre: sums of millimetres)."""
    x0, x1, y0, y1 = (round(v, 6) for v in (x0, x1, y0, y1))
    return Region.from_height(name, z, [[x0, y0], [x1, y0], [x1, y1], [x0, y1]])


def _start(x_end: float) -> tuple[Start, Region]:
    """The start (feet at x = 0, right foot stance) and the start floor up to ``x_end`` [m]."""
    h = START_HALF_STANCE
    start = Start(
        left=np.array([0.0, h, 0.0]),
        right=np.array([0.0, -h, 0.0]),
        heading=0.0,
        stance=Side.RIGHT,
    )
    return start, _box("start_floor", 0.0, -0.5, x_end, -HALF_WIDTH, HALF_WIDTH)


def discrete_steps_terrain(seed: int, ranges: DiscreteStepsRanges = DISCRETE_STEPS) -> Scene:
    """Terrain ``seed`` of the discrete-steps family: start floor, blocks, goal floor.

    Block ``k`` has a length, two side distances and a gap before it drawn uniformly from
    ``ranges``; its height is drawn uniformly from ``ranges.height`` intersected with
    ``[h_{k-1} - max_rise, h_{k-1} + max_rise]`` (the floor is h = 0), and the last block also
    within ``max_rise`` of the goal floor."""
    seed = _seed(seed)
    rng = np.random.default_rng([seed, 0])
    n = int(rng.integers(ranges.blocks[0], ranges.blocks[1] + 1))
    start, floor = _start(0.3)
    regions, x, h = [floor], 0.3, 0.0
    for k in range(n):
        x0 = x + _draw(rng, ranges.gap)
        x1 = x0 + _draw(rng, ranges.block_length)
        lo = max(ranges.height[0], h - ranges.max_rise)
        hi = min(ranges.height[1], h + ranges.max_rise)
        if k == n - 1:
            hi = min(hi, ranges.max_rise)  # the goal floor is at 0
        h = round(float(rng.uniform(lo, hi)), 3)
        y0, y1 = -_draw(rng, ranges.block_side), _draw(rng, ranges.block_side)
        regions.append(_box(f"block{k + 1}", h, x0, x1, y0, y1))
        x = x1
    x0 = x + _draw(rng, ranges.gap)
    regions.append(_box("goal_floor", 0.0, x0, x0 + GOAL_FLOOR, -HALF_WIDTH, HALF_WIDTH))
    return Scene(
        name=terrain_name("discrete_steps", seed),
        description=f"Discrete step blocks, family terrain {seed} ({n} blocks; doc. 000 fig. 5.5)",
        robot=BipedParams(),
        terrain=Terrain(tuple(regions)),
        start=start,
        goal=Goal(np.array([round(x0 + GOAL_IN, 6), 0.0, 0.0]), 0.0),
    )


def stairs_slope_gap_terrain(seed: int, ranges: StairsSlopeGapRanges = STAIRS_SLOPE_GAP) -> Scene:
    """Terrain ``seed`` of the stairs + slope + gap family: start floor, a slope up, its top
    landing, stairs back down to the floor height, a ledge, a gap, the goal floor.

    The rise is ``slope_length * tan(slope_angle)``; the stairs take it back down in
    ``ceil(rise / riser)`` equal risers (``riser`` drawn from its range), the last from the
    last tread down to the ledge; each tread's length is drawn."""
    seed = _seed(seed)
    rng = np.random.default_rng([seed, 1])
    x0 = 0.5
    start, floor = _start(x0)
    angle = math.radians(_draw(rng, ranges.slope_angle))
    x1 = x0 + _draw(rng, ranges.slope_length)
    rise = round((x1 - x0) * math.tan(angle), 4)
    w = HALF_WIDTH
    slope = Region.from_3d("slope", [[x0, -w, 0.0], [x1, -w, rise], [x1, w, rise], [x0, w, 0.0]])
    regions = [floor, slope]
    x = x1 + _draw(rng, ranges.top_length)
    regions.append(_box("top", rise, x1, x, -w, w))
    drops = max(1, math.ceil(rise / _draw(rng, ranges.riser) - 1e-9))
    for k in range(1, drops):
        x_next = x + _draw(rng, ranges.tread)
        regions.append(_box(f"stair{k}", round(rise * (1 - k / drops), 4), x, x_next, -w, w))
        x = x_next
    x_ledge = x + _draw(rng, ranges.ledge_length)
    regions.append(_box("ledge", 0.0, x, x_ledge, -w, w))
    x_land = x_ledge + _draw(rng, ranges.gap)
    regions.append(_box("landing", 0.0, x_land, x_land + GOAL_FLOOR + 0.3, -w, w))
    return Scene(
        name=terrain_name("stairs_slope_gap", seed),
        description=(
            f"Slope up ({math.degrees(angle):.1f} deg), {drops - 1} stairs down, a "
            f"{x_land - x_ledge:.2f} m gap; family terrain {seed} (doc. 000 fig. 5.6)"
        ),
        robot=BipedParams(),
        terrain=Terrain(tuple(regions)),
        start=start,
        goal=Goal(np.array([round(x_land + GOAL_IN + 0.3, 6), 0.0, 0.0]), 0.0),
    )


def family_terrain(family: str, seed: int) -> Scene:
    """Terrain ``seed`` of ``family`` (one of :func:`family_names`) with the family's ranges."""
    if family == "discrete_steps":
        return discrete_steps_terrain(seed)
    if family == "stairs_slope_gap":
        return stairs_slope_gap_terrain(seed)
    raise InputError("family", family, f"one of {', '.join(FAMILIES)}")


def family_of(scene_name: str) -> str | None:
    """The family whose generator named ``scene_name`` (:func:`terrain_name`), else None."""
    head, sep, tail = scene_name.rpartition("-t")
    if not (sep and head in FAMILIES and tail.isascii() and tail.isdigit()):
        return None
    return head if terrain_name(head, int(tail)) == scene_name else None


def ranges_dict(family: str) -> dict[str, Any]:
    """The ranges of ``family`` as plain data (a study's report and ``footfall terrain
    generate`` print them)."""
    if family not in FAMILIES:
        raise InputError("family", family, f"one of {', '.join(FAMILIES)}")
    r = FAMILIES[family]
    return {
        f.name: list(v) if isinstance(v, tuple) else v
        for f in fields(r)
        for v in [getattr(r, f.name)]
    }
