"""MuJoCo model and slope walk of document 001 (kept short: at most two gait cycles here)."""

from __future__ import annotations

import dataclasses
import json
import math
import os
from pathlib import Path

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first MuJoCo import
mujoco = pytest.importorskip("mujoco")

from footfall.errors import InputError  # noqa: E402
from footfall.quadruped import (  # noqa: E402
    LEGS,
    GaitParams,
    QuadrupedRobot,
    leg_fk,
    plan_gait,
    whole_body_com,
)
from footfall.quadruped.kinematics import body_rotation  # noqa: E402
from footfall.quadruped.stability import centre_of_pressure  # noqa: E402
from footfall.sim.quadruped import names as nm  # noqa: E402
from footfall.sim.quadruped.mjcf import stairs_scene  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim, simulate  # noqa: E402

ROBOT = QuadrupedRobot()
SLOPE = math.radians(15.0)
#: MJCF numbers are written with 6 significant digits
MJCF_TOL = 1e-5
#: a static robot's CoP must match its CoM projection to this [m]
STATIC_COP_TOL = 0.01


@pytest.fixture(scope="module")
def sim() -> QuadrupedSim:
    return QuadrupedSim(ROBOT, SLOPE)


def test_model_matches_the_robot_dataclass(sim: QuadrupedSim) -> None:
    m = sim.model
    assert float(np.sum(m.body_mass)) == pytest.approx(ROBOT.total_mass, rel=1e-6)
    assert m.nu == 12 and m.nq == 7 + 12
    rng = np.random.default_rng(3)
    body = np.array([0.2, -0.1, 0.9])
    pitch = math.radians(10.0)
    rot = body_rotation(pitch)
    for _ in range(5):
        q = rng.uniform([-0.4, -1.0, 0.3] * 4, [0.4, 1.0, 2.4] * 4)
        sim.set_pose(body, pitch, q)
        for i, leg in enumerate(LEGS):
            fk = body + rot @ (ROBOT.hip_offset(leg) + leg_fk(ROBOT, q[3 * i : 3 * i + 3]))
            np.testing.assert_allclose(sim.data.site_xpos[sim.foot_sites[i]], fk, atol=MJCF_TOL)
        com = whole_body_com(ROBOT, body, pitch, q)
        np.testing.assert_allclose(sim.data.subtree_com[sim.trunk], com, atol=MJCF_TOL)


def test_robot_parts_never_collide_with_each_other(sim: QuadrupedSim) -> None:
    m = sim.model
    robot_geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] != 0]
    for a in robot_geoms:
        for b in robot_geoms:
            touch = (m.geom_contype[a] & m.geom_conaffinity[b]) or (
                m.geom_contype[b] & m.geom_conaffinity[a]
            )
            assert not touch


def test_static_stance_cop_matches_com_projection_on_the_slope() -> None:
    plan = plan_gait(ROBOT, GaitParams(SLOPE, math.radians(10.0), cycles=1))
    s = QuadrupedSim(ROBOT, SLOPE)
    ref = plan.sample(0.01, with_zmp=False)
    s.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    for _ in range(1000):  # 2 s standing
        mujoco.mj_step(s.model, s.data)
    pts, frc, idx, trunk_hit = s.contacts()
    assert not trunk_hit and set(idx.tolist()) == {0, 1, 2, 3}
    assert frc[:, 2].sum() == pytest.approx(ROBOT.total_mass * 9.81, rel=0.01)
    cop, _ = centre_of_pressure(pts, frc, float(pts[:, 2].mean()))
    np.testing.assert_allclose(cop, s.data.subtree_com[s.trunk][:2], atol=STATIC_COP_TOL)
    # the feet do not creep down the slope (elliptic cone, impratio)
    np.testing.assert_allclose(s.data.site_xpos[s.foot_sites], ref.feet[0], atol=0.01)


@pytest.fixture(scope="module")
def walk():
    plan = plan_gait(ROBOT, GaitParams(SLOPE, math.radians(10.0), cycles=2))
    return plan, simulate(plan)


