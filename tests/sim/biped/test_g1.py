"""The Unitree G1 of example-robot-data as a walker model (issue 7, beyond the document).

Needs the ``robots`` extra. Without it these tests are skipped with a reason, except when
``FOOTFALL_REQUIRE_ROBOTS=1`` (set by .ci/run, which installs the extra): then they fail.
"""

from __future__ import annotations

import importlib.metadata
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")

try:
    importlib.metadata.distribution("example-robot-data")
except importlib.metadata.PackageNotFoundError:
    if os.environ.get("FOOTFALL_REQUIRE_ROBOTS") == "1":
        raise
    pytest.skip(
        "example-robot-data is not installed (pip install 'footfall[robots]')",
        allow_module_level=True,
    )

from footfall.sim.biped.g1 import G1Model, g1_urdf_path, urdf_joint  # noqa: E402

from footfall.errors import FootfallError, InputError  # noqa: E402
from footfall.models.biped import Side  # noqa: E402
from footfall.robots import names as nm  # noqa: E402
from footfall.sim.biped import g1 as g1_model  # noqa: E402
from footfall.sim.biped.model import measure_model, planner_params  # noqa: E402
from footfall.sim.biped.plans import robot_model  # noqa: E402
from footfall.sim.biped.plant import BipedSim, ankle_joint_torque  # noqa: E402
from footfall.terrain import builtin_scene  # noqa: E402

pytestmark = pytest.mark.robots

#: the MJCF text MuJoCo writes keeps about 7 significant digits of each link mass [kg]
MASS_TOL = 1e-5
#: exact copies (joint axes, limits, efforts) up to the MJCF text's digits
COPY_TOL = 1e-6
#: the nominal posture's residuals (solved to 1e-9) [m, rad]
POSTURE_TOL = 1e-7
#: standing on the servos for STAND_TIME: pelvis sag [m], CoM drift from the feet midpoint [m],
#: torso tilt [rad]
STAND_TIME = 3.0
STAND_SAG = 0.005
STAND_DRIFT = 0.01
STAND_TILT = math.radians(1.0)
#: short flat walk: mean distance of the landed soles from the commanded footsteps [m] (as for
#: our biped, tests.sim.biped.test_walk.LANDING_TOL)
WALK_LANDING_TOL = 0.06
#: footsteps of the short flat walk
WALK_STEPS = 6


def _urdf() -> ET.Element:
    return ET.parse(g1_urdf_path()).getroot()


def _model(params: G1Model | None = None) -> object:
    return mujoco.MjModel.from_xml_string((params or G1Model()).mjcf())


def test_g1_has_the_12_leg_joints_of_the_urdf_under_the_walker_names() -> None:
    m = _model()
    urdf = {j.get("name"): j for j in _urdf().findall("./joint")}
    obj = mujoco.mjtObj
    assert m.nu == 12
    assert m.njnt == 13  # the free joint and the legs: waist and arms are fixed
    for s in (Side.LEFT, Side.RIGHT):
        for j in nm.LEG_JOINTS:
            jid = mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.joint(s, j))
            assert jid >= 0, nm.joint(s, j)
            src = urdf[urdf_joint(s, j)]
            axis = np.array([float(v) for v in src.find("axis").get("xyz").split()])
            lim = src.find("limit")
            assert np.allclose(m.jnt_axis[jid], axis, atol=COPY_TOL)
            assert np.allclose(
                m.jnt_range[jid], [float(lim.get("lower")), float(lim.get("upper"))], atol=COPY_TOL
            )
            act = mujoco.mj_name2id(m, obj.mjOBJ_ACTUATOR, nm.actuator(s, j))
            effort = float(lim.get("effort"))
            assert np.allclose(m.actuator_forcerange[act], [-effort, effort], atol=COPY_TOL)
            assert m.actuator_gainprm[act, 0] == pytest.approx(effort / G1Model().servo_saturation)
        assert mujoco.mj_name2id(m, obj.mjOBJ_SITE, nm.sole_site(s)) >= 0
        for k in range(len(nm.FOOT_CORNERS)):
            assert mujoco.mj_name2id(m, obj.mjOBJ_GEOM, nm.corner_geom(s, k)) >= 0
    for kind, name in (
        (obj.mjOBJ_BODY, nm.PELVIS_BODY),
        (obj.mjOBJ_BODY, nm.TORSO_BODY),
        (obj.mjOBJ_GEOM, nm.PELVIS_GEOM),
        (obj.mjOBJ_GEOM, nm.TORSO_GEOM),
    ):
        assert mujoco.mj_name2id(m, kind, name) >= 0, name


