"""Walk a footstep plan with the MuJoCo biped and measure it (document 000, section 5.5).

Control loop (every ``control_dt``):

1. **Measure** the ALIP state (eq. 5.1) of the robot about the stance contact point: the CoM
   relative to the stance sole centre and either the true angular momentum
   ``L = L_G + m (c - p) x v`` (default; MuJoCo's subtree CoM, velocity and angular momentum) or
   ``m z_H (-v_y, v_x)`` from the CoM velocity (``WalkOptions.true_momentum``).
2. **Footstep / ankle-torque source** (:class:`~footfall.control.adjusters.FootstepAdjuster`):
   returns the next footstep and the ankle torque of this tick. The default
   :class:`~footfall.control.adjusters.MPCAdjuster` solves the MPC of eq. (5.19);
   :class:`~footfall.control.adjusters.PlanFollower` uses the plan's footsteps and ALIP torques,
   corrected by one-step ALIP foot placement.
3. **Reference**: the ALIP reference state is advanced by one tick with that torque, exactly
   (zero-order hold, eq. 5.5), after blending it toward the measured state by ``com_feedback``.
   In double support the contact point moves linearly to the new foot (the model behind the reset
   map, eq. 5.8-5.10). The CoM height lies on the planes through z_H above consecutive
   footsteps (:class:`~footfall.sim.biped.references.CoMHeight`), on which the horizontal motion
   is exactly the ALIP's.
4. **Whole body**: differential inverse kinematics with ``mink`` (one QP per iteration, solved by
   ``daqp``, :mod:`footfall.sim.biped.ik`) tracks the CoM, both sole poses (stance: where it
   stands; swing: a trajectory that rises above every region it passes over before moving,
   :func:`~footfall.sim.biped.references.swing_reference`) and an upright torso; the resulting
   joint angles are the set points of the joint servos.

Everything reported is *measured* in the simulation: the centre of pressure (ZMP) of the stance
foot's contact forces (``mj_contactForce``), its offset from the sole centre in the foot frame,
where each foot lands, whether the robot fell. Planned quantities are only used for errors.

:class:`BipedWalk` runs the loop, one :meth:`BipedWalk.step` per tick; :func:`walk` is the entry
point. Options are in :mod:`footfall.sim.biped.options`, the plant in
:mod:`footfall.sim.biped.plant`, the summary in :mod:`footfall.sim.biped.metrics`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.control.adjusters import (
    FootstepAdjuster,
    MPCAdjuster,
    extend_plan,
    sole_torque_limits,
)
from footfall.control.mpc import MPCWeights
from footfall.errors import InputError, SolverError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.results.walk import WalkResult, WalkTrace
from footfall.robots import names as nm
from footfall.sim._video import Video
from footfall.sim.biped.ik import WholeBodyIK
from footfall.sim.biped.leg_momentum import LegMomentumForecast
from footfall.sim.biped.metrics import summarise
from footfall.sim.biped.model import BipedSimSettings, WalkerModel
from footfall.sim.biped.options import WalkOptions, check_walk_inputs
from footfall.sim.biped.plant import BipedSim, ankle_joint_torque, sole_cop
from footfall.sim.biped.references import (
    SWING_MOVE,
    CoMHeight,
    blend_rot,
    ds_propagator,
    foot_rotation,
    pitch_about_y,
    smoothstep,
    swing_reference,
    swing_shares,
    terrain_height_along,
)
from footfall.sim.biped.state import (
    ActuationState,
    Command,
    FeetState,
    Observation,
    ReferenceState,
    SolePoses,
    SwingState,
)
from footfall.sim.biped.wbc import BipedWbc, CopTarget
from footfall.sim.disturbance import push_force
from footfall.sim.falls import HUMANOID_FALL
from footfall.sim.replay import ReplayRecorder
from footfall.terrain.edges import inset_riser_edges
from footfall.terrain.scene import Scene

#: a foot is loaded when its contact force exceeds this share of the weight
CONTACT_FORCE_SHARE = 0.02
#: a swing target that moved this far [m] from the one its apex was set for gets its apex checked
SWING_RETARGET = 0.01
#: when the MPC's footstep lies farther than this [m] from the swing target, the target may
#: move faster than ``swing_target_speed``: fast enough to reach it by the end of the swing's
#: horizontal move, at most ``FAST_TARGET_FACTOR`` times as fast. Below it the bound filters the
#: footstep's tick-to-tick moves (a bound 1.5 times as fast everywhere made Alexander fall
#: unpushed); a push moves the footstep by 0.2-0.4 m
FAST_TARGET_GAP = 0.1
FAST_TARGET_FACTOR = 2.0


def swing_target_speed(robot: BipedParams) -> float:
    """The fastest the swing target may move [m/s]: across the whole reach trapezoid (its
    diameter, the farthest two reachable footsteps apart) within one single support T_ss."""
    v = np.asarray(robot.reach.vertices, dtype=float)
    diameter = max(float(np.linalg.norm(a - b)) for a in v for b in v)
    return diameter / robot.t_ss


def step_toward(current: FloatArray, goal: FloatArray, max_step: float) -> FloatArray:
    """``current`` moved toward ``goal`` (both (3,) [m]) by at most ``max_step`` [m]."""
    delta = np.asarray(goal, dtype=float) - current
    dist = float(np.linalg.norm(delta))
    if dist <= max_step:
        return np.array(goal, dtype=float)
    return current + delta * (max_step / dist)


class BipedWalk:
    """One simulated walk of a plan: setup, then one :meth:`step` per control tick.

    A tick is :meth:`_observe` (CoM state, soles, contacts), :meth:`_schedule` (the phase of the
    walk and its references: shift, single / double support, stop), :meth:`_measure` (the stance
    foot's CoP), :meth:`_detect_fall`, :meth:`_whole_body` (ankle commands and IK) and
    :meth:`_physics`; :meth:`run` loops and returns the :class:`WalkResult`. Loop-carried state
    lives in the small objects of :mod:`footfall.sim.biped.state`.
    """

    def __init__(
        self,
        scene: Scene,
        plan: FootstepPlan,
        opts: WalkOptions,
        adjuster: FootstepAdjuster | None = None,
        model_params: WalkerModel | None = None,
        settings: BipedSimSettings | None = None,
    ) -> None:
        self.scene, self.opts = scene, opts
        self.sim = sim = BipedSim(scene, model_params, settings)
        step = sim.model.opt.timestep
        self.substeps = round(opts.control_dt / step)
        if self.substeps < 1 or abs(self.substeps * step - opts.control_dt) > 1e-9:
            raise InputError(
                "control_dt", opts.control_dt, f"a multiple of the physics step {step}"
            )
        self.dt = opts.control_dt
        self.src = adjuster if adjuster is not None else self._default_adjuster(plan)
        self.n_planned = plan.n_steps
        self.plan = extend_plan(plan, opts.stop_steps)
        self.robot = robot = plan.robot
        self.alip = robot.alip()
        self.ad_tick, self.bd_tick = self.alip.discretize(self.dt)
        self.leg_momentum = (
            LegMomentumForecast(
                self.ad_tick, self.bd_tick, self.dt, robot.t_ss, self.opts.legs_share
            )
            if self.opts.legs_share > 0.0
            else None
        )
        self.ds_map = ds_propagator(self.alip, self.dt)
        self.n = self.plan.n_steps
        #: stopping steps added on the way (``WalkOptions.walk_on``)
        self.walked_on = 0
        self.t_ss, self.t_ds = robot.t_ss, robot.t_ds
        self.target_speed = swing_target_speed(robot)
        self.t_step = self.t_ss + self.t_ds
        self.t_walk0 = opts.settle_time + opts.shift_time
        #: time the MPC's step timing moved the touchdowns forward by, in all and before the
        #: last planned step ended [s]
        self.t_saved = self.t_saved_planned = 0.0
        self._set_timeline()
        self._init_state()
        #: records the joint positions for ``footfall view`` when :meth:`run` is given one
        self.replay: ReplayRecorder | None = None

    def _default_adjuster(self, plan: FootstepPlan) -> MPCAdjuster:
        """The MPC of eq. (5.19) on the regions with their riser edges moved in."""
        opts = self.opts
        terrain = self.scene.terrain
        regions = {r.name: r for r in terrain.regions}
        # the regions the plan was made on (its riser inset), not recomputed here
        inner = inset_riser_edges(terrain, plan.riser_inset) if plan.riser_inset else None
        return MPCAdjuster(
            plan,
            {r.name: r for r in inner.regions} if inner is not None else regions,
            region_margin=plan.region_margin + opts.landing_margin,
            control_dt=self.dt,
            stop_steps=opts.stop_steps,
            torque_limits=sole_torque_limits(plan.robot),
            region_aware=opts.region_aware,
            landing_margin=opts.landing_margin,
            capture_stop=opts.capture_stop,
            weights=MPCWeights(r_mass=opts.torque_weight_mass),
            step_timing=opts.step_timing,
        )

    def _init_state(self) -> None:
        """Stand the robot at the start and set up the loop-carried state."""
        sim, scene, plan = self.sim, self.scene, self.plan
        start = scene.start
        sim.set_standing(start.left, start.right, start.heading)
        self.wbc: BipedWbc | None = None
        self.ik: WholeBodyIK | None = None
        if self.opts.controller == "wbc":
            self.wbc = BipedWbc(sim, self.opts.wbc_gains)
        else:
            self.ik = WholeBodyIK(sim)
        # the IK's nominal CoM offset: the standing CoM is where the model puts it, not at mid-feet
        self.com0, _, _ = sim.com_state()
        regions = {r.name: r for r in scene.terrain.regions}
        start_region = scene.start_regions()
        self.feet = FeetState(
            pos={s: np.array(start.foot(s)) for s in sim.sides},
            rot={
                s: foot_rotation(regions[start_region[s]].normal, start.heading) for s in sim.sides
            },
        )
        self.normals = [regions[name].normal for name in plan.regions]
        self.log = WalkTrace.empty(self.n_ticks, self.dt, plan.footsteps, self.n_planned)
        stance = plan.sides[0]
        self.swing = SwingState(
            stance=stance,
            start=self.feet.pos[stance.other].copy(),
            rot0=self.feet.rot[stance.other].copy(),
        )
        self.ref = ReferenceState(prev_stance=np.array(start.stance_foot))
        # CoM height over the footsteps (constraint planes of the 3-D LIPM); standing: over the feet
        self.height = CoMHeight(plan.footsteps, self.robot.com_height)
        self.z_stand = 0.5 * (start.left[2] + start.right[2]) + self.robot.com_height
        ctrl = np.array(sim.data.ctrl[sim.actuators], dtype=float)
        if self.wbc is not None:
            ctrl = np.zeros_like(ctrl)  # torques: nothing applied before the first tick
        self.act = ActuationState(
            ankle_mode={sd: False for sd in sim.sides},
            ctrl_prev=ctrl,
            pos_prev=np.zeros(ctrl.shape[0], dtype=bool),  # nothing to ramp from at the start
        )

    # ------------------------------------------------------------------------------- loop
    def run(
        self,
        video_path: Path | None = None,
        video_size: tuple[int, int] = (640, 480),
        progress: Callable[[float], None] | None = None,
        replay: ReplayRecorder | None = None,
    ) -> WalkResult:
        """Walk until the end of the hold (or a fall with ``stop_on_fall``) and measure it
        (``replay``: also record the joint positions at its display rate)."""
        sim = self.sim
        self.video = Video(sim.mujoco, sim.model, video_path, video_size, self.dt, nm.TRACK_CAMERA)
        self.replay = replay
        if replay is not None:
            replay.begin(sim.xml)
        wall0 = time.perf_counter()
        k = ticks = 0
        try:
            # n_ticks grows when the walker adds stopping steps (WalkOptions.walk_on)
            while k < self.n_ticks:
                ticks = k + 1
                if not self.step(k):
                    break
                if progress is not None and k % 100 == 0:
                    progress(k / self.n_ticks)
                k += 1
        except BaseException:  # an error or a signal: no half-written video in place
            self.video.close(complete=False)
            raise
        wall = time.perf_counter() - wall0
        self.log.timing["render"] = self.video.render_time
        return self._result(ticks, wall, self.video.close())

    def step(self, k: int) -> bool:
        """Control tick ``k``; False when the walk ends at it (a fall with ``stop_on_fall``)."""
        timing = self.log.timing
        t = float(self.log.t[k])
        c0 = time.perf_counter()
        if self.replay is not None:
            self.replay.sample(t, self.sim.data)
        if self.wbc is not None:
            # the torque controller needs this instant's model terms and contact forces
            self.sim.mujoco.mj_forward(self.sim.model, self.sim.data)
        obs = self._observe(k)
        cmd = self._schedule(k, t, obs)
        self._measure(k, cmd, obs)
        if self._detect_fall(t, cmd, obs) and self.opts.stop_on_fall:
            timing["control"] += time.perf_counter() - c0
            return False
        c1 = time.perf_counter()
        timing["control"] += c1 - c0
        if self.wbc is not None:
            self._torque_physics(self.wbc, t, cmd, obs)
        else:
            ctrl, servoed = self._whole_body(cmd, obs)
            c2 = time.perf_counter()
            timing["ik"] += c2 - c1
            self._physics(t, ctrl, servoed)
            timing["physics"] += time.perf_counter() - c2
        self.video.frame(k, self.sim.data)
        return True

    def _observe(self, k: int) -> Observation:
        """Measure the CoM state, log it and the soles, and read the contacts."""
        sim, log = self.sim, self.log
        com, vel, l_g = sim.com_state()
        log.com[k] = com
        log.feet[k, 0] = sim.sole(Side.LEFT)[0]
        log.feet[k, 1] = sim.sole(Side.RIGHT)[0]
        contacts, body_hit = sim.contacts()
        return Observation(com, vel, l_g, contacts, body_hit)

    # --------------------------------------------------------------------------- schedule
    def _schedule(self, k: int, t: float, obs: Observation) -> Command:
        """References of tick ``k``: the shift over the first stance foot, the steps, the stop."""
        c_next = obs.com[:2] + obs.vel[:2] * self.dt  # where the CoM is when the references apply
        if t < self.t_walk0:
            return self._shift(t)
        if t < self.t_end_steps:
            return self._stepping(k, t, obs, c_next)
        return self._stop(t, c_next)

    def _standing_feet(self) -> SolePoses:
        return {sd: (self.feet.pos[sd], self.feet.rot[sd]) for sd in self.sim.sides}

    def _shift(self, t: float) -> Command:
        """Settle, then move the CoM over the first stance foot (the plan starts there at rest)."""
        opts, start = self.opts, self.scene.start
        mid = 0.5 * (start.left + start.right)
        s = smoothstep((t - opts.settle_time) / opts.shift_time)
        target_xy = mid[:2] + (start.stance_foot[:2] - mid[:2]) * s
        z_ref = self.z_stand + (self.height(0, target_xy) - self.z_stand) * s
        com_ref = np.array([target_xy[0], target_xy[1], z_ref])
        # the standing CoM sits forward of the feet midpoint by the model's offset; keep it
        com_ref[:2] += (self.com0[:2] - mid[:2]) * (1.0 - s)
        return Command(com_ref, self._standing_feet(), start.heading)

    def _stepping(self, k: int, t: float, obs: Observation, c_next: FloatArray) -> Command:
        """Step i of the plan: single support (adjuster, ALIP reference, swing), then double."""
        tw = t - self.t_walk0 + self.t_saved
        i = min(int(tw / self.t_step), self.n - 1)
        tp = tw - i * self.t_step
        if i != self.swing.phase:
            self._begin_step(i)
        stance = self.feet.pos[self.swing.stance]
        single = tp < self.t_ss
        if single:
            self.log.phase[k] = i
            ref_xy, feet, yaw, tp = self._single_support(k, i, tp, stance, obs)
        else:
            ref_xy, feet, yaw = self._double_support(i, stance)
        support = i if single else i + 1
        com_ref = np.array([ref_xy[0], ref_xy[1], self.height(support, c_next)])
        if k + 1 < self.n_ticks and t + self.dt >= self.t_end_steps - 1e-9:
            # the stop starts from the measured CoM motion: the reference may have drifted
            self.ref.stop_from = obs.com[:2].copy()
            self.ref.stop_vel = obs.vel[:2].copy()
        return Command(com_ref, feet, yaw, walking=True, phase=i, tp=tp, single=single)

    def _begin_step(self, i: int) -> None:
        """A new single support: the foot that just landed is the stance foot; plan the swing."""
        sim, plan, feet, ref, swing = self.sim, self.plan, self.feet, self.ref, self.swing
        if swing.phase >= 0:
            sd_landed = plan.sides[i]
            feet.pos[sd_landed] = sim.sole(sd_landed)[0]
            self.log.landed[i - 1] = feet.pos[sd_landed]
            # re-express the reference relative to the new stance (eq. 5.10's -I block)
            ref.x = ref.ds_aug[:4].copy()
            ref.x[:2] -= (feet.pos[sd_landed] - ref.prev_stance)[:2]
            if i == self.n - 1:
                self._maybe_walk_on(i)
                plan = self.plan
        swing.phase = i
        swing.tau0 = swing.tp0 = 0.0
        swing.stance = plan.sides[i]
        swing_side = swing.stance.other
        swing.start = sim.sole(swing_side)[0]
        swing.rot0 = feet.rot[swing_side]
        target = plan.footsteps[i + 1]
        half = (self.robot.foot_length / 2, self.robot.foot_width / 2)
        apex = terrain_height_along(self.scene.terrain.regions, swing.start, target, *half)
        swing.apex = apex + self.opts.swing_clearance
        swing.rise, swing.descend = swing_shares(
            swing.apex - float(swing.start[2]), swing.apex - float(target[2]), self.t_ss
        )
        swing.apex_for = np.array(target, dtype=float)
        swing.target = np.array(target, dtype=float)
        # the landing orientation depends on the phase only: once per step, not per tick
        swing.rot1 = foot_rotation(self.normals[i + 1], plan.headings[i + 1])
        swing.rot1_strike = swing.rot1 @ pitch_about_y(-self.opts.heel_strike)

    def _set_timeline(self) -> None:
        """When the steps end and the walk's ticks (steps, stop, hold), from the steps ``n``."""
        opts = self.opts
        # touchdowns moved forward end the steps sooner; the walk keeps its length (the hold
        # grows), so the trace is never shorter than the ticks already walked
        t_steps = self.t_walk0 + self.n * self.t_step
        self.t_end_steps = t_steps - self.t_saved
        self.n_ticks = round((t_steps + opts.stop_time + opts.hold_time) / self.dt)

    def _maybe_walk_on(self, i: int) -> None:
        """Before the last stopping step ``i``: when the foot that just landed lies more than
        ``walk_on_distance`` from its final foothold and ``walk_on`` allows it, two more
        stopping steps (each foot onto its foothold again; the adjuster's plan and the capture
        stop move with them), and the walk's timeline and trace grow by them."""
        opts = self.opts
        extend = getattr(self.src, "extend_stop", None)
        if self.walked_on >= opts.walk_on or extend is None:
            return
        side = self.plan.sides[i]
        miss = float(np.linalg.norm(self.feet.pos[side][:2] - self.plan.footsteps[i, :2]))
        if miss <= opts.walk_on_distance:
            return
        extend(2)
        self.walked_on += 2
        self.plan = extend_plan(self.plan, 2)
        self.n = self.plan.n_steps
        self._set_timeline()
        self.log = self.log.grown(self.n_ticks, self.dt, self.plan.footsteps)
        regions = {r.name: r for r in self.scene.terrain.regions}
        self.normals = [regions[name].normal for name in self.plan.regions]
        self.height = CoMHeight(self.plan.footsteps, self.robot.com_height)

    def _limit_target(self, nxt: FloatArray, tp: float) -> FloatArray:
        """Move the swing target toward the MPC's footstep ``nxt`` (3,) [m] by at most
        ``target_speed * dt`` this tick (``swing_target_rate``); return the target to use.

        One exception, at ``tp`` [s] into the swing: before the sole starts to move horizontally
        (the first ``SWING_MOVE[0]`` share of T_ss) the path's horizontal part is its start
        whatever the target, so a target change there moves no reference. When the bounded
        target could no longer reach ``nxt`` before the horizontal move ends (farther than
        ``target_speed`` times the time left until then, e.g. a crossover after a strong inward
        push), it takes ``nxt`` at once; otherwise the bound applies from the first tick. Later,
        when ``nxt`` lies more than ``FAST_TARGET_GAP`` from the target, the bound rises to
        the speed that reaches it by the end of the horizontal move, at most
        ``FAST_TARGET_FACTOR`` times the bound.
        """
        swing = self.swing
        free = not self.opts.swing_target_rate
        # a swing shortened by the step timing runs faster, and so may its target
        fast = self._swing_speedup()
        speed = self.target_speed * fast
        t_path = self._swing_time(tp)
        gap = float(np.linalg.norm(nxt - swing.target))
        left = (SWING_MOVE[1] * self.t_ss - t_path) / fast  # until the horizontal move ends
        if not free and t_path < SWING_MOVE[0] * self.t_ss - 1e-9:
            free = gap > speed * left
        elif gap > FAST_TARGET_GAP:  # the footstep has really moved (a push), not jittered
            speed = min(max(speed, gap / max(left, self.dt)), FAST_TARGET_FACTOR * speed)
        if free:
            swing.target = np.array(nxt, dtype=float)
        else:
            swing.target = step_toward(swing.target, nxt, speed * self.dt)
        return swing.target.copy()

    def _raise_swing(self, tp: float, nxt: FloatArray) -> None:
        """A corrected target (``region_aware``) may lie across other edges than the planned
        one: while the sole is still rising, raise the apex over the regions under the new path
        (never lower it) and re-time the descent to the new target height."""
        swing = self.swing
        if self.opts.region_aware == "off" or self._swing_time(tp) / self.t_ss >= swing.rise:
            return
        if float(np.linalg.norm(nxt - swing.apex_for)) <= SWING_RETARGET:
            return
        half = (self.robot.foot_length / 2, self.robot.foot_width / 2)
        apex = terrain_height_along(self.scene.terrain.regions, swing.start, nxt, *half)
        swing.apex = max(swing.apex, apex + self.opts.swing_clearance)
        _, swing.descend = swing_shares(0.0, swing.apex - float(nxt[2]), self.t_ss)
        swing.apex_for = np.array(nxt, dtype=float)

    def _swing_speedup(self) -> float:
        """How much faster than planned the swing path runs: exactly 1.0 until a touchdown
        moved forward (:attr:`~footfall.control.adjusters.MPCAdjuster.step_timing`), then the
        path left at the move over the time left to the new touchdown."""
        swing = self.swing
        if swing.tp0 == 0.0:
            return 1.0
        return (1.0 - swing.tau0) * self.t_ss / (self.t_ss - swing.tp0)

    def _swing_time(self, tp: float) -> float:
        """Where the swing path is at step time ``tp`` [s], as the time [s] of the planned path
        (``tp`` itself until a touchdown moved forward; the path is a function of this time over
        T_ss)."""
        swing = self.swing
        if swing.tp0 == 0.0:
            return tp
        return swing.tau0 * self.t_ss + (tp - swing.tp0) * self._swing_speedup()

    def _move_touchdown(self, i: int, tp: float) -> float:
        """The adjuster moved the touchdown of single support ``i`` forward by some seconds (its
        step timing): move the walk's clock by them and re-time the swing path from where it is
        to land at the new touchdown. Returns the step time [s] on the moved clock."""
        take = getattr(self.src, "take_advance", None)
        adv = take() if take is not None else 0.0
        if adv <= 0.0:
            return tp
        swing = self.swing
        swing.tau0 = min(1.0, self._swing_time(tp) / self.t_ss)
        swing.tp0 = tp + adv
        self.t_saved += adv
        if i < self.n_planned:
            self.t_saved_planned += adv
        self.t_end_steps -= adv
        return tp + adv

    def _single_support(
        self, k: int, i: int, tp: float, stance: FloatArray, obs: Observation
    ) -> tuple[FloatArray, SolePoses, float, float]:
        """Ask the adjuster, advance the ALIP reference (eq. 5.5), place the swing sole.

        Returns the reference CoM (2,) [m], the sole targets, the torso yaw [rad] and the step
        time [s] (moved when the adjuster moved the touchdown forward).
        """
        opts, alip, ref = self.opts, self.alip, self.ref
        # measured ALIP state about the stance sole centre (eq. 5.1)
        r = obs.com - stance
        x_cv = alip.state_from_velocity(r[:2], obs.vel[:2])
        if opts.uses_true_momentum:
            l_c = obs.l_g + self.sim.mass * np.cross(r, obs.vel)
            x_meas = np.array([r[0], r[1], l_c[0], l_c[1]])
        else:
            x_meas = x_cv
        if self.leg_momentum is not None:
            x_meas = x_meas + self.leg_momentum.shift(i, tp, obs.l_g, float(self.plan.headings[i]))
        nxt, u = self.src.update(tp, x_meas, stance, i)
        tp = self._move_touchdown(i, tp)
        nxt = self._limit_target(nxt, tp)
        self._raise_swing(tp, nxt)
        self.log.targets[i] = nxt
        self.log.zmp_planned[k] = alip.zmp(np.zeros(2), u)
        fb = 1.0 if opts.ankle_torque else opts.com_feedback
        # the kinematic reference follows the CoM's own velocity: the true momentum also holds
        # the swing leg's and torso's (L_G), which the CoM does not move with
        ref.x = ref.x + fb * (x_cv - ref.x)
        self.act.ankle_u = u
        ref.x = self.ad_tick @ ref.x + self.bd_tick @ u
        feet, yaw = self._swing_targets(i, tp, stance, nxt)
        ref_xy = stance[:2] + ref.x[:2]
        # the contact point moves from the stance foot to the landing target during DS
        ref.prev_stance = stance.copy()
        ref.ds_aug = np.concatenate(
            [ref.x, np.zeros(3), (self.log.targets[i] - stance) / self.t_ds]
        )
        return ref_xy, feet, yaw, tp

    def _swing_targets(
        self, i: int, tp: float, stance: FloatArray, nxt: FloatArray
    ) -> tuple[SolePoses, float]:
        """Sole targets (stance where it stands, swing on its path to ``nxt``) and torso yaw."""
        opts, plan, swing, feet = self.opts, self.plan, self.swing, self.feet
        stance_side = swing.stance
        swing_side = stance_side.other
        tau = min(1.0, self._swing_time(tp + self.dt) / self.t_ss)
        gap = self.robot.foot_width + opts.swing_side_gap if opts.swing_side_gap > 0 else 0.0
        pos, s_h = swing_reference(
            tau, swing.start, nxt, swing.apex, swing.rise, swing.descend, stance, gap
        )
        rot = blend_rot(swing.rot0, swing.rot1_strike, s_h)
        targets = {stance_side: (stance, feet.rot[stance_side]), swing_side: (pos, rot)}
        yaw = float(plan.headings[i] + (plan.headings[i + 1] - plan.headings[i]) * 0.5 * s_h)
        if tp + self.dt >= self.t_ss - 1e-9:
            feet.rot[swing_side] = swing.rot1
        return targets, yaw

    def _double_support(self, i: int, stance: FloatArray) -> tuple[FloatArray, SolePoses, float]:
        """The contact point ramps to the new foot (eq. 5.8); both soles stay where they are."""
        ref, feet = self.ref, self.feet
        ref.ds_aug = self.ds_map @ ref.ds_aug
        ref.x = ref.ds_aug[:4]
        ref_xy = ref.prev_stance[:2] + ref.x[:2]
        stance_side = self.swing.stance
        swing_side = stance_side.other
        targets = {
            stance_side: (stance, feet.rot[stance_side]),
            swing_side: (self.log.targets[i], feet.rot[swing_side]),
        }
        yaw = float(0.5 * (self.plan.headings[i] + self.plan.headings[i + 1]))
        return ref_xy, targets, yaw

    def _stop(self, t: float, c_next: FloatArray) -> Command:
        """After the last step: a cubic Hermite from the measured CoM motion (position, velocity)
        to the middle of the final feet at rest."""
        n, feet, log = self.n, self.feet, self.log
        if math.isnan(log.landed[n - 1, 0]) and self.swing.phase < n:
            sd_landed = self.plan.sides[n]
            feet.pos[sd_landed] = self.sim.sole(sd_landed)[0]
            log.landed[n - 1] = feet.pos[sd_landed]
            self.swing.phase = n
        mid = 0.5 * (feet.pos[Side.LEFT] + feet.pos[Side.RIGHT])
        stop_time = self.opts.stop_time
        s = min(1.0, (t + self.dt - self.t_end_steps) / stop_time)
        h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
        h01 = -2 * s**3 + 3 * s**2
        xy = h00 * self.ref.stop_from + h10 * stop_time * self.ref.stop_vel + h01 * mid[:2]
        com_ref = np.array([xy[0], xy[1], self.height(n, c_next)])
        return Command(com_ref, self._standing_feet(), float(self.plan.headings[n]))

    # ------------------------------------------------------------------ measure, fall
    def _loaded_cop(self, side: Side, obs: Observation) -> FloatArray | None:
        """CoP offset (2,) [m] of the ``side`` sole if it carries ``CONTACT_FORCE_SHARE`` of the
        weight, else None."""
        pos, rot = self.sim.sole(side)
        cop = sole_cop(*obs.contacts[side], pos, rot)
        if cop is not None and cop[1] > CONTACT_FORCE_SHARE * self.sim.weight:
            return cop[0]
        return None

    def _measure(self, k: int, cmd: Command, obs: Observation) -> None:
        """Log the single-support stance-foot CoP (the measured ZMP) and the CoM reference."""
        if cmd.single:
            cop = self._loaded_cop(self.swing.stance, obs)
            if cop is not None:
                self.log.zmp_offset[k] = cop
        self.log.com_ref[k] = cmd.com_ref

    def _detect_fall(self, t: float, cmd: Command, obs: Observation) -> bool:
        """Whether the robot falls at ``t`` (first detection only): the pelvis too low above the
        stance sole or the torso tilted too far (:data:`~footfall.sim.falls.HUMANOID_FALL`), or
        the pelvis or torso on the terrain."""
        sim, pos = self.sim, self.feet.pos
        if cmd.single:
            stance_z = pos[self.swing.stance][2]
        else:
            stance_z = max(pos[Side.LEFT][2], pos[Side.RIGHT][2])
        pelvis_z = float(sim.data.xpos[sim.pelvis][2]) - float(stance_z)
        up = sim.data.xmat[sim.torso].reshape(3, 3)[:, 2]
        tilt = math.acos(max(-1.0, min(1.0, float(up[2]))))
        fallen = HUMANOID_FALL.fallen(tilt, pelvis_z, sim.params.pelvis_height)
        if self.log.fell or not (obs.body_hit or fallen):
            return False
        self.log.fell, self.log.fall_time = True, t
        return True

    # ------------------------------------------------------------------------ whole body
    def _ankle_commands(self, cmd: Command, obs: Observation) -> dict[Side, FloatArray | None]:
        """Per side, the ALIP torque (2,) [N m] of a torque-driven ankle; None: position servo."""
        opts, act = self.opts, self.act
        stance_side = self.swing.stance
        swing_side = stance_side.other
        ankle: dict[Side, FloatArray | None] = {sd: None for sd in self.sim.sides}
        if opts.ankle_torque and cmd.single:
            ankle[stance_side] = act.ankle_u
            i = cmd.phase
            late = self._swing_time(cmd.tp) >= self.swing.descend * self.t_ss
            if opts.passive_landing and act.landed_in != i and late:
                if self._loaded_cop(swing_side, obs) is not None:
                    act.landed_in = i
            if act.landed_in == i:
                # the swing sole touched down: a limp ankle lets it settle flat (see options)
                ankle[swing_side] = np.zeros(2)
        elif opts.ankle_torque and cmd.walking:
            # double support: the legs form a closed chain whose joint servos place the CoM and
            # the total CoP moves between the feet, where the contact-point ramp of eq. (5.8)
            # puts it. The landing ankle is passive; the rear ankle's torque ramps from its last
            # single-support command to zero over T_ds (dropping it at once made the rear foot
            # pivot and lift as the weight left it).
            ankle = {sd: np.zeros(2) for sd in self.sim.sides}
            if cmd.tp >= self.t_ss:
                ankle[stance_side] = max(0.0, 1.0 - (cmd.tp - self.t_ss) / self.t_ds) * act.ankle_u
        return ankle

    def _whole_body(self, cmd: Command, obs: Observation) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Actuator commands (12,) (set points [rad], ankle torques [N m]) and which actuators
        are position servoed."""
        opts, sim = self.opts, self.sim
        assert self.ik is not None
        stance_side = self.swing.stance
        com_cmd = cmd.com_ref.copy()
        ankle = self._ankle_commands(cmd, obs)
        if ankle[stance_side] is None or not cmd.single:
            com_cmd[:2] += opts.com_gain * (cmd.com_ref[:2] - obs.com[:2])
        if opts.closed_loop_ik:
            torque_ss = ankle[stance_side] is not None and cmd.single
            if torque_ss:
                # the torque-driven stance sole is where it is: pin it at its measured pose
                cmd.feet[stance_side] = sim.sole(stance_side)
            # a torque-driven stance ankle is not servoed: the IK must leave it where it is (in
            # double support the passive ankles move with the closed chain of the two legs)
            q_des = self.ik.solve(
                cmd.feet,
                com_cmd,
                cmd.yaw,
                self.dt,
                opts.ik_iterations,
                q_meas=sim.data.qpos,
                com_axes=(not torque_ss, not torque_ss, True),
                hold=sim.ankle_actuators(stance_side) if torque_ss else None,
            )
        else:
            q_des = self.ik.solve(cmd.feet, com_cmd, cmd.yaw, self.dt, opts.ik_iterations)
        return self._actuator_commands(q_des, ankle, obs)

    def _cop_target(self, cmd: Command, t_in: float) -> CopTarget | None:
        """The whole-body QP's ground moment ``t_in`` [s] into the control period: the adjuster's
        ALIP torque about the stance sole in single support (``ankle_torque``); in double
        support zero about the contact point that ramps from the stance sole to the landed one
        (the reset map's model, eq. 5.8); None outside the steps (the CoM tracks in 3-D)."""
        if not (cmd.walking and self.opts.ankle_torque):
            return None
        stance = self.swing.stance
        p0 = self.sim.sole(stance)[0]
        if cmd.single:
            return CopTarget((stance,), p0, self.act.ankle_u)
        s = min(1.0, max(0.0, (cmd.tp + t_in - self.t_ss) / self.t_ds))
        p1 = self.sim.sole(stance.other)[0]
        return CopTarget(self.sim.sides, p0 + s * (p1 - p0), np.zeros(2))

    def _torque_physics(self, wbc: BipedWbc, t: float, cmd: Command, obs: Observation) -> None:
        """Step MuJoCo through one control period with the whole-body QP's joint torques
        recomputed at every physics step from the measured state.

        The feet in contact are the stance foot in single support and both otherwise. A QP
        without a solution (a robot already falling) keeps the last torques and is counted in
        the controller's tally (``WalkTrace.controller``). Each step is ``mj_step1`` (positions
        and velocities: the model terms the QP reads; the tick's ``mj_forward`` did it for the
        first) and ``mj_step2`` with the torques: ``mj_step`` in two halves.
        """
        sim, timing = self.sim, self.log.timing
        mj, m, d = sim.mujoco, sim.model, sim.data
        step = float(m.opt.timestep)
        sides = (self.swing.stance,) if cmd.single else sim.sides
        wbc.command(cmd, self.dt)
        com, vel, l_g = obs.com, obs.vel, obs.l_g
        for j in range(self.substeps):
            c0 = time.perf_counter()
            if j > 0:
                mj.mj_step1(m, d)
                com, vel, l_g = sim.com_state()
            cop = self._cop_target(cmd, j * step)
            try:
                tau = wbc.torques((j + 1) / self.substeps, sides, cop, com, vel, l_g)
            except SolverError:  # counted in the tally
                tau = self.act.ctrl_prev
            self.act.ctrl_prev = tau
            c1 = time.perf_counter()
            timing["ik"] += c1 - c0
            d.xfrc_applied[sim.torso, :3] = push_force(self.opts.pushes, t + j * step)
            d.ctrl[sim.actuators] = tau
            mj.mj_step2(m, d)
            timing["physics"] += time.perf_counter() - c1

    def _actuator_commands(
        self, q_des: FloatArray, ankle: dict[Side, FloatArray | None], obs: Observation
    ) -> tuple[FloatArray, NDArray[np.bool_]]:
        """Switch ankle modes and put the ankle joint torques (eq. 5.3) into the set points."""
        sim, act = self.sim, self.act
        for sd in sim.sides:
            u = ankle[sd]
            if (u is not None) != act.ankle_mode[sd]:
                sim.set_ankle_torque_mode(sd, u is not None)
                act.ankle_mode[sd] = u is not None
            if u is not None:
                # the CoP bound scales with the normal force the foot carries *now*: during
                # vertical CoM and swing-leg accelerations it is below the weight, and a torque
                # sized for the weight would tip the foot onto its edge
                pos_a, rot_a = sim.sole(sd)
                cop_a = sole_cop(*obs.contacts[sd], pos_a, rot_a)
                f_n = min(sim.weight, cop_a[1]) if cop_a is not None else 0.0
                q_des[sim.ankle_actuators(sd)] = ankle_joint_torque(u, rot_a, f_n, sim.params)
        ctrl = np.array(q_des, dtype=float)
        servoed = np.ones(ctrl.shape[0], dtype=bool)
        for sd in sim.sides:
            if act.ankle_mode[sd]:
                servoed[sim.ankle_actuators(sd)] = False
        return ctrl, servoed

    # --------------------------------------------------------------------------- physics
    def _physics(self, t: float, ctrl: FloatArray, servoed: NDArray[np.bool_]) -> None:
        """Apply the pushes and step MuJoCo through one control period.

        Position set points ramp linearly over the physics substeps from the last tick's: a step
        every 10 ms into 5000 N m/rad servos jolted the stance foot. Torque-driven ankles, and
        actuators that changed mode this tick, take their new command at once.
        """
        sim, act = self.sim, self.act
        mj, m, d = sim.mujoco, sim.model, sim.data
        d.xfrc_applied[sim.torso, :3] = push_force(self.opts.pushes, t)
        ramp = servoed & act.pos_prev
        for j in range(self.substeps):
            w = (j + 1) / self.substeps
            d.ctrl[sim.actuators] = np.where(ramp, act.ctrl_prev + w * (ctrl - act.ctrl_prev), ctrl)
            mj.mj_step(m, d)
        act.ctrl_prev, act.pos_prev = ctrl, servoed

    # ---------------------------------------------------------------------------- result
    def _result(self, k_end: int, wall: float, video: Path | None) -> WalkResult:
        """The measurements of the first ``k_end`` ticks and their summary."""
        self.log.timing["total"] = wall
        if self.wbc is not None:
            self.log.controller = {"name": "wbc", **self.wbc.tally.to_dict()}
            # the whole-body time splits into model terms and tasks, and the QP
            self.log.timing["qp"] = self.wbc.qp_time
            self.log.timing["model"] = self.log.timing.pop("ik") - self.wbc.qp_time
        elif self.ik is not None:
            self.log.controller = {"name": "servo", "ik_failures": self.ik.failures}
        log = self.log.trimmed(k_end, self.dt)
        t_goal = self.t_walk0 + self.n_planned * self.t_step - self.t_saved_planned
        metrics = summarise(log, self.scene, self.plan, self.sim.params, t_goal)
        choices = getattr(self.src, "choices", None)
        if choices:
            metrics = dataclasses.replace(
                metrics, region_choices=tuple(c.to_dict() for c in choices.values())
            )
        saved = getattr(self.src, "saved_ticks", None)
        if saved:
            moved = tuple({"step": i, "earlier_s": n * self.dt} for i, n in sorted(saved.items()))
            metrics = dataclasses.replace(metrics, touchdowns_moved=moved)
        return WalkResult(
            trace=log,
            metrics=metrics,
            video=video,
            video_note=self.video.note,
        )


def walk(
    scene: Scene,
    plan: FootstepPlan,
    options: WalkOptions | None = None,
    adjuster: FootstepAdjuster | None = None,
    model_params: WalkerModel | None = None,
    settings: BipedSimSettings | None = None,
    video_path: Path | None = None,
    video_size: tuple[int, int] = (640, 480),
    progress: Callable[[float], None] | None = None,
    replay: ReplayRecorder | None = None,
) -> WalkResult:
    """Simulate the biped walking ``plan`` over ``scene`` in MuJoCo and measure it.

    Args:
        scene: the scene the plan was made for (its terrain becomes MuJoCo geoms).
        plan: a footstep plan with ALIP states and torques (any planner).
        options: controller options.
        adjuster: footstep / torque source; default :class:`MPCAdjuster` (eq. 5.19) on the
            scene's regions with their riser edges moved in by ``plan.riser_inset`` (the regions
            the plan was made on).
        model_params: the robot (default: our biped, :class:`BipedModel`); any
            :class:`~footfall.sim.biped.model.WalkerModel`, e.g. the G1 of
            a robot file (:mod:`footfall.robots`). The plan should be made for it
            (:func:`~footfall.sim.biped.model.planner_params`).
        settings: physics settings (None: the model's defaults).
        video_path: write an MP4 here (offscreen GL); None = no video.
        video_size: (width, height) [px].
        progress: optional callback receiving the fraction done.
        replay: records the joint positions for ``footfall view`` (:mod:`footfall.sim.replay`).

    Returns:
        A :class:`WalkResult`.

    Raises:
        InputError: when the plan has no footsteps, does not start on the scene's start feet, or
            was made for another robot's mass or CoM height (see ``WalkOptions.check_robot``),
            or a start sole overhangs every region (more than
            :data:`~footfall.sim.biped.options.START_OVERHANG_TOL`).
    """
    opts = options if options is not None else WalkOptions()
    check_walk_inputs(scene, plan, opts, model_params)
    walker = BipedWalk(scene, plan, opts, adjuster, model_params, settings)
    return walker.run(video_path, video_size, progress, replay)
