"""Whole-body QP (control/wbc.py) on a free-floating rigid box, checked by hand: Newton-Euler with
the returned corner forces, the centre of pressure computed from those forces, the friction
pyramid, infeasible problems, warm starts against cold solves, input errors naming the field."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from footfall.control.wbc import (
    Contact,
    MotionTask,
    WbcProblem,
    WholeBodyController,
    WrenchTask,
    tangent_basis,
)
from footfall.errors import InputError, SolverError

#: Newton-Euler residuals with the QP's forces and accelerations [N, N m]
BALANCE_TOL = 1e-6
#: friction pyramid and unilateral contact slack [N]
CONE_TOL = 1e-8
#: commanded vs realised centre of pressure [m]
COP_TOL = 1e-6
#: warm-started vs cold solve of the same problem
WARM_TOL = 1e-7

MASS = 2.0
HALF = np.array([0.2, 0.15, 0.1])  # half extents of the box [m]
#: box inertia about its CoM in its own axes [kg m^2]
INERTIA = MASS / 3.0 * np.diag([HALF[1] ** 2 + HALF[2] ** 2, HALF[0] ** 2 + HALF[2] ** 2,
                                HALF[0] ** 2 + HALF[1] ** 2])  # fmt: skip
GRAVITY = np.array([0.0, 0.0, -9.81])
FRICTION = 0.8
#: the box's bottom corners in its own axes (the contact points)
CORNERS_BODY = np.array(
    [[sx * HALF[0], sy * HALF[1], -HALF[2]] for sx in (1, -1) for sy in (1, -1)]
)
#: horizontal moment rows of a wrench (force; moment)
HORIZONTAL_MOMENT = np.hstack([np.zeros((2, 3)), np.eye(3)[:2]])


def cross_matrix(v: np.ndarray) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def box_problem(
    rot: np.ndarray,
    omega_body: np.ndarray,
    com: np.ndarray,
    origin_body: np.ndarray,
    wrench_tasks: tuple[WrenchTask, ...] = (),
    friction: float = FRICTION,
) -> WbcProblem:
    """The box with generalised velocity (v world, omega body axes): M = diag(m I, I_b),
    h = (-m g, omega x I_b omega); one contact body (the box) whose reference point is
    ``origin_body`` (box axes), touching at its four bottom corners, normal = the box's z axis."""
    mass = np.zeros((6, 6))
    mass[:3, :3] = MASS * np.eye(3)
    mass[3:, 3:] = INERTIA
    bias = np.concatenate([-MASS * GRAVITY, np.cross(omega_body, INERTIA @ omega_body)])
    r = rot @ origin_body  # origin - CoM, world
    omega = rot @ omega_body
    jac = np.zeros((6, 6))
    # velocity of the origin: v + omega x r = v - [r]x R omega_b; angular velocity R omega_b
    jac[:3, :3] = np.eye(3)
    jac[:3, 3:] = -cross_matrix(r) @ rot
    jac[3:, 3:] = rot
    # d/dt(R omega_b) = R omega_b' (the omega_b x omega_b term vanishes), so only the origin's
    # centripetal acceleration is drift
    drift = np.concatenate([np.cross(omega, np.cross(omega, r)), np.zeros(3)])
    contact = Contact(
        name="box",
        jacobian=jac,
        drift=drift,
        origin=com + r,
        points=com + CORNERS_BODY @ rot.T,
        normal=rot[:, 2].copy(),
        friction=friction,
    )
    return WbcProblem(
        mass_matrix=mass,
        bias=bias,
        actuated=np.zeros(0, dtype=int),
        torque_min=np.zeros(0),
        torque_max=np.zeros(0),
        contacts=(contact,),
        wrench_tasks=wrench_tasks,
    )


def level_problem() -> WbcProblem:
    return box_problem(np.eye(3), np.zeros(3), np.array([0.3, -0.1, HALF[2]]), np.zeros(3))