def test_g1_mass_is_the_sum_of_the_urdf_link_masses() -> None:
    urdf_mass = sum(float(e.get("value")) for e in _urdf().iter("mass"))
    assert urdf_mass > 30.0  # the G1 with its arms, not only the legs
    assert abs(float(np.sum(_model().body_mass)) - urdf_mass) < MASS_TOL
    assert abs(measure_model(G1Model()).mass - urdf_mass) < MASS_TOL


def test_g1_nominal_posture_stands_flat_on_the_stance_width_with_the_com_over_the_feet() -> None:
    g = G1Model()
    info = measure_model(g)
    # measure_model puts the upright pelvis at pelvis_height; the posture must put the soles flat
    # at z = 0, stance_width apart, and the CoM straight above their midpoint
    m = _model(g)
    d = mujoco.MjData(m)
    d.qpos[2] = g.pelvis_height
    d.qpos[3] = 1.0
    sim_q = g.nominal_joints()
    for i, s in enumerate((Side.LEFT, Side.RIGHT)):
        for k, j in enumerate(nm.LEG_JOINTS):
            jid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, nm.joint(s, j))
            d.qpos[m.jnt_qposadr[jid]] = sim_q[6 * i + k]
    mujoco.mj_forward(m, d)
    ys = []
    for s in (Side.LEFT, Side.RIGHT):
        sid = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, nm.sole_site(s))
        assert abs(d.site_xpos[sid][2]) < POSTURE_TOL
        assert np.allclose(d.site_xmat[sid].reshape(3, 3)[2], [0, 0, 1], atol=POSTURE_TOL)
        ys.append(d.site_xpos[sid][1])
    assert ys[0] - ys[1] == pytest.approx(g.stance_width, abs=POSTURE_TOL)
    assert abs(info.com_offset[0]) < POSTURE_TOL
    assert 0.5 < info.com_height < g.pelvis_height


def test_planner_params_come_from_the_g1() -> None:
    g = G1Model()
    scene = builtin_scene("flat_long")
    info = measure_model(g)
    robot = planner_params(g, base=scene.robot)
    assert robot.mass == info.mass
    assert robot.com_height == info.com_height
    assert robot.stance_width == g.stance_width
    # the sole rectangle spans the URDF's foot spheres (heel x -0.05, toe x 0.12, r 5 mm)
    assert robot.foot_length == pytest.approx(0.18)
    assert robot.foot_width == pytest.approx(0.06)
    assert robot.u_max / (robot.mass * robot.g) < robot.foot_width / 2
    assert robot.t_ss == scene.robot.t_ss  # timing and reach stay the scene's


def test_g1_ankle_torque_carries_the_moment_of_the_weight_about_the_ankle() -> None:
    # zero ALIP torque = CoP at the sole centre, 35 mm ahead of the G1's ankle: the ankle pitch
    # joint holds the weight's moment (dx F_n about +y on the foot); roll has no offset
    g = G1Model()
    dx, dy = g.ankle_offset
    assert dx == pytest.approx(0.035) and dy == 0.0
    tau = ankle_joint_torque(np.zeros(2), np.eye(3), 300.0, g)
    assert tau == pytest.approx([dx * 300.0, 0.0])


