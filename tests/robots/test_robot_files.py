"""Robots from their files: the built-in G1 and Talos (example-robot-data URDFs) checked against
independent references: the URDF read with ElementTree (masses, joints, limits, foot collision
geometry), MuJoCo's own quantities (mass, CoM), forward kinematics of the derived postures, and
inverse kinematics sampled inside the derived reach.

Needs the ``robots`` extra; without it the module is skipped, except with
``FOOTFALL_REQUIRE_ROBOTS=1`` (set by .ci/run): then it fails.
"""

from __future__ import annotations

import importlib.metadata
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

# isort: off
# first: without the robots extra this skips the module (or fails with FOOTFALL_REQUIRE_ROBOTS=1)
from tests.robots._require import mujoco

# isort: on

from footfall._geometry import convex_hull
from footfall.errors import InputError, MissingExtraError
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.robots.build import layout, raw_model, sole_from_geometry
from footfall.robots.derive import IK_TOL, JOINT_MARGIN, stance_feasible
from footfall.robots.file import LEG_JOINT_ROLES, parse_robot_file
from footfall.robots.model import RobotModel, _kinematics
from footfall.robots.registry import builtin_robot_file, builtin_robot_names
from footfall.sim.biped.model import measure_model, planner_params
from footfall.sim.biped.plans import robot_model
from footfall.terrain import builtin_scene

pytestmark = pytest.mark.robots

ROBOTS = ("g1", "talos")
#: the MJCF text MuJoCo writes keeps about 7 significant digits of each link mass [kg]
MASS_TOL = 1e-5
#: exact copies (joint axes, limits, efforts) up to the MJCF text's digits
COPY_TOL = 1e-6
#: the nominal posture's residuals [m, rad]
POSTURE_TOL = 1e-6
#: the leg joints of each robot in footfall's order, read off its URDF by hand
HAND_LEGS = {
    "g1": {
        s: tuple(f"{s.value}_{j}_joint" for j in LEG_JOINT_ROLES) for s in (Side.LEFT, Side.RIGHT)
    },
    "talos": {
        s: tuple(f"leg_{s.value}_{k}_joint" for k in range(1, 7)) for s in (Side.LEFT, Side.RIGHT)
    },
}


def _urdf(name: str) -> ET.Element:
    return ET.parse(builtin_robot_file(name).model).getroot()


def _walker(name: str) -> object:
    return mujoco.MjModel.from_xml_string(robot_model(name).mjcf())


def test_builtin_robots_are_files_besides_our_biped() -> None:
    assert builtin_robot_names() == ["biped", "g1", "talos"]
    for name in ROBOTS:
        rf = builtin_robot_file(name)
        assert rf.package is not None and rf.package[0] == "example-robot-data"
        assert rf.model.suffix == ".urdf" and rf.model.is_file()


@pytest.mark.parametrize("name", ROBOTS)
def test_legs_found_in_the_model_are_the_hand_read_ones(name: str) -> None:
    rf = builtin_robot_file(name)
    found = layout(type(rf)(name=rf.name, model=rf.model)).legs  # nothing given: all found
    for s in (Side.LEFT, Side.RIGHT):
        assert found.of(s) == HAND_LEGS[name][s]


@pytest.mark.parametrize("name", ROBOTS)
def test_walker_has_the_urdf_leg_joints_under_the_walker_names(name: str) -> None:
    m = _walker(name)
    urdf = {j.get("name"): j for j in _urdf(name).findall("./joint")}
    obj = mujoco.mjtObj
    assert m.nu == 12 and m.njnt == 13  # the free joint and the legs: everything else is fixed
    for s in (Side.LEFT, Side.RIGHT):
        for role, src_name in zip(nm.LEG_JOINTS, HAND_LEGS[name][s], strict=True):
            jid = mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.joint(s, role))
            assert jid >= 0
            src = urdf[src_name]
            axis = np.array([float(v) for v in src.find("axis").get("xyz").split()])
            lim = src.find("limit")
            lo, hi = float(lim.get("lower")), float(lim.get("upper"))
            k = int(np.argmax(np.abs(axis)))
            # an axis along a negative direction is turned around with its range negated
            sign = 1.0 if axis[k] > 0 else -1.0
            assert np.allclose(m.jnt_axis[jid], sign * axis, atol=COPY_TOL)
            expect = [lo, hi] if sign > 0 else [-hi, -lo]
            assert np.allclose(m.jnt_range[jid], expect, atol=COPY_TOL)
            act = mujoco.mj_name2id(m, obj.mjOBJ_ACTUATOR, nm.actuator(s, role))
            effort = float(lim.get("effort"))
            assert np.allclose(m.actuator_forcerange[act], [-effort, effort], atol=COPY_TOL)