#: the foot-and-mass robot: a level free-floating foot (the box, its CoM at ``FOOT_COM``) and a
#: point mass ``BODY_MASS`` at ``FOOT_COM + SLIDE`` moved by three actuated slides along the
#: world axes; at rest, so that M, h and the Jacobians are written by hand below
BODY_MASS = 10.0
FOOT_COM = np.array([0.3, -0.1, HALF[2]])
SLIDE = np.array([0.02, -0.03, 0.6])


def foot_and_mass_problem(tasks: tuple[WrenchTask, ...] = ()) -> WbcProblem:
    """Generalised velocity (v foot, omega foot (world = foot axes), slide rates) (9,). The
    point mass moves at J_b qd with J_b = [I, -[s]x, I]; so M = diag(m_f I, I_f, 0) +
    m_b J_b^T J_b and h = -(m_f g; 0; 0) - m_b J_b^T g (gravity only, at rest)."""
    jb = np.hstack([np.eye(3), -cross_matrix(SLIDE), np.eye(3)])
    mass = BODY_MASS * jb.T @ jb
    mass[:3, :3] += MASS * np.eye(3)
    mass[3:6, 3:6] += INERTIA
    bias = -BODY_MASS * jb.T @ GRAVITY
    bias[:3] -= MASS * GRAVITY
    jac = np.zeros((6, 9))
    jac[:, :6] = np.eye(6)
    contact = Contact(
        "foot", jac, np.zeros(6), FOOT_COM, FOOT_COM + CORNERS_BODY, np.array([0.0, 0.0, 1.0]),
        FRICTION,
    )  # fmt: skip
    return WbcProblem(
        mass_matrix=mass,
        bias=bias,
        actuated=np.array([6, 7, 8]),
        torque_min=np.full(3, -1e3),
        torque_max=np.full(3, 1e3),
        contacts=(contact,),
        wrench_tasks=tasks,
    )


def cop_task(
    moment: np.ndarray, about: np.ndarray, weight: float = 1e4, contact: str = "foot"
) -> WrenchTask:
    return WrenchTask("cop", about, HORIZONTAL_MOMENT, moment, weight, contacts=(contact,))


def cop_of(points: np.ndarray, forces: np.ndarray) -> np.ndarray:
    """Centre of pressure on the plane z = const: the normal-force-weighted mean of the points."""
    return (forces[:, 2] @ points) / forces[:, 2].sum()


def test_newton_euler_of_a_spinning_tilted_box() -> None:
    """A tilted box spinning about a skew axis, its contact body referenced off the CoM (so the
    drift is the centripetal term): the QP's accelerations keep the reference point still
    (a + alpha x r + omega x (omega x r) = 0, alpha = 0) and its forces satisfy Newton
    (sum f = m (a - g)) and Euler about the CoM (sum (p - c) x f = R (I w' + w x I w))."""
    rot = Rotation.from_rotvec([0.1, -0.15, 0.4]).as_matrix()
    omega_b = np.array([0.5, -0.3, 0.8])
    com = np.array([0.1, 0.2, 0.3])
    origin_b = np.array([0.05, -0.02, -HALF[2]])
    p = box_problem(rot, omega_b, com, origin_b)
    sol = WholeBodyController().solve(p)
    a, alpha_b = sol.qacc[:3], sol.qacc[3:]
    f = sol.forces["box"]
    pts = p.contacts[0].points
    r, omega = rot @ origin_b, rot @ omega_b
    assert np.allclose(alpha_b, 0.0, atol=BALANCE_TOL)
    centripetal = np.cross(omega, np.cross(omega, r))
    assert np.linalg.norm(centripetal) > 0.01  # the test means something
    np.testing.assert_allclose(a, -centripetal, atol=BALANCE_TOL)
    np.testing.assert_allclose(f.sum(axis=0), MASS * (a - GRAVITY), atol=BALANCE_TOL)
    euler = rot @ (INERTIA @ alpha_b + np.cross(omega_b, INERTIA @ omega_b))
    np.testing.assert_allclose(np.cross(pts - com, f).sum(axis=0), euler, atol=BALANCE_TOL)
    assert sol.torque.shape == (0,)


