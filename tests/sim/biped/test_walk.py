"""MuJoCo biped walking (issue 7): measured CoP, a short flat walk, bad inputs. Kept short."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

mujoco = pytest.importorskip("mujoco")
pytest.importorskip("mink")

from typer.testing import CliRunner  # noqa: E402

from footfall._geometry import inset_polygon, project_to_polygon  # noqa: E402
from footfall.cli import app  # noqa: E402
from footfall.control.adjusters import (  # noqa: E402
    MPCAdjuster,
    PlanFollower,
    sole_torque_limits,
)
from footfall.control.mpc import MPCWeights  # noqa: E402
from footfall.errors import FootfallError, InputError  # noqa: E402
from footfall.models.biped import Side  # noqa: E402
from footfall.planning import make_plan  # noqa: E402
from footfall.sim.biped.model import planner_params  # noqa: E402
from footfall.sim.biped.options import WEIGHTS_MASS, WalkOptions  # noqa: E402
from footfall.sim.biped.plant import BipedSim, ankle_joint_torque, sole_cop  # noqa: E402
from footfall.sim.biped.references import ds_propagator  # noqa: E402
from footfall.sim.biped.walk import BipedWalk, walk  # noqa: E402
from footfall.sim.disturbance import Push  # noqa: E402
from footfall.terrain import Goal, Region, builtin_scene  # noqa: E402
from tests.cli import error_line, footfall  # noqa: E402

#: exact arithmetic of the CoP formula
COP_TOL = 1e-12
#: static stance: CoP of all contacts vs the CoM's ground projection [m] (soft contacts, servos)
STATIC_COP_TOL = 0.005
#: static stance: total normal force vs the weight (relative)
WEIGHT_TOL = 0.02
#: short walk: mean distance of the landed soles from the commanded footsteps [m]
LANDING_TOL = 0.06
#: settling time of the static stance [s]
SETTLE = 0.6
#: exactness of the closed-form stop step against the propagated double-support ALIP [m]
STOP_FORMULA_TOL = 1e-9


def test_sole_cop_is_the_normal_force_weighted_mean() -> None:
    rot = np.eye(3)
    pos = np.array([1.0, 2.0, 0.3])
    pts = pos + np.array([[0.09, 0.04, 0], [0.09, -0.04, 0], [-0.09, -0.04, 0], [-0.09, 0.04, 0]])
    fz = np.array([10.0, 30.0, 20.0, 40.0])
    forces = np.column_stack([np.full(4, 3.0), np.zeros(4), fz])  # friction does not count
    offset, total = sole_cop(pts, forces, pos, rot)
    expected = (fz @ (pts - pos)[:, :2]) / fz.sum()
    assert np.allclose(offset, expected, atol=COP_TOL)
    assert total == pytest.approx(fz.sum())
    assert sole_cop(np.zeros((0, 3)), np.zeros((0, 3)), pos, rot) is None


def test_ankle_torque_sign_follows_the_alip_convention() -> None:
    # a ZMP to the left (tau_x > 0) needs the ankle roll to push the foot's left edge down:
    # joint torque -tau_x on the foot about +x
    sim_weight = 300.0
    from footfall.sim.biped.model import BipedModel

    tau = ankle_joint_torque(np.array([3.0, -2.0]), np.eye(3), sim_weight, BipedModel())
    assert tau == pytest.approx([2.0, -3.0])  # (pitch, roll)
    big = ankle_joint_torque(np.array([1e3, 0.0]), np.eye(3), sim_weight, BipedModel())
    assert abs(big[1]) < sim_weight * BipedModel().foot_width / 2


def test_static_stance_cop_is_under_the_com() -> None:
    scene = builtin_scene("flat")
    sim = BipedSim(scene)
    sim.set_standing(scene.start.left, scene.start.right, 0.0)
    for _ in range(round(SETTLE / sim.model.opt.timestep)):
        mujoco.mj_step(sim.model, sim.data)
    contacts, body_hit = sim.contacts()
    pts = np.vstack([contacts[s][0] for s in (Side.LEFT, Side.RIGHT)])
    frc = np.vstack([contacts[s][1] for s in (Side.LEFT, Side.RIGHT)])
    com, _, _ = sim.com_state()
    cop = (frc[:, 2] @ pts[:, :2]) / frc[:, 2].sum()
    assert not body_hit
    assert np.linalg.norm(cop - com[:2]) < STATIC_COP_TOL
    assert abs(frc[:, 2].sum() / sim.weight - 1.0) < WEIGHT_TOL
    # each foot carries its own CoP: the per-foot CoP lies inside its sole
    for s in (Side.LEFT, Side.RIGHT):
        pos, rot = sim.sole(s)
        off, _ = sole_cop(*contacts[s], pos, rot)
        assert abs(off[0]) <= 0.1 and abs(off[1]) <= 0.05


@pytest.fixture(scope="module")
def short_walk():  # type: ignore[no-untyped-def]
    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([1.0, 0.0, 0.0]), 0.0))
    plan = make_plan(scene, "reactive", robot=planner_params(base=scene.robot))
    # the servo walker (IK and position servos); the default whole-body QP has test_walk_wbc
    return scene, plan, walk(scene, plan, WalkOptions(controller="servo"))


def test_short_flat_walk_lands_every_planned_footstep(short_walk) -> None:  # type: ignore[no-untyped-def]
    _, plan, res = short_walk
    m = res.metrics
    assert m.steps_landed == plan.n_steps
    # no fall before the last planned footstep is down (the stop afterwards is reported, see
    # the issue 7 note)
    t_last = (
        WalkOptions().settle_time
        + WalkOptions().shift_time
        + plan.n_steps * (plan.robot.t_ss + plan.robot.t_ds)
    )
    assert (not res.trace.fell) or res.trace.fall_time >= t_last - 1e-9
    assert m.footstep_error_vs_target_m.mean < LANDING_TOL
    # the single-support CoP is measured and lies inside the sole
    assert m.zmp.samples > 0
    assert m.zmp.inside_share == 1.0


def test_bad_walk_inputs_name_the_field(short_walk) -> None:  # type: ignore[no-untyped-def]
    scene, plan, _ = short_walk
    with pytest.raises(InputError) as err:
        Push(start=0.0, duration=0.0, force=np.zeros(3))
    assert err.value.field == "push.duration"
    with pytest.raises(InputError) as err:
        WalkOptions(com_feedback=2.0)
    assert err.value.field == "com_feedback"
    with pytest.raises(InputError) as err:
        WalkOptions(control_dt=0.0)
    assert err.value.field == "control_dt"
    with pytest.raises(InputError) as err:
        WalkOptions(landing_margin=-0.01)
    assert err.value.field == "landing_margin"
    moved = replace(plan, footsteps=plan.footsteps + np.array([0.5, 0.0, 0.0]))
    with pytest.raises(InputError) as err:
        walk(scene, moved)
    assert err.value.field == "plan.footsteps[0]"
    with pytest.raises(InputError) as err:
        walk(scene, plan, WalkOptions(control_dt=0.0105))
    assert err.value.field == "control_dt"


@pytest.mark.parametrize(
    "args",
    [
        ["--planner", "bogus"],
        ["--push", "-1"],
        ["--push", "nan"],
        ["--steps", "0"],
        ["--scene", "nowhere"],
        ["--region-aware", "anywhere"],
        ["--leg-momentum", "-0.2"],
        ["--leg-momentum", "0.5", "--controller", "servo"],
    ],
)
def test_cli_walk_rejects_bad_input(args: list[str], tmp_path) -> None:  # type: ignore[no-untyped-def]
    base = ["walk", "--scene", "flat", "--planner", "reactive", "--out", str(tmp_path)]
    res = CliRunner().invoke(app, base + args)
    assert res.exit_code != 0
    # a FootfallError, which `footfall` (main) turns into exit code 2
    assert isinstance(res.exception, FootfallError)
    assert not (tmp_path / "walk.json").exists()


def test_project_to_polygon_is_the_nearest_point() -> None:
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    inside = np.array([0.3, 0.6])
    assert np.array_equal(project_to_polygon(inside, square), inside)
    assert project_to_polygon(np.array([2.0, 0.5]), square) == pytest.approx([1.0, 0.5])
    assert project_to_polygon(np.array([-1.0, -2.0]), square) == pytest.approx([0.0, 0.0])


def test_inset_polygon_moves_every_edge_in() -> None:
    tri = np.array([[0.0, 0.0], [4.0, 0.0], [0.0, 3.0]])
    inner = inset_polygon(tri, 0.5)
    assert inner is not None
    # every inset vertex lies exactly 0.5 m inside the two edges that meet there
    square = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    assert inset_polygon(square, 0.1) == pytest.approx(
        np.array([[0.1, 0.1], [0.9, 0.1], [0.9, 0.9], [0.1, 0.9]])
    )
    region = Region.from_height("tri", 0.0, tri)
    for v in inner:
        assert float(region.signed_distance(v)) == pytest.approx(-0.5)
    assert inset_polygon(square, 0.5) is None  # a point, no area
    assert inset_polygon(square, 0.7) is None  # turned inside out


def test_footstep_is_clamped_into_the_margin_even_when_the_plan_is_not(short_walk) -> None:  # type: ignore[no-untyped-def]
    # the walker's margin (half sole + landing margin) is larger than the plan's: a planned
    # footstep 0.02 m from the edge is moved to the nearest point 0.12 m inside
    _, plan, _ = short_walk
    region = Region.from_height("pad", 0.0, [[-1.0, -1.0], [0.3, -1.0], [0.3, 1.0], [-1.0, 1.0]])
    fol = PlanFollower(plan, {"pad": region}, region_margin=0.12)
    ref = np.array([0.28, 0.0, 0.0])
    out = fol._clamp_to_region(np.array([0.35, 0.05, 0.0]), ref, "pad")
    assert out == pytest.approx([0.18, 0.05, 0.0])


def test_corrected_footsteps_stay_in_the_reach_trapezoid(short_walk) -> None:  # type: ignore[no-untyped-def]
    scene, plan, _ = short_walk
    regions = {r.name: r for r in scene.terrain.regions}
    fol = PlanFollower(plan, regions, limit_reach=True)
    robot = plan.robot
    # a huge forward velocity asks for a step far beyond the reach
    state = robot.alip().state_from_velocity(np.zeros(2), np.array([3.0, 0.0]))
    for phase in (1, 2):
        stance = np.array(plan.footsteps[phase])
        target, _ = fol.update(0.0, state, stance, phase)
        th = float(plan.headings[phase])
        rot = np.array([[np.cos(th), np.sin(th)], [-np.sin(th), np.cos(th)]])
        q = rot @ (target - stance)[:2]  # in the stance foot's heading frame
        assert robot.reach.contains(q, plan.sides[phase], tol=1e-9)


def test_mpc_adjuster_keeps_the_footstep_in_its_region_and_the_cop_on_the_sole(short_walk) -> None:  # type: ignore[no-untyped-def]
    scene, plan, _ = short_walk
    robot = plan.robot
    lim = sole_torque_limits(robot)
    weight = robot.mass * robot.g
    # the ellipse's semi-axes put the CoP at 0.8 of the half sole width / length
    assert lim[0] / weight == pytest.approx(0.8 * robot.foot_width / 2)
    assert lim[1] / weight == pytest.approx(0.8 * robot.foot_length / 2)
    # a region that ends just past the planned footstep 2: a fast forward state wants it further
    p2 = plan.footsteps[2]
    margin = robot.foot_length / 2
    short = Region.from_height(
        plan.regions[2],
        float(p2[2]),
        [[-1.0, -1.0], [p2[0] + margin + 0.01, -1.0], [p2[0] + margin + 0.01, 1.0], [-1.0, 1.0]],
    )
    regions = {r.name: r for r in scene.terrain.regions} | {short.name: short}
    adj = MPCAdjuster(plan, regions, region_margin=margin, torque_limits=lim)
    assert np.array_equal(adj.mpc.model.u_limits, lim)
    state = robot.alip().state_from_velocity(np.array([0.0, 0.0]), np.array([0.5, 0.0]))
    stance = np.array(plan.footsteps[1])
    target, u = adj.update(0.0, state, stance, 1)
    assert float(short.signed_distance(target[:2])) <= -margin + 1e-6
    u_sole = in_sole_frame(u, float(plan.headings[1]))
    assert np.hypot(u_sole[0] / lim[0], u_sole[1] / lim[1]) <= 1.0 + 1e-9
    # the footstep is at the region's limit, so the ankle pushes back harder than when the
    # footstep may move freely (CoP ahead: u_y < 0 in the ALIP convention)
    free = MPCAdjuster(
        plan, regions, region_margin=margin, torque_limits=lim, footstep_in_region=False
    )
    _, u_free = free.update(0.0, state, stance, 1)
    assert u[1] < u_free[1] - 0.1


def test_mpc_adjuster_holds_footstep_and_torque_once_frozen(short_walk) -> None:  # type: ignore[no-untyped-def]
    scene, plan, _ = short_walk
    robot = plan.robot
    regions = {r.name: r for r in scene.terrain.regions}
    lim = sole_torque_limits(robot)
    stance = np.array(plan.footsteps[1])
    alip = robot.alip()
    slow = alip.state_from_velocity(np.array([0.02, 0.0]), np.array([0.3, 0.05]))
    fast = alip.state_from_velocity(np.array([0.04, 0.0]), np.array([0.7, -0.1]))
    t_freeze = 0.9 * robot.t_ss
    for hold in (True, False):
        adj = MPCAdjuster(plan, regions, torque_limits=lim, hold_frozen=hold)
        target0, u0 = adj.update(t_freeze, slow, stance, 1)
        target1, u1 = adj.update(t_freeze + 0.02, fast, stance, 1)
        np.testing.assert_array_equal(target1, target0)  # the footstep is frozen either way
        if hold:
            # the torque of the solution the footstep was frozen with, whatever the state
            np.testing.assert_array_equal(u1, u0)
        else:
            assert np.abs(u1 - u0).max() > 0.1


def in_sole_frame(u: np.ndarray, heading: float) -> np.ndarray:
    """World-frame ankle torque (2,) as (roll, pitch) about the axes of a sole at ``heading``."""
    c, s = np.cos(heading), np.sin(heading)
    return np.array([[c, s], [-s, c]]) @ u


@pytest.mark.parametrize("heading", [0.0, 0.7, np.pi / 2])
def test_mpc_adjuster_torque_ellipse_lies_along_the_stance_sole(short_walk, heading: float) -> None:  # type: ignore[no-untyped-def]
    """A large velocity error along the sole saturates the torque beyond U_x along the sole's
    axis, never outside the ellipse in the sole's frame, whatever the heading."""
    _, plan, _ = short_walk
    robot = plan.robot
    lim = sole_torque_limits(robot)
    turned = replace(plan, headings=np.full_like(plan.headings, heading))
    adj = MPCAdjuster(turned, {}, torque_limits=lim, footstep_in_region=False)
    along = np.array([np.cos(heading), np.sin(heading)])
    state = robot.alip().state_from_velocity(np.zeros(2), -0.8 * along)  # moving backwards
    _, u = adj.update(0.0, state, np.array(plan.footsteps[1]), 1)
    u_foot = in_sole_frame(u, heading)
    assert np.hypot(u_foot[0] / lim[0], u_foot[1] / lim[1]) <= 1.0 + 1e-9
    assert abs(u_foot[1]) > 1.5 * lim[0]  # pitch torque beyond the short semi-axis


