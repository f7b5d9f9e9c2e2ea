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
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import NDArray

from footfall._geometry import cross3
from footfall._io import PendingFile
from footfall._typing import FloatArray
from footfall._validate import positive
from footfall.errors import InputError
from footfall.quadruped.gait import GaitParams, GaitPlan, GaitTrajectory, PhaseKind, plan_gait
from footfall.quadruped.ground import PlaneGround, QuadrupedGround
from footfall.quadruped.robot import JOINT_NAMES, LEGS, QuadrupedRobot
from footfall.quadruped.stability import centre_of_pressure, stability_margin, support_polygon
from footfall.sim._mjcf import require_mujoco
from footfall.sim.pushes import Push
from footfall.sim.quadruped import names as nm
from footfall.sim.quadruped.mjcf import SimSettings, ground_scene
from footfall.sim.quadruped.slip import (
    SlipGuard,
    SlipMonitor,
    SlipStop,
    StanceSlip,
    check_guard,
    downhill,
    stance_slips,
)

#: a foot counts as in contact when it carries more than this fraction of the robot's weight
CONTACT_FORCE_FRACTION = 0.01
#: the robot has fallen when the trunk drops below this fraction of the planned height ...
FALL_HEIGHT_FRACTION = 0.5
#: ... or tilts this far from its planned attitude [rad]
FALL_TILT = math.radians(30.0)
#: video frame rate [1/s]
VIDEO_FPS = 30
#: the quadruped's controllers (``simulate(controller=...)``)
CONTROLLERS = ("servo", "wbc")


@dataclass(frozen=True)
class BodySway:
    """Body sway per gait cycle, averaged over the cycles (see :func:`body_sway`)."""

    path_per_cycle_m: float
    """Horizontal path length of the body centre per cycle [m]."""
    lateral_path_per_cycle_m: float
    """Lateral (y) path length of the body centre per cycle [m]."""
    excess_path_per_cycle_m: float
    """Path length minus net horizontal displacement per cycle: motion spent swaying [m]."""
    shifts_per_cycle: float
    """Body shifts per gait cycle (the final centring shift excluded)."""


