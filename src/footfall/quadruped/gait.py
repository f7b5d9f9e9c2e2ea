"""Walk-gait sequencer on a slope: ZMP planning (sec. 1.3) + posture (sec. 2) + swing (sec. 3).

``plan_gait`` builds the phase list (body shifts with four feet down, then one or two swings with
the body still); ``GaitPlan.sample`` turns it into the dense references a position controller
needs: body pose, foot positions, contacts, joint angles, and the planned CoM and ZMP.

A static walk keeps the body still during swings, so the ZMP sits on its target (up to the swing
leg's own motion) for the whole three-legged phase. Body shifts use a quintic time law (zero
velocity and acceleration at both ends); the ZMP excursion they cause is computed with eq. (5).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from enum import Enum

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall._validate import finite, non_negative, positive
from footfall.errors import InputError
from footfall.quadruped.ground import PlaneGround, QuadrupedGround, Stairs, VaryingSlope
from footfall.quadruped.kinematics import (
    body_rotation,
    foot_in_leg_frame,
    leg_ik,
    leg_mass_points,
    whole_body_com,
)
from footfall.quadruped.posture import BodyPosture, SlopePosture
from footfall.quadruped.robot import LEGS, Leg, QuadrupedRobot
from footfall.quadruped.stability import stability_margins, support_polygon, zmp_from_momentum
from footfall.quadruped.swing import SwingProfile, swing_in_leg_frame
from footfall.quadruped.zmp_planning import ZmpStrategy, swing_groups, swing_order, zmp_target

#: fixed-point iterations placing the body so that the whole-body CoM is on the ZMP target;
#: the legs hold 20 % of the mass, so each iteration shrinks the CoM error about fivefold
_COM_ITERATIONS = 3
#: bisection steps for the largest feasible slope / step reported in error messages
_BISECT_STEPS = 30


class PhaseKind(str, Enum):
    """Kinds of gait phases."""

    SHIFT = "shift"  # four feet down, body moves to the next ZMP target
    SWING = "swing"  # one leg swings (eq. 10-13), body still
    HOLD = "hold"  # four feet down, body still (end of the walk)


#: most gait cycles of one plan (the plan and its simulation grow linearly with them)
MAX_CYCLES = 1000


#: the compromise posture's body angle as a fraction of the slope (fig. 7; 10 deg on 15 deg):
#: the default body pitch on the document's slope and on any other ground (``body_ratio``)
BODY_RATIO = 2.0 / 3.0


@dataclass(frozen=True)
class GaitParams:
    """Inputs of the gait sequencer.

    Attributes:
        slope: slope angle beta_S [rad].
        body_pitch: body angle beta_B [rad], in [0, slope].
        step: step length S along the slope [m].
        swing_height: swing height H normal to the slope [m].
        swing_period: swing period T_w [s].
        shift_period: duration of each body shift [s].
        cycles: number of gait cycles n (each moves every leg once).
        strategy: ZMP placement (document's OSP or a comparison strategy).
        posture: body posture mode (sec. 2).
        height: body-centre height h_B above the foot-centre plane [m]; None = robot default.
        hold_time: standing time after the last shift [s].
        side_slope: inclination of the slope across the walking direction [rad] (positive: the
            left side higher); the body stays level across it, legs vertical (beyond document
            001, whose slope only rises along the walk).
        ground: a ground other than the plane (:class:`~footfall.quadruped.ground.VaryingSlope`
            or :class:`~footfall.quadruped.ground.Stairs`); ``slope``, ``body_pitch`` and
            ``side_slope`` must then be 0 and the body follows the local plane of its feet.
        body_ratio: with ``ground``: the body pitches by this fraction of the local plane's
            inclination (the compromise posture of fig. 7 applied locally; 0 keeps it level).
        lateral_share: how far out of its ab/ad axis each neutral foot stands, as a share of the
            leg's lateral offset (1: under a vertical leg; less: a narrower stance, smaller
            body shifts over the support triangles). The document's robot has no offset.
    """

    slope: float
    body_pitch: float
    step: float = 0.4
    swing_height: float = 0.1
    swing_period: float = 0.5
    shift_period: float = 1.5
    cycles: int = 6
    strategy: ZmpStrategy = ZmpStrategy.OSP
    posture: BodyPosture = BodyPosture.COMPROMISE
    height: float | None = None
    hold_time: float = 0.5
    side_slope: float = 0.0
    ground: QuadrupedGround | None = None
    body_ratio: float = BODY_RATIO
    lateral_share: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "step", positive("step", self.step))
        object.__setattr__(self, "swing_height", positive("swing_height", self.swing_height))
        object.__setattr__(self, "swing_period", positive("swing_period", self.swing_period))
        object.__setattr__(self, "shift_period", positive("shift_period", self.shift_period))
        object.__setattr__(self, "hold_time", non_negative("hold_time", self.hold_time))
        cycles = self.cycles
        if isinstance(cycles, bool) or not isinstance(cycles, int) or not 1 <= cycles <= MAX_CYCLES:
            raise InputError("cycles", cycles, f"an integer in 1..{MAX_CYCLES}")
        object.__setattr__(self, "strategy", ZmpStrategy(self.strategy))
        object.__setattr__(self, "posture", BodyPosture(self.posture))
        if self.height is not None:
            object.__setattr__(self, "height", positive("height", self.height))
        # validates slope and body angle (body angle within [0, slope]) early
        SlopePosture(self.slope, self.body_pitch, 1.0, self.posture)
        ratio = finite("body_ratio", self.body_ratio)
        if not 0.0 <= ratio <= 1.0:
            raise InputError("body_ratio", ratio, "a fraction of the local inclination in [0, 1]")
        object.__setattr__(self, "body_ratio", ratio)
        share = finite("lateral_share", self.lateral_share)
        if not 0.0 <= share <= 1.0:
            raise InputError(
                "lateral_share", share, "a share of the legs' lateral offset in [0, 1]"
            )
        object.__setattr__(self, "lateral_share", share)
        if self.ground is None:
            PlaneGround(self.slope, self.side_slope)  # validates the side slope
            return
        if not isinstance(self.ground, VaryingSlope | Stairs):
            raise InputError(
                "ground", type(self.ground).__name__, "a VaryingSlope or Stairs (or None: plane)"
            )
        for name in ("slope", "body_pitch", "side_slope"):
            if getattr(self, name) != 0.0:
                raise InputError(name, getattr(self, name), "0 when a ground is given")
        if self.posture is BodyPosture.PARALLEL:
            raise InputError(
                "posture", self.posture.value, "compromise or horizontal on this ground"
            )

    @property
    def terrain(self) -> QuadrupedGround:
        """The ground walked: ``ground``, or the plane of ``slope`` and ``side_slope``."""
        if self.ground is not None:
            return self.ground
        return PlaneGround(self.slope, self.side_slope)

    def pitch_for(self, plane: tuple[float, float, float]) -> float:
        """Body pitch [rad] on the local plane ``z = a + b x + c y`` of the feet: the given
        ``body_pitch`` on the document's plane, ``body_ratio`` times its inclination otherwise."""
        if self.ground is None:
            return self.body_pitch
        if self.posture is BodyPosture.HORIZONTAL:
            return 0.0
        return self.body_ratio * math.atan(plane[1])


