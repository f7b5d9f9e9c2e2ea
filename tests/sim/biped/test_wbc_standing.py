"""The biped's whole-body controller (sim/biped/wbc.py) checked by MuJoCo itself: the QP's
accelerations, torques and corner forces satisfy MuJoCo's inverse dynamics (mj_inverse), the
corners do not accelerate (mj_jac / mj_jacDot at each corner), torques within the force range,
forces inside the friction pyramid, CoP inside the sole; and the statics of a robot standing
under a known horizontal push (issue 19)."""

from __future__ import annotations

import math

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

from footfall.models.biped import Side  # noqa: E402
from footfall.robots import names as nm  # noqa: E402
from footfall.sim.biped.plant import BipedSim  # noqa: E402
from footfall.sim.biped.state import Command  # noqa: E402
from footfall.sim.biped.wbc import BipedWbc, CopTarget  # noqa: E402
from footfall.terrain.resolve import resolve_scene  # noqa: E402
from tests.sim.mj_reference import inverse_dynamics_without_constraints  # noqa: E402

#: mj_inverse's generalised force vs S^T tau + sum J(p)^T f [N, N m] (issue 19: 1e-6)
INVERSE_TOL = 1e-6
#: corner accelerations [m/s^2]
ACCEL_TOL = 1e-6
#: friction pyramid, unilateral contact and torque-limit slack [N, N m]
CONE_TOL = 1e-6
#: commanded vs realised CoP of a weighted task [m]
COP_TASK_TOL = 5e-4
#: measured CoP shift vs statics after settling [m]
STATICS_TOL = 2e-3
#: control period and physics step of the standing loop [s]
CONTROL_DT = 0.01
SETTLE_TIME = 1.0


def standing_sim() -> BipedSim:
    scene = resolve_scene("flat")
    sim = BipedSim(scene)
    sim.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    return sim


def corner_points(sim: BipedSim, side: Side) -> np.ndarray:
    """The lowest points of the side's four corner spheres (sphere centre - radius * sole z)."""
    m, d = sim.model, sim.data
    ids = [
        mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, nm.corner_geom(side, k)) for k in range(4)
    ]
    normal = d.site_xmat[sim.sole_sites[side]].reshape(3, 3)[:, 2]
    return np.array([d.geom_xpos[i] - m.geom_size[i, 0] * normal for i in ids])


def foot_body(sim: BipedSim, side: Side) -> int:
    return int(sim.model.site_bodyid[sim.sole_sites[side]])


def solve_tick(
    sim: BipedSim,
    sides: tuple[Side, ...],
    cop: CopTarget | None = None,
    com_offset: tuple[float, float, float] = (0.01, -0.005, -0.01),
) -> BipedWbc:
    """One QP at the current state (after mj_forward) with a CoM reference a little off."""
    mujoco.mj_forward(sim.model, sim.data)
    wbc = BipedWbc(sim)
    com, vel, l_g = sim.com_state()
    feet = {s: sim.sole(s) for s in sim.sides}
    wbc.command(Command(com + np.asarray(com_offset), feet, 0.05), CONTROL_DT)
    wbc.torques(1.0, sides, cop, com, vel, l_g)
    return wbc