def test_free_fall_without_contacts() -> None:
    """No contact, no actuator: the unactuated dynamics alone fix qdd = -M^-1 h (free fall plus
    the torque-free Euler equations)."""
    omega_b = np.array([1.0, -2.0, 0.5])
    p = replace(box_problem(np.eye(3), omega_b, np.zeros(3), np.zeros(3)), contacts=())
    sol = WholeBodyController().solve(p)
    np.testing.assert_allclose(sol.qacc[:3], GRAVITY, atol=1e-9)
    euler = -np.linalg.solve(INERTIA, np.cross(omega_b, INERTIA @ omega_b))
    np.testing.assert_allclose(sol.qacc[3:], euler, atol=1e-9)


def test_passive_box_cop_is_below_its_com() -> None:
    """A box that may not accelerate and has no actuator: Euler about the CoM puts the CoP
    straight below it whatever a CoP task asks (hard constraints beat tasks)."""
    p = level_problem()
    about = p.contacts[0].points.mean(axis=0)
    task = cop_task(np.array([5.0, -3.0]), about, contact="box")
    f = WholeBodyController().solve(replace(p, wrench_tasks=(task,))).forces["box"]
    np.testing.assert_allclose(cop_of(p.contacts[0].points, f)[:2], about[:2], atol=COP_TOL)


def _check_foot_and_mass(p: WbcProblem, sol) -> np.ndarray:  # type: ignore[no-untyped-def]
    """Newton and Euler (about the world origin) of the whole robot with the QP's forces, the
    slide forces m_b (s'' - g) (the mass's own Newton law); returns the foot's forces."""
    f = sol.forces["foot"]
    pts = p.contacts[0].points
    np.testing.assert_allclose(sol.qacc[:6], 0.0, atol=BALANCE_TOL)  # the foot stays put
    sdd = sol.qacc[6:]
    body = FOOT_COM + SLIDE
    total = MASS + BODY_MASS
    np.testing.assert_allclose(f.sum(axis=0) + total * GRAVITY, BODY_MASS * sdd, atol=BALANCE_TOL)
    moment = (
        np.cross(pts, f).sum(axis=0)
        + np.cross(FOOT_COM, MASS * GRAVITY)
        + np.cross(body, BODY_MASS * GRAVITY)
    )
    np.testing.assert_allclose(moment, np.cross(body, BODY_MASS * sdd), atol=BALANCE_TOL)
    np.testing.assert_allclose(sol.torque, BODY_MASS * (sdd - GRAVITY), atol=BALANCE_TOL)
    assert np.all(f[:, 2] >= -CONE_TOL)
    return np.asarray(f)


@pytest.mark.parametrize("cop", [(0.0, 0.0), (0.12, -0.05), (-0.15, 0.1), (0.05, 0.14)])
def test_commanded_cop_is_realised(cop: tuple[float, float]) -> None:
    """A moment target about the sole centre o: m = sum (p - o) x f, whose horizontal rows on a
    level sole are (F_z y_cop, -F_z x_cop) with the CoP measured from o. The CoP computed from
    the returned corner forces is the commanded one, and the robot obeys Newton-Euler."""
    p0 = foot_and_mass_problem()
    about = p0.contacts[0].points.mean(axis=0)
    fz = (MASS + BODY_MASS) * -GRAVITY[2]  # with no vertical acceleration asked, roughly
    target = np.array([fz * cop[1], -fz * cop[0]])
    p = replace(p0, wrench_tasks=(cop_task(target, about),))
    sol = WholeBodyController().solve(p)
    f = _check_foot_and_mass(p, sol)
    # the moment target fixes F_z x_cop, not x_cop: compare with the realised normal force
    got = cop_of(p.contacts[0].points, f)[:2] - about[:2]
    np.testing.assert_allclose(got * f[:, 2].sum(), target[::-1] * [-1.0, 1.0], atol=1e-4)
    if cop != (0.0, 0.0):
        assert np.linalg.norm(got) > 0.5 * np.linalg.norm(cop)


