"""Independent checker of footstep plans.

It shares no code path with the planners: regions are tested with cross products on the region
corners (not the planner's half-space rows), the plane height with a normal recomputed from the
3-D corners (Newell's formula over every edge), reachability by rotating the step into the stance
frame with the true sin/cos and testing the trapezoid corners, and the ALIP states are
re-simulated by integrating the CoM dynamics about the centre of pressure with scipy's
``solve_ivp`` (not the ZOH / reset matrices).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

from footfall._typing import FloatArray
from footfall.errors import InputError, SolverError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.solvers.base import SolveStatus
from footfall.terrain.scene import Scene

#: geometric tolerance [m]
GEOM_TOL = 1e-5
#: heading tolerance [rad]
ANGLE_TOL = 1e-6
#: ALIP state tolerance (mixed units: m and kg m^2/s, states are O(0.1 .. 10))
STATE_TOL = 1e-4
#: relative tolerance on the torque bound
TORQUE_RTOL = 1e-6
#: intervals of the ALIP re-simulation integrated together in one solve_ivp call
BATCH = 64


@dataclass(frozen=True)
class Violation:
    """One failed check: ``kind`` (e.g. ``region``), the footstep/phase ``step``, by how much."""

    kind: str
    step: int
    amount: float
    message: str

    def describe(self) -> str:
        """One line: the kind, the footstep (``step`` -1: the whole plan), the amount, the message.

        The amount is in the kind's unit: m for geometry, rad for headings, N m for torques, the
        state's mixed units for dynamics."""
        where = "the whole plan" if self.step < 0 else f"footstep {self.step}"
        return f"{self.kind} at {where} (amount {self.amount:.3g}): {self.message}"


@dataclass(frozen=True)
class CheckReport:
    """Result of :func:`check_plan`.

    Attributes:
        violations: every failed check.
        dynamics_error: largest difference between the plan's ALIP states and the re-simulation.
        checked: names of the checks that ran.
    """

    violations: tuple[Violation, ...]
    dynamics_error: float
    checked: tuple[str, ...] = field(default=())

    @property
    def ok(self) -> bool:
        """True when nothing is violated."""
        return not self.violations

    def kinds(self) -> set[str]:
        """Kinds of the violations."""
        return {v.kind for v in self.violations}

    def summary(self) -> str:
        """One line per violation (:meth:`Violation.describe`), or "ok"."""
        if self.ok:
            return "ok"
        return "\n".join(v.describe() for v in self.violations)


#: the checker's violations a planner's own output has by design: the kinematic planner has no
#: torque bound (eq. 5.12d), and a reactive walk that stops short (``incomplete``) misses the goal
BY_DESIGN: dict[str, frozenset[str]] = {"kinematic": frozenset({"torque"})}


def unexpected_violations(report: CheckReport, plan: FootstepPlan) -> list[Violation]:
    """The violations of ``report`` (of ``plan``) that its planner does not make by design
    (:data:`BY_DESIGN`): any of them means the plan is not what the planner promises."""
    allowed = BY_DESIGN.get(plan.planner, frozenset())
    if plan.status is SolveStatus.INCOMPLETE:
        allowed |= {"goal"}
    return [v for v in report.violations if v.kind not in allowed]


def _inside_polygon(xy: FloatArray, corners: FloatArray, tol: float) -> float:
    """Largest outward violation [m] of ``xy`` against a convex polygon given by its corners.

    Uses the sign of cross products along the boundary in whichever orientation the corners have.
    """
    n = corners.shape[0]
    area2 = sum(
        corners[k, 0] * corners[(k + 1) % n, 1] - corners[(k + 1) % n, 0] * corners[k, 1]
        for k in range(n)
    )
    orient = 1.0 if area2 > 0 else -1.0
    worst = -math.inf
    for k in range(n):
        a, b = corners[k], corners[(k + 1) % n]
        edge = b - a
        cross = edge[0] * (xy[1] - a[1]) - edge[1] * (xy[0] - a[0])
        worst = max(worst, -orient * cross / float(np.hypot(*edge)))
    return worst