def check_solution(sim: BipedSim, wbc: BipedWbc, sides: tuple[Side, ...]) -> None:
    """Everything the issue asks of a QP solution, against MuJoCo's own functions."""
    m, d = sim.model, sim.data
    sol = wbc.last
    assert sol is not None
    nv = m.nv
    # --- inverse dynamics: M qacc + bias - passive = S^T tau + sum J(p)^T f
    inverse = inverse_dynamics_without_constraints(m, d, sol.qacc)
    gen = np.zeros(nv)
    gen[sim.joint_dof] += sol.torque
    jp, jr = np.zeros((3, nv)), np.zeros((3, nv))
    jdp, jdr = np.zeros((3, nv)), np.zeros((3, nv))
    for side in sides:
        body = foot_body(sim, side)
        pts = corner_points(sim, side)
        forces = sol.forces[side.value]
        for p, f in zip(pts, forces, strict=True):
            mujoco.mj_jac(m, d, jp, jr, p, body)
            gen += jp.T @ f
        # --- accelerations of the corners (material points): J qacc + Jdot qvel
        sole = d.site_xpos[sim.sole_sites[side]]
        mujoco.mj_jac(m, d, jp, jr, sole, body)
        omega = jr @ d.qvel
        for p in pts:
            mujoco.mj_jac(m, d, jp, jr, p, body)
            mujoco.mj_jacDot(m, d, jdp, jdr, p, body)
            acc = jp @ sol.qacc + jdp @ d.qvel
            # the QP holds the sole centre still and the foot's angular acceleration at zero;
            # a foot that turns (omega) then has corners on circles: omega x (omega x r)
            expected = np.cross(omega, np.cross(omega, p - sole))
            np.testing.assert_allclose(acc, expected, atol=ACCEL_TOL)
            np.testing.assert_allclose(jr @ sol.qacc + jdr @ d.qvel, 0.0, atol=ACCEL_TOL)
        # --- friction pyramid, f.n >= 0, CoP inside the sole
        rot = d.site_xmat[sim.sole_sites[side]].reshape(3, 3)
        n = rot[:, 2]
        gids = [
            mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_GEOM, nm.corner_geom(side, k))
            for k in range(4)
        ]
        mu = float(np.min(m.geom_friction[gids, 0]))
        t1 = np.cross(n, [1.0, 0.0, 0.0])
        t1 /= np.linalg.norm(t1)
        t2 = np.cross(n, t1)
        fn = forces @ n
        assert np.all(fn >= -CONE_TOL)
        for t in (t1, t2):
            assert np.all(np.abs(forces @ t) <= mu / math.sqrt(2.0) * fn + CONE_TOL)
        tangential = forces - np.outer(fn, n)
        assert np.all(np.linalg.norm(tangential, axis=1) <= mu * fn + CONE_TOL)
        if fn.sum() > 1e-6:
            local = rot.T @ ((fn @ pts) / fn.sum() - sole)
            assert abs(local[0]) <= sim.params.foot_length / 2 + 1e-9
            assert abs(local[1]) <= sim.params.foot_width / 2 + 1e-9
    np.testing.assert_allclose(inverse, gen, atol=INVERSE_TOL)
    # --- torques within the model's force range
    lo, hi = m.actuator_forcerange[sim.actuators].T
    assert np.all(sol.torque >= lo - CONE_TOL) and np.all(sol.torque <= hi + CONE_TOL)


def feet_still_velocity(sim: BipedSim, rng: np.random.Generator) -> np.ndarray:
    """Random generalised velocity with both feet still (in the null space of their Jacobians):
    the torso sways, the joints move, the soles stay on the ground."""
    m, d = sim.model, sim.data
    rows = []
    for side in sim.sides:
        jp, jr = np.zeros((3, m.nv)), np.zeros((3, m.nv))
        mujoco.mj_jac(m, d, jp, jr, d.site_xpos[sim.sole_sites[side]], foot_body(sim, side))
        rows += [jp, jr]
    _, s, vt = np.linalg.svd(np.vstack(rows))
    null = vt[int(np.sum(s > 1e-9)) :]
    return null.T @ rng.normal(0.0, 0.5, null.shape[0])


def test_qp_at_rest_double_support() -> None:
    sim = standing_sim()
    wbc = solve_tick(sim, sim.sides)
    check_solution(sim, wbc, sim.sides)
    # the feet carry the weight and the CoM reference's vertical pull (Newton, approximately:
    # the accelerations are weighted tasks)
    total = sum(wbc.last.forces[s.value].sum(axis=0) for s in sim.sides)
    assert total[2] == pytest.approx(sim.weight, rel=0.2)


def test_qp_moving_with_feet_still() -> None:
    """Joints and torso moving (random velocities that keep the soles still), the torso tilted:
    the corners then truly do not accelerate."""
    sim = standing_sim()
    rng = np.random.default_rng(3)
    mujoco.mj_forward(sim.model, sim.data)
    sim.data.qvel[:] = feet_still_velocity(sim, rng)
    assert np.abs(sim.data.qvel[sim.joint_dof]).max() > 0.1
    wbc = solve_tick(sim, sim.sides)
    check_solution(sim, wbc, sim.sides)


def test_qp_at_a_generic_state() -> None:
    """Tilted base, perturbed joints, arbitrary velocities (the feet turn): the QP's solution
    still satisfies MuJoCo's inverse dynamics, and its corners move on circles about the still
    sole centre."""
    sim = standing_sim()
    rng = np.random.default_rng(7)
    d = sim.data
    quat = np.array([0.99, 0.06, -0.08, 0.03])
    d.qpos[sim.root_adr + 3 : sim.root_adr + 7] = quat / np.linalg.norm(quat)
    d.qpos[sim.joint_qpos] += rng.uniform(-0.1, 0.1, len(sim.joint_qpos))
    d.qvel[:] = rng.normal(0.0, 0.5, sim.model.nv)
    wbc = solve_tick(sim, sim.sides)
    check_solution(sim, wbc, sim.sides)


