"""Robots from their files on the walker: standing on the servos, planning for them from the
command line, a short flat walk with the whole-body controller, and the errors of a missing model
package or an unknown robot.

Needs the ``robots`` extra; without it the module is skipped, except with
``FOOTFALL_REQUIRE_ROBOTS=1`` (set by .ci/run): then it fails.
"""

from __future__ import annotations

import importlib.metadata
import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

# isort: off
# first: without the robots extra this skips the module (or fails with FOOTFALL_REQUIRE_ROBOTS=1)
from tests.robots._require import mujoco

# isort: on
from typer.testing import CliRunner

from footfall.cli import app
from footfall.errors import InputError, MissingExtraError
from footfall.robots import file as robot_file
from footfall.sim.biped.model import measure_model, planner_params
from footfall.sim.biped.plans import robot_model
from footfall.sim.biped.plant import BipedSim, ankle_joint_torque
from footfall.terrain import Goal, builtin_scene

pytestmark = pytest.mark.robots

#: standing on the servos for STAND_TIME [s]: pelvis sag [m], CoM drift from the feet midpoint
#: [m], torso tilt [rad]
STAND_TIME = 3.0
STAND_SAG = 0.005
STAND_DRIFT = 0.01
STAND_TILT = math.radians(1.0)
#: short flat walk: mean distance of the landed soles from the commanded footsteps [m]
WALK_LANDING_TOL = 0.06
WALK_STEPS = 6


@pytest.mark.parametrize("name", ["g1", "talos"])
def test_robot_stands_on_its_servos(name: str) -> None:
    scene = builtin_scene("flat")
    sim = BipedSim(scene, robot_model(name))
    sim.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    for s in sim.sides:
        assert np.allclose(sim.sole(s)[0], scene.start.foot(s), atol=1e-6)
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


def test_ankle_torque_carries_the_moment_of_the_weight_about_the_ankle() -> None:
    # zero ALIP torque = CoP at the sole centre, ahead of the G1's ankle: the ankle pitch joint
    # holds the weight's moment (dx F_n about +y on the foot); roll has no offset
    g = robot_model("g1")
    dx, dy = g.ankle_offset
    assert 0.02 < dx < 0.05 and abs(dy) < 1e-9
    tau = ankle_joint_torque(np.zeros(2), np.eye(3), 300.0, g)
    assert tau == pytest.approx([dx * 300.0, dy * -300.0])


def test_missing_model_package_names_the_extra(monkeypatch: pytest.MonkeyPatch) -> None:
    def missing(name: str) -> object:
        raise importlib.metadata.PackageNotFoundError(name)

    monkeypatch.setattr(robot_file.importlib.metadata, "distribution", missing)
    with pytest.raises(MissingExtraError, match=r"footfall\[robots\]"):
        robot_model("g1")


def test_cli_plans_for_a_robot_and_rejects_unknown_robots(tmp_path: Path) -> None:
    runner = CliRunner()
    res = runner.invoke(
        app,
        [
            "plan",
            "--scene",
            "flat",
            "--planner",
            "kinematic",
            "--robot",
            "g1",
            "--out",
            str(tmp_path),
        ],
    )
    assert res.exit_code == 0, res.output
    robot = json.loads((tmp_path / "plan.json").read_text())["robot"]
    info = measure_model(robot_model("g1"))
    assert robot["mass"] == pytest.approx(info.mass)
    assert robot["com_height"] == pytest.approx(info.com_height)
    bad = runner.invoke(
        app, ["walk", "--scene", "flat", "--robot", "atlas", "--out", str(tmp_path)]
    )
    assert isinstance(bad.exception, InputError)
    assert bad.exception.field == "robot" and bad.exception.value == "atlas"


def test_cli_inspect_writes_a_robot_file_walk_takes_as_it_is(tmp_path: Path) -> None:
    from footfall.robots.registry import builtin_robot_file, resolve_robot_file

    urdf = builtin_robot_file("g1").model
    res = CliRunner().invoke(
        app, ["robot", "inspect", str(urdf), "--name", "mine", "--out", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    assert "mass 33.34 kg" in res.output and "reach" in res.output
    assert (tmp_path / "robot.png").stat().st_size > 0
    mine = resolve_robot_file(tmp_path / "robot.yaml")
    assert mine is not None and mine.name == "mine"
    g1 = builtin_robot_file("g1")
    # the same robot as the built-in, derived afresh from its URDF alone
    assert mine.legs == g1.legs and mine.reach == g1.reach
    assert mine.pelvis_height == g1.pelvis_height and mine.step_height_max == g1.step_height_max
    bad = CliRunner().invoke(
        app, ["robot", "inspect", str(tmp_path / "nothing.urdf"), "--out", str(tmp_path)]
    )
    assert isinstance(bad.exception, InputError)


def test_g1_walks_a_short_flat_plan_made_for_it() -> None:
    pytest.importorskip("daqp")
    from footfall.planning import PlannerOptions, make_plan
    from footfall.sim.biped.walk import walk

    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([1.0, 0.0, 0.0]), 0.0))
    g = robot_model("g1")
    robot = planner_params(g, base=scene.robot)
    opts = PlannerOptions(region_margin=robot.foot_length / 2)
    plan = make_plan(scene, "kinematic", WALK_STEPS, opts, robot)
    res = walk(scene, plan, model_params=g)  # the whole-body controller, every robot's default
    m = res.metrics
    assert not res.trace.fell
    assert m.reached_goal
    assert m.steps_landed == plan.n_steps
    assert m.footstep_error_vs_target_m.mean < WALK_LANDING_TOL
    assert m.zmp.samples > 0 and m.zmp.inside_share == 1.0