@pytest.mark.parametrize("name", ROBOTS)
def test_mass_is_the_sum_of_the_urdf_link_masses(name: str) -> None:
    urdf_mass = sum(float(e.get("value")) for e in _urdf(name).iter("mass"))
    assert urdf_mass > 30.0
    assert abs(float(np.sum(_walker(name).body_mass)) - urdf_mass) < MASS_TOL
    assert abs(measure_model(robot_model(name)).mass - urdf_mass) < MASS_TOL


@pytest.mark.parametrize("name", ROBOTS)
def test_nominal_posture_by_forward_kinematics(name: str) -> None:
    """Soles flat at z = 0, stance_width apart, the CoM (summed by hand from MuJoCo's body masses
    and positions) above their midpoint, every joint inside its range."""
    walker = robot_model(name)
    m = _walker(name)
    d = mujoco.MjData(m)
    d.qpos[2] = walker.pelvis_height
    d.qpos[3] = 1.0
    q = walker.nominal_joints()
    for i, s in enumerate((Side.LEFT, Side.RIGHT)):
        for k, j in enumerate(nm.LEG_JOINTS):
            jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, nm.joint(s, j))
            assert m.jnt_range[jid, 0] <= q[6 * i + k] <= m.jnt_range[jid, 1]
            d.qpos[m.jnt_qposadr[jid]] = q[6 * i + k]
    mujoco.mj_kinematics(m, d)
    soles = []
    for s in (Side.LEFT, Side.RIGHT):
        sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, nm.sole_site(s))
        assert abs(d.site_xpos[sid][2]) < POSTURE_TOL
        assert np.allclose(d.site_xmat[sid].reshape(3, 3)[2], [0, 0, 1], atol=POSTURE_TOL)
        soles.append(d.site_xpos[sid].copy())
    assert soles[0][1] - soles[1][1] == pytest.approx(walker.stance_width, abs=POSTURE_TOL)
    com = (m.body_mass[:, None] * d.xipos).sum(axis=0) / m.body_mass.sum()
    mid = 0.5 * (soles[0] + soles[1])
    assert np.allclose(com[:2], mid[:2], atol=POSTURE_TOL)
    info = measure_model(walker)
    assert info.com_height == pytest.approx(com[2] - mid[2], abs=POSTURE_TOL)


FloatPoint = tuple[float, float, float]


def _urdf_foot_spheres() -> list[tuple[FloatPoint, float]]:
    """The G1's left foot collision spheres (centre in the ankle roll link, radius), by hand."""
    link = next(e for e in _urdf("g1").findall("./link") if e.get("name") == "left_ankle_roll_link")
    out = []
    for col in link.findall("collision"):
        sphere = col.find("geometry/sphere")
        if sphere is None:
            continue
        xyz = [float(v) for v in col.find("origin").get("xyz").split()]
        out.append((tuple(xyz), float(sphere.get("radius"))))
    return out


def test_g1_sole_lies_on_its_collision_spheres() -> None:
    spheres = _urdf_foot_spheres()
    assert len(spheres) == 4
    sole = layout(builtin_robot_file("g1")).sole
    # on the plane through the spheres' lowest points
    assert sole.z == pytest.approx(min(c[2] - r for c, r in spheres), abs=1e-9)
    # the rectangle's corners lie in the footprint: the hull of the spheres' bottom discs
    ring = [(math.cos(a), math.sin(a)) for a in np.linspace(0, 2 * math.pi, 64, endpoint=False)]
    disc = np.array([[c[0] + r * u, c[1] + r * v] for c, r in spheres for u, v in ring])
    hull = convex_hull(disc)
    for x in sole.x:
        for y in sole.y:
            assert _inside(hull, (x, y), tol=1e-3)
    # and it spans most of it (the largest rectangle, not a small one)
    assert sole.length * sole.width > 0.85 * _area(hull)
    # the same sole from the geometry again (the built-in file holds the derived one)
    derived = sole_from_geometry(raw_model(builtin_robot_file("g1")), "left_ankle_roll_link")
    assert derived.x == pytest.approx(sole.x, abs=1e-4)


def _inside(hull: np.ndarray, p: tuple[float, float], tol: float) -> bool:
    n = hull.shape[0]
    for i in range(n):
        a, b = hull[i], hull[(i + 1) % n]
        if (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) < -tol * np.hypot(
            *(b - a)
        ):
            return False
    return True


def _area(hull: np.ndarray) -> float:
    x, y = hull[:, 0], hull[:, 1]
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