def test_cop_outside_the_sole_saturates_at_its_edge() -> None:
    """A CoP commanded beyond the front edge cannot be realised with f.n >= 0: it lands on the
    edge (the back corners unloaded), not beyond it."""
    p0 = foot_and_mass_problem()
    about = p0.contacts[0].points.mean(axis=0)
    fz = (MASS + BODY_MASS) * -GRAVITY[2]
    p = replace(p0, wrench_tasks=(cop_task(np.array([0.0, -fz * 0.5]), about),))
    f = _check_foot_and_mass(p, WholeBodyController().solve(p))
    cop = cop_of(p.contacts[0].points, f)
    assert cop[0] - about[0] == pytest.approx(HALF[0], abs=COP_TOL)
    back = CORNERS_BODY[:, 0] < 0
    np.testing.assert_allclose(f[back], 0.0, atol=1e-6)


def test_warm_start_does_not_change_the_solution() -> None:
    """daqp is warm-started from the last tick's active set; a problem solved after another one
    (whose active set holds lower bounds: unloaded corners) must give the cold solve's answer."""
    p0 = foot_and_mass_problem()
    about = p0.contacts[0].points.mean(axis=0)
    fz = (MASS + BODY_MASS) * -GRAVITY[2]
    edge = replace(p0, wrench_tasks=(cop_task(np.array([0.0, -fz * 0.5]), about),))
    inside = replace(p0, wrench_tasks=(cop_task(np.array([fz * 0.03, fz * 0.02]), about),))
    for first, second in ((edge, inside), (inside, edge), (edge, edge)):
        warm = WholeBodyController()
        warm.solve(first)
        got = warm.solve(second)
        cold = WholeBodyController().solve(second)
        np.testing.assert_allclose(got.qacc, cold.qacc, atol=WARM_TOL)
        np.testing.assert_allclose(got.forces["foot"], cold.forces["foot"], atol=WARM_TOL)


def slope_problem(tan: float) -> WbcProblem:
    """The box resting on a slope of ``tan`` about the world y axis (the slope falls along the
    box's x axis, which is the pyramid's second tangent n x (n x e_x))."""
    rot = Rotation.from_rotvec([0.0, math.atan(tan), 0.0]).as_matrix()
    return box_problem(rot, np.zeros(3), np.array([0.0, 0.0, 0.5]), np.zeros(3))


def test_friction_pyramid_holds_on_a_slope() -> None:
    """On a slope just inside the pyramid every corner force satisfies |f.t_k| <= mu/sqrt(2) f.n
    for two unit tangents computed here, and f.n >= 0; the forces carry the weight."""
    tan = 0.98 * FRICTION / math.sqrt(2.0)
    p = slope_problem(tan)
    sol = WholeBodyController().solve(p)
    f = sol.forces["box"]
    n = p.contacts[0].normal
    t1 = np.cross(n, [1.0, 0.0, 0.0])
    t1 /= np.linalg.norm(t1)
    t2 = np.cross(n, t1)
    fn = f @ n
    share = FRICTION / math.sqrt(2.0)
    assert np.all(fn >= -CONE_TOL)
    assert np.all(np.abs(f @ t1) <= share * fn + CONE_TOL)
    assert np.all(np.abs(f @ t2) <= share * fn + CONE_TOL)
    np.testing.assert_allclose(f.sum(axis=0), -MASS * GRAVITY, atol=BALANCE_TOL)
    # the library's tangents are this orthonormal pair (up to sign)
    lt1, lt2 = tangent_basis(n)
    assert abs(abs(lt1 @ t1) - 1.0) < 1e-12 and abs(abs(lt2 @ t2) - 1.0) < 1e-12