@dataclass(frozen=True)
class GaitPhase:
    """One phase of the walk.

    Attributes:
        kind: shift, swing or hold.
        t0: start time [s].
        duration: length [s].
        body_start: body centre at the start, shape (3,) [m].
        body_end: body centre at the end, shape (3,) [m].
        feet_start: foot centres at the start, shape (4, 3) [m], ``LEGS`` order.
        leg: the swing leg (SWING only).
        foot_end: the swing leg's landing point (SWING only), shape (3,) [m].
        zmp_target: ZMP target the preceding shift aimed at, shape (2,) [m].
        target_margin: margin of that target in the support triangles it serves [m].
        cycle: gait cycle index.
        pitch_start: body pitch at the start [rad] (nose up positive).
        pitch_end: body pitch at the end [rad]; it changes only in shifts, with the same time
            law as the body position.
    """

    kind: PhaseKind
    t0: float
    duration: float
    body_start: FloatArray
    body_end: FloatArray
    feet_start: FloatArray
    leg: Leg | None = None
    foot_end: FloatArray | None = None
    zmp_target: FloatArray | None = None
    target_margin: float = math.nan
    cycle: int = 0
    pitch_start: float = 0.0
    pitch_end: float = 0.0

    @property
    def t1(self) -> float:
        """End time [s]."""
        return self.t0 + self.duration


