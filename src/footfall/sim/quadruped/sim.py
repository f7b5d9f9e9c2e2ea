"""Run a planned walk gait on the MuJoCo model and measure it (document 001, sec. 4).

The controller is the document's: joint-space position control tracking the planned joint angles
(inverse kinematics of the planned body pose and foot positions). Everything reported is
*measured* in the simulation: the centre of pressure (CoP) of the contact forces
(``mj_contactForce``), the support polygon of the feet actually in contact, foot slip, the trunk
trajectory. Planned quantities are only used to compute tracking errors.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall._validate import positive
from footfall.errors import FootfallError
from footfall.quadruped.gait import GaitParams, GaitPlan, GaitTrajectory, PhaseKind, plan_gait
from footfall.quadruped.robot import JOINT_NAMES, LEGS, QuadrupedRobot
from footfall.quadruped.stability import centre_of_pressure, stability_margin, support_polygon
from footfall.sim.quadruped import names as nm
from footfall.sim.quadruped.mjcf import SimSettings, slope_scene

#: a foot counts as in contact when it carries more than this fraction of the robot's weight
CONTACT_FORCE_FRACTION = 0.01
#: the robot has fallen when the trunk drops below this fraction of the planned height ...
FALL_HEIGHT_FRACTION = 0.5
#: ... or tilts this far from its planned attitude [rad]
FALL_TILT = math.radians(30.0)
#: video frame rate [1/s]
VIDEO_FPS = 30


@dataclass(frozen=True)
class SimResult:
    """Measurements of one simulated walk (arrays sampled at the control period, T samples).

    Attributes:
        t: time since the gait started, shape (T,) [s].
        trunk_pos: measured trunk centre, shape (T, 3) [m].
        trunk_pitch: measured nose-up pitch, shape (T,) [rad].
        cop: measured centre of pressure on the plane through the contacts, shape (T, 2) [m].
        margin: measured stability margin of the CoP in the measured support polygon, (T,) [m].
        n_contacts: number of feet in contact, shape (T,).
        feet: measured foot centres, shape (T, 4, 3) [m].
        slip_vel: tangential velocity of each foot's material point at its ground contact,
            shape (T, 4, 3) [m/s] (zero when the foot is off the ground). A rolling sphere has
            none, so this is true sliding, not the rolling of the spherical foot.
        planned: the planned references at the same instants.
        metrics: summary numbers (see :func:`summarise`).
        wall_time: wall-clock time of the physics + control loop [s] (video excluded).
        sim_time: simulated time [s].
        video: path of the MP4, or None.
        video_note: why there is no video, if there is none.
    """

    t: FloatArray
    trunk_pos: FloatArray
    trunk_pitch: FloatArray
    cop: FloatArray
    margin: FloatArray
    n_contacts: NDArray[np.int_]
    feet: FloatArray
    slip_vel: FloatArray
    planned: GaitTrajectory
    metrics: dict[str, Any] = field(default_factory=dict)
    wall_time: float = 0.0
    sim_time: float = 0.0
    video: Path | None = None
    video_note: str = ""


def _pitch_of(xmat: FloatArray) -> float:
    """Nose-up pitch of a rotation matrix (3, 3): angle of the body x axis above the horizon."""
    x_axis = xmat.reshape(3, 3)[:, 0]
    return float(math.atan2(x_axis[2], math.hypot(x_axis[0], x_axis[1])))


class QuadrupedSim:
    """MuJoCo model + data of the robot on a slope, with handles resolved once by name."""

    def __init__(
        self, robot: QuadrupedRobot, slope: float, settings: SimSettings | None = None
    ) -> None:
        try:
            import mujoco  # optional dependency: footfall[sim]
        except ImportError as exc:
            raise FootfallError(
                f"MuJoCo is required: pip install 'footfall[sim]' ({exc})"
            ) from None

        self.mujoco = mujoco
        self.robot = robot
        self.settings = settings if settings is not None else SimSettings()
        self.model = mujoco.MjModel.from_xml_string(slope_scene(robot, slope, self.settings))
        self.data = mujoco.MjData(self.model)
        m = self.model
        obj = mujoco.mjtObj
        self.trunk = mujoco.mj_name2id(m, obj.mjOBJ_BODY, nm.TRUNK_BODY)
        self.floor = mujoco.mj_name2id(m, obj.mjOBJ_GEOM, nm.FLOOR_GEOM)
        self.trunk_geom = mujoco.mj_name2id(m, obj.mjOBJ_GEOM, nm.TRUNK_GEOM)
        self.foot_geoms = [mujoco.mj_name2id(m, obj.mjOBJ_GEOM, nm.foot_geom(leg)) for leg in LEGS]
        self.foot_sites = [mujoco.mj_name2id(m, obj.mjOBJ_SITE, nm.foot_site(leg)) for leg in LEGS]
        joints = [
            mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.joint(leg, jn))
            for leg in LEGS
            for jn in JOINT_NAMES
        ]
        self.qpos_adr = np.array([m.jnt_qposadr[j] for j in joints])
        self.actuators = np.array(
            [
                mujoco.mj_name2id(m, obj.mjOBJ_ACTUATOR, nm.actuator(leg, jn))
                for leg in LEGS
                for jn in JOINT_NAMES
            ]
        )
        root = mujoco.mj_name2id(m, obj.mjOBJ_JOINT, nm.ROOT_JOINT)
        self.root_adr = int(m.jnt_qposadr[root])
        self._foot_of_geom = {g: i for i, g in enumerate(self.foot_geoms)}
        self._force6 = np.zeros(6)
        self._vel6 = np.zeros(6)

    def contact_slip_velocity(self, foot: int, point: FloatArray, normal: FloatArray) -> FloatArray:
        """Tangential velocity of foot ``foot``'s material point at ``point`` [m/s], shape (3,)."""
        g = self.foot_geoms[foot]
        # world-frame [angular, linear] velocity of the geom frame at the geom centre
        self.mujoco.mj_objectVelocity(
            self.model, self.data, self.mujoco.mjtObj.mjOBJ_GEOM, g, self._vel6, 0
        )
        w, v = self._vel6[:3], self._vel6[3:]
        vp = v + np.cross(w, point - self.data.geom_xpos[g])
        return vp - (vp @ normal) * normal

    def set_pose(self, body_pos: FloatArray, pitch_up: float, joints: FloatArray) -> None:
        """Place the robot (trunk pose and joint angles) at rest and run forward kinematics."""
        d = self.data
        d.qpos[:] = 0.0
        d.qvel[:] = 0.0
        d.qpos[self.root_adr : self.root_adr + 3] = body_pos
        # nose-up pitch is a rotation about y by -pitch_up
        d.qpos[self.root_adr + 3 : self.root_adr + 7] = (
            math.cos(-pitch_up / 2),
            0.0,
            math.sin(-pitch_up / 2),
            0.0,
        )
        d.qpos[self.qpos_adr] = joints
        d.ctrl[self.actuators] = joints
        self.mujoco.mj_forward(self.model, d)

    def contacts(self) -> tuple[FloatArray, FloatArray, NDArray[np.int_], bool]:
        """Foot contact points and forces on the robot in ``{W}``.

        Returns:
            ``(points (N, 3), forces (N, 3), foot index (N,), trunk_touches_ground)``.
        """
        d, m = self.data, self.model
        pts, frc, idx = [], [], []
        trunk_hit = False
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom[0]), int(c.geom[1])
            if self.trunk_geom in (g1, g2):
                trunk_hit = True
                continue
            if g1 in self._foot_of_geom:
                foot, sign = self._foot_of_geom[g1], -1.0
            elif g2 in self._foot_of_geom:
                foot, sign = self._foot_of_geom[g2], 1.0
            else:
                continue
            self.mujoco.mj_contactForce(m, d, i, self._force6)
            # contact frame rows are (normal, tangent1, tangent2); the force acts from geom1 on
            # geom2, so it is on the robot as is when the foot is geom2 and reversed otherwise
            f_world = sign * (c.frame.reshape(3, 3).T @ self._force6[:3])
            pts.append(np.array(c.pos))
            frc.append(f_world)
            idx.append(foot)
        if not pts:
            return np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, dtype=int), trunk_hit
        return np.array(pts), np.array(frc), np.array(idx), trunk_hit