@pytest.mark.parametrize("name", ROBOTS)
def test_reach_is_held_by_the_legs_inside_and_not_far_outside(name: str) -> None:
    """Points sampled inside the derived trapezoid (the derivation probed only its edges) are held
    at every step height within the bound; the inverse kinematics' joints, put through MuJoCo's
    forward kinematics on their own, place both soles flat on their targets."""
    rf = builtin_robot_file(name)
    walker = RobotModel(rf)
    kin = _kinematics(rf)
    q0 = walker.nominal_joints()
    reach = np.array(rf.reach)
    h = rf.step_height_max
    rng = np.random.default_rng(3)
    for _ in range(4):
        w = rng.dirichlet(np.ones(4))
        dx, dy = w @ reach
        for dz in (h, 0.0, -h):
            assert stance_feasible(kin, dx, dy, dz, walker.pelvis_height, q0), (dx, dy, dz)
    # check one solution by forward kinematics alone, in a model of its own
    dx, dy = reach.mean(axis=0)
    targets = [np.array([dx / 2, dy / 2, h / 2]), np.array([-dx / 2, -dy / 2, -h / 2])]
    q, pelvis, res = kin.solve(targets, walker.pelvis_height, q0)
    assert res < IK_TOL
    assert np.all(q >= kin.range[:, 0] + JOINT_MARGIN - 1e-9)
    assert np.all(q <= kin.range[:, 1] - JOINT_MARGIN + 1e-9)
    m = mujoco.MjModel.from_xml_string(walker.mjcf())
    d = mujoco.MjData(m)
    d.qpos[kin.root : kin.root + 3] = pelvis
    d.qpos[kin.root + 3] = 1.0
    d.qpos[kin.adr] = q
    mujoco.mj_kinematics(m, d)
    for sid, target in zip(kin.sites, targets, strict=True):
        assert np.allclose(d.site_xpos[sid], target, atol=1e-5)
        assert np.allclose(d.site_xmat[sid].reshape(3, 3)[2], [0, 0, 1], atol=1e-5)
    # far outside: twice the forward reach is not held stepping down by the step height (the
    # reach is where the legs hold every height within the bound; level steps reach further)
    far = 2.0 * float(reach[:, 0].max())
    mid_y = float(reach[:, 1].mean())
    assert not stance_feasible(kin, far, mid_y, -h, walker.pelvis_height, q0)


@pytest.mark.parametrize("name", ROBOTS)
def test_planner_params_come_from_the_robot(name: str) -> None:
    walker = robot_model(name)
    scene = builtin_scene("flat_long")
    info = measure_model(walker)
    robot = planner_params(walker, base=scene.robot)
    rf = builtin_robot_file(name)
    assert robot.mass == info.mass and robot.com_height == info.com_height
    assert np.allclose(robot.reach.vertices, np.array(rf.reach))
    assert robot.step_height_max == rf.step_height_max
    # the heavier legs need a slower single support than the document's 0.4 s
    assert robot.t_ss > scene.robot.t_ss
    # a planned ZMP stays inside the sole and within the ankles' torque
    assert robot.u_max / (robot.mass * robot.g) < robot.foot_width / 2
    # footfall's own biped keeps the document's parameters
    biped = planner_params(robot_model("biped"), base=scene.robot)
    assert biped.t_ss == scene.robot.t_ss and np.allclose(
        biped.reach.vertices, scene.robot.reach.vertices
    )


def test_robot_file_errors_name_their_field(tmp_path: Path) -> None:
    rf = builtin_robot_file("g1")
    assert rf.package is not None
    good = f"name: x\nmodel: {{package: {rf.package[0]}, path: {rf.package[1]}}}\n"
    cases = {
        "name: x\n": "model",
        good + "legs: {left: [a, b], right: [c]}\n": "legs",
        good + "pelvis_height: -1\n": "pelvis_height",
        good + "reach: [[0, 0.1], [0.1, 0.1], [0.1, 0.2], [0.3, 0.05]]\n": "reach",
        good + "colour: red\n": "colour",
        "name: x\nmodel: nowhere.urdf\n": "model",
        "name: x\nmodel: {package: no-such-dist, path: a.urdf}\n": "no-such-dist",
    }
    for text, field in cases.items():
        with pytest.raises((InputError, MissingExtraError)) as err:
            parse_robot_file(text, "t.yaml", tmp_path)
        assert field in str(err.value), (text, str(err.value))
    with pytest.raises(InputError, match="robot"):
        robot_model("atlas")


def test_a_model_without_legs_says_which_names_to_give(tmp_path: Path) -> None:
    urdf = tmp_path / "arm.urdf"
    urdf.write_text(
        '<robot name="arm"><link name="base"><inertial><mass value="1"/>'
        '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
    )
    rf = parse_robot_file(f"name: arm\nmodel: {urdf.name}\n", "t.yaml", tmp_path)
    with pytest.raises(InputError, match="leg"):
        layout(rf)


def test_a_model_inside_an_installed_package_is_named_by_package_and_path() -> None:
    """A robot file written for a model of example-robot-data names the distribution and the
    file in it (found anywhere), not this machine's site-packages path; a file outside any
    distribution keeps its path."""
    from footfall.robots.file import package_file, package_of

    rel = "cmeel.prefix/share/example-robot-data/robots/talos_data/robots/talos_reduced.urdf"
    found = package_file("example-robot-data", rel)
    # the RECORD of the distribution, read here by a different route than package_of's
    dist = importlib.metadata.distribution("example-robot-data")
    assert rel in {str(f) for f in dist.files or ()}
    assert package_of(found) == ("example-robot-data", rel)
    assert package_of(Path(__file__)) is None