@dataclass(frozen=True)
class GaitTrajectory:
    """Dense references sampled from a plan (shapes with T samples).

    Attributes:
        t: times, shape (T,) [s].
        body_pos: body centre in ``{W}``, shape (T, 3) [m].
        body_pitch: body angle beta_B to the horizontal, shape (T,) [rad] (constant on the
            document's plane; it follows the local plane on other grounds).
        feet: foot centres in ``{W}``, shape (T, 4, 3) [m], ``LEGS`` order.
        contact: planned stance flags, shape (T, 4).
        joints: joint angles, shape (T, 12) [rad], ``LEGS`` x (abad, pitch, knee).
        com: whole-body CoM (point-mass legs), shape (T, 3) [m].
        zmp: planned ZMP from eq. (5) with the point-mass momentum rates, shape (T, 2) [m].
        margin: planned stability margin of the ZMP in the stance feet's polygon, shape (T,) [m].
        phase: index into ``GaitPlan.phases``, shape (T,).
    """

    t: FloatArray
    body_pos: FloatArray
    body_pitch: FloatArray
    feet: FloatArray
    contact: NDArray[np.bool_]
    joints: FloatArray
    com: FloatArray
    zmp: FloatArray
    margin: FloatArray
    phase: NDArray[np.int_]


@dataclass(frozen=True)
class GaitPlan:
    """Result of :func:`plan_gait`."""

    robot: QuadrupedRobot
    params: GaitParams
    posture: SlopePosture
    phases: tuple[GaitPhase, ...] = field(repr=False)

    @property
    def duration(self) -> float:
        """Total duration [s]."""
        return self.phases[-1].t1

    @property
    def initial_body(self) -> FloatArray:
        """Body centre at t = 0, shape (3,) [m]."""
        return self.phases[0].body_start

    @property
    def initial_feet(self) -> FloatArray:
        """Foot centres at t = 0, shape (4, 3) [m]."""
        return self.phases[0].feet_start

    @property
    def ground(self) -> QuadrupedGround:
        """The ground walked (see :attr:`GaitParams.terrain`)."""
        return self.params.terrain

    def contact_point(self, foot_centre: FloatArray) -> FloatArray:
        """Ground contact point of a spherical foot: centre minus radius along the normal."""
        n = self.ground.normal(float(foot_centre[0]), float(foot_centre[1]))
        return foot_centre - self.robot.foot_radius * n

    def sample(self, dt: float = 0.01, with_zmp: bool = True) -> GaitTrajectory:
        """Sample the plan every ``dt`` seconds (see :class:`GaitTrajectory`)."""
        return sample_plan(self, dt, with_zmp)

    def shifts(self) -> list[GaitPhase]:
        """The body-shift phases."""
        return [p for p in self.phases if p.kind is PhaseKind.SHIFT]


def _quintic(u: FloatArray) -> FloatArray:
    """Minimum-jerk time law 10u^3 - 15u^4 + 6u^5 (zero velocity and acceleration at both ends)."""
    return u * u * u * (10.0 + u * (-15.0 + 6.0 * u))


def _legs_ok(robot: QuadrupedRobot, body: FloatArray, pitch: float, feet: FloatArray) -> bool:
    for i, leg in enumerate(LEGS):
        try:
            leg_ik(robot, foot_in_leg_frame(robot, leg, body, pitch, feet[i]), leg)
        except InputError:
            return False
    return True


def _neutral_ok(robot: QuadrupedRobot, post: SlopePosture, share: float = 1.0) -> bool:
    """Neutral stance (body at its nominal place, feet at the neutral footholds) reachable."""
    body = post.body_position()
    return _legs_ok(robot, body, post.body_pitch, post.neutral_feet(robot, body, share))


