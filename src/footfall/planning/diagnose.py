"""Explanations for infeasible footstep problems, from geometry alone (no solver)."""

from __future__ import annotations

import math
from collections import deque

import numpy as np

from footfall._geometry import point_polygon_distance, rot2
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import goal_feet, wrap_near
from footfall.terrain.scene import Scene
from footfall.terrain.terrain import Terrain


def _regions_at(scene: Scene, xy: np.ndarray, margin: float = 0.0) -> list[str]:
    return [r.name for r in scene.terrain if float(r.signed_distance(xy)) <= 1e-9 - margin]


def min_steps_lower_bound(scene: Scene, robot: BipedParams, swing_max: float | None = None) -> int:
    """A lower bound on the number of footsteps any plan needs (distance and heading change).

    With ``swing_max`` (the planner option, L_swing [m]) also the swings: a foot that must move
    a distance D to its goal spot needs ``ceil(D / L_swing)`` swings; the first swing foot
    swings at footsteps 1, 3, ..., the stance foot at footsteps 2, 4, ....
    """
    reach = robot.reach.radius
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
    by_swing = 0
    if swing_max is not None:
        for side in (Side.LEFT, Side.RIGHT):
            travel = float(np.linalg.norm(feet[side][:2] - start.foot(side)[:2]))
            swings = math.ceil(travel / swing_max - 1e-9)
            # swing s of the first swing foot is footstep 2 s - 1, of the stance foot 2 s
            by_swing = max(by_swing, 2 * swings - (1 if side is not start.stance else 0))
    return max(2, by_distance, by_heading, by_swing)


def reachable_regions(
    scene: Scene, robot: BipedParams, region_margin: float = 0.0
) -> dict[str, int]:
    """Regions a footstep can reach from the start, with the fewest steps to get there.

    A step is possible between regions whose polygons, each inset by ``region_margin`` (the
    planner keeps footsteps that far inside), are within the robot's largest step (the reach
    trapezoid's farthest vertex, any heading); the first step starts at the start stance foot.
    Heights and the trapezoid's shape are ignored, so this is a necessary condition only.
    """
    reach = robot.reach.radius
    adj = scene.terrain.adjacency(reach, region_margin)
    p0 = np.asarray(scene.start.stance_foot[:2], dtype=float)
    seen: dict[str, int] = {}
    queue: deque[str] = deque()
    for r in scene.terrain:
        poly = Terrain.inset(r, region_margin)
        if poly is not None and point_polygon_distance(p0, poly) <= reach:
            seen[r.name] = 1
            queue.append(r.name)
    while queue:
        r_name = queue.popleft()
        for nb in adj[r_name]:
            if nb not in seen:
                seen[nb] = seen[r_name] + 1
                queue.append(nb)
    return seen


def _goal_regions(
    scene: Scene, robot: BipedParams, region_margin: float, reasons: list[str]
) -> set[str]:
    """Regions holding both final feet (``region_margin`` inside); a reason for each foot in none."""
    theta_goal = wrap_near(scene.goal.heading, scene.start.heading)
    feet = goal_feet(robot, scene.goal.position[:2], theta_goal)
    goal_regions: set[str] = set()
    for side, xy in feet.items():
        inside = _regions_at(scene, xy, region_margin)
        if not inside:
            where = f" with the {region_margin:g} m margin" if region_margin > 0 else ""
            reasons.append(
                f"the final {side.value} foot at ({xy[0]:.3f}, {xy[1]:.3f}) m lies in no region"
                + where
            )
        goal_regions.update(inside)
    return goal_regions


def geometric_infeasibility(
    scene: Scene,
    robot: BipedParams,
    n_steps: int | None = None,
    region_margin: float = 0.0,
    swing_max: float | None = None,
) -> str | None:
    """Why no plan can exist, from geometry alone, or None if geometry does not rule it out.

    Checked before any solve: a goal foot outside every region, goal regions that no sequence of
    steps reaches (for any N), and, with ``n_steps``, too few steps for the distance, heading
    change (and swings, with ``swing_max`` [m]) or region hops. A solver would need to prove
    these by search, which for the mixed-integer planner can take longer than any time limit.
    """
    reasons: list[str] = []
    goal_regions = _goal_regions(scene, robot, region_margin, reasons)
    seen = reachable_regions(scene, robot, region_margin)
    reach = robot.reach.radius
    if goal_regions and not goal_regions & seen.keys():
        where = f" {region_margin:g} m inside their regions" if region_margin > 0 else ""
        reasons.append(
            f"no goal region ({', '.join(sorted(goal_regions))}) can be reached from the start "
            f"with steps of at most {reach:.2f} m between footsteps{where}; reachable: "
            f"{', '.join(sorted(seen)) or 'none'}"
        )
    if n_steps is not None:
        bound = min_steps_lower_bound(scene, robot, swing_max)
        hops = [seen[g] for g in goal_regions if g in seen]
        if hops:
            bound = max(bound, min(hops))
        if bound > n_steps:
            reasons.append(f"the goal needs at least {bound} footsteps, {n_steps} were asked for")
    return "infeasible: " + "; ".join(reasons) if reasons else None