@pytest.mark.parametrize("share", [1.03 / math.sqrt(2.0), 1.05])
def test_slope_steeper_than_the_pyramid_is_infeasible(share: float) -> None:
    """The box must not accelerate and has no actuator: beyond the pyramid along its tangent
    (tan > mu/sqrt(2)), or beyond Coulomb's cone itself, the QP has no solution."""
    with pytest.raises(SolverError, match="no solution"):
        WholeBodyController().solve(slope_problem(share * FRICTION))


def slider_problem(torque_max: float, normal_z: float = -1.0) -> WbcProblem:
    """A vertical actuated slider of mass m whose end may not accelerate, touching a ceiling
    that can only push down (normal -z): the motor must carry the weight alone."""
    jac = np.zeros((6, 1))
    jac[2, 0] = 1.0
    contact = Contact(
        "tip", jac, np.zeros(6), np.zeros(3), np.zeros((1, 3)), np.array([0.0, 0.0, normal_z]), 1.0
    )
    return WbcProblem(
        mass_matrix=np.array([[MASS]]),
        bias=np.array([MASS * 9.81]),
        actuated=np.array([0]),
        torque_min=np.array([-torque_max]),
        torque_max=np.array([torque_max]),
        contacts=(contact,),
    )


def test_torque_limit_makes_the_qp_infeasible() -> None:
    weight = MASS * 9.81
    sol = WholeBodyController().solve(slider_problem(1.01 * weight))
    assert sol.torque[0] == pytest.approx(weight, abs=1e-6)
    assert sol.qacc[0] == pytest.approx(0.0, abs=1e-9)
    with pytest.raises(SolverError):
        WholeBodyController().solve(slider_problem(0.99 * weight))


def test_inconsistent_contacts_are_infeasible() -> None:
    """Two contacts on the same body asking for different accelerations of the same point."""
    p = level_problem()
    c = p.contacts[0]
    other = replace(c, name="twin", drift=c.drift + np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0]))
    with pytest.raises(SolverError):
        WholeBodyController().solve(replace(p, contacts=(c, other)))


def test_unbounded_torque_limits_are_accepted() -> None:
    """MujocoWbcModel gives +-inf for an actuator without a force range ("else unbounded"):
    solve(check=True) must accept them, and the motor then carries the weight."""
    sol = WholeBodyController().solve(slider_problem(math.inf))
    assert sol.torque[0] == pytest.approx(MASS * 9.81, abs=1e-6)


def test_motion_task_is_tracked_with_an_actuator() -> None:
    """The slider without contact: a weighted acceleration task is met exactly (the torque
    regularisation is tiny), tau = m a + m g."""
    p = replace(
        slider_problem(1e3),
        contacts=(),
        motion_tasks=(MotionTask("lift", np.ones((1, 1)), np.zeros(1), np.array([2.0]), 1.0),),
    )
    sol = WholeBodyController().solve(p)
    assert sol.qacc[0] == pytest.approx(2.0, abs=1e-4)
    assert sol.torque[0] == pytest.approx(MASS * (2.0 + 9.81), abs=1e-3)


# --------------------------------------------------------------------------- input errors
def _field_error(problem: WbcProblem, field: str) -> None:
    with pytest.raises(InputError) as err:
        WholeBodyController().solve(problem)
    assert err.value.field == field
    assert field in str(err.value)