def check_reachability(robot: QuadrupedRobot, params: GaitParams) -> SlopePosture:
    """Check that the posture's neutral stance fits the leg workspace, before planning.

    Returns:
        The slope posture.

    Raises:
        InputError: naming ``slope`` when the neutral stance is out of the leg workspace (too
            steep for this body angle), with the steepest feasible slope in the message.
    """
    h = params.height if params.height is not None else robot.stance_height
    if params.ground is not None:
        # the posture where the walk starts; the body then follows the feet's local plane
        b0 = params.ground.inclination(0.0)
        post = SlopePosture(b0, params.pitch_for((0.0, math.tan(b0), 0.0)), h, params.posture)
    else:
        post = SlopePosture(params.slope, params.body_pitch, h, params.posture)
    if _neutral_ok(robot, post, params.lateral_share):
        body, pitch, feet = _initial_stance(robot, params, post)
        if not _legs_ok(robot, body, pitch, feet):
            fld = "side_slope" if params.ground is None else "ground"
            raise InputError(
                fld,
                getattr(params, fld) if params.ground is None else type(params.ground).__name__,
                "a ground whose neutral stance is in the leg workspace (legs vertical, body "
                f"{h:.3f} m above it; usable leg length {robot.min_leg_length:.3f}-"
                f"{robot.max_leg_length:.3f} m)",
            )
        return post
    if not _neutral_ok(robot, SlopePosture(0.0, 0.0, h, params.posture), params.lateral_share):
        raise InputError("height", h, "a body height the legs reach on flat ground")
    lo, hi = 0.0, params.slope
    for _ in range(_BISECT_STEPS):
        mid = 0.5 * (lo + hi)
        trial = SlopePosture(mid, min(params.body_pitch, mid), h, params.posture)
        lo, hi = (mid, hi) if _neutral_ok(robot, trial, params.lateral_share) else (lo, mid)
    raise InputError(
        "slope",
        f"{math.degrees(params.slope):.2f} deg",
        f"at most {math.degrees(lo):.2f} deg with body angle "
        f"{math.degrees(params.body_pitch):.2f} deg (leg workspace: usable length "
        f"{robot.min_leg_length:.3f}-{robot.max_leg_length:.3f} m and joint limits)",
    )


@dataclass(frozen=True)
class _Local:
    """The body's pose rule over one stance: height ``height`` above the plane
    ``z = a + b x + c y`` of the feet, pitch ``pitch`` [rad]."""

    plane: tuple[float, float, float]
    height: float
    pitch: float

    def body_position(self, x: float, y: float) -> FloatArray:
        a, b, c = self.plane
        return np.array([x, y, a + b * x + c * y + self.height])


def _local(params: GaitParams, post: SlopePosture, points: FloatArray) -> _Local:
    """The pose rule over the foot centres ``points`` (N, 3): the ground's local plane."""
    plane = params.terrain.local_plane(points)
    return _Local(plane, post.height, params.pitch_for(plane))


def _initial_stance(
    robot: QuadrupedRobot, params: GaitParams, post: SlopePosture
) -> tuple[FloatArray, float, FloatArray]:
    """Body centre (3,), pitch [rad] and neutral foot centres (4, 3) at the start: the body
    ``h_B`` above the origin, each hip's ray along the posture's leg direction meeting the
    foot-centre surface (document 001's neutral footholds on its plane)."""
    ground = params.terrain
    body = np.array([0.0, 0.0, post.height])
    pitch = post.body_pitch
    rot = body_rotation(pitch)
    d = post.leg_direction()
    share = params.lateral_share
    feet = np.array([ground.drop(body + rot @ robot.stance_offset(leg, share), d) for leg in LEGS])
    return body, pitch, feet


def _body_for_com(
    robot: QuadrupedRobot,
    local: _Local,
    target: FloatArray,
    feet: FloatArray,
    step: float,
) -> FloatArray:
    """Body position whose whole-body CoM projects on ``target`` with the feet at ``feet``.

    Raises:
        InputError: named ``step`` when that body position is outside the leg workspace.
    """
    # the trunk carries 80 % of the mass, so the target itself is a close first guess
    body = local.body_position(float(target[0]), float(target[1]))
    rot = body_rotation(local.pitch)
    hips = robot.hip_offsets()
    for _ in range(_COM_ITERATIONS):
        p_leg = (feet - body) @ rot - hips
        try:
            q = np.concatenate([leg_ik(robot, p_leg[i], leg) for i, leg in enumerate(LEGS)])
        except InputError as exc:
            raise InputError(
                "step",
                f"{step:.3f} m",
                f"a step for which the body can reach the ZMP target "
                f"({target[0]:.3f}, {target[1]:.3f}) m: leg out of reach ({exc.expected})",
            ) from None
        com = whole_body_com(robot, body, local.pitch, q)
        xy = body[:2] + (target - com[:2])
        body = local.body_position(float(xy[0]), float(xy[1]))
    return body