def test_stop_target_leaves_the_capture_point_midway(short_walk) -> None:  # type: ignore[no-untyped-def]
    # The closed form of PlanFollower.stop_target against the exact double-support ALIP
    # (contact point ramping from the stance foot to the new foot, eq. 5.8-5.10)
    scene, plan, _ = short_walk
    fol = PlanFollower(plan, {r.name: r for r in scene.terrain.regions})
    robot = plan.robot
    alip = robot.alip()
    state = np.array([0.02, -0.03, 2.0, 6.0])
    u = np.array([1.0, -2.0])
    stance = np.array([0.3, -0.1, 0.0])
    t = 0.1
    d = fol.stop_target(t, state, stance, 0, u) - stance[:2]
    a, b = alip.discretize(robot.t_ss - t)
    x = a @ state + b @ u
    step = round(robot.t_ds / 1e-3)
    ds = ds_propagator(alip, robot.t_ds / step)
    aug = np.concatenate([x, np.zeros(3), np.array([d[0], d[1], 0.0]) / robot.t_ds])
    for _ in range(step):
        aug = ds @ aug
    xi = aug[:2] + alip.velocity(aug[:4]) / alip.omega
    assert xi == pytest.approx(d / 2, abs=STOP_FORMULA_TOL)


@pytest.mark.parametrize("region_aware", ["off", "planned", "nearby"])
def test_capture_stop_places_the_last_footstep_in_every_region_mode(  # type: ignore[no-untyped-def]
    short_walk, region_aware: str
) -> None:
    """With ``capture_stop`` the last stopping step is the capture-point footstep of
    ``stop_target`` (tested above against the exact double-support ALIP) in the region-aware
    modes too (they solved their own MPC and skipped it); without, it is not."""
    scene, plan, _ = short_walk
    regions = {r.name: r for r in scene.terrain.regions}
    robot = plan.robot
    state = robot.alip().state_from_velocity(np.zeros(2), np.array([0.05, 0.12]))
    stance = np.array(plan.footsteps[-1], dtype=float)
    t = 0.1

    def last_step(capture: bool) -> tuple[np.ndarray, MPCAdjuster, np.ndarray, int]:
        adj = MPCAdjuster(plan, regions, region_aware=region_aware, capture_stop=capture)
        last = adj.plan.n_steps - 1
        target, u = adj.update(t, state, stance, last)
        return target, adj, u, last

    target, adj, u, last = last_step(True)
    expected = adj.stop_target(t, state, stance, last, u)
    assert target[:2] == pytest.approx(expected, abs=1e-9)
    other, _, _, _ = last_step(False)
    assert np.linalg.norm(other[:2] - expected) > 0.01


