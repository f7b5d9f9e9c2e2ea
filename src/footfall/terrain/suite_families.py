"""Seeded terrain families of the footstep-planning instance suite (``benchmarks/suite``).

Each family draws short terrains (a goal 1-2 m from the start, so a plan has about 4-9
footsteps) of one kind that legged-robot footstep planners are tested on: random stepping stones,
a field of tilted cinder blocks, straight stairs up and down, a spiral staircase, floor pieces
across gaps, a corridor with a corner, and a chain of pitched and rolled ramps.
``suite_terrain(family, seed)`` is deterministic (numpy's PCG64 from ``[seed, k]`` with ``k`` the
family's stream index, or from the seed alone for ``stones``, which is
:func:`~footfall.terrain.scene.random_stepping_stones`; no global state); lengths are drawn to the
millimetre and angles to the tenth of a degree so that the scene files stay readable. The robot is footfall's default biped
(:class:`~footfall.models.biped.BipedParams`: reach 0.35 m forward, 0.25 m step height, 30 deg
heading change per step).

Whether a terrain has a plan with a given N is not promised: the suite records what the
solvers proved (an infeasible instance is as useful to a solver as a feasible one).
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.terrain.families import START_HALF_STANCE, _box, _draw, _seed
from footfall.terrain.region import Region
from footfall.terrain.scene import (
    Goal,
    Scene,
    Start,
    load_scene,
    random_stepping_stones,
    scene_to_yaml,
)
from footfall.terrain.terrain import Terrain


def _start() -> Start:
    """Feet at x = 0, 0.2 m apart, heading +x, right foot standing."""
    h = START_HALF_STANCE
    return Start(
        left=np.array([0.0, h, 0.0]),
        right=np.array([0.0, -h, 0.0]),
        heading=0.0,
        stance=Side.RIGHT,
    )


def _scene(family: str, seed: int, what: str, regions: list[Region], goal: Goal) -> Scene:
    return Scene(
        name=instance_terrain_name(family, seed),
        description=f"{what}; suite family {family}, terrain {seed}",
        robot=BipedParams(),
        terrain=Terrain(tuple(regions)),
        start=_start(),
        goal=goal,
    )


def _tilted(
    name: str,
    centre: tuple[float, float, float],
    half: tuple[float, float],
    pitch: float,
    roll: float,
    yaw: float = 0.0,
) -> Region:
    """A rectangle of half sizes ``half`` [m] about ``centre``, turned by ``yaw`` and tilted:
    its height rises by ``tan(pitch)`` per metre along its length and ``tan(roll)`` across."""
    cx, cy, cz = centre
    c, s = math.cos(yaw), math.sin(yaw)
    pts = []
    for u, v in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        lx, ly = u * half[0], v * half[1]
        x, y = cx + c * lx - s * ly, cy + s * lx + c * ly
        z = cz + math.tan(pitch) * lx + math.tan(roll) * ly
        pts.append([round(x, 6), round(y, 6), round(z, 6)])
    return Region.from_3d(name, pts)


def stones(seed: int) -> Scene:
    """Random stepping stones (:func:`~footfall.terrain.scene.random_stepping_stones`, 6 regions:
    a start pad, four stones, a goal pad), reachable from centre to centre by construction."""
    scene = random_stepping_stones(seed, 6)
    return Scene(
        name=instance_terrain_name("stones", seed),
        description=f"Random stepping stones (6 regions); suite family stones, terrain {seed}",
        robot=scene.robot,
        terrain=scene.terrain,
        start=scene.start,
        goal=scene.goal,
    )


def cinder_blocks(seed: int) -> Scene:
    """Two rows of 2-3 cinder blocks (0.28-0.34 x 0.24-0.30 m, 3-6 cm apart), each 0-0.12 m
    high and tilted by up to 10 deg in pitch and roll, between a start and a goal floor."""
    rng = np.random.default_rng([seed, 1])
    cols = int(rng.integers(2, 4))
    regions = [_box("start_floor", 0.0, -0.5, 0.25, -0.5, 0.5)]
    x = 0.25
    for i in range(cols):
        x += _draw(rng, (0.03, 0.06))
        length = _draw(rng, (0.28, 0.34))
        for j, sign in enumerate((-1.0, 1.0)):
            width = _draw(rng, (0.24, 0.30))
            y = sign * (0.5 * width + 0.5 * _draw(rng, (0.03, 0.06)))
            regions.append(
                _tilted(
                    f"block{i + 1}{'rl'[j]}",
                    (round(x + 0.5 * length, 6), round(y, 6), _draw(rng, (0.0, 0.12))),
                    (0.5 * length, 0.5 * width),
                    math.radians(round(float(rng.uniform(-10, 10)), 1)),
                    math.radians(round(float(rng.uniform(-10, 10)), 1)),
                )
            )
        x += length
    x += _draw(rng, (0.03, 0.06))
    regions.append(_box("goal_floor", 0.0, x, x + 0.8, -0.5, 0.5))
    goal = Goal(np.array([round(x + 0.3, 6), 0.0, 0.0]), 0.0)
    return _scene("cinder_blocks", seed, f"{cols} x 2 tilted cinder blocks", regions, goal)


def _stairs(seed: int, up: bool) -> Scene:
    family = "stairs_up" if up else "stairs_down"
    rng = np.random.default_rng([seed, 2 if up else 3])
    steps = int(rng.integers(2, 5))
    riser = _draw(rng, (0.08, 0.15))
    half = _draw(rng, (0.35, 0.5))
    x = _draw(rng, (0.15, 0.3))
    regions = [_box("floor", 0.0, -0.5, x, -half, half)]
    z = 0.0
    for k in range(steps):
        tread = _draw(rng, (0.28, 0.34))
        z = round(z + (riser if up else -riser), 6)
        regions.append(_box(f"step{k + 1}", z, x, x + tread, -half, half))
        x += tread
    regions.append(_box("landing", z, x, x + 0.8, -half, half))
    goal = Goal(np.array([round(x + 0.3, 6), 0.0, z]), 0.0)
    what = f"{steps} stairs {'up' if up else 'down'}, {riser * 1000:.0f} mm risers"
    return _scene(family, seed, what, regions, goal)


def stairs_up(seed: int) -> Scene:
    """2-4 straight stairs up: risers 0.08-0.15 m, treads 0.28-0.34 m, 0.7-1.0 m wide."""
    return _stairs(seed, True)


def stairs_down(seed: int) -> Scene:
    """As :func:`stairs_up`, going down."""
    return _stairs(seed, False)


def spiral_stairs(seed: int) -> Scene:
    """A spiral staircase turning left or right: 3-5 treads, each an annular sector of 25-35 deg
    between radii 0.3 and 1.0 m (approximated by its chord quadrilateral) rising 0.05-0.10 m.
    The walk starts at the bottom on a floor sector and ends on the top tread."""
    rng = np.random.default_rng([seed, 4])
    sign = 1.0 if rng.random() < 0.5 else -1.0  # +1: turns left
    radius = 0.65  # the start feet lie on this circle's tangent
    centre = np.array([0.0, sign * radius])
    treads = int(rng.integers(3, 6))
    rise = _draw(rng, (0.05, 0.10))
    r_in, r_out = 0.3, 1.0

    def sector(name: str, a0: float, a1: float, z: float) -> Region:
        pts = []
        for r, a in ((r_in, a0), (r_out, a0), (r_out, a1), (r_in, a1)):
            pts.append(
                [
                    round(float(centre[0] + r * math.cos(a)), 6),
                    round(float(centre[1] + r * math.sin(a)), 6),
                    z,
                ]
            )
        return Region.from_3d(name, pts)

    start_angle = -sign * math.pi / 2  # the start point seen from the centre
    # the floor spans from behind the feet to just ahead of them
    a = start_angle + sign * math.radians(8.0)
    regions = [sector("floor", start_angle - sign * math.radians(25.0), a, 0.0)]
    z = 0.0
    for k in range(treads):
        span = math.radians(round(float(rng.uniform(25.0, 35.0)), 1))
        z = round(z + rise, 6)
        regions.append(sector(f"tread{k + 1}", a, a + sign * span, z))
        a += sign * span
    mid = a - sign * 0.5 * span
    heading = mid + sign * math.pi / 2
    goal_xy = centre + radius * np.array([math.cos(mid), math.sin(mid)])
    goal = Goal(np.array([round(float(goal_xy[0]), 6), round(float(goal_xy[1]), 6), z]), heading)
    what = f"spiral stairs, {treads} treads turning {'left' if sign > 0 else 'right'}"
    return _scene("spiral_stairs", seed, what, regions, goal)


def gaps(seed: int) -> Scene:
    """2-3 floor pieces (0.30-0.40 m long, up to 0.10 m to either side, +-0.05 m high) across
    gaps of 0.08-0.18 m, then the goal floor."""
    rng = np.random.default_rng([seed, 5])
    pieces = int(rng.integers(2, 4))
    regions = [_box("start_floor", 0.0, -0.5, 0.2, -0.4, 0.4)]
    x = 0.2
    for k in range(pieces):
        x += _draw(rng, (0.08, 0.18))
        length = _draw(rng, (0.30, 0.40))
        off = _draw(rng, (-0.10, 0.10))
        regions.append(
            _box(f"piece{k + 1}", _draw(rng, (-0.05, 0.05)), x, x + length, off - 0.3, off + 0.3)
        )
        x += length
    x += _draw(rng, (0.08, 0.18))
    regions.append(_box("goal_floor", 0.0, x, x + 0.8, -0.4, 0.4))
    goal = Goal(np.array([round(x + 0.25, 6), 0.0, 0.0]), 0.0)
    return _scene("gaps", seed, f"{pieces} floor pieces across gaps", regions, goal)


def corridor(seed: int) -> Scene:
    """A corridor 0.45-0.70 m wide, 0.4-0.8 m along x, a square corner, then 0.4-0.7 m to the
    left or right: three regions (the corner overlaps neither leg)."""
    rng = np.random.default_rng([seed, 6])
    w = _draw(rng, (0.45, 0.70))
    l1, l2 = _draw(rng, (0.4, 0.8)), _draw(rng, (0.4, 0.7))
    sign = 1.0 if rng.random() < 0.5 else -1.0
    hw = 0.5 * w
    regions = [
        _box("leg1", 0.0, -0.4, l1, -hw, hw),
        _box("corner", 0.0, l1, l1 + w, -hw, hw),
    ]
    if sign > 0:
        regions.append(_box("leg2", 0.0, l1, l1 + w, hw, hw + l2))
    else:
        regions.append(_box("leg2", 0.0, l1, l1 + w, -hw - l2, -hw))
    goal = Goal(
        np.array([round(l1 + hw, 6), round(sign * (hw + l2 - 0.3), 6), 0.0]), sign * math.pi / 2
    )
    what = f"corridor {w:.2f} m wide turning {'left' if sign > 0 else 'right'}"
    return _scene("corridor", seed, what, regions, goal)


def ramps(seed: int) -> Scene:
    """2 ramps of 0.4-0.6 m, each pitched by 5-12 deg up or down and rolled by up to 6 deg,
    joined at their edges (heights continuous along the centre line), then a level floor."""
    rng = np.random.default_rng([seed, 7])
    n = 2
    regions = [_box("start_floor", 0.0, -0.5, 0.2, -0.5, 0.5)]
    x, z = 0.2, 0.0
    for k in range(n):
        length = _draw(rng, (0.4, 0.6))
        pitch = math.radians(round(float(rng.uniform(5.0, 12.0)), 1))
        if rng.random() < 0.5 or z > 0.15:
            pitch = -pitch
        roll = math.radians(round(float(rng.uniform(-6.0, 6.0)), 1))
        cz = z + 0.5 * length * math.tan(pitch)
        regions.append(
            _tilted(
                f"ramp{k + 1}",
                (round(x + 0.5 * length, 6), 0.0, round(cz, 6)),
                (0.5 * length, 0.5),
                pitch,
                roll,
            )
        )
        x += length
        z = round(z + length * math.tan(pitch), 6)
    regions.append(_box("goal_floor", z, x, x + 0.8, -0.5, 0.5))
    goal = Goal(np.array([round(x + 0.3, 6), 0.0, z]), 0.0)
    return _scene("ramps", seed, f"{n} pitched and rolled ramps", regions, goal)


#: the families by name, in the order of their seeds' stream index
SUITE_FAMILIES: dict[str, Callable[[int], Scene]] = {
    "stones": stones,
    "cinder_blocks": cinder_blocks,
    "stairs_up": stairs_up,
    "stairs_down": stairs_down,
    "spiral_stairs": spiral_stairs,
    "gaps": gaps,
    "corridor": corridor,
    "ramps": ramps,
}


def instance_terrain_name(family: str, seed: int) -> str:
    """The scene name of terrain ``seed`` of suite ``family``."""
    return f"{family}-{int(seed):02d}"


def suite_terrain(family: str, seed: int) -> Scene:
    """Terrain ``seed`` of suite ``family`` (one of :data:`SUITE_FAMILIES`)."""
    if not isinstance(family, str) or family not in SUITE_FAMILIES:
        raise InputError("family", family, f"one of {', '.join(SUITE_FAMILIES)}")
    scene = SUITE_FAMILIES[family](_seed(seed))
    # the terrain is what its scene file says: a tilted region's SVD normal can move by an ulp
    # when its file is read back (the reader normalises it again), the file's reading does not
    return load_scene(scene_to_yaml(scene))