def plan_gait(robot: QuadrupedRobot, params: GaitParams) -> GaitPlan:
    """Plan a walk gait up a slope.

    Steps: check the posture fits the leg workspace; place the feet in the staggered stance of
    the swing order (each leg a quarter step apart, centred on the posture's neutral footholds);
    for every group of swings (pairs for the OSP method) compute the support triangles, the ZMP
    target (OSP or incentre, sec. 1.3), the body position whose CoM projects on it, a body shift
    to it and the swings (eq. 10-13), each foot landing one step S further up the slope. A final
    shift centres the CoM in the four-foot support polygon.

    Raises:
        InputError: naming ``slope`` when the posture is out of the leg workspace, ``step`` when
            the steps or the body shifts they need are out of reach (with the largest feasible
            step in the message), ``body_pitch`` when the body angle is outside [0, slope].
    """
    check_reachability(robot, params)
    try:
        return _plan(robot, params)
    except InputError as exc:
        if exc.field != "step":
            raise
        reason = exc.expected
    lo = largest_step(robot, params)
    raise InputError(
        "step",
        f"{params.step:.3f} m",
        f"at most {lo:.3f} m on a {math.degrees(params.slope):.2f} deg slope with body angle "
        f"{math.degrees(params.body_pitch):.2f} deg and strategy {params.strategy.value} "
        f"(leg workspace; {reason})",
    )


