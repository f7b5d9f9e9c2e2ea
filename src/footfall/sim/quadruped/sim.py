"""Run a planned walk gait on the MuJoCo model and measure it (document 001, sec. 4).

The controller is the document's: joint-space position control tracking the planned joint angles
(inverse kinematics of the planned body pose and foot positions). Everything reported is
*measured* in the simulation: the centre of pressure (CoP) of the contact forces
(``mj_contactForce``), the support polygon of the feet actually in contact, foot slip, the trunk
trajectory. Planned quantities are only used to compute tracking errors.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._mjcf import require_mujoco
from footfall._typing import FloatArray
from footfall._validate import positive
from footfall.errors import InputError
from footfall.quadruped.gait import GaitParams, GaitPlan, GaitTrajectory, PhaseKind, plan_gait
from footfall.quadruped.ground import PlaneGround, QuadrupedGround
from footfall.quadruped.robot import JOINT_NAMES, LEGS, QuadrupedRobot
from footfall.quadruped.stability import _GEOM_EPS
from footfall.results.quadruped import (
    BodySway,
    QuadrupedMetrics,
    QuadrupedResult,
    QuadrupedTrace,
    StanceSlip,
)
from footfall.sim._video import Video
from footfall.sim.disturbance import Push, push_force
from footfall.sim.falls import QUADRUPED_FALL
from footfall.sim.quadruped import names as nm
from footfall.sim.quadruped._measure import foot_contacts, measure_sample, slide_step
from footfall.sim.quadruped.mjcf import SimSettings, ground_scene
from footfall.sim.quadruped.slip import (
    SlipGuard,
    SlipMonitor,
    check_guard,
    downhill,
    stance_slips,
)
from footfall.sim.replay import ReplayRecorder

#: a foot counts as in contact when it carries more than this fraction of the robot's weight
CONTACT_FORCE_FRACTION = 0.01
#: the quadruped's controllers (``simulate(controller=...)``)
CONTROLLERS = ("servo", "wbc")


def _pitch_of(xmat: FloatArray) -> float:
    """Nose-up pitch of a rotation matrix (3, 3): angle of the body x axis above the horizon."""
    x_axis = xmat.reshape(3, 3)[:, 0]
    return float(math.atan2(x_axis[2], math.hypot(x_axis[0], x_axis[1])))


class QuadrupedSim:
    """MuJoCo model + data of the robot on a slope, with handles resolved once by name."""

    def __init__(
        self,
        robot: QuadrupedRobot,
        slope: float | QuadrupedGround,
        settings: SimSettings | None = None,
        x_range: tuple[float, float] = (-3.0, 12.0),
    ) -> None:
        mujoco = require_mujoco()
        self.mujoco = mujoco
        self.robot = robot
        self.settings = settings if settings is not None else SimSettings()
        #: the ground (a number is the document's slope [rad])
        self.ground = slope if not isinstance(slope, int | float) else PlaneGround(float(slope))
        xml = ground_scene(robot, self.ground, self.settings, x_range)
        #: the MJCF text compiled into ``model`` (a replay stores it, :mod:`footfall.sim.replay`)
        self.xml = xml
        self.model = mujoco.MjModel.from_xml_string(xml)
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
        #: (ngeom,) each geom's leg, -1 for the geoms that are no foot
        self.foot_of_geom = np.full(m.ngeom, -1, dtype=np.int64)
        self.foot_of_geom[self.foot_geoms] = np.arange(len(LEGS))

    def foot_velocities(self, out: FloatArray) -> None:
        """Each foot geom's world-frame ``[angular, linear]`` velocity at its centre into ``out``
        (4, 6) [rad/s, m/s] (``mj_objectVelocity``)."""
        mj, geom = self.mujoco, self.mujoco.mjtObj.mjOBJ_GEOM
        for leg, g in enumerate(self.foot_geoms):
            mj.mj_objectVelocity(self.model, self.data, geom, g, out[leg], 0)

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
        d, con = self.data, self.data.contact
        pyramidal = self.model.opt.cone == self.mujoco.mjtCone.mjCONE_PYRAMIDAL
        return foot_contacts(
            con.geom,
            con.pos,
            con.frame,
            con.efc_address,
            con.dim,
            con.friction,
            d.efc_force,
            bool(pyramidal),
            self.foot_of_geom,
            self.trunk_geom,
        )


class _Recorder:
    """Measures one walk into a :class:`~footfall.results.quadruped.QuadrupedTrace`, one control
    sample at a time, and detects a fall."""

    def __init__(self, sim: QuadrupedSim, plan: GaitPlan, ref: GaitTrajectory) -> None:
        self.sim = sim
        self.plan = plan
        #: the plan's ground, read once (GaitPlan.ground builds a checked PlaneGround per call)
        self.ground = plan.ground
        self.trace = QuadrupedTrace.empty(ref)
        self.weight = plan.robot.total_mass * float(-sim.model.opt.gravity[2])
        #: the normal force [N] above which a contact counts as loaded
        self.loaded_force = CONTACT_FORCE_FRACTION * self.weight
        #: the ground's normal on a plane (the same everywhere), None on other grounds
        self._plane_normal = (
            self.ground.normal(0.0, 0.0) if isinstance(self.ground, PlaneGround) else None
        )
        self._normals = np.zeros((0, 3))
        self._foot_vel = np.zeros((4, 6))
        self._foot_geoms = np.asarray(sim.foot_geoms, dtype=np.int64)
        #: the physics step [s], the interval of the slip's integral
        self.h = float(sim.model.opt.timestep)
        m = sim.model
        self._foot_body = np.asarray(m.geom_bodyid[self._foot_geoms], dtype=np.int64)
        self._foot_root = np.asarray(m.body_rootid[self._foot_body], dtype=np.int64)
        self._foot_sites = np.asarray(sim.foot_sites, dtype=np.int64)
        #: the ground's normal under each foot at the last sample (4, 3)
        up = self._plane_normal if self._plane_normal is not None else (0.0, 0.0, 1.0)
        self._foot_normals = np.tile(up, (4, 1))

    def _normals_at(self, pts: FloatArray, feet: FloatArray) -> FloatArray:
        """The ground's normal (N + 4, 3) at the contact points ``pts`` (N, 3), then under the
        foot centres ``feet`` (4, 3)."""
        if self._plane_normal is None:
            xy = [*pts[:, :2].tolist(), *feet[:, :2].tolist()]
            return np.array([self.ground.normal(x, y) for x, y in xy]).reshape(-1, 3)
        rows = pts.shape[0] + 4
        if self._normals.shape[0] < rows:
            self._normals = np.tile(self._plane_normal, (rows, 1))
        return self._normals[:rows]

    def measure(self, k: int) -> None:
        """Record sample ``k``: trunk, feet, loaded contacts, CoP, margin, slip; detect a fall."""
        sim, d, tr = self.sim, self.sim.data, self.trace
        tr.trunk_pos[k] = d.xpos[sim.trunk]
        tr.trunk_pitch[k] = _pitch_of(d.xmat[sim.trunk])
        feet = tr.feet[k]
        feet[:] = d.site_xpos[sim.foot_sites]
        pts, frc, idx, trunk_hit = sim.contacts()
        sim.foot_velocities(self._foot_vel)
        normals = self._normals_at(pts, feet)
        self._foot_normals[:] = normals[-4:]
        # the CoP of the loaded contacts, their support polygon (each foot touches at one point,
        # sphere on plane, so the feet's points span it) and the CoP's margin in it; each
        # contact's sliding, and that of a planned stance foot off the ground (bouncing, or the
        # ground lower than planned), which moves with its whole centre
        measure_sample(
            k,
            pts,
            frc,
            idx,
            self.loaded_force,
            _GEOM_EPS,
            tr.planned.contact[k],
            feet,
            d.geom_xpos,
            self._foot_geoms,
            self._foot_vel,
            normals,
            tr.cop,
            tr.margin,
            tr.n_contacts,
            tr.slip_vel,
        )
        tr.slip_disp[k] = tr.slip_vel[k] * self.h
        if math.isnan(tr.fallen_at) and (trunk_hit or self._fallen(k)):
            tr.fallen_at = float(tr.t[k])

    def slide(self, k: int) -> None:
        """Add one later physics step of control period ``k`` to its sliding displacement
        (``trace.slip_disp[k]``): the feet's sliding velocity at the state the step just started
        from (its kinematics, velocities and contacts, as :meth:`measure` reads them), times the
        step. The stance flags are the period's planned ones (``planned.contact[k]``); the
        ground's normal is the one under each foot at sample ``k`` (on a plane, the plane's)."""
        d, sim, tr = self.sim.data, self.sim, self.trace
        con = d.contact
        slide_step(
            con.geom,
            con.pos,
            d.cvel,
            d.subtree_com,
            self._foot_body,
            self._foot_root,
            sim.foot_of_geom,
            sim.trunk_geom,
            tr.planned.contact[k],
            d.site_xpos,
            self._foot_sites,
            self._foot_normals,
            self.h,
            tr.slip_disp[k],
        )

    def _fallen(self, k: int) -> bool:
        """Trunk tilted too far from its planned pitch, or too low above the ground
        (:data:`~footfall.sim.falls.QUADRUPED_FALL`)."""
        post, tr = self.plan.posture, self.trace
        tilt = abs(tr.trunk_pitch[k] - tr.planned.body_pitch[k])
        x, y = float(tr.trunk_pos[k, 0]), float(tr.trunk_pos[k, 1])
        low = tr.trunk_pos[k, 2] - self.ground.centre_height(x, y)
        return QUADRUPED_FALL.fallen(float(tilt), float(low), post.height)


def _sample(rec: _Recorder, k: int, guard: SlipMonitor | None, video: Video, d: Any) -> bool:
    """Measure sample ``k`` right after the first physics step of its control period, the step
    that starts at its time ``t[k]``: MuJoCo's kinematics, contacts and contact forces then
    describe the state at ``t[k]`` (``mj_step`` computes them for the state it starts from, then
    integrates), the instant of the plan's sample ``k`` they are compared with. Then the slip
    guard (True when it held the reference, ``rec.trace.planned``) and the video frame."""
    rec.measure(k)
    tr = rec.trace
    held = False
    if guard is not None and guard.update(k, tr.slip_vel[k]):
        tr.planned = guard.reference
        held = True
    video.frame(k, d)
    return held


def _track(
    sim: QuadrupedSim,
    rec: _Recorder,
    video: Video,
    control_dt: float,
    progress: Callable[[float], None] | None,
    pushes: tuple[Push, ...] = (),
    guard: SlipMonitor | None = None,
    replay: ReplayRecorder | None = None,
) -> None:
    """Track the planned joint angles sample by sample, measuring after each control period
    (``guard``: the slip guard, which may hold the reference, ``rec.trace.planned``, still)."""
    m, d, mj = sim.model, sim.data, sim.mujoco
    substeps = max(1, round(control_dt / m.opt.timestep))
    tr = rec.trace
    n = tr.planned.joints.shape[0]
    for k in range(n):
        if replay is not None:
            replay.sample(float(tr.t[k]), d)
        joints = tr.planned.joints
        q0 = joints[k]
        q1 = joints[min(k + 1, n - 1)]
        # joint targets interpolated linearly between plan samples at every physics step
        for s in range(substeps):
            d.ctrl[sim.actuators] = q0 + (q1 - q0) * (s / substeps)
            if pushes:
                d.xfrc_applied[sim.trunk, :3] = push_force(
                    pushes, float(tr.t[0]) + (k * substeps + s) * m.opt.timestep
                )
            mj.mj_step(m, d)
            if s == 0:
                _sample(rec, k, guard, video, d)
            else:
                rec.slide(k)
        if progress is not None and k % 200 == 0:
            progress(k / n)


def _track_wbc(
    sim: QuadrupedSim,
    rec: _Recorder,
    video: Video,
    control_dt: float,
    progress: Callable[[float], None] | None,
    gains: Any,
    settle_time: float,
    pushes: tuple[Push, ...] = (),
    guard: SlipMonitor | None = None,
    replay: ReplayRecorder | None = None,
) -> None:
    """Drive every joint by torque from the whole-body QP (:mod:`.wbc`) at every physics step,
    measuring after each control period; it also holds the first reference while the robot
    settles (no hand-over transient from another controller)."""
    from footfall.sim.quadruped.wbc import QuadrupedWbc

    m, d, mj = sim.model, sim.data, sim.mujoco
    tr = rec.trace
    wbc = QuadrupedWbc(sim, tr.planned, rec.ground, gains)
    substeps = max(1, round(control_dt / m.opt.timestep))
    t_start = float(tr.t[0])
    for i in range(round(settle_time / m.opt.timestep)):
        mj.mj_step1(m, d)
        if i % gains.qp_every == 0:
            d.ctrl[sim.actuators] = wbc.torques(t_start)
        mj.mj_step2(m, d)
    n = tr.t.shape[0]
    for k in range(n):
        if replay is not None:
            replay.sample(float(tr.t[k]), d)
        for s in range(substeps):
            mj.mj_step1(m, d)
            i = k * substeps + s
            t = t_start + i * m.opt.timestep
            if wbc.due(i, t):
                d.ctrl[sim.actuators] = wbc.torques(t)
            if pushes:
                d.xfrc_applied[sim.trunk, :3] = push_force(pushes, t)
            mj.mj_step2(m, d)
            if s > 0:
                rec.slide(k)
            elif _sample(rec, k, guard, video, d):
                wbc.retarget(tr.planned)
        if progress is not None and k % 200 == 0:
            progress(k / n)
    tr.qp_failures = wbc.failures


def simulate(
    plan: GaitPlan,
    settings: SimSettings | None = None,
    control_dt: float = 0.01,
    settle_time: float = 0.5,
    video_path: Path | None = None,
    video_size: tuple[int, int] = (640, 480),
    progress: Callable[[float], None] | None = None,
    controller: str = "servo",
    wbc_gains: Any = None,
    pushes: tuple[Push, ...] = (),
    slip_guard: SlipGuard | None = None,
    replay: ReplayRecorder | None = None,
) -> QuadrupedResult:
    """Simulate ``plan`` in MuJoCo and measure it.

    ``controller``: ``servo`` (document 001: joint position servos on the planned angles) or
    ``wbc`` (joint torques from the whole-body QP that puts the centre of pressure on the planned
    ZMP, :mod:`footfall.sim.quadruped.wbc`); ``wbc_gains`` its
    :class:`~footfall.sim.quadruped.wbc.QuadrupedWbcGains` (None: the defaults). ``pushes``:
    forces on the trunk (:class:`~footfall.sim.disturbance.Push`, times since the gait started).
    ``slip_guard``: stop the gait when a foot slips (:class:`~footfall.sim.quadruped.slip.SlipGuard`;
    None: off); the run keeps its planned length, holding still after a stop. ``replay``: also
    record the joint positions for ``footfall view`` (:mod:`footfall.sim.replay`).

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
        A :class:`~footfall.results.quadruped.QuadrupedResult`.
    """
    control_dt = positive("control_dt", control_dt)
    pushes = tuple(pushes)
    for i, p in enumerate(pushes):
        if not isinstance(p, Push):
            raise InputError(f"pushes[{i}]", p, "a footfall.sim.Push")
    if controller not in CONTROLLERS:
        raise InputError("controller", controller, f"one of {', '.join(CONTROLLERS)}")
    slip_guard = check_guard(slip_guard)
    if controller == "wbc":
        from footfall.sim.quadruped.wbc import QuadrupedWbcGains, check_gains

        wbc_gains = QuadrupedWbcGains() if wbc_gains is None else check_gains(wbc_gains)
    ref = plan.sample(control_dt)
    x = ref.feet[:, :, 0]
    sim = QuadrupedSim(plan.robot, plan.ground, settings, (float(x.min()) - 2, float(x.max()) + 2))
    sim.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    video = Video(sim.mujoco, sim.model, video_path, video_size, control_dt, nm.TRACK_CAMERA)
    rec = _Recorder(sim, plan, ref)
    guard = SlipMonitor(slip_guard, plan, ref) if slip_guard is not None else None
    if replay is not None:
        replay.begin(sim.xml)

    wall0 = time.perf_counter()
    try:
        if controller == "wbc":
            _track_wbc(
                sim, rec, video, control_dt, progress, wbc_gains, settle_time, pushes, guard, replay
            )
        else:
            # settle in the initial pose so the legs take the weight before the gait starts
            for _ in range(round(settle_time / sim.model.opt.timestep)):
                sim.mujoco.mj_step(sim.model, sim.data)
            _track(sim, rec, video, control_dt, progress, pushes, guard, replay)
    except BaseException:  # an error or a signal: no half-written video in place
        video.close(complete=False)
        raise
    tr = rec.trace
    tr.wall_time = time.perf_counter() - wall0 - video.render_time
    tr.sim_time = settle_time + float(ref.t[-1])
    video_file = video.close()
    return QuadrupedResult(
        trace=tr,
        metrics=summarise(plan, tr, video_file, video.note),
        controller=controller,
        slip_stop=guard.stop if guard is not None else None,
        video=video_file,
        video_note=video.note,
    )


def _sway(t: FloatArray, pos: FloatArray, cycle_of: NDArray[np.int_], cycles: int) -> list[float]:
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
    return [float(np.mean(v)) if v else math.nan for v in (path, lateral, excess)]


def body_sway(plan: GaitPlan, traj_t: FloatArray, body: FloatArray) -> BodySway:
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
    path, lateral, excess = _sway(traj_t, body, cycle_of, plan.params.cycles)
    shifts = [p for p in plan.phases if p.kind is PhaseKind.SHIFT and p.t0 < _last_swing_end(plan)]
    return BodySway(path, lateral, excess, len(shifts) / plan.params.cycles)


def _last_swing_end(plan: GaitPlan) -> float:
    return max(p.t1 for p in plan.phases if p.kind is PhaseKind.SWING)


def _foot_slips(
    plan: GaitPlan, res: QuadrupedTrace, u: FloatArray
) -> tuple[list[StanceSlip], list[float], list[float]]:
    """Each foot's sliding over each planned stance (:func:`.slip.stance_slips`), the lengths of
    those displacements and their parts against ``u`` [m].

    The displacement is the integral of the contact point's sliding velocity over the stance,
    taken at every physics step (``slip_disp``).
    """
    down = downhill(plan, res.planned.feet)
    per_stance = stance_slips(res.t, res.planned.contact, res.slip_disp, down)
    slips = [s.slip_m for s in per_stance]
    backward = [-min(0.0, float(np.dot(s.displacement_m, u))) for s in per_stance]
    return per_stance, slips, backward


def _min_mean(x: FloatArray) -> tuple[float | None, float | None]:
    """(min, mean) of ``x``, or (None, None) when it is empty."""
    return (float(x.min()), float(x.mean())) if x.size else (None, None)


def summarise(
    plan: GaitPlan, res: QuadrupedTrace, video: Path | None = None, video_note: str = ""
) -> QuadrupedMetrics:
    """Metrics of a simulated walk (all from measured data unless named ``planned``)."""
    fallen_at = res.fallen_at
    ref = res.planned
    post = plan.posture
    prm = plan.params
    # up the document's slope; along +x (the walking direction) on other grounds
    u = post.slope_direction if prm.ground is None else np.array([1.0, 0.0, 0.0])
    along = res.trunk_pos @ u
    distance = float(along[-1] - along[0])
    duration = float(res.t[-1] - res.t[0])
    # stance phases: the planner has >= 3 feet down; the walk gait has no other phases
    stance = ref.contact.sum(axis=1) >= 3
    measured_ok = stance & (res.n_contacts >= 3) & np.isfinite(res.margin)
    three = ref.contact.sum(axis=1) == 3
    m_min, m_mean = _min_mean(res.margin[measured_ok])
    m3_min, m3_mean = _min_mean(res.margin[measured_ok & three])
    err_ok = np.linalg.norm(res.cop - ref.zmp, axis=1)[measured_ok]
    per_stance, slips, backward = _foot_slips(plan, res, u)
    fell = not math.isnan(fallen_at)
    return QuadrupedMetrics(
        slope_deg=math.degrees(post.slope),
        body_deg=math.degrees(post.body_pitch),
        strategy=prm.strategy.value,
        step_m=prm.step,
        swing_height_m=prm.swing_height,
        swing_period_s=prm.swing_period,
        shift_period_s=prm.shift_period,
        cycles=prm.cycles,
        gait_duration_s=duration,
        distance_up_slope_m=distance,
        planned_distance_up_slope_m=float((ref.body_pos[-1] - ref.body_pos[0]) @ u),
        mean_speed_m_s=distance / duration if duration > 0 else math.nan,
        fell=fell,
        fall_time_s=None if not fell else fallen_at,
        stability_margin_min_m=m_min,
        stability_margin_mean_m=m_mean,
        stability_margin_min_three_leg_m=m3_min,
        stability_margin_mean_three_leg_m=m3_mean,
        planned_margin_min_m=float(np.nanmin(ref.margin)),
        planned_margin_min_three_leg_m=float(np.nanmin(ref.margin[three]))
        if three.any()
        else math.nan,
        stance_samples=int(stance.sum()),
        stance_samples_with_fewer_than_3_contacts=int((stance & (res.n_contacts < 3)).sum()),
        zmp_error_mean_m=float(err_ok.mean()) if err_ok.size else None,
        zmp_error_max_m=float(err_ok.max()) if err_ok.size else None,
        foot_slip_max_m=max(slips) if slips else 0.0,
        foot_slip_mean_m=float(np.mean(slips)) if slips else 0.0,
        foot_backward_slip_total_m=float(np.sum(backward)) if backward else 0.0,
        stance_slips=tuple(per_stance),
        trunk_drift_from_plan_m=float(np.linalg.norm(res.trunk_pos[-1] - ref.body_pos[-1])),
        body_sway_measured=body_sway(plan, res.t, res.trunk_pos),
        body_sway_planned=body_sway(plan, ref.t, ref.body_pos),
        sim_time_s=res.sim_time,
        wall_time_s=res.wall_time,
        realtime_factor=res.sim_time / res.wall_time if res.wall_time > 0 else math.nan,
        video=str(video) if video is not None else None,
        video_note=video_note,
    )


def run_slope_walk(
    robot: QuadrupedRobot,
    params: GaitParams,
    settings: SimSettings | None = None,
    video_path: Path | None = None,
) -> tuple[GaitPlan, QuadrupedResult]:
    """Plan (raising InputError before any simulation on bad input) and simulate a slope walk."""
    plan = plan_gait(robot, params)
    return plan, simulate(plan, settings, video_path=video_path)
