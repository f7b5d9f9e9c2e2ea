"""The quadruped's whole-body tick packs its QP straight into arrays (sim/quadruped/_wbc_tick.py):
tick by tick on a walk it gives the torques of the problem built the plain way, from the
Contact / MotionTask / WrenchTask dataclasses of control/wbc.py (the reference below, the
controller's tick before the packing was compiled), and its rebuilt ``last_problem`` solves to
its own solution."""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall._geometry import rotation_log  # noqa: E402
from footfall.control.wbc import (  # noqa: E402
    Contact,
    MotionTask,
    WbcProblem,
    WholeBodyController,
    WrenchTask,
)
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.quadruped.ground import VaryingSlope  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim  # noqa: E402
from footfall.sim.quadruped.wbc import QuadrupedWbc, QuadrupedWbcGains, _surface  # noqa: E402

#: fast vs reference torques [N m]: the same algebra, summed in other orders (measured: 1e-9 with
#: the CoP weight at 96 1/m^2, 4.3e-9 at the default 300, whose QP weighs the rounding more;
#: relative 1.4e-10)
TORQUE_TOL = 1e-8


def _touching(sim: QuadrupedSim) -> list[bool]:
    """Which feet touch the ground now (a contact not in the margin, ``dist <= 0``)."""
    con = sim.data.contact
    hit = set(np.asarray(con.geom)[np.asarray(con.dist) <= 0.0].ravel().tolist())
    return [g in hit for g in sim.foot_geoms]


def _since_lift(contact: np.ndarray, times: np.ndarray, near: int, leg: int, t: float) -> float:
    """Time [s] from ``leg``'s last planned lift-off at or before sample ``near`` to ``t``
    (inf: none), searched back through the plan's contacts."""
    for j in range(near, 0, -1):
        if contact[j, leg] == 0 and contact[j - 1, leg] != 0:
            return t - float(times[j])
    return math.inf


def _reference_problem(wbc: QuadrupedWbc, t: float) -> WbcProblem:
    """The tick's problem from the dataclasses, at the state in ``wbc.sim.data``."""
    sim, d, g, ref = wbc.sim, wbc.sim.data, wbc.gains, wbc.ref
    # the CoP's and unload's weights are per m^2 and per share of the weight squared
    weight = float(np.sum(sim.model.body_mass)) * -float(sim.model.opt.gravity[2])
    k, w = ref.at(t)
    near = k if w < 0.5 else k + 1
    row = (1.0 - w) * ref.table[k] + w * ref.table[k + 1]
    body, body_v, body_a = row[0:3], row[3:6], row[6:9]
    feet, feet_v, feet_a = (row[a : a + 12].reshape(4, 3) for a in (9, 21, 33))
    joints, joints_v, zmp, pitch = row[45:57], row[57:69], row[69:71], row[71]
    joints_a = row[72:84]
    qvel = d.qvel
    stance = ref.contact[near]
    # time to each leg's next switch, from the nearer sample
    to_switch = ref.to_switch[near] + (near - k) * ref.dt - w * ref.dt
    touching = _touching(sim)
    contacts, tasks, wrench, heights = [], [], [], []
    early, late, lifted, is_contact = [], [], [], []
    for leg in range(4):
        early.append(touching[leg] and to_switch[leg] <= g.touchdown_window)
        # (from the sample, then the tick's part of the period: the tick's own association;
        # t - t_lift rounds differently, and a hand-over tick's torques follow its weight to 1e-9)
        lift = _since_lift(ref.contact, ref.t, near, leg, ref.t[near])
        lifted.append(lift + w * ref.dt - (near - k) * ref.dt)
        late.append(
            not stance[leg]
            and touching[leg]
            and 0 < g.liftoff_delay
            and lifted[leg] <= g.liftoff_delay
        )
        is_contact.append((stance[leg] and touching[leg]) or early[leg] or late[leg])
    # a foot hands its load over only onto three other contacts
    handing = sum(is_contact) == 4
    for leg in range(4):
        centre = d.site_xpos[sim.foot_sites[leg]]
        if is_contact[leg]:
            normal, tangent = _surface(wbc.ground.normal(centre[0], centre[1]))
            normal_force = np.concatenate([normal, np.zeros(3)]).reshape(1, 6)
            pt = centre - wbc.radius * normal
            jac, drift = wbc.model.frame(wbc.foot_bodies[leg], pt, angular=False)
            name = f"foot{leg}"
            contacts.append(Contact.point(name, jac, drift, pt, normal, wbc.friction, 0.0, tangent))
            heights.append(pt[2])
            if handing and stance[leg] and g.unload_time > 0 and to_switch[leg] < g.unload_time:
                share = 1.0 - max(to_switch[leg], 0.0) / g.unload_time
                w_unload = g.unload_weight / weight**2 * share
                wrench.append(
                    WrenchTask(f"unload{leg}", pt, normal_force, np.zeros(1), w_unload, (name,))
                )
            elif handing and late[leg] and not early[leg]:
                w_unload = g.unload_weight / weight**2 * (max(lifted[leg], 0.0) / g.liftoff_delay)
                wrench.append(
                    WrenchTask(f"unload{leg}", pt, normal_force, np.zeros(1), w_unload, (name,))
                )
        else:
            target, target_v, target_a = feet[leg], feet_v[leg], feet_a[leg]
            if stance[leg] and to_switch[leg] >= g.unload_time:  # off the ground, not lifting
                # down along the normal from where the foot is, to reach_depth at most
                n = wbc.ground.normal(centre[0], centre[1])
                # faster the higher above its foothold
                depth = float(n @ (centre - target))
                speed = g.reach_speed + g.reach_gain * max(depth, 0.0)
                target = target + max(depth, -g.reach_depth) * n
                target_v, target_a = -speed * n, np.zeros(3)
            jac, drift = wbc.model.frame(wbc.foot_bodies[leg], centre, angular=False)
            acc = target_a + g.swing_kp * (target - centre)
            acc = acc + g.swing_kd * (target_v - jac @ qvel)
            tasks.append(MotionTask(f"swing{leg}", jac, drift, acc, g.swing_weight))
    pos = d.xpos[sim.trunk]
    jac, drift = wbc.model.frame(sim.trunk, pos)
    vel = jac @ qvel
    acc_lin = body_a + g.trunk_kp * (body - pos) - g.trunk_kd * (vel[:3] - body_v)
    c, s = math.cos(-pitch), math.sin(-pitch)
    plan_rot = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    err = rotation_log(plan_rot @ d.xmat[sim.trunk].reshape(3, 3).T)
    acc_ang = g.rot_kp * err - g.rot_kd * vel[3:]
    tasks.append(MotionTask("trunk", jac[:3], drift[:3], acc_lin, g.trunk_weight))
    tasks.append(MotionTask("trunk_rot", jac[3:], drift[3:], acc_ang, g.rot_weight))
    dofs = wbc.joint_dofs
    select = np.zeros((dofs.size, wbc.model.nv))
    select[np.arange(dofs.size), dofs] = 1.0
    acc_q = joints_a + g.posture_kp * (joints - d.qpos[sim.qpos_adr])
    acc_q = acc_q + g.posture_kd * (joints_v - qvel[dofs])
    tasks.append(MotionTask("posture", select, np.zeros(dofs.size), acc_q, g.posture_weight))
    if heights and g.cop_weight > 0:
        about = np.array([zmp[0], zmp[1], sum(heights) / len(heights)])
        rows = np.array([[0, 0, 0, 1.0, 0, 0], [0, 0, 0, 0, 1.0, 0]])
        wrench.append(WrenchTask("cop", about, rows, np.zeros(2), g.cop_weight / weight**2))
    mass, bias = wbc.model.dynamics()
    return WbcProblem(
        mass_matrix=mass,
        bias=bias,
        actuated=wbc.model.actuated,
        torque_min=wbc.model.torque_min,
        torque_max=wbc.model.torque_max,
        contacts=tuple(contacts),
        motion_tasks=tuple(tasks),
        wrench_tasks=tuple(wrench),
    )