@pytest.mark.parametrize("value", ["yes", 1, None])
def test_capture_stop_must_be_a_bool(value: object) -> None:
    with pytest.raises(InputError) as err:
        WalkOptions(capture_stop=value)  # type: ignore[arg-type]
    assert err.value.field == "capture_stop"


#: flat 20-step walk: mean landed-vs-planned footstep distance [m] and goal distance [m]
FLAT20_FOOTSTEP_TOL = 0.06
#: measured CoP against the MPC's commanded ZMP: accepted range of the regression slope
COP_SLOPE = (0.7, 1.3)


def test_flat_walk_of_twenty_steps_reaches_the_goal() -> None:
    # issue 7 must-show: 20 footsteps of 0.2 m on flat ground, planned by the MIQCQP planner and
    # walked with the MPC of eq. (5.19) in the loop, without a fall
    scene = builtin_scene("flat_long")
    robot = planner_params(base=scene.robot)
    plan = make_plan(scene, "miqcqp", 20, robot=robot)
    steps = np.linalg.norm(np.diff(plan.footsteps[:, :2], axis=0), axis=1)
    assert plan.n_steps == 20
    assert np.diff(plan.footsteps[:, 0]).mean() == pytest.approx(0.2, abs=0.01)
    assert steps.max() < 0.45  # a stride is two steps apart
    # the document's MPC: its point-mass prediction, without the legs' momentum forecast (the
    # CoP slopes below were measured with it; see tests/sim/biped/test_walk_wbc.py)
    res = walk(scene, plan, WalkOptions(leg_momentum=0.0))
    m = res.metrics
    assert not res.trace.fell
    assert m.steps_landed == plan.n_steps
    assert m.reached_goal
    assert m.footstep_error_m.mean < FLAT20_FOOTSTEP_TOL
    assert m.zmp.inside_share == 1.0
    # the MPC ran at every single-support tick and the measured CoP moved with its torque one
    # for one on average (regression slope; measured with the default whole-body QP 0.78
    # sagittal, 0.97 lateral; with the servo walker 0.85 and 1.09). The swing leg's reaction
    # scatters the sagittal CoP around it, hence no tighter bound.
    ok = ~np.isnan(res.trace.zmp_offset[:, 0]) & ~np.isnan(res.trace.zmp_planned[:, 0])
    assert ok.sum() > 20 * 30
    for ax in range(2):
        slope = np.polyfit(res.trace.zmp_planned[ok, ax], res.trace.zmp_offset[ok, ax], 1)[0]
        assert COP_SLOPE[0] < slope < COP_SLOPE[1]