def test_g1_stands_on_its_servos() -> None:
    scene = builtin_scene("flat")
    sim = BipedSim(scene, G1Model())
    sim.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    for s in sim.sides:
        assert np.allclose(sim.sole(s)[0], scene.start.foot(s), atol=POSTURE_TOL)
    z0 = float(sim.data.xpos[sim.pelvis][2])
    mid = 0.5 * (scene.start.left + scene.start.right)
    for _ in range(round(STAND_TIME / sim.model.opt.timestep)):
        mujoco.mj_step(sim.model, sim.data)
    com, _, _ = sim.com_state()
    contacts, body_hit = sim.contacts()
    assert not body_hit
    assert abs(float(sim.data.xpos[sim.pelvis][2]) - z0) < STAND_SAG
    assert np.linalg.norm(com[:2] - mid[:2]) < STAND_DRIFT
    up = sim.data.xmat[sim.torso].reshape(3, 3)[:, 2]
    assert math.acos(min(1.0, float(up[2]))) < STAND_TILT
    fz = sum(float(np.sum(f[:, 2])) for _, f in contacts.values())
    assert fz == pytest.approx(sim.weight, rel=0.02)


def test_g1_refuses_foreign_settings_and_bad_fields() -> None:
    with pytest.raises(InputError, match="settings"):
        G1Model().mjcf(settings=object())
    with pytest.raises(InputError, match=r"g1\.servo_saturation"):
        G1Model(servo_saturation=0.0)
    with pytest.raises(InputError, match="nominal_pelvis_height"):
        G1Model(nominal_pelvis_height=0.9).nominal_joints()  # above the straight legs (0.79 m)
    with pytest.raises(InputError, match="robot"):
        robot_model("atlas")


def test_missing_example_robot_data_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    def missing(name: str) -> object:
        raise importlib.metadata.PackageNotFoundError(name)

    g1_model.g1_urdf_path.cache_clear()
    monkeypatch.setattr(g1_model.importlib.metadata, "distribution", missing)
    try:
        with pytest.raises(FootfallError, match=r"footfall\[robots\]"):
            robot_model("g1")
    finally:
        monkeypatch.undo()
        g1_model.g1_urdf_path.cache_clear()


def test_cli_plans_for_the_g1_and_rejects_unknown_robots(tmp_path: object) -> None:
    import json
    from pathlib import Path

    from typer.testing import CliRunner

    from footfall.cli import app

    out = Path(str(tmp_path))
    runner = CliRunner()
    res = runner.invoke(
        app,
        ["plan", "--scene", "flat", "--planner", "kinematic", "--robot", "g1", "--out", str(out)],
    )
    assert res.exit_code == 0, res.output
    robot = json.loads((out / "plan.json").read_text())["robot"]
    info = measure_model(G1Model())
    assert robot["mass"] == pytest.approx(info.mass)
    assert robot["com_height"] == pytest.approx(info.com_height)
    # the runner bypasses main()'s error printing: the InputError itself comes back
    bad = runner.invoke(app, ["walk", "--scene", "flat", "--robot", "atlas", "--out", str(out)])
    assert isinstance(bad.exception, InputError)
    assert bad.exception.field == "robot" and bad.exception.value == "atlas"


def test_g1_walks_a_short_flat_plan_made_for_it() -> None:
    pytest.importorskip("mink")
    from dataclasses import replace

    from footfall.planning import PlannerOptions, make_plan
    from footfall.sim.biped.walk import walk
    from footfall.terrain import Goal

    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([1.0, 0.0, 0.0]), 0.0))
    g = G1Model()
    robot = planner_params(g, base=scene.robot)
    # 6 even steps of the kinematic planner with the whole sole inside the region, as
    # plan_for_walk plans (the reactive planner's uneven 0.2-0.3 m steps make the G1 fall)
    opts = PlannerOptions(region_margin=robot.foot_length / 2)
    plan = make_plan(scene, "kinematic", WALK_STEPS, opts, robot)
    res = walk(scene, plan, model_params=g)
    m = res.metrics
    assert not res.trace.fell
    assert m.reached_goal
    assert m.steps_landed == plan.n_steps
    assert m.footstep_error_vs_target_m.mean < WALK_LANDING_TOL
    assert m.zmp.samples > 0 and m.zmp.inside_share == 1.0
