"""The quadruped's whole-body controller (sim/quadruped/wbc.py, issue 21), checked by MuJoCo itself:
the QP's accelerations, torques and point-foot forces satisfy MuJoCo's inverse dynamics
(mj_inverse with the constraint solver off), the stance feet's contact points do not accelerate
(mj_jac / mj_jacDot), forces inside the friction pyramid, torques within the force range; and in
closed loop on the document's 15 and 20 degree slopes the centre of pressure measured from MuJoCo's
contact forces follows the planned ZMP (issue 21: mean <= 2 cm, max <= 5 cm)."""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.errors import InputError  # noqa: E402
from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim, simulate  # noqa: E402
from footfall.sim.quadruped.wbc import QuadrupedWbc, QuadrupedWbcGains  # noqa: E402
from tests.sim.mj_reference import inverse_dynamics_without_constraints  # noqa: E402

#: mj_inverse's generalised force vs S^T tau + sum J(p)^T f [N, N m]
INVERSE_TOL = 1e-6
#: contact point accelerations [m/s^2]
ACCEL_TOL = 1e-6
#: friction pyramid, unilateral contact and torque-limit slack [N, N m]
CONE_TOL = 1e-6
#: issue 21's bounds on the CoP - planned ZMP distance with wbc [m]
COP_MEAN_MAX = 0.02
COP_MAX_MAX = 0.05


def _plan(slope_deg: float, body_deg: float, cycles: int = 2):  # type: ignore[no-untyped-def]
    return plan_gait(
        QuadrupedRobot(),
        GaitParams(slope=math.radians(slope_deg), body_pitch=math.radians(body_deg), cycles=cycles),
    )


def _one_tick(t: float) -> tuple[QuadrupedSim, QuadrupedWbc]:
    """A QP at the plan's initial pose with the reference of gait time ``t``."""
    plan = _plan(15.0, 10.0)
    ref = plan.sample(0.01)
    sim = QuadrupedSim(plan.robot, plan.posture.slope)
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    # 1 mm lower, so that every foot touches (the pose puts them exactly on the ground, and a
    # planned stance foot counts as a contact only while it touches)
    sim.data.qpos[sim.root_adr + 2] -= 1e-3
    sim.data.qvel[:] = np.random.default_rng(0).normal(0.0, 0.05, sim.model.nv)
    mujoco.mj_forward(sim.model, sim.data)
    wbc = QuadrupedWbc(sim, ref, plan.ground, QuadrupedWbcGains())
    wbc.torques(t)
    return sim, wbc