def largest_step(robot: QuadrupedRobot, params: GaitParams) -> float:
    """The largest step length [m] up to ``params.step`` the leg workspace allows for this
    ground, posture and strategy, by bisection on whole plans (within
    ``params.step / 2**(_BISECT_STEPS // 2)``; on a plane the gait repeats every cycle, so two
    cycles are planned); 0 when none does."""
    check_reachability(robot, params)
    cycles = params.cycles if params.ground is not None else min(params.cycles, 2)
    lo, hi = 0.0, params.step
    try:
        _plan(robot, replace(params, cycles=cycles))
        return params.step
    except InputError as exc:
        if exc.field != "step":
            raise
    for _ in range(_BISECT_STEPS // 2):
        mid = 0.5 * (lo + hi)
        try:
            _plan(robot, replace(params, step=mid, cycles=cycles))
            lo = mid
        except InputError:
            hi = mid
    return lo


def _plan(robot: QuadrupedRobot, params: GaitParams) -> GaitPlan:
    """:func:`plan_gait` without the search for the largest feasible step."""
    post = check_reachability(robot, params)
    ground = params.terrain
    if isinstance(ground, Stairs) and ground.edge_margin < robot.foot_radius:
        raise InputError(
            "ground.edge_margin",
            ground.edge_margin,
            f"at least the foot radius {robot.foot_radius}",
        )
    order = swing_order(params.strategy)
    body, pitch, feet = _initial_stance(robot, params, post)
    r = robot.foot_radius
    for j, leg in enumerate(order):
        # steady state: a leg lands S/2 ahead of its neutral point at mid-swing of the cycle
        feet[leg.idx] = ground.advance(feet[leg.idx], params.step * ((j + 0.5) / 4.0 - 0.5), r)

    phases: list[GaitPhase] = []
    t = 0.0
    for cycle in range(params.cycles):
        for group in swing_groups(params.strategy):
            body, pitch, t = _shift_and_swing(
                robot, post, params, group, cycle, feet, (body, pitch), t, phases
            )
    _centre_and_hold(robot, post, params, feet, (body, pitch), t, phases)
    plan = GaitPlan(robot, params, post, tuple(phases))
    _check_plan_reach(plan)
    _check_swing_clearance(plan)
    return plan


def _shift_and_swing(
    robot: QuadrupedRobot,
    post: SlopePosture,
    params: GaitParams,
    group: tuple[Leg, ...],
    cycle: int,
    feet: FloatArray,
    pose: tuple[FloatArray, float],
    t: float,
    phases: list[GaitPhase],
) -> tuple[FloatArray, float, float]:
    """Append one body shift to the ZMP target of the support triangles of ``group`` (sec. 3),
    then the swing of each leg of the group (one step along the ground) to ``phases``.

    ``pose`` is the body position (3,) [m] and pitch [rad] before the shift; the shift ends at
    the pitch of the local plane through the feet before and after the group's swings. ``feet``
    (4, 3) [m] is updated to the landed feet. Returns the body position [m] and pitch [rad]
    after the shift and the time [s] after the last swing.
    """
    ground, r = params.terrain, robot.foot_radius
    body, pitch = pose
    tri_feet = feet.copy()
    triangles = []
    for leg in group:
        stance = [i for i in range(4) if i != leg.idx]
        triangles.append(support_polygon(tri_feet[stance]))
        tri_feet[leg.idx] = ground.advance(tri_feet[leg.idx], params.step, r)
    target, margin = zmp_target(triangles)
    local = _local(params, post, np.vstack([feet, tri_feet]))
    new_body = _body_for_com(robot, local, target, feet, params.step)
    phases.append(
        GaitPhase(
            PhaseKind.SHIFT,
            t,
            params.shift_period,
            body,
            new_body,
            feet.copy(),
            zmp_target=target,
            target_margin=margin,
            cycle=cycle,
            pitch_start=pitch,
            pitch_end=local.pitch,
        )
    )
    t += params.shift_period
    body, pitch = new_body, local.pitch
    for leg in group:
        land = tri_feet[leg.idx]
        phases.append(
            GaitPhase(
                PhaseKind.SWING,
                t,
                params.swing_period,
                body,
                body,
                feet.copy(),
                leg=leg,
                foot_end=land,
                zmp_target=target,
                target_margin=margin,
                cycle=cycle,
                pitch_start=pitch,
                pitch_end=pitch,
            )
        )
        t += params.swing_period
        feet[leg.idx] = land
    return body, pitch, t


def _centre_and_hold(
    robot: QuadrupedRobot,
    post: SlopePosture,
    params: GaitParams,
    feet: FloatArray,
    pose: tuple[FloatArray, float],
    t: float,
    phases: list[GaitPhase],
) -> None:
    """Append the final shift of the CoM over the centre of the four feet, and the standing hold
    (when ``params.hold_time`` > 0), to ``phases``."""
    body, pitch = pose
    centre = feet[:, :2].mean(axis=0)
    local = _local(params, post, feet)
    final = _body_for_com(robot, local, centre, feet, params.step)
    phases.append(
        GaitPhase(
            PhaseKind.SHIFT,
            t,
            params.shift_period,
            body,
            final,
            feet.copy(),
            zmp_target=centre,
            cycle=params.cycles - 1,
            pitch_start=pitch,
            pitch_end=local.pitch,
        )
    )
    t += params.shift_period
    if params.hold_time > 0.0:
        phases.append(
            GaitPhase(
                PhaseKind.HOLD,
                t,
                params.hold_time,
                final,
                final,
                feet.copy(),
                cycle=params.cycles - 1,
                pitch_start=local.pitch,
                pitch_end=local.pitch,
            )
        )


def _check_plan_reach(plan: GaitPlan) -> None:
    """Every phase's start and end configuration must be reachable (IK), else name ``step``."""
    robot = plan.robot
    bodies, feet, pitches, when = [], [], [], []
    for ph in plan.phases:
        feet_end = ph.feet_start.copy()
        if ph.leg is not None and ph.foot_end is not None:
            feet_end[ph.leg.idx] = ph.foot_end
        bodies += [ph.body_start, ph.body_end]
        feet += [ph.feet_start, feet_end]
        pitches += [ph.pitch_start, ph.pitch_end]
        when += [ph, ph]
    body_arr, feet_arr = np.array(bodies), np.array(feet)
    rots = _rotations(np.array(pitches))
    for i, leg in enumerate(LEGS):
        p_leg = _to_body(rots, feet_arr[:, i] - body_arr) - robot.hip_offset(leg)
        try:
            leg_ik(robot, p_leg, leg)
        except InputError as exc:
            k = next(k for k in range(len(when)) if _unreachable(robot, p_leg[k], leg))
            ph = when[k]
            raise InputError(
                "step",
                f"{plan.params.step:.3f} m",
                f"a step whose body shifts stay in the leg workspace ({ph.kind.value} at "
                f"t={ph.t0:.2f} s: {exc.field} expected {exc.expected})",
            ) from None


def _rotations(pitch: FloatArray) -> FloatArray:
    """Body rotations of nose-up pitches (T,): shape (T, 3, 3) (rotations about y by -pitch)."""
    c, s = np.cos(-pitch), np.sin(-pitch)
    rot = np.zeros((pitch.shape[0], 3, 3))
    rot[:, 0, 0], rot[:, 0, 2], rot[:, 1, 1], rot[:, 2, 0], rot[:, 2, 2] = c, s, 1.0, -s, c
    return rot


def _to_body(rot: FloatArray, v: FloatArray) -> FloatArray:
    """World vectors (T, 3) in the body frames ``rot`` (T, 3, 3): ``rot[t].T @ v[t]``."""
    return np.einsum("tji,tj->ti", rot, v)


def _check_swing_clearance(plan: GaitPlan) -> None:
    """Every swing foot stays above the ground (no foot cuts a step edge), else name
    ``swing_height``."""
    ref = plan.sample(0.01, with_zmp=False)
    ground, r = plan.ground, plan.robot.foot_radius
    for i, leg in enumerate(LEGS):
        swing = np.flatnonzero(~ref.contact[:, i])
        if swing.size == 0:
            continue
        gap = ground.clearance(ref.feet[swing, i], r)
        k = int(np.argmin(gap))
        if gap[k] < -1e-6:
            raise InputError(
                "swing_height",
                f"{plan.params.swing_height:.3f} m",
                f"a swing that clears the ground: leg {leg.value} at t={ref.t[swing[k]]:.2f} s "
                f"is {-gap[k]:.3f} m too low (x = {ref.feet[swing[k], i, 0]:.3f} m)",
            )


def _unreachable(robot: QuadrupedRobot, p_leg: FloatArray, leg: Leg) -> bool:
    try:
        leg_ik(robot, p_leg, leg)
    except InputError:
        return True
    return False


def sample_plan(plan: GaitPlan, dt: float = 0.01, with_zmp: bool = True) -> GaitTrajectory:
    """Dense references of ``plan`` every ``dt`` seconds; see :meth:`GaitPlan.sample`.

    The planned ZMP uses eq. (5) with the linear and angular momentum rates of point masses at
    the trunk centre, hips and link midpoints (accelerations by central differences); link
    rotational inertia is neglected. ``z_p`` is the mean height of the stance contact points.
    """
    dt = positive("dt", dt)
    robot = plan.robot
    t = np.arange(0.0, plan.duration + 0.5 * dt, dt)
    n = t.shape[0]
    body = np.empty((n, 3))
    pitch = np.empty(n)
    feet = np.empty((n, 4, 3))
    contact = np.ones((n, 4), dtype=bool)
    phase_idx = np.empty(n, dtype=int)
    starts = np.array([p.t0 for p in plan.phases])
    idx = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(plan.phases) - 1)
    for k, ph in enumerate(plan.phases):
        sel = np.flatnonzero(idx == k)
        if sel.size == 0:
            continue
        phase_idx[sel] = k
        tau = np.clip((t[sel] - ph.t0) / ph.duration, 0.0, 1.0)
        s = _quintic(tau)[:, None]
        body[sel] = ph.body_start + s * (ph.body_end - ph.body_start)
        pitch[sel] = ph.pitch_start + s[:, 0] * (ph.pitch_end - ph.pitch_start)
        feet[sel] = ph.feet_start
        if ph.kind is PhaseKind.SWING and ph.leg is not None and ph.foot_end is not None:
            i = ph.leg.idx
            chord = ph.foot_end - ph.feet_start[i]
            profile = SwingProfile(
                float(np.linalg.norm(chord)), plan.params.swing_height, ph.duration
            )
            mid = 0.5 * (ph.feet_start[i] + ph.foot_end)
            # eq. (13): {G} origin = centre of the step expressed in the leg frame; {G}'s x axis
            # along the step (the slope beta_S on the document's plane), beta_Delta = its angle
            # above the body's
            origin = foot_in_leg_frame(robot, ph.leg, ph.body_start, ph.pitch_start, mid)
            beta_delta = _step_angle(plan, chord) - ph.pitch_start
            p_leg = swing_in_leg_frame(profile, t[sel] - ph.t0, beta_delta, origin)
            rot = body_rotation(ph.pitch_start)
            feet[sel, i] = ph.body_start + (robot.hip_offset(ph.leg) + p_leg) @ rot.T
            contact[sel, i] = False
    joints = np.empty((n, 12))
    rots = _rotations(pitch)
    for i, leg in enumerate(LEGS):
        p_leg = _to_body(rots, feet[:, i] - body) - robot.hip_offset(leg)
        joints[:, 3 * i : 3 * i + 3] = leg_ik(robot, p_leg, leg)
    com, zmp, margin = _com_and_zmp(plan, t, body, pitch, feet, contact, joints, with_zmp)
    return GaitTrajectory(t, body, pitch, feet, contact, joints, com, zmp, margin, phase_idx)