def _plane_height(corners3d: FloatArray, xy: FloatArray) -> float:
    """Height [m] at ``xy`` of the plane through a planar polygon's 3-D corners (V, 3).

    The normal is Newell's: the sum over every edge of the cross products of consecutive corners
    (twice the vector area of the polygon), which collinear corners (a height map's outlines keep
    some) do not degenerate; three corners alone give a zero or noise-sized normal when they lie
    on a line. Its vertical component is twice the polygon's horizontal area, never 0 for a
    region."""
    p = np.asarray(corners3d, dtype=float)
    q = np.roll(p, -1, axis=0)
    normal = np.sum(np.cross(p, q), axis=0)
    centre = p.mean(axis=0)
    dx, dy = xy[0] - centre[0], xy[1] - centre[1]
    return float(centre[2] - (normal[0] * dx + normal[1] * dy) / normal[2])


def _simulate_single_support(
    robot: BipedParams, x0: FloatArray, torque: FloatArray, duration: float
) -> FloatArray:
    """Integrate c'' = g/z_H (c - cop) with the CoP of a constant ankle torque; ALIP in and out."""
    cop = np.array([-torque[1], torque[0]]) / (robot.mass * robot.g)
    return _integrate(robot, x0[None, :], cop[None, :], np.zeros((1, 2)), duration)[0]


def _integrate(
    robot: BipedParams,
    x0: FloatArray,
    cop0: FloatArray,
    cop_rate: FloatArray,
    duration: float,
) -> FloatArray:
    """ALIP states (M, 4) after ``duration`` [s] from ``x0`` (M, 4), each row integrating
    c'' = g/z_H (c - cop(t)) about its own centre of pressure ``cop0 + cop_rate t`` [m].

    The rows are independent; ``BATCH`` of them are integrated together (one ``solve_ivp`` call
    on the stacked system, so a plan of any length takes a few calls: solve_ivp's error norm is
    the RMS over the stacked components, still orders of magnitude below ``STATE_TOL``)."""
    mzh = robot.mass * robot.com_height
    omega2 = robot.g / robot.com_height
    start = np.concatenate([x0[:, :2], np.stack([x0[:, 3], -x0[:, 2]], axis=1) / mzh], axis=1)
    out = np.empty_like(start)
    for lo in range(0, start.shape[0], BATCH):
        rows = slice(lo, lo + BATCH)
        c0, rate = cop0[rows], cop_rate[rows]

        def f(t: float, y: FloatArray, c0: FloatArray = c0, rate: FloatArray = rate) -> FloatArray:
            s = y.reshape(-1, 4)
            acc = omega2 * (s[:, :2] - c0 - rate * t)
            return np.concatenate([s[:, 2:], acc], axis=1).ravel()

        sol = solve_ivp(f, (0.0, duration), start[rows].ravel(), rtol=1e-10, atol=1e-12)
        if not sol.success:
            raise SolverError(f"the re-simulation of the ALIP dynamics failed: {sol.message}")
        out[rows] = sol.y[:, -1].reshape(-1, 4)
    return np.stack([out[:, 0], out[:, 1], -mzh * out[:, 3], mzh * out[:, 2]], axis=1)


def _simulate_double_support(
    robot: BipedParams, x_minus: FloatArray, steps: FloatArray
) -> FloatArray:
    """Contact point moving linearly from the old foot to the new one over T_ds; result relative to
    the new foot (the assumption behind eq. 5.10). ``x_minus`` (M, 4), ``steps`` (M, 3) [m]."""
    rate = steps[:, :2] / robot.t_ds
    end = _integrate(robot, x_minus, np.zeros_like(rate), rate, robot.t_ds)
    end[:, :2] -= steps[:, :2]
    return end


def check_plan(plan: FootstepPlan, scene: Scene, robot: BipedParams | None = None) -> CheckReport:
    """Check every constraint of the planning problem on ``plan``, independently of the planners.

    Checks: start pose and state, regions (inside polygon and on the plane), reachability with the
    true sin/cos (in both feet's frames when the plan was made so), step height, the swing length
    (when the plan was made with ``swing_max``), heading rate, torque bound, ALIP dynamics and
    resets (re-simulated), and the goal (last two footsteps at the goal pose).
    """
    if not isinstance(plan, FootstepPlan):
        raise InputError("plan", plan, "a FootstepPlan (make_plan, load_plan)")
    if not isinstance(scene, Scene):
        raise InputError("scene", scene, "a Scene (footfall.terrain.resolve_scene)")
    if robot is not None and not isinstance(robot, BipedParams):
        raise InputError("robot", robot, "a BipedParams or None")
    robot = robot or plan.robot
    if not plan.has_solution:
        return CheckReport((Violation("no_solution", 0, math.inf, plan.message),), math.inf)
    out: list[Violation] = []
    checked = ["start", "region", "reach"]
    out += _check_start(plan, scene)
    out += _check_regions(plan, scene)
    out += _check_reach_and_step_height(plan, robot)
    if plan.swing_max is not None:
        checked.append("swing")
        out += _check_swing(plan, scene)
    checked += ["heading_rate", "torque", "dynamics", "goal"]
    out += _check_heading_rate(plan, robot)
    out += _check_torque(plan, robot)
    dynamics, worst = _check_dynamics(plan, scene, robot)
    out += dynamics
    out += _check_goal(plan, scene, robot)
    return CheckReport(tuple(out), worst, tuple(checked))


