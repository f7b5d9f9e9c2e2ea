"""Plans made for a MuJoCo walker.

:func:`plan_for_walk` makes (or loads from the plan cache, :mod:`footfall.planning.cache`) the plan
of a scene for a walker model's measured robot (:func:`~footfall.sim.biped.model.planner_params`),
with the options beyond the document that the walks need; :func:`robot_model` names the walkers.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from footfall.planning.cache import PlanCache, cached_plan
from footfall.planning.plan import (
    FootstepPlan,
    PlannerOptions,
    available_cores,
    check_planner_name,
)
from footfall.planning.run import SearchMonitor
from footfall.sim.biped.model import (
    SWING_MAX,
    WALK_HEADING_SEGMENTS,
    BipedModel,
    WalkerModel,
    planner_params,
)
from footfall.sim.biped.options import RISER_LANDING_TOLERANCE
from footfall.terrain.edges import inset_riser_edges
from footfall.terrain.scene import Scene


def robot_model(source: str | Path) -> WalkerModel:
    """The walker model named ``source``: footfall's own ``biped``, a built-in robot file's
    (``footfall.robots.registry.builtin_robot_names``) or a robot file's (a ``.yaml`` path).

    Raises:
        InputError: an unknown name or a bad robot file (naming the field).
        MissingExtraError: the model's package is not installed (naming the extra).
    """
    from footfall.robots.registry import resolve_robot_file

    rf = resolve_robot_file(source)
    if rf is None:
        return BipedModel()
    from footfall.robots.model import RobotModel

    return RobotModel(rf)


def plan_for_walk(
    scene: Scene,
    planner: str,
    n_steps: int | None = None,
    time_limit: float = 300.0,
    cache_dir: Path | None = None,
    model: WalkerModel | None = None,
    robot_aware: bool = True,
    heading_segments: int | None = None,
    monitor: SearchMonitor | None = None,
    threads: int | None = None,
    heading_windows: int = PlannerOptions.heading_windows,
) -> FootstepPlan:
    """The plan of ``scene`` for the MuJoCo biped or another walker model (robot parameters from
    :func:`planner_params`).

    With ``robot_aware`` (the default) the optimising planners (miqcqp, kinematic) also get the
    options beyond the document that this robot needs (:func:`walk_planner_options`): the reach
    set in both feet's frames and the swing bound ``SWING_MAX`` (measured on our biped, used for
    every walker model). The reactive planner cannot honour them and plans without.
    ``robot_aware=False`` plans the document's problem (with the region margin only).

    ``heading_segments``: L of the miqcqp and kinematic plans (eq. 5.12g-h); None:
    ``WALK_HEADING_SEGMENTS`` (64) for robot-aware plans, the document's 16 otherwise. Each
    segment's linear reach (eq. 5.12f) holds for every heading in it, so a heading held on a
    breakpoint (a straight walk at theta = 0 sits on the one between two 22.5 deg segments) gets
    the trapezoid intersected with its copy rotated a whole segment away: from a right stance
    foot, a left step at the inner width 0.12 m may reach 0.342 m forward in the segment below 0
    but not forward at all (-0.024 m) in the one above. With both reach frames each foot's segment
    must serve its incoming and its outgoing step, which need opposite segments, so straight
    robot-aware plans alternate 0.12 and about 0.24 m wide steps and drift sideways
    (stairs_slope_gap N = 16: to y = 0.39 m). 64 segments (5.6 deg) lose at most 4 cm of width
    there (0.329 m forward at 0.16 m); the plans take longer (stairs_slope_gap N = 16: 38 s
    instead of 4 s).

    ``heading_windows``: :attr:`PlannerOptions.heading_windows` (0: no heading-window search
    after a solve that found no plan).

    ``threads``: worker processes of the ``bnb`` backend (default: 2, or the cores if fewer; not
    part of the plan cache key).

    ``monitor`` hears of a smallest-N search (``n_steps`` None) while it runs
    (:func:`footfall.planning.run.plan_min_steps`; ``footfall walk`` prints its lines).

    With ``cache_dir`` the plan is kept in that folder's plan cache (:mod:`footfall.planning.cache`)
    and reused while the scene's contents (its regions after the riser insets, start, goal), the
    planner, N, the robot and every planner option are unchanged (MIQCQP plans take minutes).

    Beyond the document: the plan is made on the scene's regions with their riser edges moved in
    by ``RISER_LANDING_TOLERANCE`` (:func:`footfall.terrain.edges.inset_riser_edges`) and with a
    ``region_margin`` of half the sole length: footsteps stay half a sole plus the tolerance from
    the edge of a tread below a riser (a step down lands there) and half a sole from other edges.
    """
    check_planner_name(planner)
    robot = planner_params(model, base=scene.robot)
    # the sole is not a point: keep its centre half a foot length inside every region, so the
    # whole sole stands on the block (at the plan's headings, which stay near the scene's)
    margin = robot.foot_length / 2.0
    scene = replace(scene, terrain=inset_riser_edges(scene.terrain, RISER_LANDING_TOLERANCE))
    aware = walk_planner_options(planner) if robot_aware else {}
    if heading_segments is None:
        heading_segments = WALK_HEADING_SEGMENTS if robot_aware else PlannerOptions.heading_segments
    if threads is None:
        threads = min(2, available_cores())
    opts = PlannerOptions(
        time_limit=time_limit,
        region_margin=margin,
        heading_segments=heading_segments,
        threads=threads,
        heading_windows=heading_windows,
        **aware,
    )
    plan = cached_plan(
        scene,
        planner,
        n_steps,
        opts,
        robot,
        PlanCache(cache_dir) if cache_dir is not None else None,
        monitor,
    )
    # the walker keeps its corrections in the regions the plan was made on (a cached plan is
    # keyed by those regions, so it was made on them too)
    return replace(plan, riser_inset=RISER_LANDING_TOLERANCE)


def walk_planner_options(planner: str) -> dict[str, Any]:
    """The :class:`PlannerOptions` beyond the document that the MuJoCo biped's walks use.

    ``reach_both_frames``: with eq. (5.12f) alone the minimum-N plans stretch their reach by
    zig-zagging the headings (turn: 0, 22.5, 0, 30, 60, 90 deg; discrete_steps N = 13: up to
    22.5 deg on block2) and the legs cross or the swing gets long. ``swing_max``: the swing bound
    ``SWING_MAX`` measured for this robot (see there). The reactive planner gets neither (it
    refuses both).
    """
    check_planner_name(planner)
    if planner == "reactive":
        return {}
    return {"reach_both_frames": True, "swing_max": SWING_MAX}