def test_long_flat_steps_reach_the_goal_with_a_limp_landing_ankle() -> None:
    # the flat scene's plan takes 0.36 m steps; with a stiff swing ankle every landing hit the
    # toe first and lifted the robot, and the walk ended 0.51 m short (0.05 m with it limp)
    scene = builtin_scene("flat")
    plan = make_plan(scene, "miqcqp", robot=planner_params(base=scene.robot))
    assert np.linalg.norm(np.diff(plan.footsteps[:, :2], axis=0), axis=1).max() > 0.35
    res = walk(scene, plan, WalkOptions(controller="servo", passive_landing=True))
    assert not res.trace.fell
    assert res.metrics.reached_goal


def test_cli_compare_mujoco_writes_the_study_table(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # compare --sim mujoco is the study runner with the MuJoCo plant: one row per walk
    pytest.importorskip("pyarrow")
    from footfall.experiments.study.store import read_rows

    args = ["compare", "--sim", "mujoco", "--scenes", "flat", "--planners", "reactive"]
    res = CliRunner().invoke(app, [*args, "--trials", "1", "--out", str(tmp_path), "--quiet"])
    assert res.exit_code == 0, res.output
    (row,) = read_rows(tmp_path / "trials.parquet")
    assert row["simulator"] == "mujoco" and row["controller"] == "wbc" and row["error"] is None
    assert row["success"] and row["push_impulse"] == 3.0
    assert 0.0 < row["zmp_offset_mean"] <= row["zmp_offset_max"] < 0.15
    assert row["footsteps_off_terrain"] == 0
    assert "| flat |" in (tmp_path / "summary.md").read_text()
    bad = CliRunner().invoke(app, [*args, "--sim", "bogus", "--out", str(tmp_path / "x")])
    assert isinstance(bad.exception, InputError) and bad.exception.field == "simulator"


def test_walk_plan_cache_round_trip_keeps_the_region_margin(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # the walker keeps footsteps the plan's region margin (plus the landing margin) inside their
    # regions: a cached plan must come back with the margin it was made with
    from footfall.sim.biped.plans import plan_for_walk

    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0))
    made = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    assert made.has_solution and made.region_margin == pytest.approx(made.robot.foot_length / 2)
    loaded = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    assert "loaded from cache" in loaded.message
    assert loaded.region_margin == made.region_margin
    np.testing.assert_array_equal(loaded.footsteps, made.footsteps)
    np.testing.assert_array_equal(loaded.states, made.states)


