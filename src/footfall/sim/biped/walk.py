"""Walk a footstep plan with the MuJoCo biped and measure it (document 000, section 5.5).

Control loop (every ``control_dt``):

1. **Measure** the ALIP state (eq. 5.1) of the robot about the stance contact point: the CoM
   relative to the stance sole centre and either ``m z_H (-v_y, v_x)`` from the CoM velocity
   (default) or the true angular momentum ``L = L_G + m (c - p) x v`` (MuJoCo's subtree CoM,
   velocity and angular momentum; ``WalkOptions.true_momentum``).
2. **Footstep / ankle-torque source** (:class:`FootstepAdjuster`): returns the next footstep and
   the ankle torque of this tick. The built-in :class:`PlanFollower` uses the plan's footsteps and
   ALIP torques, corrected by one-step ALIP foot placement; the MPC of eq. (5.19) plugs in here.
3. **Reference**: the ALIP reference state is advanced by one tick with that torque, exactly
   (zero-order hold, eq. 5.5), after blending it toward the measured state by ``com_feedback``.
   In double support the contact point moves linearly to the new foot (the model behind the reset
   map, eq. 5.8-5.10). The CoM height lies on the planes through z_H above consecutive
   footsteps (:class:`CoMHeight`), on which the horizontal motion is exactly the ALIP's.
4. **Whole body**: differential inverse kinematics with ``mink`` (one QP per iteration, solved by
   ``daqp``) tracks the CoM, both sole poses (stance: where it stands; swing: a trajectory that
   rises above every region it passes over before moving, see :func:`swing_reference`) and an
   upright torso; the resulting joint angles are the set points of the joint servos.

Everything reported is *measured* in the simulation: the centre of pressure (ZMP) of the stance
foot's contact forces (``mj_contactForce``), its offset from the sole centre in the foot frame,
where each foot lands, whether the robot fell. Planned quantities are only used for errors.
"""

