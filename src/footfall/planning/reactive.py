"""Reactive baseline: one-step-ahead ALIP foot placement toward the goal (no horizon).

At every step the planner looks one step ahead from the current ALIP state: it chooses the next
footstep, and the ankle torques of the current single support, so that the angular momentum at
the end of the next single support is as close as possible to a desired value (the
angular-momentum foot placement of Gong & Grizzle): forward ``L_y = m z_H v_des`` toward the goal
and the lateral ``L_x`` of a periodic gait of the nominal stance width. The footstep is restricted
to points that are reachable and lie on a terrain region (a small mixed-integer QP: the ideal
placement snapped into the reachable regions), and the heading turns toward the goal by at most
theta_max per step. When both goal feet are within reach, the last two footsteps go there.

Stopping: the aimed speed is at most the distance to the goal over ``BRAKE_TIME``, the step onto
the first goal foot still aims at that slowed momentum, and the last phase brings the divergent
component of motion (DCM, ``c + v / omega``) after the final reset to the goal midpoint, where
the robot can stand. Without the braking, one final stance with a small ankle (the MuJoCo biped's
11.8 N m) could not absorb a 0.5 m/s walk and the plan ended with the DCM 25-28 cm off the feet.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from footfall._geometry import rot2
from footfall._typing import FloatArray, IntArray
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan, goal_feet, wrap_near
from footfall.solvers import ProblemBuilder, SolverOptions, SolveStatus, solve
from footfall.terrain.scene import Scene

#: nominal forward walking speed of the reactive planner [m/s]
NOMINAL_SPEED = 0.5
#: weight of the final state's momentum (as a velocity [m/s]) beside its DCM error [m]
REST_MOMENTUM_WEIGHT = 0.1
#: the aimed speed is at most the distance to the goal over this time [s]
BRAKE_TIME = 1.5


@dataclass(frozen=True)
class _Goal:
    """What the next footstep of :func:`_one_step` aims at: the ALIP angular momentum ``l_des``
    (2,) [kg m^2/s] at the end of the next single support, a fixed ``target`` (2,) [m], or both;
    with ``rest_at`` (2,) [m] the DCM of the state after the reset onto the new foot is pulled to
    that point (and its momentum, lightly, to 0)."""

    l_des: FloatArray | None = None
    target: FloatArray | None = None
    rest_at: FloatArray | None = None


def _one_step(
    scene: Scene,
    robot: BipedParams,
    x0: FloatArray,
    stance: FloatArray,
    heading: float,
    side: Side,
    goal: _Goal,
    region_margin: float = 0.0,
) -> tuple[FloatArray, str, FloatArray, FloatArray] | None:
    """One-step-ahead choice of the next footstep and the current phase's ankle torques.

    Minimises the error of the ALIP angular momentum at the end of the *next* single support
    (assuming zero torque there) against ``goal.l_des`` (or, with ``goal.target``, the distance of
    the footstep to it), plus the torque effort, over footsteps that are reachable from the
    ``side`` stance foot (true rotation: the heading is known) and lie on a region (a small
    mixed-integer QP, solved by the ``bnb`` backend).

    Returns:
        ``(footstep (3,), region, states (K, 4), torques (K-1, 2))`` or None when nothing is
        reachable.
    """
    b = ProblemBuilder()
    lo, hi = scene.terrain.bounds()
    p = b.add_vars("p", (3,), lb=lo, ub=hi)
    x, u = _add_phase(b, robot, x0)
    _add_reach(b, robot, p, stance, heading, side)
    h_vars = _add_regions(b, scene, p, region_margin)
    _add_step_cost(b, robot, p, x, stance, goal)
    for k in range(robot.n_nodes - 1):
        for j in range(2):
            b.add_square({int(u[k, j]): 1.0}, 0.0, 1e-4, "torque")
    # The momentum error can be driven to ~0, where only an absolute gap can close.
    res = solve(b.build(), "bnb", SolverOptions(time_limit=10.0, gap=1e-6, abs_gap=1e-8))
    if res.x is None:
        return None
    names = scene.terrain.names
    return res.x[p], names[int(np.argmax(res.x[h_vars]))], res.x[x], res.x[u]


def _add_phase(b: ProblemBuilder, robot: BipedParams, x0: FloatArray) -> tuple[IntArray, IntArray]:
    """The current single support: states (K, 4) from ``x0`` under the ALIP dynamics (eq. 5.12a)
    with torques (K - 1, 2) in the ``U_max`` disc (eq. 5.12d); returns their variable indices."""
    k_nodes = robot.n_nodes
    ad, bd = robot.alip().discretize(robot.node_dt)
    x = b.add_vars("x", (k_nodes, 4))
    u = b.add_vars("u", (k_nodes - 1, 2), lb=-robot.u_max, ub=robot.u_max)
    for j in range(4):
        b.add_eq({int(x[0, j]): 1.0}, float(x0[j]), "initial state")
    for k in range(k_nodes - 1):
        b.add_cone(u[k], robot.u_max)
        for j in range(4):
            row = {int(x[k + 1, j]): 1.0}
            row.update({int(x[k, jj]): -ad[j, jj] for jj in range(4) if ad[j, jj] != 0.0})
            row.update({int(u[k, jj]): -bd[j, jj] for jj in range(2) if bd[j, jj] != 0.0})
            b.add_eq(row, 0.0, "dynamics")
    return x, u


def _add_reach(
    b: ProblemBuilder,
    robot: BipedParams,
    p: IntArray,
    stance: FloatArray,
    heading: float,
    side: Side,
) -> None:
    """The footstep ``p`` in the reach trapezoid of the stance foot at its known heading
    (eq. 5.12f, exact rotation) and within the step-height bound."""
    g_rows, h_rows = robot.reach.halfspaces(side)
    rot = rot2(heading)
    for g, h in zip(g_rows, h_rows, strict=True):
        a = rot @ g
        row = {int(p[0]): float(a[0]), int(p[1]): float(a[1])}
        b.add_le(row, float(h + a @ stance[:2]), "reach")
    b.add_le({int(p[2]): 1.0}, float(stance[2] + robot.step_height_max), "step height")
    b.add_le({int(p[2]): -1.0}, float(robot.step_height_max - stance[2]), "step height")


def _add_regions(b: ProblemBuilder, scene: Scene, p: IntArray, region_margin: float) -> list[int]:
    """One region per footstep with its plane and polygon rows under big-M (eq. 5.12i-j,
    5.15-5.18); returns the region binaries in terrain order."""
    h_vars = [int(b.add_binaries(f"H[{r.name}]", ())[()]) for r in scene.terrain]
    b.add_eq(dict.fromkeys(h_vars, 1.0), 1.0, "one region")
    for z, region in zip(h_vars, scene.terrain, strict=True):
        a_poly, b_poly = region.halfspaces()
        for rows, rhs, dim in ((*region.plane_rows(), 3), (a_poly, b_poly - region_margin, 2)):
            for ra, rb in zip(rows, rhs, strict=True):
                row = {int(p[j]): float(ra[j]) for j in range(dim)}
                b.add_le_big_m(row, float(rb), z, region.name)
    return h_vars


def _add_step_cost(
    b: ProblemBuilder,
    robot: BipedParams,
    p: IntArray,
    x: IntArray,
    stance: FloatArray,
    goal: _Goal,
) -> None:
    """What the footstep aims at (see :class:`_Goal`): the target position, or the angular
    momentum at the end of the next single support through the reset map (eq. 5.8-5.10); and the
    rest state after the reset."""
    alip = robot.alip()
    k_nodes = robot.n_nodes
    a_r, b_r = alip.reset_map(robot.t_ds)
    mzh = robot.mass * robot.com_height
    if goal.target is not None:
        for j in range(2):
            b.add_eq({int(p[j]): 1.0}, float(goal.target[j]), "target")
    if goal.l_des is not None:
        ad, _ = alip.discretize(robot.node_dt)
        ad_ss = np.linalg.matrix_power(ad, k_nodes - 1)
        # L at the end of the next phase: M_x x_K + M_p (p - stance), M = (ad_ss [A_r, B_r])[2:].
        m_x = (ad_ss @ a_r)[2:]
        m_p = (ad_ss @ b_r)[2:]
        for j in range(2):
            row = {int(x[k_nodes - 1, jj]): float(m_x[j, jj]) for jj in range(4)}
            for jj in range(3):
                if m_p[j, jj] != 0.0:
                    row[int(p[jj])] = row.get(int(p[jj]), 0.0) + float(m_p[j, jj])
            offset = float(m_p[j] @ stance)
            b.add_square(row, float(goal.l_des[j]) + offset, 1.0 / mzh**2, "momentum")
    if goal.rest_at is not None:
        # x+ = A_r x_K + B_r (p - stance) (relative to p). Its divergent component of motion
        # xi = c + v / omega (absolute) goes to ``rest_at``, its momentum to 0 (lighter): with
        # the DCM between the feet the robot can shift its CoM there and stand.
        rows, targets = [], []
        for j in range(4):
            row = {int(x[k_nodes - 1, jj]): float(a_r[j, jj]) for jj in range(4)}
            for jj in range(3):
                coef = float(b_r[j, jj]) + (1.0 if j == jj and j < 2 else 0.0)
                if coef != 0.0:
                    row[int(p[jj])] = row.get(int(p[jj]), 0.0) + coef
            rows.append(row)
            targets.append(float(b_r[j] @ stance) + (float(goal.rest_at[j]) if j < 2 else 0.0))
        k_dcm = 1.0 / (mzh * alip.omega)
        # v_x = L_y / (m z_H), v_y = -L_x / (m z_H)
        for j, (jl, sign) in enumerate(((3, 1.0), (2, -1.0))):
            row = dict(rows[j])
            for key, val in rows[jl].items():
                row[key] = row.get(key, 0.0) + sign * k_dcm * val
            b.add_square(row, targets[j] + sign * k_dcm * targets[jl], 1.0, "rest dcm")
        for j in (2, 3):
            b.add_square(rows[j], targets[j], REST_MOMENTUM_WEIGHT / mzh**2, "rest")


def _periodic_lateral_momentum(robot: BipedParams) -> float:
    """|L_x| [kg m^2/s] at the end of a step of a periodic gait with the nominal stance width
    (Gong & Grizzle's ALIP foot placement)."""
    omega, t_ss = robot.alip().omega, robot.t_ss
    mzh = robot.mass * robot.com_height
    return (
        0.5 * mzh * robot.stance_width * omega * math.sinh(omega * t_ss)
        / (1 + math.cosh(omega * t_ss))
    )  # fmt: skip


def _aim(
    scene: Scene,
    robot: BipedParams,
    stance: FloatArray,
    heading: float,
    side: Side,
    feet_goal: dict[Side, FloatArray],
    theta_goal: float,
) -> tuple[float, _Goal]:
    """The next footstep's heading and aim from the stance foot: turn toward the goal position
    (the goal heading when close) by at most theta_max; step onto the goal feet once they are
    within reach, else aim at the forward and lateral momentum of a nominal gait toward the
    goal. The very last step (the stance foot already on its goal spot) ends at rest."""
    nxt_side = side.other
    to_goal = scene.goal.position[:2] - stance[:2]
    dist = float(np.linalg.norm(to_goal))
    desired_th = math.atan2(to_goal[1], to_goal[0]) if dist > 0.5 else theta_goal
    desired_th = wrap_near(desired_th, heading)
    new_th = heading + max(-robot.theta_max, min(robot.theta_max, desired_th - heading))
    target_goal = feet_goal[nxt_side]
    q_goal = rot2(heading).T @ (target_goal - stance[:2])
    if dist < 0.6 and robot.reach.contains(q_goal, side):
        # Goal feet within reach: step onto them.
        new_th = heading + max(-robot.theta_max, min(robot.theta_max, theta_goal - heading))
        last = bool(np.linalg.norm(stance[:2] - feet_goal[side]) < 1e-6)
        if last:
            return new_th, _Goal(target=target_goal, rest_at=scene.goal.position[:2])
        return new_th, _Goal(
            target=target_goal, l_des=_nominal_momentum(robot, new_th, nxt_side, dist)
        )
    return new_th, _Goal(l_des=_nominal_momentum(robot, new_th, nxt_side, dist))


def _nominal_momentum(
    robot: BipedParams, heading: float, nxt_side: Side, dist: float
) -> FloatArray:
    """(L_x, L_y) [kg m^2/s] to aim at the end of the next single support: the nominal speed,
    slowed down within ``BRAKE_TIME`` of the goal ``dist`` [m] away, and the lateral momentum of
    a periodic gait."""
    mzh = robot.mass * robot.com_height
    speed = min(NOMINAL_SPEED, dist / BRAKE_TIME)
    # At the end of a left stance the CoM moves right (v_y < 0), so L_x = -m z_H v_y > 0;
    # (L_x, L_y) rotates with the heading like a vector.
    lx_mag = _periodic_lateral_momentum(robot)
    return rot2(heading) @ np.array([nxt_side.sign * lx_mag, mzh * speed])


def plan_reactive(
    scene: Scene,
    robot: BipedParams | None = None,
    max_steps: int = 40,
    region_margin: float = 0.0,
) -> FootstepPlan:
    """Walk toward the goal one step at a time (see the module docstring).

    Args:
        scene: terrain, start and goal.
        robot: robot parameters (default ``scene.robot``).
        max_steps: give up after this many footsteps.
        region_margin: keep footsteps this far inside their region's polygon [m].

    Returns:
        A plan with status ``feasible`` when the goal was reached, ``infeasible`` otherwise (the
        partial plan is kept so it can be inspected).
    """
    t0 = time.perf_counter()
    robot = robot or scene.robot
    k = robot.n_nodes
    a_r, b_r = robot.alip().reset_map(robot.t_ds)
    start = scene.start
    theta_goal = wrap_near(scene.goal.heading, start.heading)
    feet_goal = goal_feet(robot, scene.goal.position[:2], theta_goal)

    side = start.stance
    feet = [np.array(start.stance_foot, dtype=float)]
    headings = [float(start.heading)]
    sides = [side]
    regions = [scene.start_regions()[side]]
    states: list[FloatArray] = []
    torques: list[FloatArray] = []
    x = np.array(start.alip_state, dtype=float)
    message = ""

    def at_goal() -> bool:
        # both feet on their goal positions *and* at the goal heading
        return len(feet) >= 2 and all(
            np.linalg.norm(feet[-1 - j][:2] - feet_goal[sides[-1 - j]]) < 1e-6
            and abs(headings[-1 - j] - theta_goal) < 1e-6
            for j in (0, 1)
        )

    while not (reached := at_goal()) and len(feet) <= max_steps:
        stance, th, side = feet[-1], headings[-1], sides[-1]
        new_th, goal = _aim(scene, robot, stance, th, side, feet_goal, theta_goal)
        step = _one_step(scene, robot, x, stance, th, side, goal, region_margin)
        if step is None:
            message = f"no reachable region from footstep {len(feet) - 1}"
            break
        p_next, region, phase_x, phase_u = step
        states.append(phase_x)
        torques.append(phase_u)
        x = a_r @ phase_x[-1] + b_r @ (p_next - stance)
        feet.append(p_next)
        headings.append(new_th)
        sides.append(side.other)
        regions.append(region)
    n = len(feet) - 1
    if reached:
        status, message = SolveStatus.FEASIBLE, f"reached the goal in {n} footsteps"
    else:
        # a greedy planner's failure proves nothing: a horizon planner may still find a plan
        status = SolveStatus.INCOMPLETE
        message = message or f"did not reach the goal within {max_steps} footsteps"
    return FootstepPlan(
        planner="reactive",
        status=status,
        robot=robot,
        footsteps=np.array(feet),
        headings=np.array(headings),
        sides=tuple(sides),
        regions=tuple(regions),
        states=np.array(states) if n else np.zeros((0, k, 4)),
        torques=np.array(torques) if n else np.zeros((0, k - 1, 2)),
        final_state=x if n else np.full(4, np.nan),
        solve_time=time.perf_counter() - t0,
        solver="bnb",
        message=message,
        region_margin=region_margin,
    )
