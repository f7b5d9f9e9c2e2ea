"""One entry point for every footstep planner, and the smallest-N search (``--min-steps``)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning.diagnose import min_steps_lower_bound
from footfall.planning.plan import (
    FootstepPlan,
    PlannerOptions,
    check_planner_name,
    check_planning_arguments,
)
from footfall.terrain.scene import Scene

#: how many footsteps beyond the geometric lower bound ``--min-steps`` tries by default
MIN_STEPS_SPAN = 10


def make_plan(
    scene: Scene,
    planner: str = "miqcqp",
    n_steps: int | None = None,
    options: PlannerOptions | None = None,
    robot: BipedParams | None = None,
) -> FootstepPlan:
    """Plan with the named planner (``miqcqp``, ``kinematic`` or ``reactive``).

    Args:
        scene: terrain, start and goal.
        planner: planner name.
        n_steps: footsteps N for the optimising planners; the reactive planner walks until the
            goal and uses ``n_steps`` (default 40) only as its limit. None for the optimising
            planners means the smallest feasible N (:func:`plan_min_steps`).
        options: planner options.
        robot: robot parameters (default ``scene.robot``).
    """
    check_planning_arguments(scene, robot, options)
    check_planner_name(planner)
    options = options or PlannerOptions()
    if planner == "reactive":
        from footfall.planning.reactive import plan_reactive

        if options.reach_both_frames:
            raise InputError(
                "reach_both_frames", True, "False for the reactive planner (miqcqp or kinematic)"
            )
        if options.swing_max is not None:
            raise InputError(
                "swing_max",
                options.swing_max,
                "None for the reactive planner (miqcqp or kinematic)",
            )

        return plan_reactive(
            scene, robot, max_steps=n_steps or 40, region_margin=options.region_margin
        )
    if n_steps is None:
        return plan_min_steps(scene, planner, options, robot)
    if planner == "kinematic":
        from footfall.planning.kinematic import plan_kinematic

        return plan_kinematic(scene, robot, n_steps, options)
    from footfall.planning.miqcqp import plan_footsteps

    return plan_footsteps(scene, robot, n_steps, options)


def _search_note(found: int, start: int, tried: list[dict[str, object]]) -> str:
    """What a smallest-N search proved: the N below ``found`` that were proven infeasible and the
    N that were not decided (time limit, error), in which case ``found`` may not be the smallest."""
    proven = [t["n_steps"] for t in tried if t["status"] == "infeasible"]
    open_ = [f"{t['n_steps']} ({t['status']})" for t in tried if t["status"] != "infeasible"]
    note = f"first N with a plan: {found} (searched from the lower bound {start}"
    if proven:
        # proven for the planner's model (conservative linear reach): see the plans' messages
        note += f"; proven infeasible: N = {', '.join(map(str, proven))} for the planner's model"
    if open_:
        return (
            note + f"; not decided: N = {', '.join(open_)}, so a plan with fewer steps may exist)"
        )
    return note + f"; so {found} is the smallest N with a plan in the planner's model)"


def plan_min_steps(
    scene: Scene,
    planner: str = "miqcqp",
    options: PlannerOptions | None = None,
    robot: BipedParams | None = None,
    n_max: int | None = None,
    progress: Callable[[int, FootstepPlan], None] | None = None,
) -> FootstepPlan:
    """The plan with the smallest number of footsteps N that has a solution.

    Tries N upward from a geometric lower bound (distance and heading change). Each try that ends
    without a plan is recorded in the returned plan's ``stats["tried"]`` with its status.
    """
    if planner == "reactive":
        raise InputError("planner", planner, "miqcqp or kinematic (reactive has no N to search)")
    robot = robot or scene.robot
    options = options or PlannerOptions()
    start = min_steps_lower_bound(scene, robot, options.swing_max)
    n_max = n_max if n_max is not None else start + MIN_STEPS_SPAN
    if n_max < start:
        raise InputError("n_max", n_max, f"at least the lower bound {start}")
    tried: list[dict[str, object]] = []
    plan: FootstepPlan | None = None
    for n in range(start, n_max + 1):
        plan = make_plan(scene, planner, n, options, robot)
        if progress is not None:
            progress(n, plan)
        if plan.has_solution:
            stats = dict(plan.stats)
            stats["tried"] = tried
            return replace(
                plan, stats=stats, message=plan.message + "; " + _search_note(n, start, tried)
            )
        tried.append({"n_steps": n, "status": plan.status.value})
    assert plan is not None
    return replace(
        plan, message=plan.message + f"; no plan for N = {start}..{n_max}", stats={"tried": tried}
    )
