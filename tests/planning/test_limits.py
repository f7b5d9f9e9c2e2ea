"""Sizes beyond the documented maxima are refused up front, before any work scales with them."""

from __future__ import annotations

import numpy as np
import pytest

from footfall.errors import InputError, SceneError
from footfall.models.biped import MAX_NODES, BipedParams
from footfall.planning import PlannerOptions, plan_footsteps
from footfall.planning.plan import MAX_HEADING_SEGMENTS, MAX_STEPS, available_cores
from footfall.planning.run import _search_note
from footfall.sim.reduced.closed_loop import MAX_CONTROL_RATE, SimOptions
from footfall.terrain import builtin_scene
from footfall.terrain.region import MAX_VERTICES, Region
from footfall.terrain.terrain import MAX_REGIONS, Terrain
from tests.conftest import VirtualClock


def test_too_many_footsteps() -> None:
    with pytest.raises(InputError, match="n_steps"):
        plan_footsteps(builtin_scene("flat"), n_steps=MAX_STEPS + 1)


def test_too_many_nodes() -> None:
    with pytest.raises(InputError, match="n_nodes"):
        BipedParams(n_nodes=MAX_NODES + 1)
    assert BipedParams(n_nodes=MAX_NODES).n_nodes == MAX_NODES


def test_heading_segments_and_threads_are_bounded() -> None:
    with pytest.raises(InputError, match="heading_segments"):
        PlannerOptions(heading_segments=MAX_HEADING_SEGMENTS + 1)
    with pytest.raises(InputError, match="threads"):
        PlannerOptions(threads=available_cores() + 1)
    assert PlannerOptions(threads=available_cores()).threads == available_cores()


def test_too_many_regions_or_vertices() -> None:
    square = [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]]
    regions = [Region(f"r{i}", (0.0, 0.0, 1.0), 0.0, square) for i in range(MAX_REGIONS + 1)]
    with pytest.raises(SceneError, match="regions"):
        Terrain(tuple(regions))
    angles = np.linspace(0, 2 * np.pi, MAX_VERTICES + 2)[:-1]
    circle = np.c_[np.cos(angles), np.sin(angles)]
    with pytest.raises(SceneError, match="vertices"):
        Region("disc", (0.0, 0.0, 1.0), 0.0, circle)


def test_control_rate_is_bounded() -> None:
    with pytest.raises(InputError, match="control_rate"):
        SimOptions(control_rate=MAX_CONTROL_RATE * 10)


def test_min_steps_note_says_what_was_proven() -> None:
    proven = _search_note(
        10, 8, [{"n_steps": 8, "status": "infeasible"}, {"n_steps": 9, "status": "infeasible"}]
    )
    assert "proven infeasible: N = 8, 9" in proven and "10 is the smallest" in proven
    undecided = _search_note(
        10, 8, [{"n_steps": 8, "status": "infeasible"}, {"n_steps": 9, "status": "time_limit"}]
    )
    assert (
        "not decided: N = 9 (time_limit)" in undecided
        and "smallest" not in undecided.split(";")[-1].split(",")[0]
    )
    assert "fewer steps may exist" in undecided
    skipped = {"from": 6, "to": 7, "reason": "no footstep N - 1 can be the goal foot"}
    both = _search_note(10, 8, [{"n_steps": 8, "status": "infeasible"}], skipped)
    assert "N = 6..7 ruled out without a solve (no footstep N - 1 can be the goal foot)" in both
    assert "proven infeasible: N = 8" in both


def test_a_plan_with_a_nan_footstep_is_refused_at_construction() -> None:
    from dataclasses import replace

    from footfall.planning import make_plan

    plan = make_plan(builtin_scene("flat"), "kinematic", 8)
    feet = plan.footsteps.copy()
    feet[3, 0] = np.nan
    with pytest.raises(InputError, match=r"plan.footsteps\[3\]"):
        replace(plan, footsteps=feet)
    with pytest.raises(InputError, match=r"plan\.headings"):
        replace(plan, headings=plan.headings[:-1])


def test_quadruped_cycles_are_bounded() -> None:
    from footfall.quadruped.gait import MAX_CYCLES, GaitParams

    with pytest.raises(InputError, match="cycles"):
        GaitParams(slope=0.2, body_pitch=0.1, cycles=MAX_CYCLES + 1)


