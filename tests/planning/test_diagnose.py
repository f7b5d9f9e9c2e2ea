"""Infeasibility from geometry alone: margin-aware region reachability, answered before any solve."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from footfall._geometry import inset_polygon, point_polygon_distance
from footfall.errors import SceneError
from footfall.models.biped import BipedParams
from footfall.planning import make_plan
from footfall.planning.diagnose import geometric_infeasibility, reachable_regions
from footfall.planning.plan import PlannerOptions
from footfall.solvers import SolveStatus
from footfall.terrain import Region, Scene, Terrain, builtin_scene

ROBOT = BipedParams()
#: the largest step of the default reach trapezoid (its farthest vertex) [m]
REACH = float(np.max(np.linalg.norm(ROBOT.reach.vertices, axis=1)))


def wide_gap_scene() -> Scene:
    """stairs_slope_gap as it was before the gap was narrowed: the landing starts at x = 3.44."""
    scene = builtin_scene("stairs_slope_gap")
    wide = Region.from_height("landing", 0.0, [[3.44, -0.5], [4.4, -0.5], [4.4, 0.5], [3.44, 0.5]])
    regions = tuple(wide if r.name == "landing" else r for r in scene.terrain.regions)
    return replace(scene, terrain=Terrain(regions))


def test_point_polygon_distance() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert point_polygon_distance(np.array([0.5, 0.5]), square) == 0.0
    assert point_polygon_distance(np.array([1.5, 0.5]), square) == pytest.approx(0.5)
    assert point_polygon_distance(np.array([2.0, 2.0]), square) == pytest.approx(np.sqrt(2.0))


def test_inset_polygon_is_the_polygon_moved_in() -> None:
    square = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 1.0], [0.0, 1.0]])
    inner = inset_polygon(square, 0.25)
    assert inner == pytest.approx(
        np.array([[0.25, 0.25], [1.75, 0.25], [1.75, 0.75], [0.25, 0.75]])
    )
    assert inset_polygon(square, 0.5) is None


def test_a_gap_too_wide_for_the_sole_margin() -> None:
    # ledge ends at x = 3.2, landing starts at 3.44: 0.24 m apart, 0.44 m between footsteps kept
    # 0.1 m inside, more than the largest step (~0.41 m); 0.24 m alone is not
    scene = wide_gap_scene()
    assert 0.24 < REACH < 0.44
    adj0 = scene.terrain.adjacency(REACH)
    adj1 = scene.terrain.adjacency(REACH, margin=0.1)
    assert "landing" in adj0["ledge"] and "landing" not in adj1["ledge"]
    assert "landing" in reachable_regions(scene, ROBOT)
    assert "landing" not in reachable_regions(scene, ROBOT, 0.1)
    assert geometric_infeasibility(scene, ROBOT, None, 0.0) is None
    why = geometric_infeasibility(scene, ROBOT, None, 0.1)
    assert why is not None and "landing" in why and "0.1 m inside" in why
    with pytest.raises(SceneError):
        scene.terrain.adjacency(REACH, margin=-0.1)


def test_the_shipped_gap_fits_the_sole_margin() -> None:
    # the shipped scene's landing starts at x = 3.32: 0.32 m between footsteps 0.1 m inside
    scene = builtin_scene("stairs_slope_gap")
    assert scene.terrain["landing"].vertices[:, 0].min() == pytest.approx(3.32)
    assert "landing" in scene.terrain.adjacency(REACH, margin=0.1)["ledge"]
    assert "landing" in reachable_regions(scene, ROBOT, 0.1)
    assert geometric_infeasibility(scene, ROBOT, None, 0.1) is None


def test_planners_answer_an_unreachable_goal_without_a_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    import footfall.planning.kinematic as kinematic
    import footfall.planning.miqcqp as miqcqp

    def no_solve(*args: object, **kwargs: object) -> None:
        raise AssertionError("the solver ran on a problem geometry already rules out")

    # a mixed-integer search would not prove this within minutes; geometry needs no solve
    monkeypatch.setattr(miqcqp, "solve", no_solve)
    monkeypatch.setattr(kinematic, "solve", no_solve)
    scene = wide_gap_scene()
    opts = PlannerOptions(region_margin=0.1)
    for planner in ("miqcqp", "kinematic"):
        plan = make_plan(scene, planner, 20, opts, ROBOT)
        assert plan.status is SolveStatus.INFEASIBLE and not plan.has_solution
        assert "no goal region (landing)" in plan.message


def test_reachable_regions_count_the_steps_from_the_start() -> None:
    scene = builtin_scene("discrete_steps")
    hops = reachable_regions(scene, ROBOT, 0.1)
    order = [r.name for r in scene.terrain]
    assert hops["start_floor"] == 1
    # blocks are listed in walking order and each is at least one step further than the last
    assert [hops[n] for n in order] == sorted(hops[n] for n in order)