def test_plan_for_walk_plans_on_the_riser_inset_regions(monkeypatch: pytest.MonkeyPatch) -> None:
    # the planner sees stairs_slope_gap's treads below a riser moved in by the landing tolerance
    # at that edge only, and keeps its uniform half-sole region margin (the planner is unchanged)
    import footfall.planning.cache as run
    from footfall.sim.biped.options import RISER_LANDING_TOLERANCE
    from footfall.sim.biped.plans import plan_for_walk

    seen = {}

    def capture(scene, planner, n_steps, options, robot, monitor=None):  # type: ignore[no-untyped-def]
        seen["scene"], seen["options"] = scene, options
        raise RuntimeError("captured")

    monkeypatch.setattr(run, "make_plan", capture)
    scene = builtin_scene("stairs_slope_gap")
    with pytest.raises(RuntimeError, match="captured"):
        plan_for_walk(scene, "miqcqp", 15)
    planned = seen["scene"].terrain
    # stair1 (z 0.16) spans x 2.2-2.5 below top (z 0.24): its back edge moves in, its front
    # edge (a step down to stair2) and its sides do not
    v = planned["stair1"].vertices
    assert v[:, 0].min() == pytest.approx(2.2 + RISER_LANDING_TOLERANCE)
    assert v[:, 0].max() == pytest.approx(2.5)
    assert (v[:, 1].min(), v[:, 1].max()) == pytest.approx((-0.5, 0.5))
    assert planned["top"] is scene.terrain["top"]
    assert planned["landing"] is scene.terrain["landing"]
    assert seen["options"].region_margin == pytest.approx(planner_params().foot_length / 2)


