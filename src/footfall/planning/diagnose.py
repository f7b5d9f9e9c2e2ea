"""Explanations for infeasible footstep problems, from geometry alone (no solver)."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import goal_feet, wrap_near
from footfall.terrain.scene import Scene


def _regions_at(scene: Scene, xy: np.ndarray) -> list[str]:
    return [r.name for r in scene.terrain if float(r.signed_distance(xy)) <= 1e-9]


def min_steps_lower_bound(scene: Scene, robot: BipedParams) -> int:
    """A lower bound on the number of footsteps any plan needs (distance and heading change)."""
    reach = float(np.max(np.linalg.norm(robot.reach.vertices, axis=1)))
    start = scene.start
    theta_goal = wrap_near(scene.goal.heading, start.heading)
    feet = goal_feet(robot, scene.goal.position[:2], theta_goal)
    # Footstep k of the plan is the foot of side sides[k]; the final two are the goal feet.
    far = max(
        float(np.linalg.norm(feet[side][:2] - start.stance_foot[:2]))
        for side in (Side.LEFT, Side.RIGHT)
    )
    by_distance = math.ceil(far / reach - 1e-9)
    by_heading = math.ceil(abs(theta_goal - start.heading) / robot.theta_max - 1e-9) + 1
    return max(2, by_distance, by_heading)


def diagnose_infeasible(scene: Scene, robot: BipedParams, n_steps: int) -> str:
    """Say what is known about why ``n_steps`` footsteps cannot reach the goal of ``scene``."""
    reasons: list[str] = []
    theta_goal = wrap_near(scene.goal.heading, scene.start.heading)
    feet = goal_feet(robot, scene.goal.position[:2], theta_goal)
    goal_regions: set[str] = set()
    for side, xy in feet.items():
        inside = _regions_at(scene, xy)
        if not inside:
            reasons.append(
                f"the final {side.value} foot at ({xy[0]:.3f}, {xy[1]:.3f}) m lies in no region"
            )
        goal_regions.update(inside)
    reach = float(np.max(np.linalg.norm(robot.reach.vertices, axis=1)))
    adj = scene.terrain.adjacency(reach)
    start_region = scene.start_regions()[scene.start.stance]
    seen = {start_region: 0}
    queue = deque([start_region])
    while queue:
        r = queue.popleft()
        for nb in adj[r]:
            if nb not in seen:
                seen[nb] = seen[r] + 1
                queue.append(nb)
    if goal_regions and not goal_regions & seen.keys():
        reasons.append(
            f"no goal region ({', '.join(sorted(goal_regions))}) can be reached from the start region "
            f"{start_region!r} with steps of at most {reach:.2f} m; reachable: {', '.join(sorted(seen))}"
        )
    bound = min_steps_lower_bound(scene, robot)
    hops = [seen[g] for g in goal_regions if g in seen]
    if hops:
        bound = max(bound, min(hops))
    if bound > n_steps:
        reasons.append(f"the goal needs at least {bound} footsteps, {n_steps} were asked for")
    if not reasons:
        reasons.append(
            f"no assignment of regions and headings satisfies reach, step height, torque bound "
            f"({robot.u_max:g} N m) and goal with {n_steps} footsteps; try more steps (--min-steps)"
        )
    return "infeasible: " + "; ".join(reasons)