def test_wrong_shapes_name_the_field() -> None:
    p = level_problem()
    c = p.contacts[0]
    _field_error(replace(p, bias=np.zeros(5)), "bias")
    _field_error(replace(p, mass_matrix=np.eye(6)[:, :5]), "mass_matrix")
    _field_error(
        replace(p, contacts=(replace(c, jacobian=np.zeros((6, 5))),)), "contact box.jacobian"
    )
    _field_error(replace(p, contacts=(replace(c, drift=np.zeros(3)),)), "contact box.drift")
    _field_error(replace(p, contacts=(replace(c, points=np.zeros((4, 2))),)), "contact box.points")
    _field_error(replace(p, torque_min=np.zeros(1)), "torque_min")
    task = MotionTask("t", np.zeros((2, 5)), np.zeros(2), np.zeros(2))
    _field_error(replace(p, motion_tasks=(task,)), "task t.jacobian")
    wt = WrenchTask("w", np.zeros(3), np.zeros((2, 5)), np.zeros(2))
    _field_error(replace(p, wrench_tasks=(wt,)), "task w.rows")


def test_non_finite_values_name_the_field() -> None:
    p = level_problem()
    c = p.contacts[0]
    bad = np.array([0.0, np.nan, 0.0, 0.0, 0.0, 0.0])
    _field_error(replace(p, bias=bad), "bias")
    _field_error(replace(p, contacts=(replace(c, drift=bad),)), "contact box.drift")
    _field_error(replace(p, contacts=(replace(c, friction=math.nan),)), "contact box.friction")


def test_non_finite_contact_points_name_the_field() -> None:
    p = level_problem()
    c = p.contacts[0]
    pts = c.points.copy()
    pts[1, 2] = math.inf
    _field_error(replace(p, contacts=(replace(c, points=pts),)), "contact box.points")


def test_non_finite_motion_target_names_the_field() -> None:
    """The docstring promises InputError on non-finite values; a task's desired acceleration is
    one of them (today a NaN there reaches daqp, which returns an all-NaN 'optimal' solution)."""
    task = MotionTask("t", np.eye(6)[:2], np.zeros(2), np.array([0.0, np.nan]))
    _field_error(replace(level_problem(), motion_tasks=(task,)), "task t.acceleration")


def test_non_finite_wrench_target_names_the_field() -> None:
    wt = cop_task(np.array([np.inf, 0.0]), np.zeros(3), contact="box")
    _field_error(replace(level_problem(), wrench_tasks=(wt,)), "task cop.target")


def test_unchecked_nan_is_not_returned_as_a_solution() -> None:
    """The walk solves with check=False every tick: a NaN that slips in (a diverged state) must
    raise SolverError (the walk then keeps the last torques), not become NaN joint torques."""
    task = MotionTask("t", np.eye(6)[:2], np.zeros(2), np.array([0.0, np.nan]))
    p = replace(level_problem(), motion_tasks=(task,))
    try:
        sol = WholeBodyController().solve(p, check=False)
    except SolverError:
        return
    assert np.all(np.isfinite(sol.qacc)), "NaN accelerations returned as a solution"


def test_negative_weights_name_the_task() -> None:
    p = level_problem()
    wt = cop_task(np.zeros(2), np.zeros(3), -1.0, contact="box")
    _field_error(replace(p, wrench_tasks=(wt,)), "task cop.weight")
    task = MotionTask("t", np.eye(6)[:2], np.zeros(2), np.zeros(2), np.array([1.0, -1.0]))
    _field_error(replace(p, motion_tasks=(task,)), "task t.weight")
    task = MotionTask("t", np.eye(6)[:2], np.zeros(2), np.zeros(2), np.ones(3))
    _field_error(replace(p, motion_tasks=(task,)), "task t.weight")


def test_contact_names_are_checked() -> None:
    p = level_problem()
    c = p.contacts[0]
    _field_error(replace(p, contacts=(c, c)), "contacts")
    wt = replace(cop_task(np.zeros(2), np.zeros(3)), contacts=("box", "left"))
    with pytest.raises(InputError) as err:
        WholeBodyController().solve(replace(p, wrench_tasks=(wt,)))
    assert err.value.field == "task cop.contacts" and "left" in str(err.value)