def test_walk_plans_are_robot_aware_and_cached_with_their_options(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # the walk's plans use the options beyond the document (both reach frames, the measured
    # swing bound); the cache gives a plan back with them, and never for other options
    from footfall.planning import check_plan
    from footfall.sim.biped.model import SWING_MAX
    from footfall.sim.biped.plans import plan_for_walk

    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0))
    made = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    assert made.reach_both_frames and made.swing_max == SWING_MAX
    report = check_plan(made, scene)  # (a kinematic plan may need more torque than U_max)
    assert {"reach", "swing"} <= set(report.checked) and not {"reach", "swing"} & report.kinds()
    loaded = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    assert "loaded from cache" in loaded.message
    assert loaded.reach_both_frames and loaded.swing_max == SWING_MAX
    plain = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path, robot_aware=False)
    assert "loaded from cache" not in plain.message
    assert not plain.reach_both_frames and plain.swing_max is None
    # the reactive planner cannot honour them and plans without
    reactive = plan_for_walk(scene, "reactive", None, 60.0, None)
    assert not reactive.reach_both_frames and reactive.swing_max is None


def test_walk_plans_record_their_heading_segments_and_cache_by_them(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # plan_for_walk(heading_segments=L): the plan, plan.json and the cache key keep L, and a plan
    # made with another L is not served from the cache
    import json

    from footfall.sim.biped.plans import plan_for_walk

    scene = replace(builtin_scene("flat"), goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0))
    made = plan_for_walk(scene, "miqcqp", 4, 60.0, tmp_path, heading_segments=64)
    assert made.has_solution and made.heading_segments == 64
    (path,) = tmp_path.glob("plan-*.json")
    stored = json.loads(path.read_text())
    assert stored["heading_segments"] == 64
    again = plan_for_walk(scene, "miqcqp", 4, 60.0, tmp_path, heading_segments=64)
    assert "loaded from cache" in again.message and again.heading_segments == 64
    coarse = plan_for_walk(scene, "miqcqp", 4, 60.0, tmp_path, heading_segments=16)
    assert "loaded from cache" not in coarse.message and coarse.heading_segments == 16
    # defaults: WALK_HEADING_SEGMENTS for the robot-aware plans, the document's 16 otherwise
    from footfall.sim.biped.model import WALK_HEADING_SEGMENTS

    assert plan_for_walk(scene, "miqcqp", 4, 60.0, None).heading_segments == WALK_HEADING_SEGMENTS
    document = plan_for_walk(scene, "miqcqp", 4, 60.0, None, robot_aware=False)
    assert document.heading_segments == 16
    with pytest.raises(InputError, match="heading_segments"):
        plan_for_walk(scene, "miqcqp", 4, 60.0, None, heading_segments=2)