#: headings sampled across one heading segment by :func:`linear_reach_forward`
_SEGMENT_SAMPLES = 33


def linear_reach_forward(robot: BipedParams, heading_segments: int) -> tuple[float, float]:
    """The longest forward step [m] the linear reach rows of eq. 5.12f allow with
    ``heading_segments`` segments, and the reach polygon's own (its largest forward vertex).

    With the heading ``theta`` in a segment ``[phi_l, phi_{l+1}]``, every trapezoid row is imposed
    rotated to both segment ends with a positive bound shrunk by ``cos(dphi / 2)`` (module
    docstring of :mod:`footfall.planning.miqcqp`), so the rows cut into the polygon. The first
    value is the largest forward component ``q_x`` of a step (stance frame) the rows allow, the
    best over headings sampled across a segment (a small linear program per heading).
    """
    from scipy.optimize import linprog

    g_rows, h_rows = robot.reach.halfspaces(Side.RIGHT)
    half = math.pi / heading_segments
    h_eff = np.where(h_rows > 0, h_rows * math.cos(half), h_rows)
    best = -math.inf
    for t in np.linspace(-half, half, _SEGMENT_SAMPLES):
        # the row (Rot(phi) g)^T d <= h' with d = Rot(theta) q is (Rot(phi - theta) g)^T q <= h'
        a_ub = np.vstack([g_rows @ rot2(a).T for a in (-half - t, half - t)])
        res = linprog(
            [-1.0, 0.0], A_ub=a_ub, b_ub=np.concatenate([h_eff, h_eff]), bounds=(None, None)
        )
        if res.status == 0:
            best = max(best, -float(res.fun))
    return best, float(np.max(robot.reach.vertices[:, 0]))


def reach_model_note(robot: BipedParams, heading_segments: int | None) -> str:
    """What the planner's linear reach model (eq. 5.12f with L segments) gives up, in words."""
    if heading_segments is None:
        return "the planner's reach model (eq. 5.12f)"
    linear, polygon = linear_reach_forward(robot, heading_segments)
    return (
        f"the conservative linear reach model (eq. 5.12f-h; with L = {heading_segments} heading "
        f"segments it allows a forward step of at most about {linear:.3f} m where the reach "
        f"polygon allows {polygon:.3f} m)"
    )


def diagnose_infeasible(
    scene: Scene,
    robot: BipedParams,
    n_steps: int,
    region_margin: float = 0.0,
    swing_max: float | None = None,
    heading_segments: int | None = None,
    torque_bound: bool = True,
) -> str:
    """Say what is known about why ``n_steps`` footsteps cannot reach the goal of ``scene``.

    A geometric reason (:func:`geometric_infeasibility`) holds for any planner. Otherwise the
    solver proved only that its model has no plan: the linear reach rows are conservative (see
    :func:`linear_reach_forward`), so a plan the true reach polygon allows may exist, and the
    message says so and names the option that relaxes the model (``heading_segments``). With
    ``torque_bound`` False (the kinematic planner) the torque bound is not part of the model and
    is not cited.
    """
    found = geometric_infeasibility(scene, robot, n_steps, region_margin, swing_max)
    if found is not None:
        return found
    torque = f", the ankle-torque bound U_max = {robot.u_max:g} N m" if torque_bound else ""
    relax = (
        "more heading segments make it less conservative (heading_segments / "
        "--heading-segments, now "
        f"{heading_segments}); or try more steps (--min-steps)"
        if heading_segments is not None
        else "try more steps (--min-steps)"
    )
    return (
        f"infeasible within the planner's model: no plan with {n_steps} footsteps satisfies the "
        f"regions, {reach_model_note(robot, heading_segments)}, step height, heading rate"
        f"{torque} and the goal; a plan outside this model is not ruled out: {relax}"
    )
