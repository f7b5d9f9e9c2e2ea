"""Unpushed, the MuJoCo walker reaches the goal on generated terrains that the planner has a plan
for, and never commands a footstep outside every region.

Terrains: random stepping stones (a start pad the soles stand on, ``pad_ahead`` = 0.11 m),
floor pieces across gaps and corridors with a square turn, three seeds each, generated here from
their seeds. Their miqcqp plans (``footfall walk``'s, smallest N) are stored in
``data/generated/`` so that the test does not plan for minutes; stones seed 1 is left out because
the walker's planner proves it infeasible (risers and region margins for this robot). Every
commanded footstep (the walker's target at each touchdown) and every landed sole centre is checked
against the regions with shapely, not with the walker's own region code.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("mink")

from shapely.geometry import Point, Polygon

from footfall.planning.plan_file import load_plan
from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.walk import walk
from footfall.terrain import Scene, suite_families
from footfall.terrain.scene import random_stepping_stones

DATA = Path(__file__).parent / "data" / "generated"
#: a footstep stands on a region when inside its polygon and this close to its surface [m]
ON_SURFACE_TOL = 0.03

GENERATORS: dict[str, Callable[[int], Scene]] = {
    "stones": lambda seed: random_stepping_stones(seed, 6, pad_ahead=0.11),
    "gaps": suite_families.gaps,
    "corridor": suite_families.corridor,
}
CASES = [
    ("stones", 0),
    ("stones", 2),
    ("stones", 3),
    ("gaps", 0),
    ("gaps", 3),
    ("gaps", 4),
    ("corridor", 0),
    ("corridor", 1),
    ("corridor", 2),
]


def _on_a_region(scene: Scene, p: np.ndarray) -> bool:
    return any(
        Polygon(r.vertices).buffer(1e-9).covers(Point(p[:2]))
        and abs(float(r.height_at(p[:2])) - float(p[2])) <= ON_SURFACE_TOL
        for r in scene.terrain.regions
    )


def _walk_and_check(family: str, seed: int, mode: str) -> None:
    scene = GENERATORS[family](seed)
    plan = load_plan(DATA / f"{family}-{seed}.json", scene)
    assert plan.has_solution
    opts = WalkOptions(region_aware=mode)
    res = walk(scene, plan, opts)
    m = res.metrics
    assert not m.fell, (family, seed, mode, m.fall_time_s)
    assert m.reached_goal, (family, seed, mode, m.goal_error_m)
    n = plan.n_steps + opts.stop_steps
    targets = res.trace.targets[:n]
    assert not np.isnan(targets).any()
    for j, p in enumerate(targets):
        assert _on_a_region(scene, p), (family, seed, mode, "commanded", j, p)
    landed = res.trace.landed[~np.isnan(res.trace.landed[:, 0])]
    assert landed.shape[0] == n
    for j, p in enumerate(landed):
        assert _on_a_region(scene, p), (family, seed, mode, "landed", j, p)
    assert m.footsteps_off_regions == 0


@pytest.mark.parametrize(("family", "seed"), CASES)
def test_the_default_walker_reaches_every_generated_goal_on_the_regions(
    family: str, seed: int
) -> None:
    _walk_and_check(family, seed, WalkOptions().region_aware)


@pytest.mark.parametrize(("family", "seed"), [("stones", 2), ("gaps", 0), ("corridor", 1)])
def test_the_short_horizon_walker_does_too(family: str, seed: int) -> None:
    _walk_and_check(family, seed, "horizon")


def test_the_benchmark_stones_start_is_refused_for_this_sole() -> None:
    """The planner benchmark's stones (pad 0.05 m ahead of the feet) are not walkable with a
    0.2 m sole: the walker says so before the walk rather than tipping over the pad's edge."""
    from footfall.errors import InputError

    scene = random_stepping_stones(0, 6)
    plan_scene = GENERATORS["stones"](0)
    plan = load_plan(DATA / "stones-0.json", plan_scene)
    with pytest.raises(InputError, match=r"scene\.start"):
        walk(scene, plan, WalkOptions())


def test_pad_ahead_moves_only_the_pads_front_edge() -> None:
    """``pad_ahead`` puts the start pad's front edge that far ahead of the feet (x = 0) and keeps
    its back edge at -0.45 m; the default's pad is the benchmark's, 0.05 m; bad values name the
    field."""
    from footfall.errors import InputError

    for ahead in (0.05, 0.11):
        pad = random_stepping_stones(0, 6, pad_ahead=ahead).terrain.regions[0]
        xs = np.asarray(pad.vertices)[:, 0]
        assert xs.max() == pytest.approx(ahead, abs=1e-12)
        assert xs.min() == pytest.approx(-0.45, abs=1e-12)
    default = np.asarray(random_stepping_stones(0, 6).terrain.regions[0].vertices)
    assert np.array_equal(
        default,
        np.asarray(random_stepping_stones(0, 6, pad_ahead=0.05).terrain.regions[0].vertices),
    )
    for bad in (0.0, -1.0, float("nan"), 0.6):
        with pytest.raises(InputError, match="pad_ahead"):
            random_stepping_stones(0, 6, pad_ahead=bad)
