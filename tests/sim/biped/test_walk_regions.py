"""Region-aware corrections in MuJoCo: the walker walks stepping_stones with the
miqcqp plan of ``footfall walk`` (stored in data/, so the test does not plan for minutes) and a
2 N s push, every footstep landing on a stone; the walk metrics' region counts are checked
against shapely on the landed soles."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("mink")

from shapely.geometry import Point, Polygon  # noqa: E402

from footfall.planning.plan_file import load_plan  # noqa: E402
from footfall.sim.biped.options import WalkOptions  # noqa: E402
from footfall.sim.biped.trial import MujocoBipedPlant  # noqa: E402
from footfall.sim.biped.walk import walk  # noqa: E402
from footfall.sim.disturbance import Disturbance  # noqa: E402
from footfall.sim.trial import run_trial  # noqa: E402
from footfall.terrain import Scene, builtin_scene  # noqa: E402

PLAN = Path(__file__).parent / "data" / "stepping_stones_miqcqp.json"
#: the measured sole centre sits this close to the stone's surface [m]
ON_SURFACE_TOL = 0.03


def _assert_on_regions(scene: Scene, landed: np.ndarray) -> None:
    """Every landed sole centre (n, 3) inside a region's polygon (shapely) and on its surface."""
    for p in landed:
        assert any(
            Polygon(r.vertices).covers(Point(p[:2]))
            and abs(float(r.height_at(p[:2])) - p[2]) <= ON_SURFACE_TOL
            for r in scene.terrain.regions
        ), p


def test_region_aware_walk_keeps_every_footstep_on_a_stone() -> None:
    scene = builtin_scene("stepping_stones")
    plan = load_plan(PLAN, scene)
    opts = WalkOptions(region_aware="planned")
    outcome = run_trial(MujocoBipedPlant(opts), scene, plan, Disturbance.of_seed(0, impulse=2.0))
    res = outcome.detail
    m = res.metrics
    assert outcome.footsteps_off_terrain == m.footsteps_off_regions
    assert not m.fell and m.reached_goal
    polys = [(Polygon(r.vertices), r) for r in scene.terrain.regions]
    landed = res.trace.landed[~np.isnan(res.trace.landed[:, 0])]
    assert landed.shape[0] == plan.n_steps + opts.stop_steps
    for p in landed:
        on = [
            r.name
            for poly, r in polys
            if poly.covers(Point(p[:2])) and abs(float(r.height_at(p[:2])) - p[2]) <= ON_SURFACE_TOL
        ]
        assert on, p
    assert m.footsteps_off_regions == 0
    # the adjuster recorded a choice per phase, every one on the planned stone
    assert len(m.region_choices) == plan.n_steps + opts.stop_steps
    assert all(c["region"] == c["planned"] for c in m.region_choices)
    assert m.region_changes == ()
    # corrections are the distances of the commanded footsteps from the plan
    corr = np.linalg.norm((res.trace.targets - res.trace.planned)[: plan.n_steps, :2], axis=1)
    assert m.correction_m.max == pytest.approx(corr.max(), abs=1e-12)
    assert 0.0 < m.correction_m.max < 0.1


def test_horizon_mode_walks_the_stones_asking_the_short_horizon_miqp() -> None:
    """``horizon``: the next footstep's region comes from the 3-footstep MIQP (its solves counted
    by a spy: at least one per phase with three footsteps ahead), the walk with a 2 N s push
    reaches the goal and every landed sole centre is on a stone (shapely)."""
    from footfall.control import horizon_regions

    scene = builtin_scene("stepping_stones")
    plan = load_plan(PLAN, scene)
    calls: list[int] = []
    orig = horizon_regions.HorizonRegions.choose

    def spy(self: horizon_regions.HorizonRegions, phase: int, *args: object) -> str | None:
        before = self.solves
        out = orig(self, phase, *args)  # type: ignore[arg-type]
        if self.solves > before:
            calls.append(phase)
        return out

    opts = WalkOptions(region_aware="horizon")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(horizon_regions.HorizonRegions, "choose", spy)
        outcome = run_trial(
            MujocoBipedPlant(opts), scene, plan, Disturbance.of_seed(0, impulse=2.0)
        )
    m = outcome.detail.metrics
    assert not m.fell and m.reached_goal
    # every phase with three footsteps of the walker's plan (stopping steps included) ahead asked
    n = plan.n_steps + opts.stop_steps
    assert set(calls) == set(range(n - 3 + 1))
    landed = outcome.detail.trace.landed[~np.isnan(outcome.detail.trace.landed[:, 0])]
    _assert_on_regions(scene, landed)
    assert m.footsteps_off_regions == 0