def _step_angle(plan: GaitPlan, chord: FloatArray) -> float:
    """Angle of a step above the horizontal [rad]: the slope beta_S itself on the document's
    plane, the chord's elevation on other grounds."""
    if plan.params.ground is None:
        return plan.posture.slope
    return math.atan2(float(chord[2]), float(np.hypot(chord[0], chord[1])))


def _point_masses(
    plan: GaitPlan, body: FloatArray, pitch: FloatArray, joints: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Point masses (trunk, per leg ab/ad link/thigh/shank, each at its centre of mass),
    positions shape (T, 13, 3), masses (13,)."""
    robot = plan.robot
    rot = _rotations(pitch)
    n = body.shape[0]
    pos = np.empty((n, 13, 3))
    masses = np.empty(13)
    pos[:, 0] = body + rot @ np.asarray(robot.body_com)
    masses[0] = robot.body_mass
    for i, leg in enumerate(LEGS):
        local = leg_mass_points(robot, joints[:, 3 * i : 3 * i + 3], leg)
        pos[:, 1 + 3 * i : 4 + 3 * i] = body[:, None, :] + np.einsum(
            "tij,tkj->tki", rot, local + robot.hip_offset(leg)
        )
        masses[1 + 3 * i : 4 + 3 * i] = robot.leg_geometry(leg).masses
    return pos, masses


def _com_and_zmp(
    plan: GaitPlan,
    t: FloatArray,
    body: FloatArray,
    pitch: FloatArray,
    feet: FloatArray,
    contact: NDArray[np.bool_],
    joints: FloatArray,
    with_zmp: bool,
) -> tuple[FloatArray, FloatArray, FloatArray]:
    pos, masses = _point_masses(plan, body, pitch, joints)
    total = float(masses.sum())
    com = np.einsum("tkj,k->tj", pos, masses) / total
    n = t.shape[0]
    if not with_zmp or n < 3:
        return com, np.full((n, 2), np.nan), np.full(n, np.nan)
    dt = float(t[1] - t[0])
    acc = np.gradient(np.gradient(pos, dt, axis=0), dt, axis=0)
    p_dot = np.einsum("tkj,k->tj", acc, masses)
    l_dot = np.einsum("tkj,k->tj", np.cross(pos, acc), masses)
    zmp = np.empty((n, 2))
    margin = np.empty(n)
    # within a phase the stance feet do not move, so one polygon and one z_p serve the phase
    phase = np.searchsorted([p.t0 for p in plan.phases], t, side="right") - 1
    for k in range(len(plan.phases)):
        sel = np.flatnonzero(phase == k)
        if sel.size == 0:
            continue
        stance = np.flatnonzero(contact[sel[0]])
        pts = np.array([plan.contact_point(feet[sel[0], i]) for i in stance])
        z_p = float(pts[:, 2].mean())
        zmp[sel] = zmp_from_momentum(total, com[sel], p_dot[sel], l_dot[sel], z_p)
        margin[sel] = stability_margins(zmp[sel], support_polygon(pts))
    return com, zmp, margin


__all__ = [
    "GaitParams",
    "GaitPhase",
    "GaitPlan",
    "GaitTrajectory",
    "PhaseKind",
    "check_reachability",
    "largest_step",
    "plan_gait",
    "sample_plan",
]