def test_qp_single_support_commanded_cop() -> None:
    """Right foot only, a ground moment u about its sole centre (the ALIP torque): the CoP of
    the QP's forces is (-u_y, u_x) / F_n from the sole centre (u = sum (p - o) x f on a level
    sole), and the solution passes every check."""
    sim = standing_sim()
    sole = sim.sole(Side.RIGHT)[0]
    u = np.array([3.0, -5.0])
    wbc = solve_tick(sim, (Side.RIGHT,), CopTarget((Side.RIGHT,), sole, u))
    check_solution(sim, wbc, (Side.RIGHT,))
    f = wbc.last.forces["right"]
    pts = corner_points(sim, Side.RIGHT)
    fn = f[:, 2].sum()
    cop = (f[:, 2] @ pts) / fn - sole
    np.testing.assert_allclose(cop[:2], np.array([-u[1], u[0]]) / fn, atol=COP_TASK_TOL)


def test_qp_respects_tightened_torque_limits() -> None:
    """With the force range cut below what the unconstrained solution uses, the torques stay
    inside it and the solution still satisfies the dynamics (or the QP says it has none)."""
    sim = standing_sim()
    free = solve_tick(sim, sim.sides).last
    assert free is not None
    cap = 0.7 * float(np.abs(free.torque).max())
    sim.model.actuator_forcerange[sim.actuators] = (-cap, cap)
    wbc = solve_tick(sim, sim.sides)
    assert wbc.last is not None and np.abs(wbc.last.torque).max() <= cap + CONE_TOL
    check_solution(sim, wbc, sim.sides)


# ------------------------------------------------------------------------------- statics
def stand_pushed(force: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, BipedSim]:
    """Stand under WBC control (CoM reference fixed at the start) with ``force`` (3,) [N] on the
    torso for SETTLE_TIME; returns the CoP of all contact forces, the CoM, the total contact
    force (MuJoCo's contacts), and the sim."""
    sim = standing_sim()
    m, d = sim.model, sim.data
    wbc = BipedWbc(sim)
    com0, _, _ = sim.com_state()
    cmd = Command(com0.copy(), {s: sim.sole(s) for s in sim.sides}, 0.0)
    substeps = round(CONTROL_DT / m.opt.timestep)
    for k in range(round(SETTLE_TIME / m.opt.timestep)):
        if k % substeps == 0:
            wbc.command(cmd, CONTROL_DT)
        com, vel, l_g = sim.com_state()
        d.ctrl[sim.actuators] = wbc.torques(
            (k % substeps + 1) / substeps, sim.sides, None, com, vel, l_g
        )
        d.xfrc_applied[sim.torso, :3] = force
        mujoco.mj_step(m, d)
        mujoco.mj_forward(m, d)
    contacts, body_hit = sim.contacts()
    assert not body_hit
    pts = np.vstack([contacts[s][0] for s in sim.sides])
    frc = np.vstack([contacts[s][1] for s in sim.sides])
    cop = (frc[:, 2] @ pts) / frc[:, 2].sum()
    com, vel, _ = sim.com_state()
    assert np.abs(vel).max() < 1e-3  # settled
    return cop, com, frc.sum(axis=0), sim


@pytest.mark.parametrize("force", [(10.0, 0.0), (-8.0, 6.0), (0.0, 0.0)])
def test_cop_shift_under_a_known_push(force: tuple[float, float]) -> None:
    """Statics of the robot at rest on flat ground (z = 0) with a horizontal force F on the
    torso. MuJoCo applies xfrc_applied at the body's CoM, xipos, at height z_F. Sum of forces:
    the ground gives -F horizontally and m g vertically. Moments about the CoP p (a point of the
    ground where the ground forces have no horizontal moment), y component of r x f being
    r_z f_x - r_x f_z:
        gravity at c:  -(c_x - p_x)(-m g) = (c_x - p_x) m g
        push at x_F:   z_F F_x  (f_z = 0)
    and nothing accelerates, so (c_x - p_x) m g + z_F F_x = 0: p_x = c_x + F_x z_F / (m g);
    likewise (x component) p_y = c_y + F_y z_F / (m g). The CoP moves with the push."""
    push = np.array([*force, 0.0])
    cop, com, total, sim = stand_pushed(push)
    z_f = float(sim.data.xipos[sim.torso][2])
    expected = push[:2] * z_f / sim.weight
    np.testing.assert_allclose(cop[:2] - com[:2], expected, atol=STATICS_TOL)
    np.testing.assert_allclose(total, [-push[0], -push[1], sim.weight], atol=0.05 * sim.weight)
    if np.any(push):
        assert np.linalg.norm(expected) > 10 * STATICS_TOL  # the shift is measurable