def _check_start(plan: FootstepPlan, scene: Scene) -> list[Violation]:
    """Footstep 0 is the scene's stance foot at its heading; the feet alternate."""
    out = []
    start = scene.start
    d0 = float(np.max(np.abs(plan.footsteps[0] - start.foot(start.stance))))
    if d0 > GEOM_TOL or plan.sides[0] is not start.stance:
        out.append(Violation("start", 0, d0, "footstep 0 is not the given stance foot"))
    if abs(plan.headings[0] - start.heading) > ANGLE_TOL:
        out.append(
            Violation("start", 0, abs(plan.headings[0] - start.heading), "heading 0 differs")
        )
    for i in range(1, plan.n_steps + 1):
        if plan.sides[i] is plan.sides[i - 1]:
            out.append(Violation("alternation", i, 1.0, "two consecutive steps with the same foot"))
    return out


def _check_regions(plan: FootstepPlan, scene: Scene) -> list[Violation]:
    """Every footstep inside its region's polygon (by the plan's margin) and on its plane."""
    out = []
    feet = plan.footsteps
    by_name = {r.name: r for r in scene.terrain}
    for i in range(1, plan.n_steps + 1):
        region = by_name.get(plan.regions[i])
        if region is None:
            out.append(Violation("region", i, math.inf, f"unknown region {plan.regions[i]!r}"))
            continue
        corners = region.vertices3d
        # distance outside the polygon, plus the margin the plan promised to keep
        outside = _inside_polygon(feet[i, :2], corners[:, :2], GEOM_TOL) + plan.region_margin
        if outside > GEOM_TOL:
            msg = f"{outside:.2e} m outside {region.name} (margin {plan.region_margin:g} m)"
            out.append(Violation("region", i, outside, msg))
        dz = abs(feet[i, 2] - _plane_height(corners, feet[i, :2]))
        if dz > GEOM_TOL:
            out.append(Violation("region", i, dz, f"{dz:.2e} m off the plane of {region.name}"))
    return out


def _check_reach_and_step_height(plan: FootstepPlan, robot: BipedParams) -> list[Violation]:
    """Each step in the stance foot's reach trapezoid (eq. 5.12f; also in the landing foot's frame
    when the plan was made so), with the true sin/cos of the heading; the step-height bound."""
    out = []
    feet = plan.footsteps
    for i in range(plan.n_steps):
        d = feet[i + 1, :2] - feet[i, :2]
        corners = np.array(robot.reach.vertices, dtype=float)  # for a right stance foot
        if plan.sides[i] is Side.LEFT:
            corners = corners * np.array([1.0, -1.0])
        for k in (i, i + 1) if plan.reach_both_frames else (i,):
            th = plan.headings[k]
            q = np.array(
                [
                    math.cos(th) * d[0] + math.sin(th) * d[1],
                    -math.sin(th) * d[0] + math.cos(th) * d[1],
                ]
            )
            outside = _inside_polygon(q, corners, GEOM_TOL)
            if outside > GEOM_TOL:
                frame = "" if k == i else " in the landing foot's frame"
                msg = f"{outside:.2e} m outside the reach set{frame}"
                out.append(Violation("reach", i + 1, outside, msg))
        dz = abs(feet[i + 1, 2] - feet[i, 2])
        if dz > robot.step_height_max + GEOM_TOL:
            out.append(Violation("step_height", i + 1, dz, f"step height {dz:.3f} m"))
    return out


