"""How the quadruped's whole-body controller puts its feet down and hands the load over
(sim/quadruped/wbc.py, _wbc_tick.py), checked on walks against the plan's own contact timeline:

- a foot is unloaded only before its planned lift-off (or just after it, while it still touches),
  never in the first ticks after its touchdown;
- a foot hands its load over only onto three other contacts;
- ANYmal C, whose legs are 26 % of its mass, walks 20 deg up and 15 deg down with its centre of
  pressure within 3 cm of the planned ZMP at every sample (the quadruped issue's number; before
  the landing changes its front feet touched down 20-30 ms early at 0.1 m/s and the maximum was
  3.2 and 11.5 cm).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.quadruped.scaling import scale_gait  # noqa: E402
from footfall.robots.quadruped import resolve_quadruped  # noqa: E402
from footfall.sim.quadruped.mjcf import robot_settings  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim, simulate  # noqa: E402
from footfall.sim.quadruped.wbc import QuadrupedWbc, QuadrupedWbcGains  # noqa: E402

#: the quadruped issue's numbers on the planes: CoP against the planned ZMP [m]
COP_MAX = 0.03
COP_MEAN = 0.01
#: slip of one foot over one stance [m]
SLIP_MAX = 0.01


def _switches(contact: np.ndarray, times: np.ndarray, leg: int) -> tuple[np.ndarray, np.ndarray]:
    """The plan's touchdown and lift-off times of ``leg`` [s] (a touchdown at the first stance
    sample after a swing, a lift-off at the first swing sample)."""
    c = contact[:, leg].astype(bool)
    down = times[1:][c[1:] & ~c[:-1]]
    up = times[1:][~c[1:] & c[:-1]]
    return down, up


def test_feet_are_unloaded_only_before_lift_off_and_onto_three_contacts() -> None:
    """Tick by tick on a document-robot walk (15 deg, one cycle): every unload row belongs to a
    foot whose planned lift-off is at most ``unload_time`` ahead or ``liftoff_delay`` behind,
    and comes with four contacts in the problem."""
    gains = QuadrupedWbcGains()
    plan = plan_gait(
        QuadrupedRobot(), GaitParams(slope=math.radians(15), body_pitch=math.radians(10), cycles=1)
    )
    ref = plan.sample(0.01)
    sim = QuadrupedSim(plan.robot, plan.ground)
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    wbc = QuadrupedWbc(sim, ref, plan.ground, gains)
    m, d = sim.model, sim.data
    lifts = [_switches(ref.contact, ref.t, leg)[1] for leg in range(4)]
    unloads = 0
    for i in range(round(float(ref.t[-1]) / m.opt.timestep)):
        mujoco.mj_step1(m, d)
        t = i * m.opt.timestep
        if wbc.due(i, t):
            d.ctrl[sim.actuators] = wbc.torques(t)
            problem = wbc.last_problem
            assert problem is not None
            for task in problem.wrench_tasks:
                if not task.name.startswith("unload"):
                    continue
                unloads += 1
                leg = int(task.name[-1])
                assert len(problem.contacts) == 4
                ahead = lifts[leg] - t
                assert np.any(
                    (ahead <= gains.unload_time + 1e-9) & (ahead >= -gains.liftoff_delay - 1e-9)
                ), (t, leg)
        mujoco.mj_step2(m, d)
    assert unloads > 20  # the hand-overs were exercised
    assert wbc.failures == 0


@pytest.mark.parametrize("slope_deg", [20.0, -15.0])
def test_anymal_lands_its_feet_without_kicking_the_centre_of_pressure(slope_deg: float) -> None:
    robot = resolve_quadruped("anymal_c")
    params = scale_gait(
        robot,
        GaitParams(
            slope=math.radians(slope_deg), body_pitch=math.radians(slope_deg * 2 / 3), cycles=2
        ),
    )
    res = simulate(plan_gait(robot, params), robot_settings(robot, 0.8), controller="wbc")
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0
    assert m.zmp_error_max_m is not None and m.zmp_error_mean_m is not None
    assert m.zmp_error_max_m <= COP_MAX
    assert m.zmp_error_mean_m <= COP_MEAN
    assert m.foot_slip_max_m <= SLIP_MAX


def test_the_qp_runs_at_every_step_only_near_a_touchdown() -> None:
    """``due``: every ``qp_every``-th physics step, and every step within ``landing_window`` of a
    planned touchdown (from the plan's contact timeline, not the controller's arrays)."""
    gains = QuadrupedWbcGains(qp_every=2, landing_window=0.1)
    plan = plan_gait(
        QuadrupedRobot(), GaitParams(slope=math.radians(15), body_pitch=math.radians(10), cycles=1)
    )
    ref = plan.sample(0.01)
    sim = QuadrupedSim(plan.robot, plan.ground)
    wbc = QuadrupedWbc(sim, ref, plan.ground, gains)
    downs = np.concatenate([_switches(ref.contact, ref.t, leg)[0] for leg in range(4)])
    h = float(sim.model.opt.timestep)
    odd_due = 0
    for i in range(1, round(float(ref.t[-1]) / h), 2):  # the odd steps
        t = i * h
        ahead = downs - t
        near = np.any((ahead > 0) & (ahead <= gains.landing_window))
        far = not np.any((ahead > -0.02) & (ahead <= gains.landing_window + 0.02))
        if near:
            assert wbc.due(i, t)
        if far:
            assert not wbc.due(i, t)
        odd_due += int(wbc.due(i, t))
    assert wbc.due(0, 0.0) and wbc.due(2, 2 * h)
    assert 0 < odd_due < round(float(ref.t[-1]) / h) // 2


def test_feet_tipped_off_the_ground_come_back_fast_enough_after_pushes() -> None:
    """Go2 pushed sideways with seeds 2 and 4 of ``footfall bench quadruped-pushes`` (in four-
    and three-foot stances; the robot tips onto two feet) at 0.3-0.65 m/s, 16 walks: none falls.
    The tipped feet descend at ``reach_speed + reach_gain x height``; measured with
    ``reach_gain`` 0 (the slow landing speed alone) three of these walks fell, with 10 one."""
    from footfall.experiments.quadruped_pushes import push_of_seed, push_walk_plan
    from footfall.sim.disturbance import Push

    robot = resolve_quadruped("go2")
    plan = push_walk_plan("go2", 15.0, 4)
    settings = robot_settings(robot)
    falls = []
    for seed in (2, 4):
        share, side = push_of_seed(seed, 0.05)
        for dv in (0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65):
            push = Push.horizontal(
                share * plan.duration, robot.total_mass * dv, side * math.pi / 2, 0.05
            )
            if simulate(plan, settings, controller="wbc", pushes=(push,)).metrics.fell:
                falls.append((seed, dv))
    assert falls == []