def _make_renderer(sim: QuadrupedSim, width: int, height: int) -> tuple[Any, str]:
    """An offscreen renderer, or (None, reason) when no GL backend works."""
    try:
        renderer = sim.mujoco.Renderer(sim.model, height=height, width=width)
    except Exception as exc:  # any GL failure means "no video", never a crash
        return None, f"no offscreen GL backend ({type(exc).__name__}: {exc}); video skipped"
    return renderer, ""


def simulate(
    plan: GaitPlan,
    settings: SimSettings | None = None,
    control_dt: float = 0.01,
    settle_time: float = 0.5,
    video_path: Path | None = None,
    video_size: tuple[int, int] = (640, 480),
    progress: Callable[[float], None] | None = None,
) -> SimResult:
    """Simulate ``plan`` in MuJoCo with joint position control and measure it.

    Args:
        plan: the gait plan (its slope defines the scene).
        settings: physics settings.
        control_dt: control and measurement period [s]; joint targets are interpolated linearly
            between plan samples at every physics step.
        settle_time: standing time before the gait starts, in the initial pose [s].
        video_path: write an MP4 here (offscreen GL); None = no video.
        video_size: (width, height) of the video [px].
        progress: optional callback receiving the fraction done.

    Returns:
        A :class:`SimResult` with metrics.
    """
    control_dt = positive("control_dt", control_dt)
    sim = QuadrupedSim(plan.robot, plan.posture.slope, settings)
    m, d = sim.model, sim.data
    mj = sim.mujoco
    ref = plan.sample(control_dt)
    sim.set_pose(ref.body_pos[0], ref.body_pitch, ref.joints[0])
    substeps = max(1, round(control_dt / m.opt.timestep))

    renderer: Any = None
    note = ""
    writer = None
    if video_path is not None:
        renderer, note = _make_renderer(sim, *video_size)
        if renderer is not None:
            import imageio.v2 as imageio

            video_path.parent.mkdir(parents=True, exist_ok=True)
            writer = imageio.get_writer(str(video_path), fps=VIDEO_FPS, macro_block_size=8)
    frame_every = max(1, round(1.0 / (VIDEO_FPS * control_dt)))
    render_time = 0.0

    normal = plan.posture.slope_normal
    weight = plan.robot.total_mass * float(-m.opt.gravity[2])
    n = ref.t.shape[0]
    trunk = np.empty((n, 3))
    pitch = np.empty(n)
    cop = np.full((n, 2), np.nan)
    margin = np.full(n, np.nan)
    ncon = np.zeros(n, dtype=int)
    feet = np.empty((n, 4, 3))
    slip_vel = np.zeros((n, 4, 3))
    fallen_at = math.nan

    wall0 = time.perf_counter()
    # settle in the initial pose so the legs take the weight before the gait starts
    for _ in range(round(settle_time / m.opt.timestep)):
        mj.mj_step(m, d)
    for k in range(n):
        q0 = ref.joints[k]
        q1 = ref.joints[min(k + 1, n - 1)]
        for s in range(substeps):
            d.ctrl[sim.actuators] = q0 + (q1 - q0) * (s / substeps)
            mj.mj_step(m, d)
        trunk[k] = d.xpos[sim.trunk]
        pitch[k] = _pitch_of(d.xmat[sim.trunk])
        feet[k] = d.site_xpos[sim.foot_sites]
        pts, frc, idx, trunk_hit = sim.contacts()
        loaded = frc[:, 2] > CONTACT_FORCE_FRACTION * weight if frc.size else np.zeros(0, bool)
        in_contact = np.unique(idx[loaded])
        ncon[k] = in_contact.size
        if loaded.any():
            z_p = float(pts[loaded, 2].mean())
            cop[k], _ = centre_of_pressure(pts[loaded], frc[loaded], z_p)
            # each foot touches at one point (sphere on plane), so the feet's points span it
            margin[k] = stability_margin(cop[k], support_polygon(pts[loaded]))
        for j in range(idx.size):
            slip_vel[k, idx[j]] = sim.contact_slip_velocity(idx[j], pts[j], normal)
        tilt = abs(pitch[k] - ref.body_pitch)
        low = trunk[k, 2] - plan.posture.plane_height(float(trunk[k, 0]))
        if math.isnan(fallen_at) and (
            trunk_hit or tilt > FALL_TILT or low < FALL_HEIGHT_FRACTION * plan.posture.height
        ):
            fallen_at = float(ref.t[k])
        if writer is not None and k % frame_every == 0:
            r0 = time.perf_counter()
            renderer.update_scene(d, camera=nm.TRACK_CAMERA)
            writer.append_data(renderer.render())
            render_time += time.perf_counter() - r0
        if progress is not None and k % 200 == 0:
            progress(k / n)
    wall = time.perf_counter() - wall0 - render_time
    if writer is not None:
        writer.close()
    if renderer is not None:
        renderer.close()
    result = SimResult(
        t=ref.t,
        trunk_pos=trunk,
        trunk_pitch=pitch,
        cop=cop,
        margin=margin,
        n_contacts=ncon,
        feet=feet,
        slip_vel=slip_vel,
        planned=ref,
        wall_time=wall,
        sim_time=settle_time + float(ref.t[-1]),
        video=video_path if writer is not None else None,
        video_note=note,
    )
    result.metrics.update(summarise(plan, result, fallen_at))
    return result