@pytest.mark.parametrize(
    "params",
    [
        GaitParams(slope=math.radians(15), body_pitch=math.radians(10), cycles=1),
        GaitParams(slope=0.0, body_pitch=0.0, ground=VaryingSlope((0.3, 1.3), (0.0, 0.26))),
    ],
    ids=["plane", "varying_slope"],
)
def test_packed_tick_equals_the_dataclass_problem_tick_by_tick(params: GaitParams) -> None:
    plan = plan_gait(QuadrupedRobot(), params)
    ref = plan.sample(0.01)
    sim = QuadrupedSim(plan.robot, plan.ground)
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    wbc = QuadrupedWbc(sim, ref, plan.ground, QuadrupedWbcGains())
    plain, rebuilt = WholeBodyController(), WholeBodyController()
    m, d = sim.model, sim.data
    n_contacts = set()
    late = 0  # ticks with a planned stance foot off the ground (reaching down)
    handover = 0  # ticks with a lifted foot still a contact (liftoff_delay)
    steps = round(float(ref.t[-1]) / m.opt.timestep)
    for i in range(0, steps, 2):  # the QP every 2nd step, as simulate()
        mujoco.mj_step1(m, d)
        t = i * m.opt.timestep
        expected = plain.solve(_reference_problem(wbc, t))
        k, w = wbc.ref.at(t)
        stance = wbc.ref.contact[k] if w < 0.5 else wbc.ref.contact[k + 1]
        late += int(any(s and not on for s, on in zip(stance, _touching(sim), strict=True)))
        tau = wbc.torques(t)
        np.testing.assert_allclose(tau, expected.torque, rtol=0, atol=TORQUE_TOL)
        problem, sol = wbc.last_problem, wbc.last
        assert problem is not None and sol is not None
        # a lifted foot still a contact, handing its load over (its unload row present)
        unloading = {c.name for c in problem.wrench_tasks}
        handover += int(any(not s and f"unload{leg}" in unloading for leg, s in enumerate(stance)))
        assert [c.name for c in problem.contacts] == list(expected.forces)
        for name, f in expected.forces.items():
            np.testing.assert_allclose(sol.forces[name], f, rtol=0, atol=TORQUE_TOL)
        np.testing.assert_allclose(rebuilt.solve(problem).torque, tau, rtol=0, atol=1e-12)
        n_contacts.add(len(problem.contacts))
        d.ctrl[sim.actuators] = tau
        mujoco.mj_step2(m, d)
        mujoco.mj_step1(m, d)
        mujoco.mj_step2(m, d)
    assert wbc.failures == 0 and plain.failures == 0
    assert {3, 4} <= n_contacts  # swings and four-foot stances were both compared
    assert late > 0  # and feet reaching down for the ground
    assert handover > 0  # and feet handing their load over after lift-off