def test_two_cycles_up_15_degrees_without_falling(walk) -> None:
    _plan, res = walk
    m = res.metrics
    assert not m.fell
    # every stance sample had three or more loaded feet and a CoP inside their polygon
    assert m.stance_samples_with_fewer_than_3_contacts == 0
    assert m.stability_margin_min_m > 0.0
    # it climbs: at least 80 % of the planned distance (2 cycles x 0.4 m along the slope)
    assert m.distance_up_slope_m > 0.8 * m.planned_distance_up_slope_m
    assert m.planned_distance_up_slope_m > 0.7
    # it rose by the slope's share of that distance
    rise = res.trace.trunk_pos[-1, 2] - res.trace.trunk_pos[0, 2]
    assert rise == pytest.approx(m.distance_up_slope_m * math.sin(SLOPE), abs=0.03)


def test_measured_cop_follows_the_planned_zmp(walk) -> None:
    _, res = walk
    # within the OSP's inradius on average: the plan is what the robot does
    assert res.metrics.zmp_error_mean_m < 0.08


def test_stairs_scene_compiles_with_steps() -> None:
    m = mujoco.MjModel.from_xml_string(stairs_scene(ROBOT, steps=4))
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_GEOM, g) for g in range(m.ngeom)]
    assert sum(1 for n in names if n and n.startswith(nm.STAIR_GEOM_PREFIX)) == 4


def _cli_app():
    from footfall.cli import app

    return app


def test_cli_rejects_bad_input_before_simulating(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    runner = CliRunner()
    app = _cli_app()
    cases = [
        (["--slope-deg", "15", "--body-deg", "20"], "--body-deg"),
        (["--slope-deg", "45", "--body-deg", "0"], "slope"),
        (["--step", "1.5"], "step"),
    ]
    for args, field in cases:
        out = tmp_path / field.strip("-")
        res = runner.invoke(app, ["quadruped", *args, "--out", str(out), "--no-video"])
        assert isinstance(res.exception, InputError), res.output
        assert res.exception.field == field
        assert not (out / "quadruped.json").exists()


def test_cli_writes_metrics_figures_and_video(tmp_path: Path) -> None:
    from typer.testing import CliRunner

    res = CliRunner().invoke(
        _cli_app(), ["quadruped", "--cycles", "1", "--out", str(tmp_path), "--video"]
    )
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "quadruped.json").read_text())
    assert data["fell"] is False
    for fig in data["figures"]:
        assert Path(fig).stat().st_size > 10_000
    if data["video"] is None:
        pytest.skip(f"no GL backend: {data['video_note']}")
    assert (tmp_path / "quadruped.mp4").stat().st_size > 10_000


def test_metrics_dict_has_one_key_per_field_and_nested_sway(walk) -> None:
    _, res = walk
    d = res.metrics.to_dict()
    assert list(d) == [f.name for f in dataclasses.fields(res.metrics)]
    assert d["body_sway_measured"]["path_per_cycle_m"] == pytest.approx(
        res.metrics.body_sway_measured.path_per_cycle_m
    )
    json.dumps(d)  # JSON-ready


class _Planned(Exception):
    """Stops the command once it has its gait parameters."""


@pytest.mark.parametrize(("slope", "body"), [("-15", -10.0), ("15", 10.0), ("21", 14.0)])
def test_the_default_body_angle_follows_the_slope(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, slope: str, body: float
) -> None:
    """Downhill, the default body angle is downhill too (10 deg up was refused on -15 deg)."""
    import math

    from typer.testing import CliRunner

    from footfall.experiments import slope_walk

    seen = []

    def plan_strategies(robot: object, params: object, compare: bool) -> None:
        seen.append(params)
        raise _Planned

    monkeypatch.setattr(slope_walk, "plan_strategies", plan_strategies)
    args = ["quadruped", "--slope-deg", slope, "--no-video", "--out", str(tmp_path)]
    res = CliRunner().invoke(_cli_app(), args)
    assert isinstance(res.exception, _Planned), res.output
    (params,) = seen
    assert math.degrees(params.slope) == pytest.approx(float(slope), abs=1e-12)
    assert math.degrees(params.body_pitch) == pytest.approx(body, abs=1e-12)