def _sway(t: FloatArray, pos: FloatArray, cycle_of: NDArray[np.int_], cycles: int) -> dict:
    """Per-cycle body sway: horizontal path length, lateral path, excess path over net motion."""
    path, lateral, excess = [], [], []
    for c in range(cycles):
        sel = np.flatnonzero(cycle_of == c)
        if sel.size < 2:
            continue
        p = pos[sel, :2]
        seg = np.diff(p, axis=0)
        length = float(np.linalg.norm(seg, axis=1).sum())
        path.append(length)
        lateral.append(float(np.abs(seg[:, 1]).sum()))
        excess.append(length - float(np.linalg.norm(p[-1] - p[0])))
    return {
        "path_per_cycle_m": float(np.mean(path)) if path else math.nan,
        "lateral_path_per_cycle_m": float(np.mean(lateral)) if lateral else math.nan,
        "excess_path_per_cycle_m": float(np.mean(excess)) if excess else math.nan,
    }


def body_sway(plan: GaitPlan, traj_t: FloatArray, body: FloatArray) -> dict[str, float]:
    """Body sway per gait cycle of a body trajectory sampled at ``traj_t`` (planned or measured).

    Three measures per cycle, averaged over cycles: horizontal path length of the body centre,
    its lateral (y) path length, and the excess of the path over the net displacement (the
    motion spent on swaying rather than progressing). Also the number of body shifts per cycle.
    """
    starts = np.array([p.t0 for p in plan.phases])
    idx = np.clip(np.searchsorted(starts, traj_t, side="right") - 1, 0, len(plan.phases) - 1)
    cycle_of = np.array([plan.phases[i].cycle for i in idx])
    # the final centring shift and hold are not part of a gait cycle
    tail = np.array([plan.phases[i].t0 >= _last_swing_end(plan) for i in idx])
    cycle_of[tail] = -1
    out = _sway(traj_t, body, cycle_of, plan.params.cycles)
    shifts = [p for p in plan.phases if p.kind is PhaseKind.SHIFT and p.t0 < _last_swing_end(plan)]
    out["shifts_per_cycle"] = len(shifts) / plan.params.cycles
    return out