@pytest.mark.parametrize(("segments", "widest"), [(16, (0.22, 0.26)), (64, (0.12, 0.18))])
def test_straight_plans_with_both_frames_step_wide_only_with_coarse_segments(
    segments: int, widest: tuple[float, float]
) -> None:
    # why walks plan with WALK_HEADING_SEGMENTS = 64: a straight walk holds theta = 0, a breakpoint
    # of the 16 segments, where each segment's reach (eq. 5.12f at both segment ends) loses most of one
    # side's forward reach; with both frames the plan then alternates narrow and ~0.24 m wide
    # steps. With 64 segments the steps stay near the inner width 0.12 m. (The last step is the
    # goal stance, 0.20 m.)
    from footfall.planning import PlannerOptions
    from footfall.sim.biped.model import WALK_HEADING_SEGMENTS

    assert segments in (16, WALK_HEADING_SEGMENTS)
    scene = replace(builtin_scene("flat"), goal=Goal(np.array([1.2, 0.0, 0.0]), 0.0))
    opts = PlannerOptions(reach_both_frames=True, heading_segments=segments, gap=1e-3)
    plan = make_plan(scene, "miqcqp", 6, opts, scene.robot)
    # straight: every heading at 0 (within the interior-point accuracy)
    assert plan.has_solution and np.allclose(plan.headings, 0.0, atol=1e-3)
    widths = np.abs(np.diff(plan.footsteps[:, 1]))[:-1]
    assert widths.min() >= 0.12 - 1e-6  # the inner reach bound
    assert widest[0] <= widths.max() <= widest[1]


@pytest.mark.parametrize(("flag", "both_frames"), [([], True), (["--document-reach"], False)])
def test_cli_walk_plans_robot_aware_unless_document_reach(  # type: ignore[no-untyped-def]
    flag: list[str], both_frames: bool, tmp_path
) -> None:
    # `walk` plans with both reach frames and the swing bound by default; --document-reach plans
    # the document's problem (eq. 5.12f in the stance frame only); plan.json says which
    import json

    from footfall.sim.biped.model import SWING_MAX
    from footfall.terrain.scene import scene_to_yaml

    scene = replace(builtin_scene("flat"), goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0))
    path = tmp_path / "short.yaml"
    path.write_text(scene_to_yaml(scene))
    out = tmp_path / "out"
    args = ["walk", str(path), "--planner", "kinematic", "--steps", "4", "--no-video"]
    res = CliRunner().invoke(app, [*args, "--out", str(out), *flag])
    assert res.exit_code == 0, res.output
    saved = json.loads((out / "plan.json").read_text())
    assert saved["reach_both_frames"] is both_frames
    assert saved.get("swing_max") == (SWING_MAX if both_frames else None)
    assert json.loads((out / "walk.json").read_text())["metrics"]["reached_goal"]