@dataclass(frozen=True)
class QuadrupedMetrics:
    """Summary of one simulated walk; measured in MuJoCo unless the name says ``planned``.

    ``None`` marks a measure with no sample to average (for example no stance sample with three
    loaded feet before a fall).
    """

    slope_deg: float
    """Slope angle beta_S [deg]."""
    body_deg: float
    """Planned body angle beta_B to the horizontal [deg]."""
    strategy: str
    """ZMP placement strategy (:class:`~footfall.quadruped.gait.ZmpStrategy` value)."""
    step_m: float
    """Planned step length S along the slope [m]."""
    swing_height_m: float
    """Planned swing height H normal to the slope [m]."""
    swing_period_s: float
    """Planned swing period T_w [s]."""
    shift_period_s: float
    """Planned duration of each body shift [s]."""
    cycles: int
    """Number of gait cycles."""
    gait_duration_s: float
    """Duration of the gait, settling excluded [s]."""
    distance_up_slope_m: float
    """Trunk displacement along the slope direction [m]."""
    planned_distance_up_slope_m: float
    """Planned body displacement along the slope direction [m]."""
    mean_speed_m_s: float
    """Distance up the slope over gait duration [m/s] (NaN for a zero duration)."""
    fell: bool
    """Whether the trunk touched the ground, tilted past FALL_TILT or dropped too low."""
    fall_time_s: float | None
    """Gait time of the first fall sample [s], None when it did not fall."""
    stability_margin_min_m: float | None
    """Smallest measured stability margin over planned-stance samples with >= 3 contacts [m]."""
    stability_margin_mean_m: float | None
    """Mean measured stability margin over the same samples [m]."""
    stability_margin_min_three_leg_m: float | None
    """Smallest measured margin over samples with exactly three planned contacts [m]."""
    stability_margin_mean_three_leg_m: float | None
    """Mean measured margin over samples with exactly three planned contacts [m]."""
    planned_margin_min_m: float
    """Smallest planned stability margin [m]."""
    planned_margin_min_three_leg_m: float
    """Smallest planned margin with exactly three planned contacts [m] (NaN without such a
    sample: the slip guard stopped the gait before the first swing)."""
    stance_samples: int
    """Number of samples where the plan has three or more feet down."""
    stance_samples_with_fewer_than_3_contacts: int
    """Planned-stance samples with fewer than three loaded feet measured."""
    zmp_error_mean_m: float | None
    """Mean distance of the measured CoP from the planned ZMP (eq. 5) [m]."""
    zmp_error_max_m: float | None
    """Largest distance of the measured CoP from the planned ZMP [m]."""
    foot_slip_max_m: float
    """Largest sliding displacement of a foot over one planned stance [m]."""
    foot_slip_mean_m: float
    """Mean sliding displacement of a foot over one planned stance [m]."""
    foot_backward_slip_total_m: float
    """Total sliding of the feet down the slope, summed over stances [m]."""
    stance_slips: tuple[StanceSlip, ...]
    """Sliding of every foot over each of its planned stances, ordered by start time."""
    trunk_drift_from_plan_m: float
    """Distance of the final trunk position from the planned final body position [m]."""
    body_sway_measured: BodySway
    """Sway of the measured trunk."""
    body_sway_planned: BodySway
    """Sway of the planned body."""
    sim_time_s: float
    """Simulated time, settling included [s]."""
    wall_time_s: float
    """Wall-clock time of the physics and control loop, video excluded [s]."""
    realtime_factor: float
    """Simulated seconds per wall-clock second."""
    video: str | None
    """Path of the MP4, None when no video was written."""
    video_note: str
    """Why there is no video, if there is none."""

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready dict with one key per field (the sways as nested dicts)."""
        return asdict(self)


class Measured(Protocol):
    """What :func:`summarise` reads of a simulated walk (a :class:`SimResult` has it all)."""

    @property
    def t(self) -> FloatArray: ...
    @property
    def trunk_pos(self) -> FloatArray: ...
    @property
    def cop(self) -> FloatArray: ...
    @property
    def margin(self) -> FloatArray: ...
    @property
    def n_contacts(self) -> NDArray[np.int_]: ...
    @property
    def slip_vel(self) -> FloatArray: ...
    @property
    def planned(self) -> GaitTrajectory: ...
    @property
    def wall_time(self) -> float: ...
    @property
    def sim_time(self) -> float: ...
    @property
    def video(self) -> Path | None: ...
    @property
    def video_note(self) -> str: ...


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
            shape (T, 4, 3) [m/s]. A rolling sphere has none, so this is true sliding, not the
            rolling of the spherical foot. A foot planned in stance but off the ground (it
            bounced, or the ground is lower than planned) slides with its centre: the centre's
            velocity along the ground; a swing foot off the ground has none.
        planned: the commanded references at the same instants: the plan, held on four feet
            from the slip guard's stop on (:mod:`.slip`; the plan itself without a stop).
        metrics: summary numbers (see :func:`summarise`).
        wall_time: wall-clock time of the physics + control loop [s] (video excluded).
        sim_time: simulated time [s].
        video: path of the MP4, or None.
        video_note: why there is no video, if there is none.
        controller: ``servo`` or ``wbc`` (see :func:`simulate`).
        qp_failures: physics steps whose whole-body QP failed (``wbc``; the last torques held).
        slip_stop: when and why the slip guard stopped the gait, None when it did not.
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
    metrics: QuadrupedMetrics
    wall_time: float = 0.0
    sim_time: float = 0.0
    video: Path | None = None
    video_note: str = ""
    controller: str = "servo"
    qp_failures: int = 0
    slip_stop: SlipStop | None = None


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
        vp = v + cross3(w, point - self.data.geom_xpos[g])
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


class _Video:
    """Offscreen MP4 of the tracking camera; a no-op when there is no path or no GL backend."""

    def __init__(self, sim: QuadrupedSim, path: Path | None, size: tuple[int, int]) -> None:
        self.renderer: Any = None
        self.writer: Any = None
        self.file: PendingFile | None = None
        self.note = ""
        self.path = path
        #: wall time spent rendering, subtracted from the loop's wall time [s]
        self.render_time = 0.0
        if path is None:
            return
        self.renderer, self.note = _make_renderer(sim, *size)
        if self.renderer is not None:
            import imageio.v2 as imageio

            # written beside the destination and renamed over it when complete (close)
            self.file = PendingFile(path)
            self.writer = imageio.get_writer(str(self.file.tmp), fps=VIDEO_FPS, macro_block_size=8)

    def frame(self, data: Any) -> None:
        """Append the current scene as a frame."""
        if self.writer is None:
            return
        r0 = time.perf_counter()
        self.renderer.update_scene(data, camera=nm.TRACK_CAMERA)
        self.writer.append_data(self.renderer.render())
        self.render_time += time.perf_counter() - r0

    def close(self, complete: bool = True) -> Path | None:
        """Finish the file (put in place when ``complete``; removed, the previous video left,
        when the walk was interrupted); its path, or None when none was written."""
        if self.writer is not None:
            self.writer.close()
            assert self.file is not None
            self.file.finish(complete)
        if self.renderer is not None:
            self.renderer.close()
        return self.path if self.writer is not None and complete else None


class _Recorder:
    """Measured arrays of one walk, filled one control sample at a time (a :class:`Measured`)."""

    def __init__(self, sim: QuadrupedSim, plan: GaitPlan, ref: GaitTrajectory) -> None:
        self.sim = sim
        self.plan = plan
        #: the plan's ground, read once (GaitPlan.ground builds a checked PlaneGround per call)
        self.ground = plan.ground
        self.planned = ref
        self.t = ref.t
        n = ref.t.shape[0]
        self.trunk_pos = np.empty((n, 3))
        self.trunk_pitch = np.empty(n)
        self.cop = np.full((n, 2), np.nan)
        self.margin = np.full(n, np.nan)
        self.n_contacts = np.zeros(n, dtype=int)
        self.feet = np.empty((n, 4, 3))
        self.slip_vel = np.zeros((n, 4, 3))
        #: gait time of the first fall sample [s], NaN while standing
        self.fallen_at = math.nan
        self.weight = plan.robot.total_mass * float(-sim.model.opt.gravity[2])
        self.wall_time = 0.0
        self.sim_time = 0.0
        self.video: Path | None = None
        self.video_note = ""
        #: whole-body QP solves that failed (the last torques held for that step)
        self.qp_failures = 0

    def measure(self, k: int) -> None:
        """Record sample ``k``: trunk, feet, loaded contacts, CoP, margin, slip; detect a fall."""
        sim, d = self.sim, self.sim.data
        self.trunk_pos[k] = d.xpos[sim.trunk]
        self.trunk_pitch[k] = _pitch_of(d.xmat[sim.trunk])
        self.feet[k] = d.site_xpos[sim.foot_sites]
        pts, frc, idx, trunk_hit = sim.contacts()
        loaded = frc[:, 2] > CONTACT_FORCE_FRACTION * self.weight if frc.size else np.zeros(0, bool)
        self.n_contacts[k] = np.unique(idx[loaded]).size
        if loaded.any():
            z_p = float(pts[loaded, 2].mean())
            self.cop[k], _ = centre_of_pressure(pts[loaded], frc[loaded], z_p)
            # each foot touches at one point (sphere on plane), so the feet's points span it
            self.margin[k] = stability_margin(self.cop[k], support_polygon(pts[loaded]))
        for j in range(idx.size):
            normal = self.ground.normal(float(pts[j, 0]), float(pts[j, 1]))
            self.slip_vel[k, idx[j]] = sim.contact_slip_velocity(idx[j], pts[j], normal)
        # a planned stance foot off the ground (bouncing, or the ground lower than planned)
        # moves with its whole centre: that motion along the ground is slip too
        stance = self.planned.contact[k]
        for leg in range(4):
            if stance[leg] and not np.any(idx == leg):
                c = self.feet[k, leg]
                normal = self.ground.normal(float(c[0]), float(c[1]))
                self.slip_vel[k, leg] = sim.contact_slip_velocity(leg, c, normal)
        if math.isnan(self.fallen_at) and (trunk_hit or self._fallen(k)):
            self.fallen_at = float(self.t[k])

    def _fallen(self, k: int) -> bool:
        """Trunk tilted past FALL_TILT from its planned pitch, or too low above the ground."""
        post = self.plan.posture
        tilt = abs(self.trunk_pitch[k] - self.planned.body_pitch[k])
        x, y = float(self.trunk_pos[k, 0]), float(self.trunk_pos[k, 1])
        low = self.trunk_pos[k, 2] - self.ground.centre_height(x, y)
        return bool(tilt > FALL_TILT or low < FALL_HEIGHT_FRACTION * post.height)


def _push_force(sim: QuadrupedSim, pushes: tuple[Push, ...], t: float) -> None:
    """Apply the pushes active at gait time ``t`` [s] to the trunk (world frame, at its centre)."""
    f = np.zeros(3)
    for p in pushes:
        if p.active(t):
            f += p.force
    sim.data.xfrc_applied[sim.trunk, :3] = f


def _track(
    sim: QuadrupedSim,
    rec: _Recorder,
    video: _Video,
    control_dt: float,
    progress: Callable[[float], None] | None,
    pushes: tuple[Push, ...] = (),
    guard: SlipMonitor | None = None,
) -> None:
    """Track the planned joint angles sample by sample, measuring after each control period
    (``guard``: the slip guard, which may hold the reference, ``rec.planned``, still)."""
    m, d, mj = sim.model, sim.data, sim.mujoco
    substeps = max(1, round(control_dt / m.opt.timestep))
    frame_every = max(1, round(1.0 / (VIDEO_FPS * control_dt)))
    n = rec.planned.joints.shape[0]
    for k in range(n):
        joints = rec.planned.joints
        q0 = joints[k]
        q1 = joints[min(k + 1, n - 1)]
        # joint targets interpolated linearly between plan samples at every physics step
        for s in range(substeps):
            d.ctrl[sim.actuators] = q0 + (q1 - q0) * (s / substeps)
            if pushes:
                _push_force(sim, pushes, float(rec.t[0]) + (k * substeps + s) * m.opt.timestep)
            mj.mj_step(m, d)
        rec.measure(k)
        if guard is not None and guard.update(k, rec.slip_vel[k]):
            rec.planned = guard.reference
        if k % frame_every == 0:
            video.frame(d)
        if progress is not None and k % 200 == 0:
            progress(k / n)


def _track_wbc(
    sim: QuadrupedSim,
    rec: _Recorder,
    video: _Video,
    control_dt: float,
    progress: Callable[[float], None] | None,
    gains: Any,
    settle_time: float,
    pushes: tuple[Push, ...] = (),
    guard: SlipMonitor | None = None,
) -> None:
    """Drive every joint by torque from the whole-body QP (:mod:`.wbc`) at every physics step,
    measuring after each control period; it also holds the first reference while the robot
    settles (no hand-over transient from another controller)."""
    from footfall.sim.quadruped.wbc import QuadrupedWbc

    m, d, mj = sim.model, sim.data, sim.mujoco
    wbc = QuadrupedWbc(sim, rec.planned, rec.ground, gains)
    substeps = max(1, round(control_dt / m.opt.timestep))
    frame_every = max(1, round(1.0 / (VIDEO_FPS * control_dt)))
    t_start = float(rec.t[0])
    every = gains.qp_every
    for i in range(round(settle_time / m.opt.timestep)):
        mj.mj_step1(m, d)
        if i % every == 0:
            d.ctrl[sim.actuators] = wbc.torques(t_start)
        mj.mj_step2(m, d)
    n = rec.t.shape[0]
    for k in range(n):
        for s in range(substeps):
            mj.mj_step1(m, d)
            i = k * substeps + s
            if i % every == 0:
                d.ctrl[sim.actuators] = wbc.torques(t_start + i * m.opt.timestep)
            if pushes:
                _push_force(sim, pushes, t_start + i * m.opt.timestep)
            mj.mj_step2(m, d)
        rec.measure(k)
        if guard is not None and guard.update(k, rec.slip_vel[k]):
            rec.planned = guard.reference
            wbc.retarget(rec.planned)
        if k % frame_every == 0:
            video.frame(d)
        if progress is not None and k % 200 == 0:
            progress(k / n)
    rec.qp_failures = wbc.failures


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
) -> SimResult:
    """Simulate ``plan`` in MuJoCo and measure it.

    ``controller``: ``servo`` (document 001: joint position servos on the planned angles) or
    ``wbc`` (joint torques from the whole-body QP that puts the centre of pressure on the planned
    ZMP, :mod:`footfall.sim.quadruped.wbc`); ``wbc_gains`` its
    :class:`~footfall.sim.quadruped.wbc.QuadrupedWbcGains` (None: the defaults). ``pushes``:
    forces on the trunk (:class:`~footfall.sim.pushes.Push`, times since the gait started).
    ``slip_guard``: stop the gait when a foot slips (:class:`~footfall.sim.quadruped.slip.SlipGuard`;
    None: off); the run keeps its planned length, holding still after a stop.

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
    video = _Video(sim, video_path, video_size)
    rec = _Recorder(sim, plan, ref)
    guard = SlipMonitor(slip_guard, plan, ref) if slip_guard is not None else None

    wall0 = time.perf_counter()
    try:
        if controller == "wbc":
            _track_wbc(sim, rec, video, control_dt, progress, wbc_gains, settle_time, pushes, guard)
        else:
            # settle in the initial pose so the legs take the weight before the gait starts
            for _ in range(round(settle_time / sim.model.opt.timestep)):
                sim.mujoco.mj_step(sim.model, sim.data)
            _track(sim, rec, video, control_dt, progress, pushes, guard)
    except BaseException:  # an error or a signal: no half-written video in place
        video.close(complete=False)
        raise
    rec.wall_time = time.perf_counter() - wall0 - video.render_time
    rec.video = video.close()
    rec.video_note = video.note
    rec.sim_time = settle_time + float(ref.t[-1])
    return SimResult(
        t=ref.t,
        trunk_pos=rec.trunk_pos,
        trunk_pitch=rec.trunk_pitch,
        cop=rec.cop,
        margin=rec.margin,
        n_contacts=rec.n_contacts,
        feet=rec.feet,
        slip_vel=rec.slip_vel,
        planned=rec.planned,
        metrics=summarise(plan, rec, rec.fallen_at),
        wall_time=rec.wall_time,
        sim_time=rec.sim_time,
        video=rec.video,
        video_note=rec.video_note,
        controller=controller,
        qp_failures=rec.qp_failures,
        slip_stop=guard.stop if guard is not None else None,
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
    plan: GaitPlan, res: Measured, u: FloatArray
) -> tuple[list[StanceSlip], list[float], list[float]]:
    """Each foot's sliding over each planned stance (:func:`.slip.stance_slips`), the lengths of
    those displacements and their parts against ``u`` [m].

    The displacement is the integral of the contact point's sliding velocity over the stance.
    """
    down = downhill(plan, res.planned.feet)
    per_stance = stance_slips(res.t, res.planned.contact, res.slip_vel, down)
    slips = [s.slip_m for s in per_stance]
    backward = [-min(0.0, float(np.dot(s.displacement_m, u))) for s in per_stance]
    return per_stance, slips, backward


def _min_mean(x: FloatArray) -> tuple[float | None, float | None]:
    """(min, mean) of ``x``, or (None, None) when it is empty."""
    return (float(x.min()), float(x.mean())) if x.size else (None, None)


def summarise(plan: GaitPlan, res: Measured, fallen_at: float = math.nan) -> QuadrupedMetrics:
    """Metrics of a simulated walk (all from measured data unless named ``planned``)."""
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
        video=str(res.video) if res.video is not None else None,
        video_note=res.video_note,
    )


def run_slope_walk(
    robot: QuadrupedRobot,
    params: GaitParams,
    settings: SimSettings | None = None,
    video_path: Path | None = None,
) -> tuple[GaitPlan, SimResult]:
    """Plan (raising InputError before any simulation on bad input) and simulate a slope walk."""
    plan = plan_gait(robot, params)
    return plan, simulate(plan, settings, video_path=video_path)
