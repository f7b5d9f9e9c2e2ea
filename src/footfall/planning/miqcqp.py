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
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any

import numpy as np

from footfall._geometry import rot2
from footfall._typing import FloatArray, IntArray
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import (
    SWING_SIDES,
    FootstepPlan,
    PlannerOptions,
    check_n_steps,
    check_planning_arguments,
    goal_feet,
    result_meta,
    wrap_near,
)
from footfall.solvers import ProblemBuilder, SolveStatus, solve
from footfall.solvers.base import SolveProgress, SolverResult, relative_gap
from footfall.solvers.problem import MIQCQP
from footfall.terrain.scene import Scene

if TYPE_CHECKING:
    from footfall.planning.bounds import LiveMembers


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


@dataclass
class _Model:
    """The model of :func:`build_footstep_problem` while it is built: the builder, the problem data
    every group of rows needs, and the variable blocks made so far (see :class:`FootstepProblem`).

    The groups are added in a fixed order (variables, then rows equation by equation), so a
    model's variable and row order, and hence every solver's path through it, is reproducible.
    """

    b: ProblemBuilder
    scene: Scene
    robot: BipedParams
    options: PlannerOptions
    n: int
    dynamics: bool
    sides: tuple[Side, ...]
    theta0: float
    theta_goal: float
    #: horizontal goal positions of the two final feet (2,) [m]
    feet: dict[Side, FloatArray]
    #: footstep 0, the given stance foot (3,) [m]
    p0: FloatArray
    #: start position (2,) [m] of the first swing foot
    swing_from: FloatArray
    p: IntArray = field(default_factory=lambda: np.zeros((0, 3), dtype=np.int64))
    theta: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    s: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    c: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    x: IntArray = field(default_factory=lambda: np.zeros((0, 0, 4), dtype=np.int64))
    u: IntArray = field(default_factory=lambda: np.zeros((0, 0, 2), dtype=np.int64))
    x_final: IntArray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    breaks: FloatArray = field(default_factory=lambda: np.zeros(0))
    segments: IntArray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int64))
    regions: IntArray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int64))


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
    check_planning_arguments(scene, robot, options)
    robot = robot or scene.robot
    options = options or PlannerOptions()
    check_n_steps(n_steps)
    start = scene.start
    theta0 = float(start.heading)
    theta_goal = wrap_near(float(scene.goal.heading), theta0)
    sides = _side_sequence(start.stance, n_steps)
    m = _Model(
        b=ProblemBuilder(),
        scene=scene,
        robot=robot,
        options=options,
        n=n_steps,
        dynamics=dynamics,
        sides=sides,
        theta0=theta0,
        theta_goal=theta_goal,
        feet=goal_feet(robot, scene.goal.position[:2], theta_goal),
        p0=start.foot(start.stance),
        swing_from=start.foot(sides[1])[:2],
    )
    _add_footsteps(m)
    _add_headings(m)
    _add_alip(m)
    _add_heading_rate_and_step_height(m)
    _add_heading_segments(m)
    _add_reach(m)
    _add_swing_bound(m)
    _add_regions(m)
    x_goal = _add_goal(m)
    _add_objective(m, x_goal)
    return FootstepProblem(
        problem=m.b.build(),
        scene=scene,
        robot=robot,
        n_steps=m.n,
        options=options,
        sides=sides,
        p=m.p,
        theta=m.theta,
        s=m.s,
        c=m.c,
        x=m.x,
        u=m.u,
        x_final=m.x_final,
        regions=m.regions,
        segments=m.segments,
        breakpoints=m.breaks,
        x_goal=x_goal,
    )


