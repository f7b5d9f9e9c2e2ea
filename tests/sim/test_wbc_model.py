"""MujocoWbcModel (sim/wbc_model.py): M and h against MuJoCo's own mj_mulM / mj_rne and the
forward dynamics, frame Jacobians against finite differences of positions, torque limits read from
the model, torque mode (qfrc_actuator == ctrl)."""

from __future__ import annotations

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.errors import InputError  # noqa: E402
from footfall.sim.biped.plant import BipedSim  # noqa: E402
from footfall.sim.wbc_model import MujocoWbcModel  # noqa: E402
from footfall.terrain.resolve import resolve_scene  # noqa: E402

#: model terms vs MuJoCo's own functions (same floating-point operations, different paths)
TERM_TOL = 1e-9
#: Jacobian and drift vs central finite differences of the point's position / velocity
FD_STEP = 1e-6
FD_TOL = 1e-6


@pytest.fixture
def sim() -> BipedSim:
    """The biped standing, then moved to a generic state: tilted, random joint angles and rates."""
    scene = resolve_scene("flat")
    s = BipedSim(scene)
    s.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    rng = np.random.default_rng(5)
    d = s.data
    d.qpos[s.joint_qpos] += rng.uniform(-0.2, 0.2, len(s.joint_qpos))
    quat = np.array([0.98, 0.1, -0.12, 0.05])
    d.qpos[s.root_adr + 3 : s.root_adr + 7] = quat / np.linalg.norm(quat)
    d.qvel[:] = rng.normal(0.0, 1.0, s.model.nv)
    mujoco.mj_forward(s.model, d)
    return s


def wbc_model(s: BipedSim) -> MujocoWbcModel:
    return MujocoWbcModel(mujoco, s.model, s.data, s.actuators)


def test_mass_matrix_is_mj_mulM_on_unit_vectors(sim: BipedSim) -> None:
    m_mat, _ = wbc_model(sim).dynamics()
    nv = sim.model.nv
    cols = np.empty((nv, nv))
    out = np.zeros(nv)
    for j in range(nv):
        mujoco.mj_mulM(sim.model, sim.data, out, np.eye(nv)[j])
        cols[:, j] = out
    np.testing.assert_allclose(m_mat, cols, atol=TERM_TOL)
    # armature is part of M (MuJoCo adds it to the diagonal)
    assert np.all(np.diag(m_mat)[6:] >= sim.model.dof_armature[6:])


def test_bias_is_rne_minus_passive(sim: BipedSim) -> None:
    """h = C qd + g - passive: mj_rne with qacc = 0 (no acceleration term), minus joint damping
    -b qd computed from dof_damping here (the model has no springs)."""
    m, d = sim.model, sim.data
    _, h = wbc_model(sim).dynamics()
    rne = np.zeros(m.nv)
    mujoco.mj_rne(m, d, 0, rne)
    assert np.all(m.jnt_stiffness == 0.0)
    passive = -m.dof_damping * d.qvel
    assert np.abs(passive).max() > 0.1  # the damping term is tested
    np.testing.assert_allclose(h, rne - passive, atol=TERM_TOL)


def test_dynamics_reproduce_mujoco_forward_dynamics(sim: BipedSim) -> None:
    """M qacc + h = qfrc_actuator + qfrc_constraint + qfrc_applied after mj_forward with some
    controls, feet in contact (the identity MuJoCo's forward dynamics solves)."""
    m, d = sim.model, sim.data
    corners = list(sim.foot_of_geom)
    lowest = float(np.min(d.geom_xpos[corners, 2] - m.geom_size[corners, 0]))
    d.qpos[sim.root_adr + 2] -= lowest + 0.003  # the lowest corner 3 mm into the ground
    d.ctrl[sim.actuators] = np.linspace(-0.3, 0.3, len(sim.actuators))
    mujoco.mj_forward(m, d)
    assert d.ncon > 0 and np.abs(d.qfrc_constraint).max() > 1.0
    m_mat, h = wbc_model(sim).dynamics()
    rhs = d.qfrc_actuator + d.qfrc_constraint + d.qfrc_applied
    np.testing.assert_allclose(m_mat @ d.qacc + h, rhs, atol=1e-7)


