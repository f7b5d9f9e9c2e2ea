"""Quadrupeds from their files: Go2, Solo-12 and ANYmal C (example-robot-data URDFs) checked
against independent references: MuJoCo's own forward kinematics, masses and centres of mass of the
model as its file has it, the standing postures example-robot-data ships (its SRDFs), and walks in
MuJoCo measured by the simulator's contact forces.

Needs the ``robots`` extra; without it the module is skipped, except with
``FOOTFALL_REQUIRE_ROBOTS=1`` (set by .ci/run): then it fails.
"""

from __future__ import annotations

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

from footfall.errors import InputError
from footfall.quadruped import GaitParams
from footfall.quadruped.gait import largest_step, plan_gait
from footfall.quadruped.ground import Stairs
from footfall.quadruped.kinematics import leg_fk, leg_ik, whole_body_com, whole_body_ik
from footfall.quadruped.robot import LEGS, QuadrupedRobot
from footfall.quadruped.scaling import EDGE_RADII, STEP_MARGIN, gait_scale, scale_gait
from footfall.robots.build import RawModel, raw_model
from footfall.robots.quadruped import (
    builtin_quadruped_names,
    derive_quadruped,
    parse_quadruped_file,
    resolve_quadruped,
)

ROBOTS = ("go2", "solo12", "anymal_c")
PATHS = {
    "go2": "go2_description/urdf/go2.urdf",
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal_c": "anymal_c_simple_description/urdf/anymal.urdf",
}
PREFIX = "cmeel.prefix/share/example-robot-data/robots/"


def _file(name: str, extra: str = "") -> str:
    return (
        f"name: {name}\nkind: quadruped\n"
        f"model: {{package: example-robot-data, path: {PREFIX}{PATHS[name]}}}\n{extra}"
    )


def _raw(name: str) -> RawModel:
    return raw_model(parse_quadruped_file(_file(name), name, None))


def test_builtins_are_listed() -> None:
    assert builtin_quadruped_names() == ["document", "anymal_c", "go2", "solo12"]
    assert isinstance(resolve_quadruped("document"), QuadrupedRobot)
    with pytest.raises(InputError) as e:
        resolve_quadruped("spot")
    assert e.value.field == "robot"


@pytest.mark.parametrize("name", ROBOTS)
def test_leg_kinematics_match_mujoco(name: str) -> None:
    """The derived legs' closed-form FK against MuJoCo's kinematics of the file's own model
    (bodies, joints and frames as the URDF has them) at random joint angles within limits."""
    robot = resolve_quadruped(name)
    raw = _raw(name)
    m = raw.model
    d = mujoco.MjData(m)
    rng = np.random.default_rng(3)
    for _ in range(10):
        d.qpos[:] = m.qpos0
        qs = []
        for g in robot.legs or ():
            q = rng.uniform(np.maximum(g.lower, -2.5), np.minimum(g.upper, 2.5))
            qs.append(q)
            for jn, v in zip(g.joints, q, strict=True):
                d.qpos[m.jnt_qposadr[m.joint(jn).id]] = v
        mujoco.mj_kinematics(m, d)
        for leg, g, q in zip(LEGS, robot.legs or (), qs, strict=True):
            knee_body = int(m.jnt_bodyid[m.joint(g.joints[2]).id])
            # the foot is a point fixed in the knee's body: where it is at zero angles, carried
            zero = np.asarray(g.origin) + np.add(g.hfe, g.knee) + np.asarray(g.foot)
            local = raw.data.xmat[knee_body].reshape(3, 3).T @ (zero - raw.data.xpos[knee_body])
            mj_foot = d.xpos[knee_body] + d.xmat[knee_body].reshape(3, 3) @ local
            ours = robot.hip_offset(leg) + leg_fk(robot, q, leg)
            np.testing.assert_allclose(ours, mj_foot, atol=1e-9)
            # and IK gives back angles with the same foot, inside the limits
            if robot.legs is not None:
                try:
                    q2 = leg_ik(robot, leg_fk(robot, q, leg), leg)
                except InputError:
                    continue  # the other knee bend than the leg's branch
                np.testing.assert_allclose(leg_fk(robot, q2, leg), leg_fk(robot, q, leg), atol=1e-9)