def test_cli_walk_rejects_too_few_heading_segments(tmp_path) -> None:  # type: ignore[no-untyped-def]
    import subprocess
    import sys

    args = ["walk", "--scene", "flat", "--heading-segments", "3", "--no-video"]
    res = subprocess.run(
        [sys.executable, "-m", "footfall", *args, "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    said = res.stdout + res.stderr
    assert res.returncode == 2 and "heading_segments: got 3" in said and "Traceback" not in said


def test_walk_plan_cache_is_not_reused_for_an_edited_scene_of_the_same_name(tmp_path) -> None:  # type: ignore[no-untyped-def]
    # the cache file is named after the scene; a scene edited under the same name (here its goal)
    # must be planned again, not served the old plan
    from footfall.sim.biped.plans import plan_for_walk

    scene = replace(builtin_scene("flat"), goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0))
    first = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    again = plan_for_walk(scene, "kinematic", 4, 60.0, tmp_path)
    assert "loaded from cache" in again.message
    edited = replace(scene, goal=Goal(np.array([0.7, 0.0, 0.0]), 0.0))
    other = plan_for_walk(edited, "kinematic", 4, 60.0, tmp_path)
    assert "loaded from cache" not in other.message
    mid = 0.5 * (other.footsteps[-1, :2] + other.footsteps[-2, :2])
    assert mid == pytest.approx([0.7, 0.0], abs=1e-6)
    assert first.footsteps[-1, 0] != pytest.approx(other.footsteps[-1, 0])


def test_a_plan_for_another_robot_is_refused_unless_asked_for() -> None:
    # the scene's own robot (32 kg, CoM 0.60 m) is not the MuJoCo biped (30.1 kg, 0.67 m)
    scene = builtin_scene("flat")
    scene = replace(scene, goal=Goal(np.array([1.0, 0.0, 0.0]), 0.0))
    plan = make_plan(scene, "reactive", robot=scene.robot)
    with pytest.raises(InputError, match=r"plan\.robot\.mass: got 32\.0.*planner_params") as err:
        walk(scene, plan)
    assert "check_robot=False" in str(err.value)
    # with the check off, the walk goes on to its next input check (a cheap way to show it ran)
    with pytest.raises(InputError, match="control_dt"):
        walk(scene, plan, WalkOptions(check_robot=False, control_dt=0.0105))
    taller = replace(planner_params(base=scene.robot), com_height=0.80)
    with pytest.raises(InputError, match=r"plan\.robot\.com_height"):
        walk(scene, make_plan(scene, "reactive", robot=taller))


# a start pad that ends 0.05 m ahead of the feet, as the planner benchmark's stepping stones: the
# box biped's 0.2 m sole overhangs it by 0.1 - 0.05 = 0.05 m (a hand count)
SHORT_PAD = """
name: short_pad
description: the start pad ends 5 cm ahead of the feet
start: {left: [0, 0.1, 0], right: [0, -0.1, 0], heading: 0, stance: right}
goal: {position: [1.0, 0, 0], heading: 0}
regions:
  - {name: start, height: 0.0, vertices: [[-0.45, -0.35], [0.05, -0.35], [0.05, 0.35], [-0.45, 0.35]]}
  - {name: goal, height: 0.0, vertices: [[0.25, -0.35], [1.5, -0.35], [1.5, 0.35], [0.25, 0.35]]}
"""


def test_a_start_sole_over_the_pad_edge_is_refused(tmp_path) -> None:  # type: ignore[no-untyped-def]
    """The walker stands on whole soles: a start foot whose sole overhangs every region by more
    than START_OVERHANG_TOL is refused with the overhang (API: before the walk; CLI: exit 2
    before any planning, nothing written); 1 cm of overhang is accepted."""
    from footfall.models.biped import BipedParams
    from footfall.sim.biped.options import START_OVERHANG_TOL, check_start_soles
    from footfall.terrain import load_scene

    path = tmp_path / "short_pad.yaml"
    path.write_text(SHORT_PAD)
    scene = load_scene(path)
    robot = BipedParams()
    assert robot.foot_length == pytest.approx(0.2)
    with pytest.raises(InputError, match=r"scene\.start\.left.*0\.050 m beyond") as err:
        check_start_soles(scene, robot)
    assert err.value.field == "scene.start.left"
    # a sole 8 cm long overhangs by 0.04 - 0.05 < 0: accepted; 0.12 m long: 0.01 m, at the limit
    check_start_soles(scene, replace(robot, foot_length=0.08))
    check_start_soles(scene, replace(robot, foot_length=0.1 + 2 * START_OVERHANG_TOL - 1e-9))
    with pytest.raises(InputError):
        check_start_soles(scene, replace(robot, foot_length=0.1 + 2 * START_OVERHANG_TOL + 1e-3))
    # every built-in scene's start is accepted
    for name in ("flat_long", "discrete_steps", "stairs_slope_gap", "stepping_stones"):
        check_start_soles(builtin_scene(name), robot)

    out = tmp_path / "out"
    r = footfall("walk", "--scene", str(path), "--no-video", "--out", str(out), timeout=120)
    line = error_line(r, "scene.start.left")
    assert "0.050 m beyond" in line
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("value", [0.0, -30.0, float("nan"), float("inf"), "30"])
def test_torque_weight_mass_must_be_a_positive_mass(value: object) -> None:
    with pytest.raises(InputError) as err:
        WalkOptions(torque_weight_mass=value)  # type: ignore[arg-type]
    assert err.value.field == "torque_weight_mass"


def test_the_walker_scales_the_torque_weight_by_the_plan_robots_mass() -> None:
    """The walker's MPC gets ``R = r (torque_weight_mass / m)^2`` for the plan's robot of mass
    ``m`` (footfall's biped: ``m`` = WEIGHTS_MASS, so ``R = r`` by default), and the literal ``r``
    with ``torque_weight_mass=None``."""
    scene = builtin_scene("flat_long")
    plan = make_plan(scene, "reactive", robot=planner_params(base=scene.robot))
    m = plan.robot.mass
    r = MPCWeights().r
    cases = ((WEIGHTS_MASS, r * (WEIGHTS_MASS / m) ** 2), (2.0 * m, 4.0 * r), (None, r))
    for mass, expected in cases:
        walker = BipedWalk(scene, plan, WalkOptions(torque_weight_mass=mass))
        mdl = walker.src.mpc.model  # type: ignore[attr-defined]
        assert mdl.weights.torque_weight(m) == pytest.approx(expected, rel=1e-12)
    assert abs(m - WEIGHTS_MASS) < 1e-9
