"""The quadruped in MuJoCo on side slopes, a varying slope and stairs (issue 21).

The MuJoCo ground is checked by casting rays at it (``mj_ray``) against the ground written out
again; the walks are kept short (a few cycles) and checked from measured data: no fall, the trunk
where the plan puts it, the feet on the treads, and, with the whole-body controller, the centre
of pressure on the planned ZMP within the issue's bound (mean <= 2 cm, max <= 5 cm).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

os.environ.setdefault("MUJOCO_GL", "egl")  # must precede the first MuJoCo import
mujoco = pytest.importorskip("mujoco")

from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait  # noqa: E402
from footfall.quadruped.ground import PlaneGround, Stairs, VaryingSlope  # noqa: E402
from footfall.sim.quadruped.mjcf import PLANK_LENGTH  # noqa: E402
from footfall.sim.quadruped.sim import QuadrupedSim, simulate  # noqa: E402

ROBOT = QuadrupedRobot()
R = ROBOT.foot_radius
#: MJCF numbers are written with 6 significant digits
GEOM_TOL = 2e-5


def _ray_down(sim: QuadrupedSim, x: float, y: float) -> float:
    """Height of the ground under (x, y), by a ray cast down from 5 m (robot geoms excluded)."""
    geomid = np.zeros(1, dtype=np.int32)
    start = np.array([x, y, 5.0])
    # geomgroup None, flg_static 1, bodyexclude: the trunk (the robot's root)
    dist = mujoco.mj_ray(
        sim.model, sim.data, start, np.array([0.0, 0.0, -1.0]), None, 1, sim.trunk, geomid
    )
    assert dist >= 0, (x, y)
    return 5.0 - dist


def test_side_slope_plane_lies_one_radius_below_the_foot_centres() -> None:
    g = PlaneGround(math.radians(10.0), math.radians(15.0))
    sim = QuadrupedSim(ROBOT, g)
    mujoco.mj_forward(sim.model, sim.data)
    n = g.normal(0.0, 0.0)
    for x, y in [(-1.0, 2.0), (0.0, 0.0), (2.0, -1.5), (3.3, 0.7)]:
        # ground = the foot-centre plane shifted by R along -n: z = centre height - R / n_z
        expected = x * math.tan(math.radians(10)) + y * math.tan(math.radians(15)) - R / n[2]
        assert _ray_down(sim, x, y) == pytest.approx(expected, abs=GEOM_TOL)


def test_varying_slope_planks_follow_the_offset_curve() -> None:
    g = VaryingSlope((0.5, 2.5, 4.5), (0.0, math.radians(20.0), math.radians(-10.0)))
    sim = QuadrupedSim(ROBOT, g, x_range=(-1.0, 6.0))
    mujoco.mj_forward(sim.model, sim.data)
    # a plank is a chord of the curve: it sags below it by at most curvature * length^2 / 8
    # (curvature = d beta / ds <= 30 deg per 2 m, and a little more on the offset curve)
    sag = 1.1 * math.radians(30.0) / 2.0 * PLANK_LENGTH**2 / 8.0
    for xc in np.linspace(-0.48, 5.52, 25):  # between plank joints (a ray on a joint may miss)
        b = g.inclination(float(xc))
        # the ground point under a foot centred above xc: R back along the normal
        gx = xc + R * math.sin(b)
        gz = g.centre_height(float(xc)) - R * math.cos(b)
        assert _ray_down(sim, gx, 0.3) == pytest.approx(gz, abs=GEOM_TOL + sag), xc


def test_stairs_treads_and_landing() -> None:
    g = Stairs(rise=0.1, run=0.4, steps=3, start_x=0.8, landing=2.0)
    sim = QuadrupedSim(ROBOT, g)
    mujoco.mj_forward(sim.model, sim.data)
    for x, tread in [(0.5, 0), (1.0, 1), (1.4, 2), (1.8, 3), (3.5, 3)]:
        assert _ray_down(sim, x, 0.2) == pytest.approx(0.1 * tread - R, abs=GEOM_TOL), x


def _walk(params: GaitParams, controller: str):  # type: ignore[no-untyped-def]
    plan = plan_gait(ROBOT, params)
    return plan, simulate(plan, controller=controller)


@pytest.mark.parametrize("controller", ["servo", "wbc"])
def test_climbs_two_10cm_stairs(controller: str) -> None:
    g = Stairs(rise=0.1, run=0.4, steps=2, start_x=0.8, landing=2.0)
    params = GaitParams(slope=0.0, body_pitch=0.0, ground=g, swing_height=0.15, cycles=5)
    plan, res = _walk(params, controller)
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0
    # measured: the trunk ends on top, 0.2 m up, where the plan puts it
    assert res.trace.trunk_pos[-1, 2] == pytest.approx(plan.phases[-1].body_end[2], abs=0.03)
    assert plan.phases[-1].body_end[2] == pytest.approx(0.2 + ROBOT.stance_height, abs=0.01)
    # every foot ends resting on the top tread (foot centre R above it)
    np.testing.assert_allclose(res.trace.feet[-1, :, 2], 0.2, atol=0.01)
    if controller == "wbc":
        assert m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None
        assert m.zmp_error_mean_m <= 0.02 and m.zmp_error_max_m <= 0.05


def test_wbc_walks_a_side_slope_with_the_cop_on_the_plan() -> None:
    params = GaitParams(
        slope=math.radians(10), body_pitch=math.radians(6), side_slope=math.radians(15), cycles=2
    )
    _, res = _walk(params, "wbc")
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0
    assert m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None
    assert m.zmp_error_mean_m <= 0.02 and m.zmp_error_max_m <= 0.05
    assert m.trunk_drift_from_plan_m < 0.03
    assert m.foot_slip_max_m < 0.01


def test_wbc_pitches_with_a_varying_slope() -> None:
    g = VaryingSlope((0.3, 1.3), (0.0, math.radians(15.0)))
    params = GaitParams(slope=0.0, body_pitch=0.0, ground=g, cycles=4)
    _, res = _walk(params, "wbc")
    m = res.metrics
    assert not m.fell and res.trace.qp_failures == 0
    assert m.zmp_error_mean_m is not None and m.zmp_error_max_m is not None
    assert m.zmp_error_mean_m <= 0.02 and m.zmp_error_max_m <= 0.05
    # the measured trunk pitch follows the planned one, which changes along the walk
    assert np.ptp(res.trace.planned.body_pitch) > math.radians(4.0)
    assert np.max(np.abs(res.trace.trunk_pitch - res.trace.planned.body_pitch)) < math.radians(2.0)


def test_cli_walks_a_scene(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import json

    from typer.testing import CliRunner

    from footfall.cli import app

    args = ["quadruped", "--scene", "side_slope", "--cycles", "1", "--controller", "wbc"]
    res = CliRunner().invoke(app, [*args, "--no-video", "--out", str(tmp_path)])
    assert res.exit_code == 0, res.output
    data = json.loads((tmp_path / "quadruped.json").read_text())
    assert data["scene"] == "side_slope" and data["fell"] is False
    assert data["zmp_error_mean_m"] <= 0.02


@pytest.mark.parametrize(
    ("args", "field"),
    [
        (["--scene", "stairs_10cm", "--step", "0.3"], "--step"),
        (["--scene", "stairs_10cm", "--slope-deg", "5"], "--slope-deg"),
        (["--scene", "no_such_scene.yaml"], "scene file"),
    ],
)
def test_cli_scene_errors_name_the_option(tmp_path, args: list[str], field: str) -> None:  # type: ignore[no-untyped-def]
    from typer.testing import CliRunner

    from footfall.cli import app
    from footfall.errors import InputError

    res = CliRunner().invoke(app, ["quadruped", *args, "--no-video", "--out", str(tmp_path)])
    assert isinstance(res.exception, InputError), res.output
    assert res.exception.field == field
    assert not (tmp_path / "quadruped.json").exists()