@pytest.mark.parametrize("name", ROBOTS)
def test_mass_and_com_match_mujoco(name: str) -> None:
    """Total mass and whole-body CoM of the planner's point masses against MuJoCo's subtree mass
    and centre of mass of the file's model in the same posture (the link inertias are exact, so
    only the rotational inertia the planner neglects differs: not at all for the CoM)."""
    robot = resolve_quadruped(name)
    raw = _raw(name)
    m = raw.model
    base = m.body(raw.base).id
    assert robot.total_mass == pytest.approx(float(m.body_subtreemass[base]), rel=1e-9)
    d = mujoco.MjData(m)
    body, pitch = np.array([0.1, -0.05, robot.stance_height]), math.radians(8.0)
    # feet under the neutral stance points, each shifted along x by a different amount
    shift = np.array([[0.03 * (i - 1.5), 0.0, 0.0] for i in range(4)])
    feet = np.array([robot.stance_offset(leg) for leg in LEGS]) + shift + [0.1, -0.05, 0.0]
    feet[:, 2] = 0.0
    q = whole_body_ik(robot, body, pitch, feet)
    d.qpos[:] = m.qpos0
    d.qpos[:3] = body
    d.qpos[3:7] = (math.cos(-pitch / 2), 0.0, math.sin(-pitch / 2), 0.0)
    for i, g in enumerate(robot.legs or ()):
        for jn, v in zip(g.joints, q[3 * i : 3 * i + 3], strict=True):
            d.qpos[m.jnt_qposadr[m.joint(jn).id]] = v
    mujoco.mj_forward(m, d)
    np.testing.assert_allclose(
        whole_body_com(robot, body, pitch, q), d.subtree_com[base], atol=1e-9
    )


@pytest.mark.parametrize(("name", "front", "hind"), [("solo12", -1, 1), ("anymal_c", -1, 1)])
def test_default_knees_bend_as_the_shipped_standing_pose(name: str, front: int, hind: int) -> None:
    """The SRDFs' ``standing`` poses bend the front knees back (KFE < 0) and the hind knees
    forward (KFE > 0): the default ``inward`` bend when the limits allow both."""
    robot = resolve_quadruped(name)
    for leg in LEGS:
        q = leg_ik(
            robot, np.array([0.0, robot.leg_geometry(leg).lateral, -0.9 * robot.stance_height]), leg
        )
        assert np.sign(q[2]) == (front if leg.is_front else hind), leg


def test_go2_knees_follow_the_limits_and_a_contrary_file_is_refused() -> None:
    robot = resolve_quadruped("go2")
    assert all(g.upper[2] < 0.0 for g in robot.legs or ())
    with pytest.raises(InputError) as e:
        derive_quadruped(parse_quadruped_file(_file("go2", "knees: forward\n"), "x", None))
    assert e.value.field == "knees"


def test_anymal_placeholder_inertia_is_repaired_and_said() -> None:
    raw = _raw("anymal_c")
    assert "hatch" in raw.repaired


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        ("knees: sideways\n", "knees"),
        ("torque_limit: [1, -2, 3]\n", "torque_limit"),
        ("foot_radius: 0\n", "foot_radius"),
        ("legs: {LF: [a, b, c], RF: [a, b, c], RH: [a, b, c], LH: [a, b, c]}\n", "legs.LF"),
    ],
)
def test_bad_files_name_the_field(extra: str, field: str) -> None:
    with pytest.raises(InputError) as e:
        derive_quadruped(parse_quadruped_file(_file("go2", extra), "x", None))
    assert e.value.field == field


def test_a_humanoid_is_not_a_quadruped(tmp_path: Path) -> None:
    path = "talos_data/robots/talos_reduced.urdf"
    text = (
        f"name: t\nkind: quadruped\nmodel: {{package: example-robot-data, path: {PREFIX}{path}}}\n"
    )
    with pytest.raises(InputError) as e:
        derive_quadruped(parse_quadruped_file(text, "t", None))
    assert e.value.field.startswith("legs")


def test_gait_scales_with_the_robot() -> None:
    go2 = resolve_quadruped("go2")
    doc = QuadrupedRobot()
    k = gait_scale(go2)
    params = GaitParams(slope=math.radians(15), body_pitch=math.radians(10))
    assert scale_gait(doc, params) is params
    scaled = scale_gait(go2, params)
    assert scaled.swing_height == pytest.approx(k * params.swing_height)
    assert scaled.swing_period == pytest.approx(math.sqrt(k) * params.swing_period)
    assert scaled.step <= k * params.step + 1e-12
    most = largest_step(go2, scaled)
    assert scaled.step <= most + 1e-12 or scaled.step == pytest.approx(STEP_MARGIN * most)
    stairs = GaitParams(slope=0.0, body_pitch=0.0, ground=Stairs(), body_ratio=0.67)
    s2 = scale_gait(go2, stairs)
    assert isinstance(s2.ground, Stairs)
    assert s2.ground.rise == pytest.approx(k * 0.1)
    assert s2.ground.edge_margin >= EDGE_RADII * go2.foot_radius
    assert s2.lateral_share == 1.0  # Go2's feet under vertical legs on the stairs
    plan_gait(go2, s2)  # plannable