def _add_footsteps(m: _Model) -> None:
    """Footstep variables ``p_i`` (N + 1, 3) [m], footstep 0 fixed to the stance foot.

    Tight bounds, all implied by the constraints (so the optimum is unchanged): inside the terrain
    box, within i steps of reach of footstep 0 and within N - i (N - 1 - i) of the final footstep
    N (N - 1), whose positions the goal fixes; heights likewise. With ``swing_max`` a foot is also
    within L_swing per swing of its previous and next position of the same foot (its start
    position and its goal spot).
    """
    b, n, robot, p0, feet, sides = m.b, m.n, m.robot, m.p0, m.feet, m.sides
    reach = robot.reach.radius
    swing_max = m.options.swing_max
    lo_box, hi_box = m.scene.terrain.bounds()
    m.p = p = b.add_vars("p", (n + 1, 3), lb=lo_box, ub=hi_box)
    for i in range(n + 1):
        anchors = [(p0[:2], float(i) * reach), (feet[sides[n]], float(n - i) * reach)]
        if i <= n - 1:
            anchors.append((feet[sides[n - 1]], float(n - 1 - i) * reach))
        if swing_max is not None and i >= 1:
            home = p0[:2] if i % 2 == 0 else m.swing_from
            goal_i = n if (n - i) % 2 == 0 else n - 1
            anchors.append((home, math.ceil(i / 2) * swing_max))
            anchors.append((feet[sides[goal_i]], (goal_i - i) // 2 * swing_max))
        for j in range(2):
            lo = max(float(centre[j]) - r for centre, r in anchors)
            hi = min(float(centre[j]) + r for centre, r in anchors)
            b.set_bounds(int(p[i, j]), lo, hi)
        b.set_bounds(
            int(p[i, 2]), p0[2] - i * robot.step_height_max, p0[2] + i * robot.step_height_max
        )
    for j in range(3):
        b.set_bounds(int(p[0, j]), float(p0[j]), float(p0[j]))


def _add_headings(m: _Model) -> None:
    """Headings ``theta_i`` [rad] and their piecewise-linear ``s_i``, ``c_i`` (eq. 5.12g-h).

    ``|theta_i - theta_0| <= i theta_max`` and ``|theta_i - theta_goal| <= (N - i) theta_max``
    follow from (5.12e) and the goal heading; the window is one turn around theta_0.
    """
    b, n, robot, theta0, theta_goal = m.b, m.n, m.robot, m.theta0, m.theta_goal
    m.theta = theta = b.add_vars("theta", (n + 1,))
    for i in range(n + 1):
        span = min(i * robot.theta_max, math.pi)
        to_goal = (n - i) * robot.theta_max
        b.set_bounds(
            int(theta[i]),
            max(theta0 - span, theta_goal - to_goal),
            min(theta0 + span, theta_goal + to_goal),
        )
    m.s = b.add_vars("s", (n + 1,), lb=-1.0, ub=1.0)
    m.c = b.add_vars("c", (n + 1,), lb=-1.0, ub=1.0)
    for arr, val in ((m.s, math.sin(theta0)), (m.c, math.cos(theta0))):
        b.set_bounds(int(arr[0]), val, val)


def _add_alip(m: _Model) -> None:
    """ALIP states ``x_{i,k}`` and torques ``u_{i,k}`` (sparse form) with the initial state
    (5.12c), the single-support dynamics (5.12a), the reset map onto the next footstep (5.12b,
    with the corrected eq. 5.10) and the torque bound (5.12d). Without dynamics the blocks are
    empty."""
    b, n, robot, p = m.b, m.n, m.robot, m.p
    k_nodes = robot.n_nodes
    pos_b = 1.0  # |CoM - stance| <= 1 m: a leg longer than that is not a biped this models
    mom_b = robot.mass * robot.com_height * m.options.momentum_bound
    x_lb = np.array([-pos_b, -pos_b, -mom_b, -mom_b])
    n_dyn, n_final = (n, 4) if m.dynamics else (0, 0)
    m.x = x = b.add_vars("x", (n_dyn, k_nodes, 4), lb=x_lb, ub=-x_lb)
    m.u = u = b.add_vars("u", (n_dyn, k_nodes - 1, 2), lb=-robot.u_max, ub=robot.u_max)
    m.x_final = b.add_vars("x_final", (n_final,), lb=x_lb[:n_final], ub=-x_lb[:n_final])
    alip = robot.alip()
    ad, bd = alip.discretize(robot.node_dt)
    a_r, b_r = alip.reset_map(robot.t_ds)
    for j in range(n_final):  # (5.12c) initial state
        b.add_eq({int(x[0, 0, j]): 1.0}, float(m.scene.start.alip_state[j]), f"5.12c x_init[{j}]")
    for i in range(n_dyn):  # (5.12a) single-support dynamics
        for k in range(k_nodes - 1):
            for j in range(4):
                row: dict[int, float] = {int(x[i, k + 1, j]): 1.0}
                for jj in range(4):
                    row[int(x[i, k, jj])] = row.get(int(x[i, k, jj]), 0.0) - ad[j, jj]
                for jj in range(2):
                    row[int(u[i, k, jj])] = row.get(int(u[i, k, jj]), 0.0) - bd[j, jj]
                b.add_eq(row, 0.0, f"5.12a dynamics step {i} node {k} row {j}")
    for i in range(n_dyn):  # (5.12b) reset map onto the next footstep
        nxt = x[i + 1, 0] if i + 1 < n else m.x_final
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
    for i in range(n_dyn):  # (5.12d) torque bound
        for k in range(k_nodes - 1):
            b.add_cone(u[i, k], robot.u_max)


def _add_heading_rate_and_step_height(m: _Model) -> None:
    """Heading rate ``|theta_{i+1} - theta_i| <= theta_max`` (5.12e) and the step-height bound
    ``|z_{i+1} - z_i| <= step_height_max``."""
    b, robot, theta, p = m.b, m.robot, m.theta, m.p
    for i in range(m.n):
        b.add_le({int(theta[i + 1]): 1.0, int(theta[i]): -1.0}, robot.theta_max, f"5.12e rate {i}")
        b.add_le({int(theta[i + 1]): -1.0, int(theta[i]): 1.0}, robot.theta_max, f"5.12e rate {i}")
    for i in range(m.n):
        zi, zn = int(p[i, 2]), int(p[i + 1, 2])
        b.add_le({zn: 1.0, zi: -1.0}, robot.step_height_max, f"step height {i}")
        b.add_le({zn: -1.0, zi: 1.0}, robot.step_height_max, f"step height {i}")


def _add_heading_segments(m: _Model) -> None:
    """Segment binaries ``S_{l,i}`` over ``[theta0 - pi, theta0 + pi]``: one segment per footstep
    (5.12k), theta in it (5.14) and ``s_i``, ``c_i`` on its chord of sin and cos (5.12g-h).
    Segments outside a footstep's heading bounds get no binary."""
    b, n_seg = m.b, m.options.heading_segments
    m.breaks = breaks = m.theta0 - math.pi + 2.0 * math.pi * np.arange(n_seg + 1) / n_seg
    m.segments = segments = np.full((m.n + 1, n_seg), -1, dtype=np.int64)
    for i in range(1, m.n + 1):
        t_lo, t_hi = b.bounds(int(m.theta[i]))
        live = [
            ell
            for ell in range(n_seg)
            if breaks[ell + 1] >= t_lo - 1e-12 and breaks[ell] <= t_hi + 1e-12
        ]
        for ell in live:
            segments[i, ell] = int(b.add_binaries(f"S[{i},{ell}]", ())[()])
        b.add_eq({int(segments[i, ell]): 1.0 for ell in live}, 1.0, f"5.12j one segment {i}")
        ti = int(m.theta[i])
        for ell in live:
            z = int(segments[i, ell])
            phi_a, phi_b = float(breaks[ell]), float(breaks[ell + 1])
            b.add_le_big_m({ti: -1.0}, -phi_a, z, f"5.14a theta_{i} >= phi_{ell}")
            b.add_le_big_m({ti: 1.0}, phi_b, z, f"5.14a theta_{i} <= phi_{ell + 1}")
            for var, fn in ((m.s, math.sin), (m.c, math.cos)):
                g_l = (fn(phi_b) - fn(phi_a)) / (phi_b - phi_a)
                h_l = fn(phi_a) - g_l * phi_a
                label = f"5.12{'g' if fn is math.sin else 'h'} step {i} segment {ell}"
                b.add_le_big_m({int(var[i]): 1.0, ti: -g_l}, h_l, z, label)
                b.add_le_big_m({int(var[i]): -1.0, ti: g_l}, -h_l, z, label)


def _add_reach(m: _Model) -> None:
    """Reachability (5.12f) of footstep i+1 from footstep i in ``Rot(theta_i) R_reach(side_i)``,
    linear and conservative per heading segment (module docstring); with ``reach_both_frames``
    the same step also in the landing foot's frame ``Rot(theta_{i+1})``."""
    b, p, n_seg, breaks = m.b, m.p, m.options.heading_segments, m.breaks
    half = math.pi / n_seg  # half the segment width
    frames = (0, 1) if m.options.reach_both_frames else (0,)
    for i in range(m.n):
        g_rows, h_rows = m.robot.reach.halfspaces(m.sides[i])
        d = {int(p[i + 1, 0]): 1.0, int(p[i, 0]): -1.0}, {int(p[i + 1, 1]): 1.0, int(p[i, 1]): -1.0}
        for f in frames:
            k = i + f  # the footstep whose heading frame holds the step
            if k == 0:
                rot = rot2(m.theta0)
                for j, (g, h) in enumerate(zip(g_rows, h_rows, strict=True)):
                    a = rot @ g  # (Rot g)^T d = g^T Rot^T d
                    b.add_le(_combine(d, a), float(h), f"5.12f reach 0 row {j}")
                continue
            for ell in range(n_seg):
                z = int(m.segments[k, ell])
                if z < 0:
                    continue
                for j, (g, h) in enumerate(zip(g_rows, h_rows, strict=True)):
                    h_eff = float(h) * math.cos(half) if h > 0 else float(h)
                    for phi in (breaks[ell], breaks[ell + 1]):
                        row = _combine(d, rot2(float(phi)) @ g)
                        label = f"5.12f reach {i} frame {k} segment {ell} row {j}"
                        b.add_le_big_m(row, h_eff, z, label)


def _add_swing_bound(m: _Model) -> None:
    """Beyond the document (option ``swing_max``): footstep i within L_swing of the same foot's
    previous position, through the rows of the inscribed ``SWING_SIDES``-gon."""
    if m.options.swing_max is None:
        return
    b, p = m.b, m.p
    rhs = m.options.swing_max * math.cos(math.pi / SWING_SIDES)
    for i in range(1, m.n + 1):
        for j in range(SWING_SIDES):
            phi = 2.0 * math.pi * j / SWING_SIDES
            nx, ny = math.cos(phi), math.sin(phi)
            row = {int(p[i, 0]): nx, int(p[i, 1]): ny}
            if i >= 2:
                row[int(p[i - 2, 0])] = -nx
                row[int(p[i - 2, 1])] = -ny
                b.add_le(row, rhs, f"swing {i} row {j}")
            else:  # the first swing starts at the scene's start position of that foot
                start = m.swing_from
                b.add_le(row, rhs + nx * start[0] + ny * start[1], f"swing 1 row {j}")


def _add_regions(m: _Model) -> None:
    """Region binaries ``H_{r,i}`` of footsteps 1..N: one region per footstep (5.12j) and, under
    big-M (5.12i), the region's plane rows (5.15-5.17) and polygon rows (5.18, moved in by
    ``region_margin``). A region whose bounding box misses the footstep's bounds can never hold
    it, so it gets no binary (H fixed to 0)."""
    b, p, terrain = m.b, m.p, m.scene.terrain
    m.regions = regions = np.full((m.n + 1, len(terrain)), -1, dtype=np.int64)
    for i in range(1, m.n + 1):
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
                row = dict(zip(pv, map(float, row_a), strict=True))
                b.add_le_big_m(row, float(row_b), z, f"5.17 plane {region.name} step {i}")
            a_poly, b_poly = region.halfspaces()  # eq. 5.18, unit outward normals
            b_poly = b_poly - m.options.region_margin
            for row_a, row_b in zip(a_poly, b_poly, strict=True):
                row = dict(zip(pv[:2], map(float, row_a), strict=True))
                b.add_le_big_m(row, float(row_b), z, f"5.18 polygon {region.name} step {i}")


def _add_goal(m: _Model) -> FloatArray:
    """The last two footsteps stand at the goal pose; returns ``x_goal`` (4,): at rest with the
    CoM at the goal midpoint, relative to footstep N."""
    for i in (m.n - 1, m.n):
        for j in range(2):
            m.b.add_eq({int(m.p[i, j]): 1.0}, float(m.feet[m.sides[i]][j]), f"goal footstep {i}")
        m.b.add_eq({int(m.theta[i]): 1.0}, m.theta_goal, f"goal heading {i}")
    mid_rel = m.scene.goal.position[:2] - m.feet[m.sides[m.n]]
    return np.array([mid_rel[0], mid_rel[1], 0.0, 0.0])


def _add_objective(m: _Model, x_goal: FloatArray) -> None:
    """The objective (5.11): torque effort, terminal state, heading smoothness, step size."""
    b, n, w, p, theta = m.b, m.n, m.options.weights, m.p, m.theta
    for i in range(m.x.shape[0]):
        for k in range(m.robot.n_nodes - 1):
            for j in range(2):
                b.add_square({int(m.u[i, k, j]): 1.0}, 0.0, w.torque, "torque")
    q_x = w.terminal_diag(m.robot)
    for j in range(m.x_final.shape[0]):
        b.add_square({int(m.x_final[j]): 1.0}, float(x_goal[j]), w.terminal * q_x[j], "terminal")
    for i in range(n - 1):
        row = {int(theta[i + 2]): 1.0, int(theta[i + 1]): -2.0, int(theta[i]): 1.0}
        b.add_square(row, 0.0, w.heading, "heading")
    for i in range(n):
        for j in range(3):
            row = {int(p[i + 1, j]): 1.0, int(p[i, j]): -1.0}
            b.add_square(row, 0.0, w.step * w.step_matrix[j], "step")


def _combine(d: tuple[dict[int, float], dict[int, float]], a: FloatArray) -> dict[int, float]:
    """Linear expression ``a[0] d_x + a[1] d_y`` for ``d`` given as two linear expressions."""
    row: dict[int, float] = {}
    for expr, coef in zip(d, a, strict=True):
        for k, v in expr.items():
            row[k] = row.get(k, 0.0) + float(coef) * v
    return row


def restrict_members(fp: FootstepProblem, members: LiveMembers) -> tuple[FootstepProblem, int]:
    """``fp`` with the segment and region binaries that ``members`` rules out fixed to 0 (through
    their upper bounds), and how many were fixed. ``members`` must come from
    :func:`footfall.planning.bounds.live_members` for the same scene, robot, options and N: it
    only rules out members no plan of the model uses, so the feasible set stays the same."""
    shapes = (fp.segments.shape, fp.regions.shape)
    if (members.segments.shape, members.regions.shape) != shapes:
        raise InputError(
            "members", (members.segments.shape, members.regions.shape), f"shapes {shapes}"
        )
    dead = np.concatenate(
        [
            fp.segments[(fp.segments >= 0) & ~members.segments],
            fp.regions[(fp.regions >= 0) & ~members.regions],
        ]
    )
    if len(dead) == 0:
        return fp, 0
    ub = fp.problem.ub.copy()
    ub[dead] = 0.0
    return replace(fp, problem=replace(fp.problem, ub=ub)), len(dead)


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
    solve_progress: Callable[[SolveProgress], None] | None = None,
    members: LiveMembers | None = None,
) -> FootstepPlan:
    """Plan ``n_steps`` footsteps with the full-horizon MIQCQP (document 000, section 5.3).

    ``solve_progress`` is called about once a second while the ``bnb`` backend searches
    (``SolverOptions.progress``). ``members``: the heading segments and regions each footstep
    can use at all (:func:`footfall.planning.bounds.live_members` for these arguments); the
    others are fixed out before the solve (:func:`restrict_members`: same feasible set, smaller
    search; ``stats["members_fixed_out"]`` counts them).

    Returns:
        A :class:`FootstepPlan`; its status says whether it is optimal (within the gap), a
        time-limited incumbent, or infeasible (with a diagnosis in ``message``).
    """
    from footfall.planning.diagnose import geometric_infeasibility

    check_planning_arguments(scene, robot, options)
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
            _model_infeasible(scene, fp.robot, n_steps, options),
            solver=options.solver,
        )
    fixed_out = 0
    if members is not None:
        fp, fixed_out = restrict_members(fp, members)
    solver_options = replace(options.solver_options(), progress=solve_progress)
    result = solve(fp.problem, options.solver, solver_options)
    if members is not None:
        result.stats["members_fixed_out"] = fixed_out
    searched = ""
    if result.x is None and result.status is SolveStatus.TIME_LIMIT and options.heading_windows:
        result, searched = _windows(fp, scene, options, result, solve_progress)
    meta = result_meta(result)
    if result.x is None:
        if result.status is SolveStatus.INFEASIBLE:
            message = _model_infeasible(scene, fp.robot, n_steps, options)
        elif result.status is SolveStatus.TIME_LIMIT:
            message = (
                f"no feasible plan found within the time limit of {options.time_limit:g} s"
                + searched
            )
        else:
            message = solver_failure_message(result)
        return FootstepPlan.empty("miqcqp", robot=fp.robot, message=message, **meta)
    message = {
        SolveStatus.OPTIMAL: f"optimal within gap {options.gap:g}",
        SolveStatus.TIME_LIMIT: f"time limit reached; best plan has gap {result.gap:.3g}",
        SolveStatus.FEASIBLE: f"feasible plan, gap {result.gap:.3g}",
    }.get(result.status, "")
    return extract_plan(fp, result.x, message=message + searched, **meta)