def test_bad_region_mode_names_the_field() -> None:
    from footfall.errors import InputError

    with pytest.raises(InputError, match="region_aware"):
        WalkOptions(region_aware="anywhere")


@pytest.mark.parametrize("mode", ["off", "planned"])
def test_a_retargeted_swing_is_raised_over_the_regions_under_its_new_path(mode: str) -> None:
    """A correction that moves the swing target across a higher stone raises the apex over it
    while the sole is still rising (region-aware walks only); the height is checked with shapely
    against the stones the sole's swept path crosses."""
    from shapely.geometry import LineString

    from footfall.sim.biped.walk import BipedWalk

    scene = builtin_scene("stepping_stones")
    plan = load_plan(PLAN, scene)
    walker = BipedWalk(scene, plan, WalkOptions(region_aware=mode))
    walker._begin_step(0)
    apex0 = walker.swing.apex
    # a target on stone4 (0.08 m high), far across stones 1-3, instead of the planned one
    target = np.array([1.31, -0.14, 0.08])
    walker._raise_swing(0.0, target)
    start = walker.swing.start
    robot = plan.robot
    path = LineString([start[:2], target[:2]]).buffer(robot.foot_width / 2)
    crossed = max(
        float(np.max(r.height_at(r.vertices)))
        for r in scene.terrain.regions
        if Polygon(r.vertices).intersects(path)
    )
    clearance = WalkOptions().swing_clearance
    if mode == "off":
        assert walker.swing.apex == apex0
    else:
        assert walker.swing.apex >= crossed + clearance - 1e-9
        assert walker.swing.apex > apex0
    # late in the swing (the sole no longer rising) nothing changes
    walker.swing.apex = apex0
    walker._raise_swing(0.9 * robot.t_ss, target + 0.05)
    assert walker.swing.apex == apex0


@pytest.mark.parametrize("name", ["narrow_stones_gap", "roll_ramps", "corridor_corner"])
def test_new_scenes_are_walked_with_every_footstep_on_a_region(name: str) -> None:
    """Smoke test of the region scenes (plans of ``footfall walk`` stored in data/): the
    walker's default (region-aware: ``horizon``) reaches the goal and no landed sole centre is
    off the terrain (shapely)."""
    scene = builtin_scene(name)
    plan = load_plan(Path(__file__).parent / "data" / f"{name}_miqcqp.json", scene)
    opts = WalkOptions()
    assert opts.region_aware == "horizon"
    res = walk(scene, plan, opts)
    assert not res.metrics.fell and res.metrics.reached_goal
    landed = res.trace.landed[~np.isnan(res.trace.landed[:, 0])]
    _assert_on_regions(scene, landed)
    assert res.metrics.footsteps_off_regions == 0


@pytest.mark.parametrize("limited", [True, False])
def test_the_swing_target_moves_at_most_its_speed_per_tick(limited: bool) -> None:
    """Once the sole moves horizontally, the swing path's target moves toward a jumped MPC
    footstep by at most speed * dt per tick; the speed crosses the reach trapezoid's diameter in
    one single support. By hand for the biped: the corners (-0.20, 0.12) and (0.35, 0.12) are
    0.55 m apart, T_ss = 0.4 s, so 1.375 m/s and 13.75 mm per 10 ms tick; a 0.10 m jump takes 8
    ticks (7 full, 0.75 mm). The horizontal move starts at 10 % of T_ss, 0.04 s."""
    from footfall.sim.biped.walk import BipedWalk

    scene = builtin_scene("stepping_stones")
    plan = load_plan(PLAN, scene)
    walker = BipedWalk(scene, plan, WalkOptions(swing_target_rate=limited))
    assert walker.target_speed == pytest.approx(0.55 / 0.4)
    assert walker.dt == pytest.approx(0.01)
    walker._begin_step(0)
    planned = np.asarray(plan.footsteps[1], dtype=float)
    goal = planned + np.array([0.0, 0.10, 0.0])
    tp = 0.04
    if not limited:
        assert np.allclose(walker._limit_target(goal, tp), goal)
        return
    expected_y = [0.01375 * k for k in range(1, 8)] + [0.10, 0.10]
    for y in expected_y:
        target = walker._limit_target(goal, tp)
        assert target == pytest.approx(planned + np.array([0.0, y, 0.0]), abs=1e-12)
        tp += walker.dt
    # the next step starts from its own planned footstep
    walker._begin_step(1)
    assert walker.swing.target == pytest.approx(np.asarray(plan.footsteps[2], dtype=float))