def test_a_wide_stance_narrows_where_the_legs_do_not_reach() -> None:
    """ANYmal C's feet stand 0.20 m out of its ab/ad axes: on the side slope no step fits with
    vertical legs (the planner proves it for the whole stance), with half the offset it does."""
    from footfall.quadruped.scene import builtin_quadruped_scene

    anymal = resolve_quadruped("anymal_c")
    params = builtin_quadruped_scene("side_slope").params
    scaled = scale_gait(anymal, params)
    assert scaled.lateral_share == 0.5
    assert largest_step(anymal, replace(scaled, lateral_share=1.0)) < 0.25 * scaled.step
    plan = plan_gait(anymal, scaled)
    feet = plan.initial_feet
    for i, leg in enumerate(LEGS):
        g = anymal.leg_geometry(leg)
        # on the side slope the body stays level: the foot's y is the hip's plus half the offset
        assert feet[i, 1] == pytest.approx(g.origin[1] + 0.5 * g.lateral, abs=1e-9)


def test_cli_walks_go2_up_15_degrees_with_the_default_controller(tmp_path: Path) -> None:
    """A user's first run: the built-in Go2 up the document's slope, the whole-body controller by
    default; the measured centre of pressure stays near the planned ZMP and no foot slips."""
    from typer.testing import CliRunner

    from footfall.cli import app

    res = CliRunner().invoke(
        app, ["quadruped", "--robot", "go2", "--cycles", "2", "--no-video", "--out", str(tmp_path)]
    )
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "quadruped.json").read_text())
    assert data["controller"]["name"] == "wbc"
    assert data["robot"]["name"] == "go2"
    assert data["fell"] is False
    assert data["distance_up_slope_m"] > 0.25
    assert data["zmp_error_mean_m"] < 0.01
    assert data["foot_slip_max_m"] < 0.01


def test_cli_unknown_robot_is_an_input_error(tmp_path: Path) -> None:
    """(the console entry point turns an InputError into its message and exit 2)"""
    from typer.testing import CliRunner

    from footfall.cli import app

    res = CliRunner().invoke(
        app, ["quadruped", "--robot", "nope", "--no-video", "--out", str(tmp_path)]
    )
    assert isinstance(res.exception, InputError), res.output
    assert res.exception.field == "robot"
    assert not (tmp_path / "quadruped.json").exists()


def _urdf(path: str) -> Path:
    from footfall.robots.file import package_file

    return package_file("example-robot-data", PREFIX + path)


def test_inspect_tells_quadrupeds_from_humanoids() -> None:
    from footfall.robots.inspect_quadruped import looks_quadruped

    assert looks_quadruped(_urdf(PATHS["go2"]), None)
    assert not looks_quadruped(_urdf("talos_data/robots/talos_reduced.urdf"), None)


def test_inspect_a_quadruped_that_is_not_built_in_and_walk_its_file(tmp_path: Path) -> None:
    """A new user's path: the Unitree A1's URDF (not a built-in) inspected into a robot file,
    which `footfall quadruped --robot` takes as it is and walks up 15 degrees."""
    from typer.testing import CliRunner

    from footfall.cli import app

    urdf = _urdf("a1_description/urdf/a1.urdf")
    res = CliRunner().invoke(app, ["robot", "inspect", str(urdf), "--out", str(tmp_path / "a1")])
    assert res.exit_code == 0, res.output
    robot_yaml = tmp_path / "a1" / "robot.yaml"
    assert (tmp_path / "a1" / "robot.png").stat().st_size > 10_000
    qf = parse_quadruped_file(robot_yaml, str(robot_yaml), robot_yaml.parent)
    assert qf.package is not None and qf.package[0] == "example-robot-data"
    assert qf.legs is not None and qf.legs[0] == ("FL_hip_joint", "FL_thigh_joint", "FL_calf_joint")
    # the written file derives the same robot as the model alone
    alone = derive_quadruped(replace(qf, legs=None, foot_radius=None, stance_height=None))
    written = derive_quadruped(qf).robot
    assert written.total_mass == pytest.approx(alone.robot.total_mass, rel=1e-12)
    assert written.stance_height == pytest.approx(alone.robot.stance_height, abs=6e-4)
    out = tmp_path / "walk"
    args = ["quadruped", "--robot", str(robot_yaml), "--slope-deg", "15", "--cycles", "1"]
    res = CliRunner().invoke(app, [*args, "--no-video", "--out", str(out)])
    assert res.exit_code == 0, res.output
    data = json.loads((out / "quadruped.json").read_text())
    assert data["robot"]["name"] == "a1" and data["fell"] is False
    assert data["distance_up_slope_m"] > 0.1


