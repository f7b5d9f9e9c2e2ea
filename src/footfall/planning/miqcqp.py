"""Full-horizon MIQCQP footstep planner of document 000, section 5.3 (eq. 5.11-5.18).

Decision variables: footsteps ``p_i`` (3-D) and headings ``theta_i`` (i = 1..N; i = 0 is the given
stance foot), the piecewise-linear ``s_i ~ sin theta_i`` and ``c_i ~ cos theta_i`` with one set of
segment binaries ``S_{l,i}`` shared by both (the document's S and C pin theta to the same segment,
so one set is exact), region binaries ``H_{r,i}``, ALIP states ``x_{i,k}`` at K nodes of every
single-support phase and ankle torques ``u_{i,k}`` between them (sparse form: states are
variables; a condensed form was numerically poor because of the unstable ALIP mode).

Objective (5.11):
    sum_{i,k} u^T Q_u u + lambda_x ||x_N - x_goal||^2_{Q_x}
    + lambda_theta sum_i (theta_{i+2} - 2 theta_{i+1} + theta_i)^2
    + lambda_l sum_i (p_{i+1} - p_i)^T Q_l (p_{i+1} - p_i)

Constraints: ALIP dynamics (5.12a) with the ZOH matrices, reset map (5.12b) with the corrected
eq. (5.10), initial state (5.12c), ``||u||_2 <= U_max`` (5.12d) as a convex quadratic constraint,
heading rate (5.12e), reachability (5.12f) in the stance foot's rotated trapezoid (mirrored for the
left foot), the sin/cos segments (5.12g-h, 5.14), region assignment with the plane rows (5.15-5.17)
and the polygon rows (5.18) under big-M (5.12i), one region and one segment per step (5.12j-k),
a step-height bound, and the goal: the last two footsteps stand at the goal pose (midpoint at the
goal position, both at the goal heading, nominal stance width), and ``x_goal`` is the rest state
between them.

Reachability is made linear and conservative (never overestimated, as Deits & Tedrake require):
with the segment ``[phi_l, phi_{l+1}]`` active, each trapezoid row ``g^T q <= h`` of the step ``q``
in the stance frame is imposed at both segment ends, ``(Rot(phi) g)^T d <= h'``, with
``h' = h cos(dphi / 2)`` when ``h > 0`` and ``h' = h`` otherwise. Every ``Rot(theta) g`` with theta in
the segment is a non-negative combination of the two end rotations with weights summing to between
1 and ``1 / cos(dphi / 2)``, so the row then holds for the true heading. (Substituting the
piecewise-linear ``s_i, c_i`` into ``Rot(theta_i)`` instead would give bilinear terms ``c_i d`` and
could overestimate reach.)

Big-M constants are computed per row from tight variable bounds (terrain bounding box, heading
range ``theta_0 +- i theta_max``).

Beyond the document (:class:`PlannerOptions`, all off by default): ``region_margin`` (eq. 5.18 with
the edges moved inward), ``reach_both_frames`` (eq. 5.12f also in the landing foot's frame) and
``swing_max``, a bound L_swing on the horizontal swing ``||p_{i+1} - p_{i-1}||_2`` of each foot.
The swing bound is a second-order cone on a difference of footsteps; it is imposed as the
regular ``SWING_SIDES``-gon inscribed in that disc, ``n_j^T (p_{i+1} - p_{i-1}) <= L cos(pi / M)``
with the M facet normals ``n_j``: linear rows that every backend (and ``bnb``'s plain-row path)
takes as they are, conservative like the linear reach (a planned swing is never longer than
L_swing, at most ``1 - cos(pi / M)`` shorter in the worst direction). A cone would need auxiliary
difference variables, which ``bnb`` condenses away with the ALIP states (dropping the cone from
its node relaxations).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import (
    FootstepPlan,
    PlannerOptions,
    goal_feet,
    result_meta,
    rot2,
    wrap_near,
)
from footfall.solvers import ProblemBuilder, SolveStatus, solve
from footfall.solvers.problem import MIQCQP
from footfall.terrain.scene import Scene

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.int64]

#: sides M of the regular polygon inscribed in the swing disc ``||d|| <= L_swing`` (option
#: ``swing_max``): 16 facets lose at most 1 - cos(pi / 16) = 1.9 % of L_swing (about 1 cm)
SWING_SIDES = 16


@dataclass(frozen=True)
class FootstepProblem:
    """A built planner model: the :class:`MIQCQP` and where each document variable lives in it.

    Index arrays hold variable indices of ``problem``: ``p`` (N+1, 3), ``theta`` (N+1,),
    ``s``/``c`` (N+1,), ``x`` (N, K, 4), ``u`` (N, K-1, 2), ``x_final`` (4,), ``regions`` (N+1, R)
    (-1 where not a variable: footstep 0), ``segments`` (N+1, L) (-1 where the segment is out of
    the heading range or for footstep 0).
    """

    problem: MIQCQP
    scene: Scene
    robot: BipedParams
    n_steps: int
    options: PlannerOptions
    sides: tuple[Side, ...]
    p: IntArray
    theta: IntArray
    s: IntArray
    c: IntArray
    x: IntArray
    u: IntArray
    x_final: IntArray
    regions: IntArray
    segments: IntArray
    breakpoints: FloatArray
    x_goal: FloatArray


def _side_sequence(stance: Side, n_steps: int) -> tuple[Side, ...]:
    sides = [stance]
    for _ in range(n_steps):
        sides.append(sides[-1].other)
    return tuple(sides)


def build_footstep_problem(
    scene: Scene,
    robot: BipedParams | None = None,
    n_steps: int = 8,
    options: PlannerOptions | None = None,
    dynamics: bool = True,
) -> FootstepProblem:
    """Build the MIQCQP of eq. (5.11)-(5.18) for ``scene`` (see the module docstring).

    Args:
        scene: terrain, start and goal.
        robot: robot parameters; defaults to ``scene.robot``.
        n_steps: number of footsteps N to plan (>= 1).
        options: weights and discretisation.
        dynamics: include the ALIP states, torques and their terms (False gives the kinematic
            navigation-goal baseline: same regions, reach, heading and goal, no dynamics).

    Returns:
        The inspectable model.
    """
    robot = robot or scene.robot
    options = options or PlannerOptions()
    if isinstance(n_steps, bool) or not isinstance(n_steps, int) or n_steps < 1:
        raise InputError("n_steps", n_steps, "an integer >= 1")
    w = options.weights
    n = n_steps
    k_nodes = robot.n_nodes
    alip = robot.alip()
    ad, bd = alip.discretize(robot.node_dt)
    a_r, b_r = alip.reset_map(robot.t_ds)
    start = scene.start
    theta0 = float(start.heading)
    theta_goal = wrap_near(float(scene.goal.heading), theta0)
    sides = _side_sequence(start.stance, n)
    terrain = scene.terrain
    lo_box, hi_box = terrain.bounds()
    mzh = robot.mass * robot.com_height

    feet = goal_feet(robot, scene.goal.position[:2], theta_goal)
    reach = robot.reach.radius
    p0 = start.foot(start.stance)

    b = ProblemBuilder()
    # Footsteps (3-D). Tight bounds, all implied by the constraints (so the optimum is unchanged):
    # inside the terrain box, within i steps of reach of footstep 0 and within N - i (N - 1 - i) of
    # the final footstep N (N - 1), whose positions the goal fixes; heights likewise.
    # With ``swing_max`` a foot is also within L_swing per swing of its previous and next
    # position of the same foot (its start position and its goal spot).
    swing_from = start.foot(sides[1])[:2] if n >= 1 else p0[:2]
    p = b.add_vars("p", (n + 1, 3), lb=lo_box, ub=hi_box)
    for i in range(n + 1):
        anchors = [(p0[:2], float(i) * reach), (feet[sides[n]], float(n - i) * reach)]
        if i <= n - 1:
            anchors.append((feet[sides[n - 1]], float(n - 1 - i) * reach))
        if options.swing_max is not None and i >= 1:
            home = p0[:2] if i % 2 == 0 else swing_from
            goal_i = n if (n - i) % 2 == 0 else n - 1
            anchors.append((home, math.ceil(i / 2) * options.swing_max))
            anchors.append((feet[sides[goal_i]], (goal_i - i) // 2 * options.swing_max))
        for j in range(2):
            lo = max(float(centre[j]) - r for centre, r in anchors)
            hi = min(float(centre[j]) + r for centre, r in anchors)
            b.set_bounds(int(p[i, j]), lo, hi)
        b.set_bounds(
            int(p[i, 2]), p0[2] - i * robot.step_height_max, p0[2] + i * robot.step_height_max
        )
    for j in range(3):
        b.set_bounds(int(p[0, j]), float(p0[j]), float(p0[j]))

    # Headings: |theta_i - theta_0| <= i theta_max and |theta_i - theta_goal| <= (N - i) theta_max
    # follow from (5.12e) and the goal heading; the window is one turn around theta_0.
    theta = b.add_vars("theta", (n + 1,))
    for i in range(n + 1):
        span = min(i * robot.theta_max, math.pi)
        to_goal = (n - i) * robot.theta_max
        b.set_bounds(
            int(theta[i]),
            max(theta0 - span, theta_goal - to_goal),
            min(theta0 + span, theta_goal + to_goal),
        )
    s = b.add_vars("s", (n + 1,), lb=-1.0, ub=1.0)
    c = b.add_vars("c", (n + 1,), lb=-1.0, ub=1.0)
    for arr, val in ((s, math.sin(theta0)), (c, math.cos(theta0))):
        b.set_bounds(int(arr[0]), val, val)

    # ALIP states and torques (sparse form).
    pos_b = 1.0  # |CoM - stance| <= 1 m: a leg longer than that is not a biped this models
    mom_b = mzh * options.momentum_bound
    x_lb = np.array([-pos_b, -pos_b, -mom_b, -mom_b])
    shape_x, shape_u = (
        ((n, k_nodes, 4), (n, k_nodes - 1, 2))
        if dynamics
        else ((0, k_nodes, 4), (0, k_nodes - 1, 2))
    )
    x = b.add_vars("x", shape_x, lb=x_lb, ub=-x_lb)
    u = b.add_vars("u", shape_u, lb=-robot.u_max, ub=robot.u_max)
    x_final = b.add_vars(
        "x_final",
        (4 if dynamics else 0,),
        lb=x_lb[: 4 if dynamics else 0],
        ub=-x_lb[: 4 if dynamics else 0],
    )

    # (5.12c) initial state
    for j in range(4 if dynamics else 0):
        b.add_eq({int(x[0, 0, j]): 1.0}, float(start.alip_state[j]), f"5.12c x_init[{j}]")
    # (5.12a) single-support dynamics
    for i in range(n if dynamics else 0):
        for k in range(k_nodes - 1):
            for j in range(4):
                row: dict[int, float] = {int(x[i, k + 1, j]): 1.0}
                for jj in range(4):
                    row[int(x[i, k, jj])] = row.get(int(x[i, k, jj]), 0.0) - ad[j, jj]
                for jj in range(2):
                    row[int(u[i, k, jj])] = row.get(int(u[i, k, jj]), 0.0) - bd[j, jj]
                b.add_eq(row, 0.0, f"5.12a dynamics step {i} node {k} row {j}")
    # (5.12b) reset map onto the next footstep
    for i in range(n if dynamics else 0):
        nxt = x[i + 1, 0] if i + 1 < n else x_final
        for j in range(4):
            row = {int(nxt[j]): 1.0}
            for jj in range(4):
                row[int(x[i, k_nodes - 1, jj])] = -a_r[j, jj]
            for jj in range(3):
                coef = b_r[j, jj]
                if coef != 0.0:
                    row[int(p[i + 1, jj])] = row.get(int(p[i + 1, jj]), 0.0) - coef
                    row[int(p[i, jj])] = row.get(int(p[i, jj]), 0.0) + coef
            b.add_eq(row, 0.0, f"5.12b reset {i}->{i + 1} row {j}")
    # (5.12d) torque bound
    for i in range(n if dynamics else 0):
        for k in range(k_nodes - 1):
            b.add_cone(u[i, k], robot.u_max)
    # (5.12e) heading rate
    for i in range(n):
        b.add_le({int(theta[i + 1]): 1.0, int(theta[i]): -1.0}, robot.theta_max, f"5.12e rate {i}")
        b.add_le({int(theta[i + 1]): -1.0, int(theta[i]): 1.0}, robot.theta_max, f"5.12e rate {i}")
    # Step height between consecutive footsteps.
    for i in range(n):
        zi, zn = int(p[i, 2]), int(p[i + 1, 2])
        b.add_le({zn: 1.0, zi: -1.0}, robot.step_height_max, f"step height {i}")
        b.add_le({zn: -1.0, zi: 1.0}, robot.step_height_max, f"step height {i}")

    # (5.12g-h, 5.14) heading segments over [theta0 - pi, theta0 + pi]
    n_seg = options.heading_segments
    breaks = theta0 - math.pi + 2.0 * math.pi * np.arange(n_seg + 1) / n_seg
    half = math.pi / n_seg  # half the segment width
    segments = np.full((n + 1, n_seg), -1, dtype=np.int64)
    for i in range(1, n + 1):
        t_lo, t_hi = b.bounds(int(theta[i]))
        live = [
            ell
            for ell in range(n_seg)
            if breaks[ell + 1] >= t_lo - 1e-12 and breaks[ell] <= t_hi + 1e-12
        ]
        for ell in live:
            segments[i, ell] = int(b.add_binaries(f"S[{i},{ell}]", ())[()])
        b.add_eq({int(segments[i, ell]): 1.0 for ell in live}, 1.0, f"5.12j one segment {i}")
        ti = int(theta[i])
        for ell in live:
            z = int(segments[i, ell])
            phi_a, phi_b = float(breaks[ell]), float(breaks[ell + 1])
            b.add_le_big_m({ti: -1.0}, -phi_a, z, f"5.14a theta_{i} >= phi_{ell}")
            b.add_le_big_m({ti: 1.0}, phi_b, z, f"5.14a theta_{i} <= phi_{ell + 1}")
            for var, fn in ((s, math.sin), (c, math.cos)):
                g_l = (fn(phi_b) - fn(phi_a)) / (phi_b - phi_a)
                h_l = fn(phi_a) - g_l * phi_a
                label = f"5.12{'g' if fn is math.sin else 'h'} step {i} segment {ell}"
                b.add_le_big_m({int(var[i]): 1.0, ti: -g_l}, h_l, z, label)
                b.add_le_big_m({int(var[i]): -1.0, ti: g_l}, -h_l, z, label)

    # (5.12f) reachability of footstep i+1 from footstep i in Rot(theta_i) R_reach(side_i); with
    # ``reach_both_frames`` the same step also in the landing foot's frame Rot(theta_{i+1}).
    frames = (0, 1) if options.reach_both_frames else (0,)
    for i in range(n):
        g_rows, h_rows = robot.reach.halfspaces(sides[i])
        d = {int(p[i + 1, 0]): 1.0, int(p[i, 0]): -1.0}, {int(p[i + 1, 1]): 1.0, int(p[i, 1]): -1.0}
        for f in frames:
            k = i + f  # the footstep whose heading frame holds the step
            if k == 0:
                rot = rot2(theta0)
                for j, (g, h) in enumerate(zip(g_rows, h_rows, strict=True)):
                    a = rot @ g  # (Rot g)^T d = g^T Rot^T d
                    row = _combine(d, a)
                    b.add_le(row, float(h), f"5.12f reach 0 row {j}")
                continue
            for ell in range(n_seg):
                z = int(segments[k, ell])
                if z < 0:
                    continue
                for j, (g, h) in enumerate(zip(g_rows, h_rows, strict=True)):
                    h_eff = float(h) * math.cos(half) if h > 0 else float(h)
                    for phi in (breaks[ell], breaks[ell + 1]):
                        row = _combine(d, rot2(float(phi)) @ g)
                        label = f"5.12f reach {i} frame {k} segment {ell} row {j}"
                        b.add_le_big_m(row, h_eff, z, label)

    # Swing bound (beyond the document, option ``swing_max``): footstep i within L_swing of the
    # same foot's previous position, through the rows of the inscribed SWING_SIDES-gon.
    if options.swing_max is not None:
        m_sides = SWING_SIDES
        rhs = options.swing_max * math.cos(math.pi / m_sides)
        for i in range(1, n + 1):
            for j in range(m_sides):
                phi = 2.0 * math.pi * j / m_sides
                nx, ny = math.cos(phi), math.sin(phi)
                row = {int(p[i, 0]): nx, int(p[i, 1]): ny}
                if i >= 2:
                    row[int(p[i - 2, 0])] = -nx
                    row[int(p[i - 2, 1])] = -ny
                    b.add_le(row, rhs, f"swing {i} row {j}")
                else:  # the first swing starts at the scene's start position of that foot
                    b.add_le(row, rhs + nx * swing_from[0] + ny * swing_from[1], f"swing 1 row {j}")

    # (5.12i-k) region assignment for footsteps 1..N. A region whose bounding box misses the
    # footstep's bounds can never hold it, so it gets no binary (H fixed to 0).
    regions = np.full((n + 1, len(terrain)), -1, dtype=np.int64)
    for i in range(1, n + 1):
        box = [b.bounds(int(p[i, j])) for j in range(3)]
        for r_idx, region in enumerate(terrain):
            corners = region.vertices3d
            if all(
                corners[:, j].min() <= box[j][1] + 1e-9 and corners[:, j].max() >= box[j][0] - 1e-9
                for j in range(3)
            ):
                regions[i, r_idx] = int(b.add_binaries(f"H[{i},{region.name}]", ())[()])
        live = [int(v) for v in regions[i] if v >= 0]
        if not live:  # no region near enough: keep the model well formed, it is infeasible
            live = [int(b.add_vars(f"H[{i},none]", (), 0.0, 0.0)[()])]
        b.add_eq(dict.fromkeys(live, 1.0), 1.0, f"5.12j one region {i}")
        pv = [int(p[i, j]) for j in range(3)]
        for r_idx, region in enumerate(terrain):
            z = int(regions[i, r_idx])
            if z < 0:
                continue
            a_pl, b_pl = region.plane_rows()  # eq. 5.17
            for row_a, row_b in zip(a_pl, b_pl, strict=True):
                b.add_le_big_m(
                    dict(zip(pv, map(float, row_a), strict=True)), float(row_b), z,
                    f"5.17 plane {region.name} step {i}",
                )  # fmt: skip
            a_poly, b_poly = region.halfspaces()  # eq. 5.18, unit outward normals
            b_poly = b_poly - options.region_margin
            for row_a, row_b in zip(a_poly, b_poly, strict=True):
                b.add_le_big_m(
                    dict(zip(pv[:2], map(float, row_a), strict=True)), float(row_b), z,
                    f"5.18 polygon {region.name} step {i}",
                )  # fmt: skip

    # Goal: the last two footsteps stand at the goal pose.
    for i in (n - 1, n):
        for j in range(2):
            b.add_eq({int(p[i, j]): 1.0}, float(feet[sides[i]][j]), f"goal footstep {i}")
        b.add_eq({int(theta[i]): 1.0}, theta_goal, f"goal heading {i}")
    # x_goal: at rest with the CoM at the goal midpoint, relative to footstep N.
    mid_rel = scene.goal.position[:2] - feet[sides[n]]
    x_goal = np.array([mid_rel[0], mid_rel[1], 0.0, 0.0])

    # Objective (5.11)
    for i in range(n if dynamics else 0):
        for k in range(k_nodes - 1):
            for j in range(2):
                b.add_square({int(u[i, k, j]): 1.0}, 0.0, w.torque, "torque")
    q_x = w.terminal_diag(robot)
    for j in range(4 if dynamics else 0):
        b.add_square({int(x_final[j]): 1.0}, float(x_goal[j]), w.terminal * q_x[j], "terminal")
    for i in range(n - 1):
        b.add_square(
            {int(theta[i + 2]): 1.0, int(theta[i + 1]): -2.0, int(theta[i]): 1.0}, 0.0, w.heading,
            "heading",
        )  # fmt: skip
    for i in range(n):
        for j in range(3):
            b.add_square(
                {int(p[i + 1, j]): 1.0, int(p[i, j]): -1.0}, 0.0, w.step * w.step_matrix[j], "step"
            )

    return FootstepProblem(
        problem=b.build(),
        scene=scene,
        robot=robot,
        n_steps=n,
        options=options,
        sides=sides,
        p=p,
        theta=theta,
        s=s,
        c=c,
        x=x,
        u=u,
        x_final=x_final,
        regions=regions,
        segments=segments,
        breakpoints=breaks,
        x_goal=x_goal,
    )


def _combine(d: tuple[dict[int, float], dict[int, float]], a: FloatArray) -> dict[int, float]:
    """Linear expression ``a[0] d_x + a[1] d_y`` for ``d`` given as two linear expressions."""
    row: dict[int, float] = {}
    for expr, coef in zip(d, a, strict=True):
        for k, v in expr.items():
            row[k] = row.get(k, 0.0) + float(coef) * v
    return row


def extract_plan(fp: FootstepProblem, x: FloatArray, **meta: Any) -> FootstepPlan:
    """Read a :class:`FootstepPlan` out of a solution vector of ``fp.problem``."""
    names = fp.scene.terrain.names
    regions = [fp.scene.start_regions()[fp.sides[0]]]
    for i in range(1, fp.n_steps + 1):
        live = np.flatnonzero(fp.regions[i] >= 0)
        regions.append(names[int(live[np.argmax(x[fp.regions[i, live]])])])
    return FootstepPlan(
        planner="miqcqp",
        robot=fp.robot,
        footsteps=x[fp.p],
        headings=x[fp.theta],
        sides=fp.sides,
        regions=tuple(regions),
        states=x[fp.x],
        torques=x[fp.u],
        final_state=x[fp.x_final],
        sin_cos=np.stack([x[fp.s], x[fp.c]], axis=1),
        region_margin=fp.options.region_margin,
        reach_both_frames=fp.options.reach_both_frames,
        swing_max=fp.options.swing_max,
        heading_segments=fp.options.heading_segments,
        **meta,
    )


def solver_failure_message(result: Any) -> str:
    """Why a solve that ended without a plan and without a proof of infeasibility did so."""
    stats = result.stats
    failed = stats.get("failed_nodes") or {}
    if not failed:
        return f"solver {result.solver} failed: {stats.get('raw_status')}"
    counts = ", ".join(f"{n} x {status or 'unknown'}" for status, n in sorted(failed.items()))
    return (
        f"no plan found, and infeasibility not proven: {sum(failed.values())} of "
        f"{stats.get('nodes', '?')} node relaxations could not be solved by Clarabel ({counts}); "
        f"try another N, or solver='scip'"
    )


def plan_footsteps(
    scene: Scene,
    robot: BipedParams | None = None,
    n_steps: int = 8,
    options: PlannerOptions | None = None,
) -> FootstepPlan:
    """Plan ``n_steps`` footsteps with the full-horizon MIQCQP (document 000, section 5.3).

    Returns:
        A :class:`FootstepPlan`; its status says whether it is optimal (within the gap), a
        time-limited incumbent, or infeasible (with a diagnosis in ``message``).
    """
    from footfall.planning.diagnose import diagnose_infeasible, geometric_infeasibility

    options = options or PlannerOptions()
    fp = build_footstep_problem(scene, robot, n_steps, options)
    early = geometric_infeasibility(
        scene, fp.robot, n_steps, options.region_margin, options.swing_max
    )
    if early is not None:
        # proven by geometry: no search (a branch and bound can take longer than any limit)
        return FootstepPlan.empty(
            "miqcqp", SolveStatus.INFEASIBLE, fp.robot, early, solver=options.solver
        )
    if fp.problem.bounds_conflict():
        # The bounds implied by reach, heading rate and goal already contradict each other.
        return FootstepPlan.empty(
            "miqcqp",
            SolveStatus.INFEASIBLE,
            fp.robot,
            diagnose_infeasible(scene, fp.robot, n_steps, options.region_margin, options.swing_max),
            solver=options.solver,
        )
    result = solve(fp.problem, options.solver, options.solver_options())
    meta = result_meta(result)
    if result.x is None:
        if result.status is SolveStatus.INFEASIBLE:
            message = diagnose_infeasible(
                scene, fp.robot, n_steps, options.region_margin, options.swing_max
            )
        elif result.status is SolveStatus.TIME_LIMIT:
            message = f"no feasible plan found within the time limit of {options.time_limit:g} s"
        else:
            message = solver_failure_message(result)
        return FootstepPlan.empty("miqcqp", robot=fp.robot, message=message, **meta)
    message = {
        SolveStatus.OPTIMAL: f"optimal within gap {options.gap:g}",
        SolveStatus.TIME_LIMIT: f"time limit reached; best plan has gap {result.gap:.3g}",
        SolveStatus.FEASIBLE: f"feasible plan, gap {result.gap:.3g}",
    }.get(result.status, "")
    return extract_plan(fp, result.x, message=message, **meta)