def _last_swing_end(plan: GaitPlan) -> float:
    return max(p.t1 for p in plan.phases if p.kind is PhaseKind.SWING)


def summarise(plan: GaitPlan, res: SimResult, fallen_at: float = math.nan) -> dict[str, Any]:
    """Metrics of a simulated walk (all from measured data unless named ``planned``)."""
    ref = res.planned
    post = plan.posture
    u = post.slope_direction
    along = res.trunk_pos @ u
    distance = float(along[-1] - along[0])
    duration = float(res.t[-1] - res.t[0])
    # stance phases: the planner has >= 3 feet down; the walk gait has no other phases
    stance = ref.contact.sum(axis=1) >= 3
    measured_ok = stance & (res.n_contacts >= 3) & np.isfinite(res.margin)
    three = ref.contact.sum(axis=1) == 3
    m_all = res.margin[measured_ok]
    m_three = res.margin[measured_ok & three]
    err = np.linalg.norm(res.cop - ref.zmp, axis=1)
    err_ok = err[measured_ok]
    # foot slip: integral of the contact points' sliding velocity over each planned stance
    dt = float(res.t[1] - res.t[0])
    slips: list[float] = []
    backward: list[float] = []
    for i in range(4):
        c = ref.contact[:, i]
        edges = np.flatnonzero(np.diff(c.astype(int)) != 0) + 1
        bounds = np.concatenate([[0], edges, [c.size]])
        for a, b in itertools.pairwise(bounds):
            if not c[a]:
                continue
            disp = res.slip_vel[a:b, i].sum(axis=0) * dt
            slips.append(float(np.linalg.norm(disp)))
            backward.append(float(-min(0.0, disp @ u)))
    fell = not math.isnan(fallen_at)
    sway_meas = body_sway(plan, res.t, res.trunk_pos)
    sway_plan = body_sway(plan, ref.t, ref.body_pos)
    return {
        "slope_deg": math.degrees(post.slope),
        "body_deg": math.degrees(post.body_pitch),
        "strategy": plan.params.strategy.value,
        "step_m": plan.params.step,
        "swing_height_m": plan.params.swing_height,
        "swing_period_s": plan.params.swing_period,
        "shift_period_s": plan.params.shift_period,
        "cycles": plan.params.cycles,
        "gait_duration_s": duration,
        "distance_up_slope_m": distance,
        "planned_distance_up_slope_m": float((ref.body_pos[-1] - ref.body_pos[0]) @ u),
        "mean_speed_m_s": distance / duration if duration > 0 else math.nan,
        "fell": fell,
        "fall_time_s": None if not fell else fallen_at,
        "stability_margin_min_m": float(m_all.min()) if m_all.size else None,
        "stability_margin_mean_m": float(m_all.mean()) if m_all.size else None,
        "stability_margin_min_three_leg_m": float(m_three.min()) if m_three.size else None,
        "stability_margin_mean_three_leg_m": float(m_three.mean()) if m_three.size else None,
        "planned_margin_min_m": float(np.nanmin(ref.margin)),
        "planned_margin_min_three_leg_m": float(np.nanmin(ref.margin[three])),
        "stance_samples": int(stance.sum()),
        "stance_samples_with_fewer_than_3_contacts": int((stance & (res.n_contacts < 3)).sum()),
        "zmp_error_mean_m": float(err_ok.mean()) if err_ok.size else None,
        "zmp_error_max_m": float(err_ok.max()) if err_ok.size else None,
        "foot_slip_max_m": max(slips) if slips else 0.0,
        "foot_slip_mean_m": float(np.mean(slips)) if slips else 0.0,
        "foot_backward_slip_total_m": float(np.sum(backward)) if backward else 0.0,
        "trunk_drift_from_plan_m": float(np.linalg.norm(res.trunk_pos[-1] - ref.body_pos[-1])),
        "body_sway_measured": sway_meas,
        "body_sway_planned": sway_plan,
        "sim_time_s": res.sim_time,
        "wall_time_s": res.wall_time,
        "realtime_factor": res.sim_time / res.wall_time if res.wall_time > 0 else math.nan,
        "video": str(res.video) if res.video is not None else None,
        "video_note": res.video_note,
    }


