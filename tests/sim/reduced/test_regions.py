"""Region-aware corrections in the reduced-order closed loop (issue 23): the option's engine
rules, and a sideways push on stepping stones: the document's free footstep lands off its stone,
the region-aware one keeps every footstep on its stone (checked with shapely, not the loop's own
metrics)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from shapely.geometry import Point, Polygon

from footfall.errors import InputError
from footfall.planning.plan import FootstepPlan
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, simulate
from footfall.terrain import builtin_scene
from footfall.terrain.region import Region
from tests.conftest import first_steps

#: stone half-sizes [m] around each planned footstep: 3 cm of room each way for the 0.2 x 0.1 sole
STONE_HALF = np.array([0.13, 0.08])
#: the push: 8 N s to the left in the second single support
PUSH = Push.horizontal(0.55, 8.0, np.pi / 2, 0.1)


@pytest.fixture(scope="module")
def stones() -> tuple[FootstepPlan, tuple[Region, ...]]:
    """The flat scene's first 5 reactive steps, each footstep on a small stone of its own."""
    plan = first_steps(plan_reactive(builtin_scene("flat")), 5)
    box = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * STONE_HALF
    regions = tuple(
        Region.from_height(f"stone{j}", 0.0, f[:2] + box) for j, f in enumerate(plan.footsteps)
    )
    return replace(plan, regions=tuple(r.name for r in regions)), regions


def _off_stones(feet: np.ndarray, regions: tuple[Region, ...]) -> list[int]:
    polys = [Polygon(r.vertices) for r in regions]
    return [
        j for j in range(1, feet.shape[0]) if not any(p.covers(Point(feet[j, :2])) for p in polys)
    ]


def test_region_aware_needs_the_python_engine_and_the_regions(stones) -> None:  # type: ignore[no-untyped-def]
    plan, regions = stones
    with pytest.raises(InputError, match="engine"):
        SimOptions(region_aware="planned", engine="compiled")
    with pytest.raises(InputError, match="region_aware"):
        SimOptions(region_aware="everywhere")
    with pytest.raises(InputError, match="engine"):
        SimOptions(region_aware="horizon", engine="compiled")
    with pytest.raises(InputError, match="regions"):
        simulate(plan, SimOptions(region_aware="planned"))
    res = simulate(first_steps(plan, 2), SimOptions(region_aware="planned"), regions=regions)
    assert res.metrics.engine == "python"


def test_a_sideways_push_leaves_the_stones_free_but_not_region_aware(stones) -> None:  # type: ignore[no-untyped-def]
    plan, regions = stones
    free = simulate(plan, SimOptions(pushes=(PUSH,)), regions=regions)
    off = _off_stones(free.footsteps, regions)
    assert off, "the push must send a free footstep off its stone"
    assert free.metrics.footsteps_off_regions == len(off)
    assert set(free.metrics.region_changes) >= set(off)
    for mode in ("planned", "nearby", "horizon"):
        res = simulate(plan, SimOptions(pushes=(PUSH,), region_aware=mode), regions=regions)
        assert _off_stones(res.footsteps, regions) == []
        assert res.metrics.footsteps_off_regions == 0
        # every landed footstep is on its own planned stone, inset by the sole
        for j in range(1, res.footsteps.shape[0]):
            d = np.abs(res.footsteps[j, :2] - plan.footsteps[j, :2])
            sole_half = np.array([plan.robot.foot_length, plan.robot.foot_width]) / 2
            assert np.all(d <= STONE_HALF - sole_half + 1e-9), (mode, j)


def test_horizon_mode_asks_the_short_horizon_miqp_and_keeps_the_feet_on_the_stones() -> None:
    """narrow_stones_gap with a 10 N s push to the left: with ``horizon`` the region of every
    next footstep comes from the 3-footstep MIQP (its solves counted; the plan's region only in
    the last three phases), and every landed footstep stands on a stone (shapely)."""
    from footfall.sim.reduced import regions as reduced_regions

    scene = builtin_scene("narrow_stones_gap")
    plan = plan_reactive(scene)
    regions = tuple(scene.terrain)
    made: list[reduced_regions.RegionFeet] = []
    orig = reduced_regions.RegionFeet.__post_init__

    def spy(self: reduced_regions.RegionFeet) -> None:
        orig(self)
        made.append(self)

    push = Push.horizontal(1.05, 10.0, np.pi / 2, 0.1)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(reduced_regions.RegionFeet, "__post_init__", spy)
        res = simulate(plan, SimOptions(pushes=(push,), region_aware="horizon"), regions=regions)
    assert len(made) == 1 and not res.metrics.fell
    # a solve at the first tick of every phase with three footsteps ahead, and every 10 ticks
    ticks = round(plan.robot.t_ss * 500.0)
    assert made[0].horizon_solves == (plan.n_steps - 3 + 1) * math.ceil(ticks / 10)
    assert _off_stones(res.footsteps, regions) == []
    assert res.metrics.footsteps_off_regions == 0