def _windows(
    fp: FootstepProblem,
    scene: Scene,
    options: PlannerOptions,
    result: SolverResult,
    solve_progress: Callable[[SolveProgress], None] | None,
) -> tuple[SolverResult, str]:
    """After a solve that ended at its time limit without a plan: the heading-window search
    (:mod:`footfall.planning.windows`) for as long again, and the message it adds. Its plan is
    returned at status TIME_LIMIT with the solve's bound (valid for the whole model), so the
    gap claims no more than the solve proved."""
    from footfall.planning.windows import heading_window_search

    nodes = int(result.stats.get("nodes", 0))
    after = SolveProgress(nodes, result.solve_time, None, result.bound, math.inf)
    found = heading_window_search(fp, scene, options, options.time_limit, solve_progress, after)
    stats = dict(result.stats)
    if found is None:
        stats["heading_windows"] = {"found": False}
        return replace(result, stats=stats), (
            f"; nor did the heading-window search in {options.time_limit:g} s more"
        )
    stats["heading_windows"] = {
        "found": True,
        "centre": found.centre,
        "width": found.width,
        "tried": found.tried,
        "feasible": found.feasible,
        "seconds": found.seconds,
    }
    lo, hi = max(1, found.centre - found.width), min(fp.n_steps - 2, found.centre + found.width)
    plan_result = replace(
        result,
        x=found.x,
        objective=found.objective,
        gap=relative_gap(found.objective, result.bound),
        solve_time=result.solve_time + found.seconds,
        stats=stats,
    )
    return plan_result, (
        f" (the solve found none in {options.time_limit:g} s; the heading-window search found "
        f"this one with headings free at footsteps {lo}..{hi} only, {found.feasible} of "
        f"{found.tried} windows with a plan)"
    )


def _model_infeasible(
    scene: Scene, robot: BipedParams, n_steps: int, options: PlannerOptions
) -> str:
    """The message of a plan the MIQCQP proved infeasible: infeasible for its model (the
    conservative linear reach with L heading segments), which rules out no other plan."""
    from footfall.planning.diagnose import diagnose_infeasible

    return diagnose_infeasible(
        scene,
        robot,
        n_steps,
        options.region_margin,
        options.swing_max,
        heading_segments=options.heading_segments,
    )