def run_slope_walk(
    robot: QuadrupedRobot,
    params: GaitParams,
    settings: SimSettings | None = None,
    video_path: Path | None = None,
) -> tuple[GaitPlan, SimResult]:
    """Plan (raising InputError before any simulation on bad input) and simulate a slope walk."""
    plan = plan_gait(robot, params)
    return plan, simulate(plan, settings, video_path=video_path)


def benchmark_quadruped(
    slope_deg: float = 15.0,
    body_deg: float = 10.0,
    sim_cycles: int = 6,
    plan_cycles: int = 10,
    plan_repeats: int = 20,
) -> dict[str, Any]:
    """Speed of the slope walk (issue goals: >= 5x real time; 10-cycle plan < 50 ms).

    Measures, in one run on the current core:

    * the closed-loop simulation (control, contact forces, CoP, margins, slip; no video) as
      simulated seconds per wall second, against a baseline of bare ``mj_step`` calls on the same
      model for the same simulated time (so ``overhead_ratio`` is what footfall's loop costs on
      top of the physics);
    * the gait plan of ``plan_cycles`` cycles (``plan_gait``) and its dense sampling at 100 Hz
      with joint angles and eq.-(5) ZMP (``GaitPlan.sample``), median of ``plan_repeats``.

    Returns:
        A JSON-ready dict of timings and ratios.
    """
    import mujoco

    robot = QuadrupedRobot()
    slope, pitch = math.radians(slope_deg), math.radians(body_deg)
    plan = plan_gait(robot, GaitParams(slope, pitch, cycles=sim_cycles))
    res = simulate(plan)
    loop_rtf = res.sim_time / res.wall_time

    base = QuadrupedSim(robot, slope)
    ref = plan.sample(0.01, with_zmp=False)
    base.set_pose(ref.body_pos[0], ref.body_pitch, ref.joints[0])
    steps = round(res.sim_time / base.model.opt.timestep)
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(base.model, base.data)
    base_wall = time.perf_counter() - t0
    base_rtf = res.sim_time / base_wall

    params = GaitParams(slope, pitch, cycles=plan_cycles)
    plan_gait(robot, params).sample(0.01)  # warm-up (imports, caches)
    plan_times, sample_times = [], []
    for _ in range(plan_repeats):
        t0 = time.perf_counter()
        p = plan_gait(robot, params)
        t1 = time.perf_counter()
        p.sample(0.01)
        plan_times.append(t1 - t0)
        sample_times.append(time.perf_counter() - t1)
    plan_ms = 1e3 * float(np.median(plan_times))
    sample_ms = 1e3 * float(np.median(sample_times))
    return {
        "slope_deg": slope_deg,
        "body_deg": body_deg,
        "sim_cycles": sim_cycles,
        "simulated_s": res.sim_time,
        "loop_wall_s": res.wall_time,
        "loop_realtime_factor": loop_rtf,
        "baseline_mj_step_realtime_factor": base_rtf,
        "overhead_ratio": base_rtf / loop_rtf,
        "realtime_goal": 5.0,
        "realtime_vs_goal": loop_rtf / 5.0,
        "fell": res.metrics["fell"],
        "plan_cycles": plan_cycles,
        "plan_ms_median": plan_ms,
        "sample_100hz_ms_median": sample_ms,
        "plan_plus_sample_ms_median": plan_ms + sample_ms,
        "plan_goal_ms": 50.0,
        "plan_goal_over_plan_ms": 50.0 / plan_ms,
        "plan_goal_over_plan_plus_sample_ms": 50.0 / (plan_ms + sample_ms),
    }