def test_frame_jacobian_and_drift_by_finite_differences(sim: BipedSim) -> None:
    """The velocity of a point fixed on the foot, differentiated along qvel: J qd is the time
    derivative of its position, and Jdot qd the time derivative of J qd minus J qdd (qacc = 0)."""
    m, d = sim.model, sim.data
    model = wbc_model(sim)
    body = int(m.site_bodyid[sim.sole_sites[sim.sides[0]]])
    local = np.array([0.03, -0.02, -0.01])

    def point_and_rot(qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        d2 = mujoco.MjData(m)
        d2.qpos[:] = qpos
        mujoco.mj_kinematics(m, d2)
        return d2.xpos[body] + d2.xmat[body].reshape(3, 3) @ local, d2.xmat[body].reshape(3, 3)

    point, rot = point_and_rot(d.qpos)
    jac, drift = model.frame(body, point)

    def moved(t: float) -> np.ndarray:
        q = np.array(d.qpos)
        mujoco.mj_integratePos(m, q, d.qvel, t)
        return q

    (p1, r1), (p0, r0) = point_and_rot(moved(FD_STEP)), point_and_rot(moved(-FD_STEP))
    np.testing.assert_allclose(jac[:3] @ d.qvel, (p1 - p0) / (2 * FD_STEP), atol=FD_TOL)
    skew = (r1 - r0) / (2 * FD_STEP) @ rot.T  # d R / dt R^T = [omega]x
    omega = np.array([skew[2, 1], skew[0, 2], skew[1, 0]])
    np.testing.assert_allclose(jac[3:] @ d.qvel, omega, atol=FD_TOL)

    # drift: with qacc = 0, d/dt (J(q) qd) = Jdot qd; J taken at the same body point
    def velocity(t: float) -> np.ndarray:
        d2 = mujoco.MjData(m)
        d2.qpos[:] = moved(t)
        mujoco.mj_kinematics(m, d2)
        mujoco.mj_comPos(m, d2)
        p_t = d2.xpos[body] + d2.xmat[body].reshape(3, 3) @ local
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jac(m, d2, jp, jr, p_t, body)
        return np.concatenate([jp @ d.qvel, jr @ d.qvel])

    np.testing.assert_allclose(
        drift, (velocity(FD_STEP) - velocity(-FD_STEP)) / (2 * FD_STEP), atol=1e-5
    )


def test_torque_limits_read_from_the_model() -> None:
    """actuator_forcerange where force-limited, else the joint's actfrcrange, else unbounded."""
    scene = resolve_scene("flat")
    s = BipedSim(scene)
    m = s.model
    a0, a1, a2 = (int(a) for a in s.actuators[:3])
    j1, j2 = int(m.actuator_trnid[a1, 0]), int(m.actuator_trnid[a2, 0])
    m.actuator_forcerange[a0] = (-12.0, 34.0)
    m.actuator_forcelimited[a1] = 0
    m.jnt_actfrclimited[j1] = 1
    m.jnt_actfrcrange[j1] = (-56.0, 78.0)
    m.actuator_forcelimited[a2] = 0
    m.jnt_actfrclimited[j2] = 0
    model = MujocoWbcModel(mujoco, m, s.data, s.actuators)
    np.testing.assert_array_equal(model.torque_min[:3], [-12.0, -56.0, -np.inf])
    np.testing.assert_array_equal(model.torque_max[:3], [34.0, 78.0, np.inf])
    np.testing.assert_array_equal(model.torque_min[3:], m.actuator_forcerange[s.actuators[3:], 0])
    np.testing.assert_array_equal(model.torque_max[3:], m.actuator_forcerange[s.actuators[3:], 1])
    # actuated dofs are the actuators' joints' dofs, in actuator order
    np.testing.assert_array_equal(model.actuated, s.joint_dof)


def test_torque_mode_makes_ctrl_the_joint_torque(sim: BipedSim) -> None:
    """After set_torque_mode, qfrc_actuator at each driven dof equals ctrl (away from the joint
    targets and with joint velocities, where a position servo would add kp, kv terms), clipped
    to the force range."""
    m, d = sim.model, sim.data
    model = wbc_model(sim)
    model.set_torque_mode()
    lim = m.actuator_forcerange[sim.actuators, 1]
    ctrl = np.linspace(-40.0, 40.0, len(sim.actuators))
    ctrl[0] = 2.0 * lim[0]  # beyond the force range: clipped
    d.ctrl[sim.actuators] = ctrl
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(
        d.qfrc_actuator[model.actuated], np.clip(ctrl, -lim, lim), atol=1e-12
    )
    # nothing else is driven
    others = np.setdiff1d(np.arange(m.nv), model.actuated)
    np.testing.assert_array_equal(d.qfrc_actuator[others], 0.0)


def test_actuator_with_a_gear_is_rejected() -> None:
    s = BipedSim(resolve_scene("flat"))
    s.model.actuator_gear[s.actuators[2], 0] = 2.0
    with pytest.raises(InputError) as err:
        MujocoWbcModel(mujoco, s.model, s.data, s.actuators)
    assert err.value.field == "actuators"


def test_implicit_damping_predicts_the_implicit_step(sim: BipedSim) -> None:
    """With ``implicit_damping``, ``M + h D`` and ``h`` give the acceleration MuJoCo's
    implicit-fast step realizes, ``(qvel' - qvel) / h`` after ``mj_step`` (the robot in the air, so
    no contact, some joint torques); ``M`` alone misses it by more than the tolerance."""
    m, d = sim.model, sim.data
    assert int(m.opt.integrator) == int(mujoco.mjtIntegrator.mjINT_IMPLICITFAST)
    assert np.any(m.dof_damping > 0.0)
    d.qpos[sim.root_adr + 2] += 1.0  # in the air
    model = MujocoWbcModel(mujoco, m, d, sim.actuators, implicit_damping=True)
    model.set_torque_mode()
    d.ctrl[sim.actuators] = np.linspace(-20.0, 20.0, len(sim.actuators))
    mujoco.mj_forward(m, d)
    assert d.ncon == 0
    m_eff, h = model.dynamics()
    tau = np.zeros(m.nv)
    tau[model.actuated] = d.ctrl[sim.actuators]
    predicted = np.linalg.solve(m_eff, tau - h)
    explicit = np.linalg.solve(m_eff - np.diag(model.implicit_damping), tau - h)
    qvel = np.array(d.qvel)
    mujoco.mj_step(m, d)
    realized = (d.qvel - qvel) / m.opt.timestep
    np.testing.assert_allclose(predicted, realized, atol=1e-6)
    assert np.abs(explicit - realized).max() > 1e-3