def test_the_swing_target_jumps_only_to_a_footstep_the_bound_could_not_reach_in_time() -> None:
    """In the first 10 % of T_ss (0.04 s for the biped) the swing path's horizontal part is its
    start whatever the target (checked on the path itself). There a footstep farther than the
    bounded target can travel before the horizontal move ends (1.375 m/s x (0.36 s - tp):
    0.495 m at tp = 0, 0.4675 m at tp = 0.02 s) is taken at once, e.g. a crossover after a
    strong inward push; a nearer one is approached at 13.75 mm per tick from the first tick."""
    from footfall.sim.biped.references import swing_reference
    from footfall.sim.biped.walk import BipedWalk

    scene = builtin_scene("stepping_stones")
    plan = load_plan(PLAN, scene)
    walker = BipedWalk(scene, plan, WalkOptions())
    walker._begin_step(0)
    planned = np.asarray(plan.footsteps[1], dtype=float)
    start = np.asarray(walker.swing.start, dtype=float)
    far = planned + np.array([0.0, -0.6, 0.0])
    for tp in (0.0, 0.01, 0.02, 0.03):
        a, _ = swing_reference(tp / 0.4, start, planned, 0.1)
        b, _ = swing_reference(tp / 0.4, start, far, 0.1)
        assert a[:2] == pytest.approx(start[:2], abs=1e-12)
        assert b[:2] == pytest.approx(start[:2], abs=1e-12)
    # near: 0.10 m away, reachable in time, so bounded from tp = 0 on
    near = planned + np.array([0.0, 0.10, 0.0])
    assert walker._limit_target(near, 0.0) == pytest.approx(
        planned + np.array([0.0, 0.01375, 0.0]), abs=1e-12
    )
    # 0.48 m from the target at tp = 0.02 s: beyond 0.4675 m, so it is taken at once
    now = walker.swing.target.copy()
    jump = now + np.array([0.0, -0.48, 0.0])
    assert walker._limit_target(jump, 0.02) == pytest.approx(jump, abs=1e-12)
    # 0.48 m at tp = 0: within 0.495 m, bounded
    walker._begin_step(0)
    jump = planned + np.array([0.0, -0.48, 0.0])
    assert walker._limit_target(jump, 0.0) == pytest.approx(
        planned + np.array([0.0, -0.01375, 0.0]), abs=1e-12
    )
    # once the sole moves (tp >= 0.04 s) a far footstep is approached at a bounded speed: the
    # one that reaches it by the end of the horizontal move, 0.6 m / (0.36 - 0.04) s = 1.875 m/s
    # (18.75 mm per tick), above the bound because it is more than FAST_TARGET_GAP away ...
    walker._begin_step(0)
    assert walker._limit_target(far, 0.04) == pytest.approx(
        planned + np.array([0.0, -0.01875, 0.0]), abs=1e-12
    )
    # ... and never above FAST_TARGET_FACTOR (2) times the bound: 1.0 m at tp = 0.2 s would need
    # 6.25 m/s, it gets 2.75 m/s (27.5 mm per tick)
    walker._begin_step(0)
    very = planned + np.array([0.0, -1.0, 0.0])
    assert walker._limit_target(very, 0.2) == pytest.approx(
        planned + np.array([0.0, -0.0275, 0.0]), abs=1e-12
    )
    # a footstep within FAST_TARGET_GAP (0.1 m) is approached at the bound, late as well
    walker._begin_step(0)
    close = planned + np.array([0.0, -0.09, 0.0])
    assert walker._limit_target(close, 0.3) == pytest.approx(
        planned + np.array([0.0, -0.01375, 0.0]), abs=1e-12
    )


def test_every_front_door_defaults_to_the_walkers_region_mode() -> None:
    """``footfall walk``, ``footfall bench pushes`` and the push protocol's API default to
    :attr:`WalkOptions.region_aware` (written out there as a string, to keep imports light)."""
    import inspect

    from footfall.cli.bench import bench_pushes_cmd
    from footfall.cli.simulation import walk_cmd
    from footfall.experiments.protocol import PushProtocol

    default = WalkOptions().region_aware
    for cmd in (walk_cmd, bench_pushes_cmd):
        option = inspect.signature(cmd).parameters["region_aware"].default
        assert option.default == default, cmd.__name__
    assert PushProtocol.__dataclass_fields__["region_aware"].default == default