def test_lateral_pushes_are_paired_and_fail_when_too_strong() -> None:
    """The same seed pushes at the same time and side at every level; an unpushed Go2 walk
    succeeds and a 2 m/s sideways push (32 N s on 16 kg) does not."""
    from footfall.experiments.quadruped_pushes import (
        PUSH_SPAN,
        push_of_seed,
        run_quadruped_pushes,
        summary_lines,
    )

    assert push_of_seed(3, 0.05) == push_of_seed(3, 0.05)
    shares = [push_of_seed(s, 0.05)[0] for s in range(20)]
    assert all(PUSH_SPAN[0] <= v <= PUSH_SPAN[1] for v in shares)
    assert {push_of_seed(s, 0.05)[1] for s in range(20)} == {-1.0, 1.0}
    rows = run_quadruped_pushes("go2", 15.0, (0.0, 2.0), (0,), cycles=2)
    mass = resolve_quadruped("go2").total_mass
    assert [r.impulse_n_s for r in rows] == pytest.approx([0.0, 2.0 * mass])
    assert rows[0].start_s == rows[1].start_s and rows[0].side == rows[1].side
    assert rows[0].success and not rows[0].fell
    assert not rows[1].success
    text = "\n".join(summary_lines(rows))
    assert "| 0 | 0.00 | 1/1 |" in text and "| 2 | " in text and "0/1" in text
    assert "largest level every seed survived: 0 m/s" in text


def test_a_robot_file_of_the_other_kind_is_refused_by_name(tmp_path: Path) -> None:
    """A humanoid's file given to the quadruped, and a quadruped's to the humanoid walker: each
    error names the file and says which command takes it."""
    from importlib import resources

    from footfall.robots.registry import resolve_robot_file

    builtin = resources.files("footfall.robots").joinpath("builtin")
    g1 = tmp_path / "g1.yaml"
    g1.write_text(builtin.joinpath("g1.yaml").read_text())
    go2 = tmp_path / "go2.yaml"
    go2.write_text(builtin.joinpath("quadrupeds", "go2.yaml").read_text())
    with pytest.raises(InputError) as e:
        resolve_quadruped(g1)
    assert e.value.field == "robot" and "kind: quadruped" in e.value.expected
    with pytest.raises(InputError) as e:
        resolve_robot_file(go2)
    assert e.value.field == "robot" and "footfall quadruped --robot" in e.value.expected


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (["--duration", "0"], "duration"),
        (["--slope-deg", "nan"], "slope_deg"),
        (["--dv", "-1"], "dv"),
    ],
)
def test_push_sweep_bad_input_leaves_the_last_results(
    tmp_path: Path, args: list[str], field: str
) -> None:
    from typer.testing import CliRunner

    from footfall.cli import app

    last = tmp_path / "quadruped_pushes.md"
    last.write_text("the last run's table\n")
    res = CliRunner().invoke(app, ["bench", "quadruped-pushes", *args, "--out", str(tmp_path)])
    assert isinstance(res.exception, InputError), res.output
    assert res.exception.field == field
    assert last.read_text() == "the last run's table\n"


def test_push_summary_says_what_qualifies_the_largest_level() -> None:
    """The largest level every seed survived, with a lower level that lost a seed said, and a
    grid that never failed said as a lower bound (made-up rows, no walk)."""
    from footfall.experiments.quadruped_pushes import QuadrupedPushRow, summary_lines

    def rows(outcomes: dict[float, list[bool]]) -> list[QuadrupedPushRow]:
        return [
            QuadrupedPushRow("go2", 15.0, dv, seed, 16.0 * dv, 5.0, "left", not ok, 0.0, 1.0, ok)
            for dv, oks in outcomes.items()
            for seed, ok in enumerate(oks)
        ]

    text = "\n".join(summary_lines(rows({0.5: [True, True], 0.55: [True, False], 0.6: [True] * 2})))
    assert "largest level every seed survived: 0.6 m/s (but not 0.55 m/s)" in text
    text = "\n".join(summary_lines(rows({0.5: [True, True], 0.6: [True, True]})))
    assert "largest level every seed survived: >= 0.6 m/s (no level of the grid failed)" in text
    text = "\n".join(summary_lines(rows({0.5: [True, False], 0.6: [False, False]})))
    assert "no level every seed survived" in text
    text = "\n".join(summary_lines(rows({0.5: [True, True], 0.6: [True, False]})))
    assert text.endswith("largest level every seed survived: 0.5 m/s")