import math
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.control.adjusters import (
    FootstepAdjuster,
    MPCAdjuster,
    extend_plan,
    sole_torque_limits,
)
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped import names as nm
from footfall.sim.biped.ik import WholeBodyIK
from footfall.sim.biped.metrics import summarise
from footfall.sim.biped.model import BipedModel, BipedSimSettings, WalkerModel, measure_model
from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.plant import BipedSim, ankle_joint_torque, sole_cop
from footfall.sim.biped.references import (
    SWING_SHARES,
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
from footfall.sim.biped.result import WalkResult
from footfall.terrain.edges import inset_riser_edges
from footfall.terrain.scene import Scene

#: a foot is loaded when its contact force exceeds this share of the weight
CONTACT_FORCE_SHARE = 0.02
#: the robot has fallen when the pelvis is lower than this share of its nominal height above the
#: stance sole ...
FALL_HEIGHT_SHARE = 0.6
#: ... or the torso tilts more than this [rad], or the pelvis or torso touches the terrain
FALL_TILT = math.radians(40.0)
#: video frame rate [1/s]
VIDEO_FPS = 30
#: a plan's robot mass and CoM height may differ this much (relative) from the walker model's
#: (:func:`~footfall.sim.biped.model.planner_params` measures them: 0.0 exactly)
PLAN_ROBOT_RTOL = 0.01


def _check_plan_robot(robot: BipedParams, model: WalkerModel | None) -> None:
    """Raise :class:`InputError` when the plan's robot is not the walker model's pendulum (mass
    and CoM height within ``PLAN_ROBOT_RTOL``, see :func:`planner_params`)."""
    info = measure_model(model)
    name = (model if model is not None else BipedModel()).name
    for field_name, planned, actual, unit in (
        ("mass", robot.mass, info.mass, "kg"),
        ("com_height", robot.com_height, info.com_height, "m"),
    ):
        if abs(planned - actual) > PLAN_ROBOT_RTOL * abs(actual):
            raise InputError(
                f"plan.robot.{field_name}",
                planned,
                f"the {name} model's {actual:.4g} {unit} within {PLAN_ROBOT_RTOL:.0%}: plan with "
                "footfall.sim.biped.model.planner_params(model) as the robot, or walk a "
                "mismatched plan on purpose with WalkOptions(check_robot=False)",
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
) -> WalkResult:
    """Simulate the biped walking ``plan`` over ``scene`` in MuJoCo and measure it.

    Args:
        scene: the scene the plan was made for (its terrain becomes MuJoCo geoms).
        plan: a footstep plan with ALIP states and torques (any planner).
        options: controller options.
        adjuster: footstep / torque source; default :class:`PlanFollower`.
        model_params: the robot (default: our biped, :class:`BipedModel`); any
            :class:`~footfall.sim.biped.model.WalkerModel`, e.g. the G1 of
            :mod:`footfall.sim.biped.g1`. The plan should be made for it
            (:func:`~footfall.sim.biped.model.planner_params`).
        settings: physics settings (None: the model's defaults).
        video_path: write an MP4 here (offscreen GL); None = no video.
        video_size: (width, height) [px].
        progress: optional callback receiving the fraction done.

    Returns:
        A :class:`WalkResult`.

    Raises:
        InputError: when the plan has no footsteps, does not start on the scene's start feet, or
            was made for another robot's mass or CoM height (see ``WalkOptions.check_robot``).
    """
    opts = options if options is not None else WalkOptions()
    if not plan.has_solution or plan.n_steps < 1:
        raise InputError("plan", plan.status.value, "a plan with at least one footstep")
    robot = plan.robot
    start_stance = scene.start.stance_foot
    if np.linalg.norm(plan.footsteps[0] - start_stance) > 1e-6:
        raise InputError(
            "plan.footsteps[0]",
            plan.footsteps[0].tolist(),
            f"the scene's start stance foot {start_stance.tolist()}",
        )
    if opts.check_robot:
        _check_plan_robot(robot, model_params)
    sim = BipedSim(scene, model_params, settings)
    mj, m, d = sim.mujoco, sim.model, sim.data
    substeps = round(opts.control_dt / m.opt.timestep)
    if substeps < 1 or abs(substeps * m.opt.timestep - opts.control_dt) > 1e-9:
        raise InputError(
            "control_dt", opts.control_dt, f"a multiple of the physics step {m.opt.timestep}"
        )
    dt = opts.control_dt
    regions = {r.name: r for r in scene.terrain.regions}
    inner = inset_riser_edges(scene.terrain, opts.riser_tolerance) if opts.riser_tolerance else None
    src: FootstepAdjuster = (
        adjuster
        if adjuster is not None
        else MPCAdjuster(
            plan,
            {r.name: r for r in inner.regions} if inner is not None else regions,
            region_margin=plan.region_margin + opts.landing_margin,
            control_dt=dt,
            stop_steps=opts.stop_steps,
            torque_limits=sole_torque_limits(plan.robot),
        )
    )
    n_planned = plan.n_steps
    plan = extend_plan(plan, opts.stop_steps)
    alip = robot.alip()
    ad_tick, bd_tick = alip.discretize(dt)
    ds_map = ds_propagator(alip, dt)
    z_h = robot.com_height
    n = plan.n_steps
    t_ss, t_ds = robot.t_ss, robot.t_ds
    t_step = t_ss + t_ds

    sim.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    ik = WholeBodyIK(sim)
    # the IK's nominal CoM offset: the standing CoM is where the model puts it, not at mid-feet
    com0, _, _ = sim.com_state()

    # foot state: where each foot is (measured at its last touchdown) and its planned heading/region
    foot_pos = {s: np.array(scene.start.foot(s)) for s in sim.sides}
    start_region = scene.start_regions()
    foot_rot = {
        s: foot_rotation(regions[start_region[s]].normal, scene.start.heading) for s in sim.sides
    }
    normals = [regions[name].normal for name in plan.regions]

    t_walk0 = opts.settle_time + opts.shift_time
    t_end_steps = t_walk0 + n * t_step
    t_total = t_end_steps + opts.stop_time + opts.hold_time
    n_ticks = round(t_total / dt)

    ts = np.arange(n_ticks, dtype=np.float64) * dt
    phase_log = np.full(n_ticks, -1, dtype=int)
    com_log = np.full((n_ticks, 3), np.nan)
    ref_log = np.full((n_ticks, 3), np.nan)
    zmp_log = np.full((n_ticks, 2), np.nan)
    zmp_plan_log = np.full((n_ticks, 2), np.nan)
    feet_log = np.full((n_ticks, 2, 3), np.nan)
    landed = np.full((n, 3), np.nan)
    targets = np.array(plan.footsteps[1:], dtype=float)
    timing = {"control": 0.0, "ik": 0.0, "physics": 0.0, "render": 0.0}

    renderer: Any = None
    writer: Any = None
    video_note = ""
    if video_path is not None:
        try:
            renderer = mj.Renderer(m, height=video_size[1], width=video_size[0])
        except Exception as exc:  # any GL failure means "no video", never a crash
            renderer, video_note = (
                None,
                f"no offscreen GL ({type(exc).__name__}: {exc}); video skipped",
            )
        if renderer is not None:
            import imageio.v2 as imageio

            video_path.parent.mkdir(parents=True, exist_ok=True)
            writer = imageio.get_writer(str(video_path), fps=VIDEO_FPS, macro_block_size=8)
    frame_every = max(1, round(1.0 / (VIDEO_FPS * dt)))

    stance_side = plan.sides[0]
    x_ref = np.zeros(4)  # ALIP reference relative to the current stance contact point
    prev_stance = np.array(scene.start.stance_foot)
    ds_aug = np.zeros(10)
    swing_start = foot_pos[stance_side.other].copy()
    swing_rot0 = foot_rot[stance_side.other].copy()
    apex, rise, descend = 0.0, SWING_SHARES[0], 1.0 - SWING_SHARES[0]
    cur_phase = -1
    stop_from = np.zeros(2)
    stop_vel = np.zeros(2)
    fell, fall_time = False, math.nan
    push_force = np.zeros(3)

    # CoM height over the footsteps (constraint planes of the 3-D LIPM); standing: over the feet
    height = CoMHeight(plan.footsteps, z_h)
    z_stand = 0.5 * (scene.start.left[2] + scene.start.right[2]) + z_h

    ankle_mode = {sd: False for sd in sim.sides}
    ctrl_prev = np.array(d.ctrl[sim.actuators], dtype=float)
    pos_prev = np.zeros(ctrl_prev.shape[0], dtype=bool)  # nothing to ramp from at the start
    ankle_u = np.zeros(2)
    landed_in = -1  # the single support in which the swing sole touched down early
    wall0 = time.perf_counter()
    for k in range(n_ticks):
        t = float(ts[k])
        c0 = time.perf_counter()
        com, vel, l_g = sim.com_state()
        com_log[k] = com
        feet_log[k, 0] = sim.sole(Side.LEFT)[0]
        feet_log[k, 1] = sim.sole(Side.RIGHT)[0]
        contacts, body_hit = sim.contacts()

        # ---------------------------------------------------------------- schedule
        c_next = com[:2] + vel[:2] * dt  # where the CoM will be when the references apply
        if t < t_walk0:
            # settle, then move the CoM over the first stance foot (the plan starts there at rest)
            mid = 0.5 * (scene.start.left + scene.start.right)
            s = smoothstep((t - opts.settle_time) / opts.shift_time)
            target_xy = mid[:2] + (start_stance[:2] - mid[:2]) * s
            z_ref = z_stand + (height(0, target_xy) - z_stand) * s
            com_ref = np.array([target_xy[0], target_xy[1], z_ref])
            # the standing CoM sits forward of the feet midpoint by the model's offset; keep it
            com_ref[:2] += (com0[:2] - mid[:2]) * (1.0 - s)
            targets_now = {sd: (foot_pos[sd], foot_rot[sd]) for sd in sim.sides}
            yaw = scene.start.heading
        elif t < t_end_steps:
            tw = t - t_walk0
            i = min(int(tw / t_step), n - 1)
            tp = tw - i * t_step
            if i != cur_phase:
                # a new single support: the foot that just landed is the stance foot
                if cur_phase >= 0:
                    sd_landed = plan.sides[i]
                    foot_pos[sd_landed] = sim.sole(sd_landed)[0]
                    landed[i - 1] = foot_pos[sd_landed]
                    # re-express the reference relative to the new stance (eq. 5.10's -I block)
                    x_ref = ds_aug[:4].copy()
                    x_ref[:2] -= (foot_pos[sd_landed] - prev_stance)[:2]
                cur_phase = i
                stance_side = plan.sides[i]
                swing_side = stance_side.other
                swing_start = sim.sole(swing_side)[0]
                swing_rot0 = foot_rot[swing_side]
                apex = (
                    terrain_height_along(
                        scene.terrain.regions,
                        swing_start,
                        plan.footsteps[i + 1],
                        robot.foot_length / 2,
                        robot.foot_width / 2,
                    )
                    + opts.swing_clearance
                )
                rise, descend = swing_shares(
                    apex - float(swing_start[2]), apex - float(plan.footsteps[i + 1][2]), t_ss
                )
            stance = foot_pos[stance_side]
            swing_side = stance_side.other
            # measured ALIP state about the stance sole centre (eq. 5.1)
            r = com - stance
            l_c = l_g + sim.mass * np.cross(r, vel)
            x_meas = np.array([r[0], r[1], l_c[0], l_c[1]])
            if tp < t_ss:
                phase_log[k] = i
                nxt, u = src.update(
                    tp,
                    x_meas if opts.true_momentum else alip.state_from_velocity(r[:2], vel[:2]),
                    stance,
                    i,
                )
                targets[i] = nxt
                zmp_plan_log[k] = alip.zmp(np.zeros(2), u)
                fb = 1.0 if opts.ankle_torque else opts.com_feedback
                # the kinematic reference follows the CoM's own velocity: the true momentum also
                # holds the swing leg's and torso's (L_G), which the CoM does not move with
                x_cv = alip.state_from_velocity(r[:2], vel[:2])
                x_ref = x_ref + fb * (x_cv - x_ref)
                ankle_u = u
                x_ref = ad_tick @ x_ref + bd_tick @ u
                tau = min(1.0, (tp + dt) / t_ss)
                pos, s_h = swing_reference(
                    tau,
                    swing_start,
                    nxt,
                    apex,
                    rise,
                    descend,
                    stance,
                    robot.foot_width + opts.swing_side_gap if opts.swing_side_gap > 0 else 0.0,
                )
                rot1 = foot_rotation(normals[i + 1], plan.headings[i + 1])
                rot = blend_rot(swing_rot0, rot1 @ pitch_about_y(-opts.heel_strike), s_h)
                targets_now = {stance_side: (stance, foot_rot[stance_side]), swing_side: (pos, rot)}
                yaw = float(
                    plan.headings[i] + (plan.headings[i + 1] - plan.headings[i]) * 0.5 * s_h
                )
                if tp + dt >= t_ss - 1e-9:
                    foot_rot[swing_side] = rot1
                ref_xy = stance[:2] + x_ref[:2]
                # the contact point moves from the stance foot to the landing target during DS
                prev_stance = stance.copy()
                ds_aug = np.concatenate([x_ref, np.zeros(3), (targets[i] - stance) / t_ds])
            else:
                ds_aug = ds_map @ ds_aug
                x_ref = ds_aug[:4]
                ref_xy = prev_stance[:2] + x_ref[:2]
                targets_now = {
                    stance_side: (stance, foot_rot[stance_side]),
                    swing_side: (targets[i], foot_rot[swing_side]),
                }
                yaw = float(0.5 * (plan.headings[i] + plan.headings[i + 1]))
            support = i if tp < t_ss else i + 1
            com_ref = np.array([ref_xy[0], ref_xy[1], height(support, c_next)])
            if k + 1 < n_ticks and t + dt >= t_end_steps - 1e-9:
                # the stop starts from the measured CoM motion: the reference may have drifted
                stop_from = com[:2].copy()
                stop_vel = vel[:2].copy()
        else:
            if not math.isnan(landed[n - 1, 0]) or cur_phase < n:
                if math.isnan(landed[n - 1, 0]):
                    sd_landed = plan.sides[n]
                    foot_pos[sd_landed] = sim.sole(sd_landed)[0]
                    landed[n - 1] = foot_pos[sd_landed]
                    cur_phase = n
            # stop: cubic Hermite from the last reference (position, velocity) to the middle of
            # the final feet at rest
            mid = 0.5 * (foot_pos[Side.LEFT] + foot_pos[Side.RIGHT])
            s = min(1.0, (t + dt - t_end_steps) / opts.stop_time)
            h00, h10 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s
            h01 = -2 * s**3 + 3 * s**2
            xy = h00 * stop_from + h10 * opts.stop_time * stop_vel + h01 * mid[:2]
            com_ref = np.array([xy[0], xy[1], height(n, c_next)])
            targets_now = {sd: (foot_pos[sd], foot_rot[sd]) for sd in sim.sides}
            yaw = float(plan.headings[n])

        # ---------------------------------------------------------------- measurement: ZMP
        if phase_log[k] >= 0:
            pos_s, rot_s = sim.sole(stance_side)
            pts, frc = contacts[stance_side]
            cop = sole_cop(pts, frc, pos_s, rot_s)
            if cop is not None and cop[1] > CONTACT_FORCE_SHARE * sim.weight:
                zmp_log[k] = cop[0]
        ref_log[k] = com_ref

        # ---------------------------------------------------------------- fall detection
        stance_z = (
            max(foot_pos[Side.LEFT][2], foot_pos[Side.RIGHT][2])
            if phase_log[k] < 0
            else foot_pos[stance_side][2]
        )
        pelvis_z = float(d.xpos[sim.pelvis][2]) - float(stance_z)
        up = d.xmat[sim.torso].reshape(3, 3)[:, 2]
        tilt = math.acos(max(-1.0, min(1.0, float(up[2]))))
        if not fell and (
            body_hit or tilt > FALL_TILT or pelvis_z < FALL_HEIGHT_SHARE * sim.params.pelvis_height
        ):
            fell, fall_time = True, t
            if opts.stop_on_fall:
                timing["control"] += time.perf_counter() - c0
                break
        c1 = time.perf_counter()
        timing["control"] += c1 - c0

        # ---------------------------------------------------------------- whole body
        com_cmd = com_ref.copy()
        # which ankles are torque-driven and with what ALIP torque (None = position servo)
        ankle_cmd: dict[Side, FloatArray | None] = {sd: None for sd in sim.sides}
        if opts.ankle_torque and phase_log[k] >= 0:
            ankle_cmd[stance_side] = ankle_u
            swing_side = stance_side.other
            if opts.passive_landing and landed_in != i and tp >= descend * t_ss:
                pos_w, rot_w = sim.sole(swing_side)
                cop_w = sole_cop(*contacts[swing_side], pos_w, rot_w)
                if cop_w is not None and cop_w[1] > CONTACT_FORCE_SHARE * sim.weight:
                    landed_in = i
            if landed_in == i:
                # the swing sole touched down: a limp ankle lets it settle flat (see options)
                ankle_cmd[swing_side] = np.zeros(2)
        elif opts.ankle_torque and t_walk0 <= t < t_end_steps:
            # double support: the legs form a closed chain whose joint servos place the CoM and
            # the total CoP moves between the feet, where the contact-point ramp of eq. (5.8)
            # puts it. The landing ankle is passive; the rear ankle's torque ramps from its last
            # single-support command to zero over T_ds. (Dropping it at once made the rear foot
            # pivot and lift as the weight left it, both feet unloaded for a few ticks: with the
            # ramp 12 of 12 pushed walks of discrete_steps N = 18 reached the goal, without 10.)
            ankle_cmd = {sd: np.zeros(2) for sd in sim.sides}
            if tp >= t_ss:
                ankle_cmd[stance_side] = max(0.0, 1.0 - (tp - t_ss) / t_ds) * ankle_u
        if ankle_cmd[stance_side] is None or phase_log[k] < 0:
            com_cmd[:2] += opts.com_gain * (com_ref[:2] - com[:2])
        if opts.closed_loop_ik:
            torque_ss = ankle_cmd[stance_side] is not None and phase_log[k] >= 0
            if torque_ss:
                # the torque-driven stance sole is where it is: pin it at its measured pose
                targets_now[stance_side] = sim.sole(stance_side)
            # a torque-driven stance ankle is not servoed: the IK must leave it where it is (in
            # double support the passive ankles move with the closed chain of the two legs)
            held = [sim.ankle_actuators(stance_side)] if torque_ss else []
            q_des = ik.solve(
                targets_now,
                com_cmd,
                yaw,
                dt,
                opts.ik_iterations,
                q_meas=d.qpos,
                com_axes=(not torque_ss, not torque_ss, True),
                hold=np.concatenate(held) if held else None,
            )
        else:
            q_des = ik.solve(targets_now, com_cmd, yaw, dt, opts.ik_iterations)
        for sd in sim.sides:
            cmd = ankle_cmd[sd]
            if (cmd is not None) != ankle_mode[sd]:
                sim.set_ankle_torque_mode(sd, cmd is not None)
                ankle_mode[sd] = cmd is not None
            if cmd is not None:
                # the CoP bound scales with the normal force the foot carries *now*: during
                # vertical CoM and swing-leg accelerations it is below the weight, and a torque
                # sized for the weight would tip the foot onto its edge
                pos_a, rot_a = sim.sole(sd)
                cop_a = sole_cop(*contacts[sd], pos_a, rot_a)
                f_n = min(sim.weight, cop_a[1]) if cop_a is not None else 0.0
                q_des[sim.ankle_actuators(sd)] = ankle_joint_torque(cmd, rot_a, f_n, sim.params)
        # Position set points ramp linearly over the physics substeps from the last tick's: a step
        # every 10 ms into 5000 N m/rad servos jolted the stance foot (normal force spikes from
        # 300 to 570 N at every tick); torque-driven ankles, and actuators that changed mode this
        # tick, take their new command at once.
        ctrl_new = np.array(q_des, dtype=float)
        pos_now = np.ones(ctrl_new.shape[0], dtype=bool)
        for sd in sim.sides:
            if ankle_mode[sd]:
                pos_now[sim.ankle_actuators(sd)] = False
        ramp = pos_now & pos_prev
        c2 = time.perf_counter()
        timing["ik"] += c2 - c1

        # ---------------------------------------------------------------- physics
        push_force[:] = 0.0
        for p in opts.pushes:
            if p.active(t):
                push_force += p.force
        d.xfrc_applied[sim.torso, :3] = push_force
        for j in range(substeps):
            w = (j + 1) / substeps
            d.ctrl[sim.actuators] = np.where(ramp, ctrl_prev + w * (ctrl_new - ctrl_prev), ctrl_new)
            mj.mj_step(m, d)
        ctrl_prev, pos_prev = ctrl_new, pos_now
        c3 = time.perf_counter()
        timing["physics"] += c3 - c2
        if writer is not None and k % frame_every == 0:
            renderer.update_scene(d, camera=nm.TRACK_CAMERA)
            writer.append_data(renderer.render())
            timing["render"] += time.perf_counter() - c3
        if progress is not None and k % 100 == 0:
            progress(k / n_ticks)
    wall = time.perf_counter() - wall0
    if writer is not None:
        writer.close()
    if renderer is not None:
        renderer.close()
    k_end = k + 1
    timing["total"] = wall
    sim_time = k_end * dt
    result = WalkResult(
        t=ts[:k_end],
        phase=phase_log[:k_end],
        com=com_log[:k_end],
        com_ref=ref_log[:k_end],
        zmp_offset=zmp_log[:k_end],
        zmp_planned=zmp_plan_log[:k_end],
        feet=feet_log[:k_end],
        landed=landed,
        targets=targets,
        planned=np.array(plan.footsteps[1:]),
        n_planned=n_planned,
        fell=fell,
        fall_time=fall_time,
        metrics={},
        timing=timing,
        sim_time=sim_time,
        video=video_path if writer is not None else None,
        video_note=video_note,
    )
    t_goal = t_walk0 + n_planned * t_step
    metrics = summarise(result, scene, plan, sim.params, t_goal)
    object.__setattr__(result, "metrics", metrics)
    return result