# --- the documented maxima finish, and time limits hold ---------------------------------------
def _stone_grid(n: int, rng: np.random.Generator | None = None) -> Terrain:
    """``n`` square stones 0.2 m wide on a 0.25 m grid, eight per row (a field of stepping
    stones); with ``rng``, each turned and shrunk at random (polygons that are not boxes)."""
    regions = []
    for k in range(n):
        row, col = divmod(k, 8)
        centre = np.array([0.25 * col, 0.25 * row])
        half, turn = 0.1, 0.0
        if rng is not None:
            half, turn = rng.uniform(0.03, 0.14), rng.uniform(0.0, np.pi / 2)
        c, s = np.cos(turn), np.sin(turn)
        corners = np.array([[-half, -half], [half, -half], [half, half], [-half, half]])
        regions.append(Region.from_height(f"s{k}", 0.0, centre + corners @ [[c, s], [-s, c]]))
    return Terrain(tuple(regions))


def test_adjacency_of_the_largest_terrain_measures_only_near_pairs(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """1000 regions: the exact distance is computed for the pairs whose boxes come within the
    radius (about ten per region here), not for all 499,500 pairs (16.7 s for 300 regions)."""
    from footfall.terrain import terrain as terrain_mod

    terrain = _stone_grid(MAX_REGIONS)
    calls = [0]
    exact = terrain_mod.polygon_distance

    def counted(p: np.ndarray, q: np.ndarray) -> float:
        calls[0] += 1
        if calls[0] > 20 * MAX_REGIONS:
            raise AssertionError("the adjacency measures far pairs")
        return exact(p, q)

    monkeypatch.setattr(terrain_mod, "polygon_distance", counted)
    adj = terrain.adjacency(0.5)
    # an inner stone's neighbours within 0.5 m on the 0.25 m grid: the 5 x 5 block around it
    # (two cells away the gap is 0.3 m, 0.3 sqrt(2) = 0.42 m diagonally; three cells: 0.55 m)
    inner = 8 * 10 + 3  # row 10, column 3
    assert adj[f"s{inner}"] == {
        f"s{inner + 8 * dr + dc}"
        for dr in range(-2, 3)
        for dc in range(-2, 3)
        if (dr, dc) != (0, 0)
    }


def test_adjacency_agrees_with_shapely_distances() -> None:
    """An independent reference (GEOS through shapely) on turned stones of random sizes."""
    shapely = pytest.importorskip("shapely")
    terrain = _stone_grid(120, np.random.default_rng(3))
    radius = 0.31
    shapes = {r.name: shapely.Polygon(r.vertices) for r in terrain}
    adj = terrain.adjacency(radius)
    for a in terrain.names:
        for b in terrain.names:
            if a < b:
                d = shapes[a].distance(shapes[b])
                if abs(d - radius) > 1e-9:  # no tie at the radius
                    assert (b in adj[a]) == (d <= radius), (a, b, d)
                    assert (a in adj[b]) == (d <= radius)


def test_each_n_of_the_smallest_n_search_keeps_to_the_time_limit(
    monkeypatch: pytest.MonkeyPatch, virtual_clock: VirtualClock
) -> None:
    """The reachable sets before each solve made a 0.3 s limit last 2-8 s per N. Here each cut
    of a set into a region costs 50 ms of the test's clock (a large terrain): every N, its sets,
    its kinematic check and its solve together, stays within its limit (plus one cut and the
    clock reads of a few node solves)."""
    from footfall.planning import bounds
    from footfall.planning.run import plan_min_steps

    cut = bounds._cuts

    def costly(*args, **kwargs):  # type: ignore[no-untyped-def]
        virtual_clock.advance(0.05)
        return cut(*args, **kwargs)

    monkeypatch.setattr(bounds, "_cuts", costly)
    seen: list[tuple[int, str, float]] = []

    class Monitor:
        def skipped(self, first: int, last: int, reason: str) -> None:
            pass

        def solving(self, *args: object, **kwargs: object) -> None:
            pass

        def tried(self, n: int, plan: object, seconds: float, proof: str) -> None:
            seen.append((n, proof, seconds))

    limit = 2.0
    sc = builtin_scene("discrete_steps")
    plan = plan_min_steps(
        sc, "miqcqp", PlannerOptions(time_limit=limit), n_max=12, monitor=Monitor()
    )
    assert seen and all(seconds <= limit + 0.2 for _, _, seconds in seen), seen
    # the search is still exact: the N below the answer are proven, the answer is N = 11
    assert plan.status.value == "optimal" and plan.n_steps == 11, plan.message