@pytest.mark.parametrize("t", [0.5, 1.75])  # all four feet down; one foot in its swing
def test_qp_solution_satisfies_mujoco_inverse_dynamics_and_the_contacts(t: float) -> None:
    sim, wbc = _one_tick(t)
    m, d = sim.model, sim.data
    sol, prob = wbc.last, wbc.last_problem
    assert sol is not None and prob is not None and wbc.failures == 0
    n_down = len(prob.contacts)
    assert n_down == (4 if t < 1.5 else 3)
    # the QP's accelerations are those of MuJoCo's implicit-fast step, whose damping acts at the
    # end of the step: (M + h D) qacc + h = S^T tau + J^T f (tests/sim/test_wbc_model.py checks
    # that identity against mj_step)
    inverse = inverse_dynamics_without_constraints(m, d, sol.qacc)
    inverse += m.opt.timestep * m.dof_damping * sol.qacc
    gen = np.zeros(m.nv)
    dofs = [int(m.jnt_dofadr[int(m.actuator_trnid[a, 0])]) for a in sim.actuators]
    gen[dofs] += sol.torque
    jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    jdp, jdr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
    normal = sim.ground.normal(0.0, 0.0)
    mu = float(m.geom_friction[sim.foot_geoms[0], 0])
    t1 = np.cross(normal, [0.0, 1.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(normal, t1)
    for c in prob.contacts:
        leg = int(c.name[-1])
        body = int(m.site_bodyid[sim.foot_sites[leg]])
        radius = float(m.geom_size[sim.foot_geoms[leg], 0])
        # the bottom of the foot sphere, recomputed here from the site
        p = d.site_xpos[sim.foot_sites[leg]] - radius * normal
        (f,) = sol.forces[c.name]
        mujoco.mj_jac(m, d, jp, jr, p, body)
        mujoco.mj_jacDot(m, d, jdp, jdr, p, body)
        gen += jp.T @ f
        np.testing.assert_allclose(jp @ sol.qacc + jdp @ d.qvel, 0.0, atol=ACCEL_TOL)
        fn = f @ normal
        assert fn >= -CONE_TOL
        for tangent in (t1, t2):
            assert abs(f @ tangent) <= mu / math.sqrt(2.0) * fn + CONE_TOL
    np.testing.assert_allclose(inverse, gen, atol=INVERSE_TOL)
    lo, hi = m.actuator_forcerange[sim.actuators].T
    assert np.all(sol.torque >= lo - CONE_TOL) and np.all(sol.torque <= hi + CONE_TOL)


@pytest.fixture(scope="module")
def walks() -> dict[tuple[float, str], object]:
    out = {}
    for slope, body in ((15.0, 10.0), (20.0, 13.0)):
        plan = _plan(slope, body)
        for ctrl in ("wbc", "servo"):
            out[(slope, ctrl)] = simulate(plan, controller=ctrl)
    return out


@pytest.mark.parametrize("slope", [15.0, 20.0])
def test_wbc_puts_the_measured_cop_on_the_planned_zmp(walks: dict, slope: float) -> None:
    res = walks[(slope, "wbc")]
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0 and res.controller == "wbc"
    assert m.zmp_error_mean_m <= COP_MEAN_MAX
    assert m.zmp_error_max_m <= COP_MAX_MAX
    # recomputed here from the recorded CoP and plan, over the samples with three or four feet
    # planned and measured down
    ok = (
        (res.trace.planned.contact.sum(axis=1) >= 3)
        & (res.trace.n_contacts >= 3)
        & np.isfinite(res.trace.margin)
    )
    err = np.linalg.norm(res.trace.cop - res.trace.planned.zmp, axis=1)[ok]
    assert ok.sum() > 0.9 * ok.size
    assert err.mean() == pytest.approx(m.zmp_error_mean_m)
    # the document's servos on the same plan leave the CoP much further away
    servo = walks[(slope, "servo")].metrics
    assert servo.zmp_error_mean_m > 3 * m.zmp_error_mean_m
    # and the walk still climbs the slope
    assert m.distance_up_slope_m > 0.5 * servo.distance_up_slope_m > 0


def test_controller_and_gains_are_checked() -> None:
    plan = _plan(15.0, 10.0, cycles=1)
    with pytest.raises(InputError) as err:
        simulate(plan, controller="pd")
    assert err.value.field == "controller"
    with pytest.raises(InputError) as err:
        simulate(plan, controller="wbc", wbc_gains={"cop_weight": 1.0})
    assert err.value.field == "wbc_gains"
    with pytest.raises(InputError) as err:
        QuadrupedWbcGains(trunk_kp=-1.0)
    assert err.value.field == "wbc_gains.trunk_kp"


def test_a_push_moves_the_trunk_by_its_impulse() -> None:
    """A lateral push of J [N s] moves the trunk sideways by at most what it would move in free
    flight over the pulse, 1/2 (J / m) T, and by a good part of it (the legs resist)."""
    from footfall.sim.disturbance import Push

    plan = _plan(15.0, 10.0, cycles=1)
    push = Push.horizontal(0.5, 40.0, math.pi / 2, 0.1)
    quiet = simulate(plan, controller="wbc")
    pushed = simulate(plan, controller="wbc", pushes=(push,))
    k0, k1 = np.searchsorted(quiet.trace.t, [0.5, 0.6])
    # the same walk until the push, then pushed sideways (+y) relative to the quiet walk
    np.testing.assert_allclose(pushed.trace.trunk_pos[:k0], quiet.trace.trunk_pos[:k0], atol=1e-9)
    dy = pushed.trace.trunk_pos[k1, 1] - quiet.trace.trunk_pos[k1, 1]
    # free flight would move the trunk 1/2 (J / m) * 0.1 s = 2 cm; the stance legs resist
    free = 0.5 * 40.0 / plan.robot.total_mass * 0.1
    assert 0.2 * free < dy < 1.2 * free
    with pytest.raises(InputError) as err:
        simulate(plan, pushes=("push",))  # type: ignore[arg-type]
    assert err.value.field == "pushes[0]"


def test_downhill_walk_descends_with_the_cop_on_the_plan() -> None:
    """A negative slope walks downhill (issue 21): the trunk goes down by about the slope's drop
    over the distance walked, and the wbc keeps the CoP on the planned ZMP."""
    plan = _plan(-15.0, -10.0)
    res = simulate(plan, controller="wbc")
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0
    dx = res.trace.trunk_pos[-1, 0] - res.trace.trunk_pos[0, 0]
    dz = res.trace.trunk_pos[-1, 2] - res.trace.trunk_pos[0, 2]
    assert dx > 0.3
    assert dz == pytest.approx(dx * math.tan(math.radians(-15.0)), abs=0.03)
    assert m.zmp_error_mean_m <= COP_MEAN_MAX and m.zmp_error_max_m <= COP_MAX_MAX


def test_downhill_posture_is_checked() -> None:
    from footfall.quadruped.posture import BodyPosture, SlopePosture

    SlopePosture(math.radians(-20.0), math.radians(-13.0), 0.5, BodyPosture.COMPROMISE)
    with pytest.raises(InputError) as err:  # a nose-up body on a downhill slope
        SlopePosture(math.radians(-20.0), math.radians(5.0), 0.5, BodyPosture.COMPROMISE)
    assert err.value.field == "body_pitch"
    with pytest.raises(InputError) as err:
        SlopePosture(math.radians(-61.0), 0.0, 0.5, BodyPosture.COMPROMISE)
    assert err.value.field == "slope"


@pytest.mark.parametrize("friction", [0.4, 1.0])
def test_the_friction_setting_is_the_contacts_friction(friction: float) -> None:
    """MuJoCo mixes two geoms' friction by their maximum unless one has priority: the feet have
    it, so SimSettings.friction is the friction of every foot contact (the floor's default 1 did
    override a smaller setting before) and the wbc's friction pyramid uses the same number."""
    from footfall.sim.quadruped.mjcf import SimSettings

    plan = _plan(15.0, 10.0, cycles=1)
    ref = plan.sample(0.01)
    sim = QuadrupedSim(plan.robot, plan.posture.slope, SimSettings(friction=friction))
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    for _ in range(50):
        mujoco.mj_step(sim.model, sim.data)
    d = sim.data
    feet = set(sim.foot_geoms)
    mus = [float(d.contact[i].friction[0]) for i in range(d.ncon) if set(d.contact[i].geom) & feet]
    assert len(mus) >= 4 and np.allclose(mus, friction)
    wbc = QuadrupedWbc(sim, ref, plan.ground, QuadrupedWbcGains())
    assert wbc.friction == pytest.approx(friction)


def test_forty_degrees_is_walked_with_the_pyramid_edge_downhill() -> None:
    """With the friction pyramid turned so that gravity's pull along the slope points at an edge
    (where it reaches Coulomb's cone), the wbc walks 40 degrees at friction 1: an inscribed
    pyramid facing the slope would admit atan(1 / sqrt(2)) = 35 degrees and its QP would fail."""
    params = GaitParams(
        slope=math.radians(40.0), body_pitch=math.radians(27.0), step=0.25, cycles=2
    )
    plan = plan_gait(QuadrupedRobot(), params)
    res = simulate(plan, controller="wbc")
    assert not res.metrics.fell and res.trace.qp_failures == 0
    assert res.metrics.zmp_error_mean_m <= COP_MEAN_MAX