def _check_swing(plan: FootstepPlan, scene: Scene) -> list[Violation]:
    """Beyond the document: each foot's horizontal swing from its previous foothold (the scene's
    start position for the first swing of each foot), against the true disc of ``swing_max``."""
    assert plan.swing_max is not None
    out = []
    feet = plan.footsteps
    for i in range(1, plan.n_steps + 1):
        prev = feet[i - 2, :2] if i >= 2 else scene.start.foot(plan.sides[i])[:2]
        length = float(np.hypot(*(feet[i, :2] - prev)))
        if length > plan.swing_max + GEOM_TOL:
            msg = f"swing of {length:.3f} m, longer than {plan.swing_max:g} m"
            out.append(Violation("swing", i, length - plan.swing_max, msg))
    return out


def _check_heading_rate(plan: FootstepPlan, robot: BipedParams) -> list[Violation]:
    """``|theta_{i+1} - theta_i| <= theta_max`` (eq. 5.12e)."""
    rates = np.abs(np.diff(plan.headings))
    return [
        Violation("heading_rate", i + 1, float(r), f"heading change {r:.4f} rad")
        for i, r in enumerate(rates)
        if r > robot.theta_max + ANGLE_TOL
    ]


def _check_torque(plan: FootstepPlan, robot: BipedParams) -> list[Violation]:
    """``||u|| <= U_max`` (eq. 5.12d)."""
    norms = np.linalg.norm(plan.torques, axis=-1)
    if norms.size and norms.max() > robot.u_max * (1 + TORQUE_RTOL):
        i = int(np.argmax(norms.max(axis=1)))
        return [Violation("torque", i, float(norms.max()), f"|u| = {norms.max():.3f} N m")]
    return []


def _check_dynamics(
    plan: FootstepPlan, scene: Scene, robot: BipedParams
) -> tuple[list[Violation], float]:
    """The initial ALIP state is the scene's, and every node and reset matches a re-simulation
    (eq. 5.12a-c integrated with ``solve_ivp``); returns the violations and the largest error."""
    out = []
    worst = 0.0
    x_init_err = float(np.max(np.abs(plan.states[0, 0] - scene.start.alip_state)))
    if x_init_err > STATE_TOL:
        out.append(Violation("dynamics", 0, x_init_err, "initial state differs from the scene's"))
    n = plan.n_steps
    if plan.states.shape[:2] != (n, robot.n_nodes):
        shape = plan.states.shape[:2]
        msg = f"ALIP states for {shape[0]} supports of {shape[1]} nodes, not {n} of {robot.n_nodes}"
        return [*out, Violation("dynamics", -1, math.inf, msg)], math.inf
    # every single-support interval (N (K - 1) of them) and every reset (N) in a few stacked calls
    x0 = plan.states[:, :-1].reshape(-1, 4)
    u = plan.torques.reshape(-1, 2)
    cop = np.stack([-u[:, 1], u[:, 0]], axis=1) / (robot.mass * robot.g)
    sim = _integrate(robot, x0, cop, np.zeros_like(cop), robot.node_dt)
    if sim.size:
        worst = max(worst, float(np.max(np.abs(sim - plan.states[:, 1:].reshape(-1, 4)))))
    nxt = np.concatenate([plan.states[1:, 0], plan.final_state[None, :]])[:n]
    steps = np.diff(plan.footsteps, axis=0)[:n]
    sim = _simulate_double_support(robot, plan.states[:, -1], steps)
    if sim.size:
        worst = max(worst, float(np.max(np.abs(sim - nxt))))
    if worst > STATE_TOL:
        msg = f"ALIP states differ from simulation by {worst:.2e}"
        out.append(Violation("dynamics", -1, worst, msg))
    return out, worst


def _check_goal(plan: FootstepPlan, scene: Scene, robot: BipedParams) -> list[Violation]:
    """The last two footsteps at their goal spots (the goal midpoint -/+ half the stance width)
    and at the goal heading."""
    out = []
    th_goal = scene.goal.heading
    left_normal = np.array([-math.sin(th_goal), math.cos(th_goal)])
    n = plan.n_steps
    for i in (n - 1, n):
        want = scene.goal.position[:2] + plan.sides[i].sign * 0.5 * robot.stance_width * left_normal
        err = float(np.linalg.norm(plan.footsteps[i, :2] - want))
        if err > GEOM_TOL:
            out.append(Violation("goal", i, err, f"footstep {i} is {err:.3f} m from its goal spot"))
        dth = abs((plan.headings[i] - th_goal + math.pi) % (2 * math.pi) - math.pi)
        if dth > ANGLE_TOL * 10:
            out.append(Violation("goal", i, dth, f"footstep {i} heading off by {dth:.4f} rad"))
    return out
