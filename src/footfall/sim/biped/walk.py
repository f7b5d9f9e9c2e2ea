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

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import expm

from footfall._geometry import inset_polygon
from footfall._typing import FloatArray
from footfall._validate import non_negative, positive
from footfall.control.mpc import MPC, MPCWeights, build_mpc
from footfall.errors import FootfallError, InputError
from footfall.models.alip import ALIP
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped import names as nm
from footfall.sim.biped.model import (
    U_MAX_FOOT_SHARE,
    BipedModel,
    BipedSimSettings,
    WalkerModel,
    measure_model,
    require_mujoco,
)
from footfall.sim.biped.terrain_mjcf import terrain_xml
from footfall.sim.pushes import Push
from footfall.terrain.edges import inset_riser_edges
from footfall.terrain.region import Region
from footfall.terrain.scene import Scene

#: a foot is loaded when its contact force exceeds this share of the weight
CONTACT_FORCE_SHARE = 0.02
#: the robot has fallen when the pelvis is lower than this share of its nominal height above the
#: stance sole ...
FALL_HEIGHT_SHARE = 0.6
#: ... or the torso tilts more than this [rad], or the pelvis or torso touches the terrain
FALL_TILT = math.radians(40.0)
#: the CoP counts as "at the edge" of the sole (the foot starts to tip) within this distance [m]
EDGE_TOL = 0.005
#: the goal is reached when the final feet midpoint is this close to it in plan view [m]
GOAL_TOL = 0.10
#: video frame rate [1/s]
VIDEO_FPS = 30
#: extra footsteps after the plan's last one, onto the plan's final footholds (the goal stance),
#: corrected by foot placement toward zero momentum: they absorb the momentum the walk ends with
#: and finish a walk whose last steps the MPC shortened (discrete_steps, smallest N = 15 with 64
#: heading segments: 0.139 m short of the goal with none, 0.029 m with 2; flat_long N = 20:
#: 0.004 / 0.024 m, both at the goal)
STOP_STEPS = 2
#: a plan's robot mass and CoM height may differ this much (relative) from the walker model's
#: (:func:`~footfall.sim.biped.model.planner_params` measures them: 0.0 exactly)
PLAN_ROBOT_RTOL = 0.01
#: sole-pose and CoM costs of the inverse kinematics: the feet must be where they are (the stance
#: foot cannot move), the CoM is the ALIP's; torso and posture are secondary
FOOT_POSITION_COST = 10.0
FOOT_ORIENTATION_COST = 5.0
COM_COST = 10.0
TORSO_ORIENTATION_COST = 2.0
POSTURE_COST = 0.05
#: cost of keeping a joint that is not position servoed at its measured angle
HOLD_COST = 100.0
#: Levenberg-Marquardt style damping of the IK QP
IK_DAMPING = 1e-3
#: positions of the ankle joints in ``LEG_JOINTS``
ANKLE_PITCH, ANKLE_ROLL = 4, 5
#: damping of a torque-driven ankle [N m s / rad]
ANKLE_TORQUE_DAMPING = 0.5
#: share of the sole's contact rectangle the commanded ankle torque may use (CoP margin)
SOLE_TORQUE_SHARE = 0.9
#: corrected footsteps stay this far inside the reach trapezoid [m]; the planners use its
#: boundary (the first lateral step of the reactive plan lies on it), so no margin
REACH_MARGIN = 0.0
#: landing error [m] the walk leaves room for at riser edges (:mod:`footfall.terrain.edges`):
#: landings fall 2-4 cm short of their targets, and on stairs_slope_gap a heel that landed on the
#: edge of the tread above (step down from ``top``, footstep 0.10 m from the riser) tipped the foot
RISER_LANDING_TOLERANCE = 0.04


# ============================================================================= options
@dataclass(frozen=True)
class WalkOptions:
    """Options of the walking controller.

    Attributes:
        control_dt: control period (measurement, adjuster, reference, IK) [s]; a multiple of the
            physics step.
        ik_iterations: differential-IK QP solves per control tick.
        swing_clearance: height of the swing sole above the highest region it passes over [m].
        heel_strike: the swing sole turns toe-up by this angle [rad] about its lateral axis
            (relative to lying flat on the landing region) as it moves, so it touches down heel
            first and the limp ankle (``passive_landing``) lets it roll flat; beyond the document.
            Landing flat, the sole met the ground toe-first (about 1 deg toe-down from the IK's
            lag) and stayed on its toe through double support: the CoP sat at the toe for the
            first 1-3 ticks of the next single support, costing 0.03-0.09 m/s of walking speed
            per step, and on stairs_slope_gap (N = 15, one footstep per tread) the robot stalled
            on stair2 and fell. With 1.5-4 deg it walks to the goal (1 deg falls). The angle
            trades against push recovery on discrete_steps N = 18 (seeded 20 N pushes: 0 deg
            23/24, 1.5 deg 24/24, 2.5 deg 19/24; 30 N: 8/12 at 1.5 deg, 12/12 before any); 1.5 deg
            kept the unpushed battery (discrete_steps N = 16/18/20, flat_long, flat) at the goal.
            0 = land flat.
        swing_side_gap: the swing sole passes the stance sole at least this far apart sideways
            [m]: their centres at least the sole width plus this (:func:`swing_bow`; beyond the
            document). 0 = straight swing paths.
        com_feedback: share in [0, 1] by which the ALIP reference is pulled toward the measured
            state every tick: 0 tracks the planned CoM motion stiffly (the ankle absorbs every
            error), 1 lets the CoM move as an ALIP from the measured state (errors are corrected
            only by foot placement and torque).
        settle_time: standing time before the CoM shifts over the first stance foot [s].
        shift_time: duration of that shift [s].
        stop_time: time to bring the CoM to the middle of the final feet after the last step [s].
        hold_time: standing time at the end [s].
        pushes: external pushes.
        stop_steps: stopping steps after the plan (:func:`extend_plan`); the adjuster must
            answer for phases up to ``N + stop_steps - 1`` (:class:`PlanFollower` does).
        com_gain: gain of the CoM tracking feedback: the IK's CoM target is the reference plus
            ``com_gain`` times the horizontal tracking error. Without it the joint servos'
            compliance lets a robot standing on one foot roll slowly over it.
        ankle_torque: in single support, drive the stance ankle (pitch and roll) with the ALIP
            torque instead of a position servo: the sole then lies flat whatever the body does and
            the CoP is the commanded torque over the weight (the ALIP input, eq. 5.3); the CoM
            moves as the pendulum it is, with the reference following the measured state
            (``com_feedback`` = 1 and no ``com_gain`` in single support). False: every joint is
            position-servoed and the ankle torque is whatever tracking the CoM reference needs.
        true_momentum: give the adjuster the true angular momentum about the stance point
            (``L_G + m (c - p) x v``, Gong & Grizzle) instead of ``m z_H (-v_y, v_x)`` from the
            CoM velocity. Default True: with the MPC it lowered the mean single-support ZMP
            offset on flat ground (20 x 0.2 m: 0.042 -> 0.027 m) and kept the 0.33 m steps of
            the ``flat`` scene from falling.
        stop_on_fall: end the simulation when a fall is detected.
        landing_margin: the walker's MPC keeps each footstep this much further inside its region
            than the plan did (its ``region_margin``, half the sole length for
            :func:`footfall.experiments.compare_mujoco.plan_for_walk`) [m]: landings fall ~2 cm short of
            their targets, and a heel over a block's edge on a step down tipped the landing foot.
        riser_tolerance: the MPC keeps each footstep in its region with the riser edges moved
            in by :func:`footfall.terrain.edges.inset_riser_edges` with this landing tolerance
            [m] (on top of ``region_margin`` + ``landing_margin``), as
            :func:`footfall.experiments.compare_mujoco.plan_for_walk` plans; 0 = the regions as they are.
            Without it the MPC moved the footstep below ``top``'s riser of stairs_slope_gap
            (N = 15) from the plan's 0.147 m to 0.12 m from the riser, the heel landed on the
            riser edge and the robot fell at 6.4 s (8 steps); with it, at 7.5 s (10 steps).
        passive_landing: the swing ankle goes limp (torque mode, zero torque) from the first
            contact of the swing sole during its descent until the double support, where the
            landing ankle is passive anyway. A position-servoed ankle (5000 N m / rad) met the
            ground on the toe (0.6 deg off flat) and held the foot's angle: 900 N on the toe for
            20 ms lifted the robot (CoM vertical velocity -0.02 -> +0.29 m/s), both feet left the
            ground for 30-50 ms and the landing lost 10-20 % of the angular momentum about the new
            foot (flat, 0.33 m steps: 0.22 m short of the goal before, 0.05 m after). See
            :attr:`MPCAdjuster.hold_frozen` for what the two did together.
        closed_loop_ik: start the IK from the measured configuration every tick, so the torso
            orientation, the CoM height and the swing foot are fed back through the joint
            servos; a torque-driven stance ankle is held at its measured angles and its sole at
            its measured pose, leaving the horizontal CoM to the pendulum and the adjuster.
            False: the IK integrates its own kinematic copy (open loop; the robot fell within a
            few steps on every scene).
        check_robot: refuse a plan whose robot mass or CoM height differs by more than
            ``PLAN_ROBOT_RTOL`` from the walker model's (:func:`planner_params`): its ALIP motion
            is then another pendulum's. False walks such a plan on purpose (a mismatch study).
    """

    control_dt: float = 0.01
    ik_iterations: int = 2
    swing_clearance: float = 0.05
    swing_side_gap: float = 0.03
    heel_strike: float = math.radians(1.5)
    com_feedback: float = 0.0
    settle_time: float = 0.3
    shift_time: float = 2.0
    stop_time: float = 1.0
    hold_time: float = 0.5
    pushes: tuple[Push, ...] = ()
    stop_steps: int = STOP_STEPS
    com_gain: float = 1.5
    ankle_torque: bool = True
    true_momentum: bool = True
    stop_on_fall: bool = True
    closed_loop_ik: bool = True
    landing_margin: float = 0.02
    riser_tolerance: float = RISER_LANDING_TOLERANCE
    passive_landing: bool = True
    check_robot: bool = True

    def __post_init__(self) -> None:
        for name in ("control_dt", "swing_clearance", "shift_time", "stop_time"):
            object.__setattr__(self, name, positive(name, getattr(self, name)))
        for name in (
            "settle_time",
            "hold_time",
            "com_gain",
            "landing_margin",
            "swing_side_gap",
            "heel_strike",
            "riser_tolerance",
        ):
            object.__setattr__(self, name, non_negative(name, getattr(self, name)))
        fb = non_negative("com_feedback", self.com_feedback)
        if fb > 1.0:
            raise InputError("com_feedback", self.com_feedback, "a share in [0, 1]")
        object.__setattr__(self, "com_feedback", fb)
        it = self.ik_iterations
        if isinstance(it, bool) or not isinstance(it, int) or it < 1:
            raise InputError("ik_iterations", it, "an integer >= 1")
        pushes = tuple(self.pushes)
        for i, p in enumerate(pushes):
            if not isinstance(p, Push):
                raise InputError(f"pushes[{i}]", p, "a Push")
        object.__setattr__(self, "pushes", pushes)


# ============================================================================= adjuster
class FootstepAdjuster(Protocol):
    """Source of the next footstep and the ankle torque, called once per control tick.

    This is where the MPC of document 000 eq. (5.19) plugs in: it receives the measured ALIP state
    of the current single support and returns the (re-optimised) next footstep and the torque to
    apply now.
    """

    def update(
        self, t: float, state: FloatArray, stance: FloatArray, phase: int
    ) -> tuple[FloatArray, FloatArray]:
        """One control tick.

        Args:
            t: time since the start of single-support phase ``phase`` [s], in [0, T_ss).
            state: measured ALIP state ``[x_c, y_c, L_x, L_y]`` (4,) relative to the stance
                sole centre [m, m, kg m^2/s, kg m^2/s] (eq. 5.1).
            stance: measured stance sole centre (3,) [m], world frame.
            phase: single-support phase index i (stance on footstep i of the plan).

        Returns:
            ``(next_footstep (3,) [m] world, ankle torque (2,) [N m])`` with the torque in the
            ALIP convention (ground on robot, ZMP = stance + (-tau_y, tau_x) / (m g)).
        """
        ...


def extend_plan(plan: FootstepPlan, extra: int = STOP_STEPS) -> FootstepPlan:
    """``plan`` with ``extra`` stopping steps appended (each foot steps onto its last foothold).

    Their ALIP states and torques are zero (the CoM at rest over the stance foot): as a foot
    placement reference this asks to end the next phase with zero momentum, i.e. to capture the
    remaining motion.
    """
    if extra <= 0:
        return plan
    n = plan.n_steps
    idx = [n - 1 + (j % 2) for j in range(extra)]
    k = plan.states.shape[1]
    return replace(
        plan,
        footsteps=np.vstack([plan.footsteps, plan.footsteps[idx]]),
        headings=np.concatenate([plan.headings, plan.headings[idx]]),
        sides=plan.sides + tuple(plan.sides[i] for i in idx),
        regions=plan.regions + tuple(plan.regions[i] for i in idx),
        states=np.concatenate([plan.states, np.zeros((extra, k, 4))]),
        torques=np.concatenate([plan.torques, np.zeros((extra, k - 1, 2))]),
    )


def _point_in_region(region: Region, xy: FloatArray, margin: float) -> bool:
    return float(region.signed_distance(xy)) <= -margin


@dataclass
class PlanFollower:
    """Built-in source: the plan's footsteps and ALIP torques plus one-step foot placement.

    The torque is the plan's zero-order-hold torque of the current node interval (eq. 5.12b). The
    footstep correction is the one-step ALIP foot placement of Gong & Grizzle: the measured state
    is predicted to the end of the phase with the planned torques, and the next footstep moves by
    the ``dp`` that cancels the resulting angular-momentum error at the end of the *next* single
    support (through the reset map, eq. 5.10: ``L`` after the next phase is linear in ``dp``).
    The corrected footstep is kept inside the planned region (``region_margin`` from its edges),
    its height is that region's plane, and it is frozen for the last ``1 - freeze_after`` of the
    swing so the landing is not chased.

    Attributes:
        plan: the footstep plan.
        regions: the scene's regions by name.
        gain: share of the computed correction that is applied (0 = follow the plan exactly).
        max_correction: bound on the correction's length [m].
        region_margin: the corrected footstep stays this far inside its region [m].
        freeze_after: phase share after which the footstep is frozen.
        dcm_gain: gain of the capture-point feedback on the ZMP (0 = planned torque only).
        stop_steps: stopping steps appended to the plan (:func:`extend_plan`); the walker asks
            for phases up to ``N + stop_steps - 1``.
        capture_stop: place the final footstep by the capture point (:meth:`stop_target`)
            instead of the plan's: the walk must end with the divergent component of motion
            between the feet, whatever the plan's final state was.
        limit_reach: project every corrected footstep into the reach trapezoid (the capture-point
            final step always is, so the robot ends in a legal stance). Off by default:
            on flat ground (five goals, issue 7 note) it lowered the share of walks without a
            fall from 2/5 to 1/5, because this walker's lateral recovery needs steps narrower
            than the trapezoid's 0.12 m minimum width.
        reach_margin: with ``limit_reach``, every corrected footstep stays this far inside the reach trapezoid of the
            measured stance foot (``BipedParams.reach``) [m].
    """

    plan: FootstepPlan
    regions: dict[str, Region]
    gain: float = 1.0
    max_correction: float = 0.12
    region_margin: float = 0.05
    freeze_after: float = 0.7
    dcm_gain: float = 2.5
    stop_steps: int = STOP_STEPS
    capture_stop: bool = True
    limit_reach: bool = False
    reach_margin: float = REACH_MARGIN
    _frozen: dict[int, FloatArray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        self.plan = extend_plan(self.plan, self.stop_steps)
        robot = self.plan.robot
        self._alip = robot.alip()
        self._dt = robot.node_dt
        self._ad, self._bd = self._alip.discretize(self._dt)
        a_r, b_r = self._alip.reset_map(robot.t_ds)
        ad_ss = np.linalg.matrix_power(self._ad, robot.n_nodes - 1)
        self._to_next_end = ad_ss @ a_r  # end-of-phase state -> end of next phase (dp = 0)
        self._dp_to_next_end = (ad_ss @ b_r)[2:4, 0:2]  # dp (x, y) -> L at end of next phase
        self._dp_inv = np.linalg.inv(self._dp_to_next_end)

    def torque(self, t: float, phase: int) -> FloatArray:
        """Planned torque (2,) [N m] of ``phase`` at time ``t`` in it (zero-order hold)."""
        k = min(int(t / self._dt), self.plan.torques.shape[1] - 1)
        return np.array(self.plan.torques[phase, k])

    def predict_end(self, t: float, state: FloatArray, phase: int) -> FloatArray:
        """Measured ``state`` at ``t`` propagated to the end of the phase with planned torques."""
        k = min(int(t / self._dt), self.plan.torques.shape[1] - 1)
        # partial interval first, then the remaining whole node intervals
        rest = (k + 1) * self._dt - t
        a_p, b_p = self._alip.discretize(rest) if rest > 1e-9 else (np.eye(4), np.zeros((4, 2)))
        x = a_p @ state + b_p @ self.plan.torques[phase, k]
        for j in range(k + 1, self.plan.torques.shape[1]):
            x = self._ad @ x + self._bd @ self.plan.torques[phase, j]
        return np.asarray(x)

    def planned_state(self, t: float, phase: int) -> FloatArray:
        """The plan's ALIP state (4,) at ``t`` in ``phase`` (exact ZOH from the previous node)."""
        k = min(int(t / self._dt), self.plan.torques.shape[1] - 1)
        a_p, b_p = self._alip.discretize(max(t - k * self._dt, 1e-9))
        return np.asarray(a_p @ self.plan.states[phase, k] + b_p @ self.plan.torques[phase, k])

    def dcm_torque(self, t: float, state: FloatArray, phase: int) -> FloatArray:
        """Planned torque plus divergent-component-of-motion feedback (capture point tracking).

        With ``xi = c + v / omega`` the ALIP obeys ``xi' = omega (xi - zmp)``; the ZMP command
        ``zmp_plan + dcm_gain (xi - xi_plan)`` makes the error decay as
        ``exp(omega (1 - dcm_gain) t)``.
        """
        u = self.torque(t, phase)
        if self.dcm_gain <= 0.0:
            return u
        omega = self._alip.omega
        ref = self.planned_state(t, phase)
        xi = state[:2] + self._alip.velocity(state) / omega
        xi_ref = ref[:2] + self._alip.velocity(ref) / omega
        zmp = self._alip.zmp(np.zeros(2), u) + self.dcm_gain * (xi - xi_ref)
        return np.asarray(self._alip.torque_for_zmp(zmp))

    def update(
        self, t: float, state: FloatArray, stance: FloatArray, phase: int
    ) -> tuple[FloatArray, FloatArray]:
        """See :class:`FootstepAdjuster`."""
        plan = self.plan
        ref_next = np.array(plan.footsteps[phase + 1])
        u = self.dcm_torque(t, state, phase)
        if phase in self._frozen:
            return self._frozen[phase], u
        # the plan's footstep relative to where the stance foot really is
        target = ref_next.copy()
        if self.capture_stop and phase == plan.n_steps - 1:
            target[:2] = self.stop_target(t, state, stance, phase, u)
            target = self._limit_reach(target, stance, phase)
            target = self._clamp_to_region(target, ref_next, plan.regions[phase + 1])
        elif self.gain > 0.0:
            x_end = self.predict_end(t, state, phase)
            err = self._to_next_end @ (x_end - plan.states[phase, -1])
            # The reset acts on the step p_{i+1} - p_i: if the robot stands off its planned
            # footstep by s, keeping the planned step vector needs dp = s. The foot-placement
            # term then cancels the angular-momentum error at the end of the next phase.
            shift = (stance - plan.footsteps[phase])[:2]
            fb = -self.gain * (self._dp_inv @ err[2:4])
            norm = float(np.linalg.norm(fb))
            if norm > self.max_correction:
                fb *= self.max_correction / norm
            target[:2] = ref_next[:2] + shift + fb
            target = self._legal(target, ref_next, stance, phase)
        return self._maybe_freeze(t, phase, target), u

    def _legal(
        self, target: FloatArray, ref_next: FloatArray, stance: FloatArray, phase: int
    ) -> FloatArray:
        """``target`` in the reach trapezoid (with ``limit_reach``) and in its planned region."""
        if self.limit_reach:
            target = self._limit_reach(target, stance, phase)
        return self._clamp_to_region(target, ref_next, self.plan.regions[phase + 1])

    def _maybe_freeze(self, t: float, phase: int, target: FloatArray) -> FloatArray:
        """Freeze the footstep of ``phase`` once ``t`` passes ``freeze_after`` of T_ss."""
        if t >= self.freeze_after * self.plan.robot.t_ss:
            self._frozen[phase] = target
        return target

    def stop_target(
        self, t: float, state: FloatArray, stance: FloatArray, phase: int, u: FloatArray
    ) -> FloatArray:
        """Final footstep (x, y) [m] that leaves the capture point midway between the feet.

        The measured state is propagated to the end of the phase with the torque ``u`` of this
        tick held (the ankle's, clipped to the sole). In the following double support the
        contact point moves linearly from the stance foot to the new foot ``d`` away (eq. 5.8);
        the divergent component ``xi = c + v / omega`` then ends at
        ``e^(w) xi_0 - d (e^(w) - 1 - w) / w`` with ``w = omega T_ds``. Asking it to end at the
        feet's midpoint ``d / 2`` gives ``d``: the robot can then shift its CoM between its feet
        and stand.
        """
        robot = self.plan.robot
        alip = self._alip
        sole_half = SOLE_TORQUE_SHARE * np.array([robot.foot_length / 2, robot.foot_width / 2])
        zmp = np.clip(alip.zmp(np.zeros(2), u), -sole_half, sole_half)
        u_hold = alip.torque_for_zmp(zmp)
        rest = max(robot.t_ss - t, 0.0)
        a_p, b_p = alip.discretize(rest) if rest > 1e-9 else (np.eye(4), np.zeros((4, 2)))
        x_end = a_p @ state + b_p @ u_hold
        xi = x_end[:2] + alip.velocity(x_end) / alip.omega
        w = alip.omega * robot.t_ds
        d = math.exp(w) * xi / (0.5 + (math.exp(w) - 1.0 - w) / w)
        return np.asarray(stance[:2] + d)

    def _limit_reach(self, target: FloatArray, stance: FloatArray, phase: int) -> FloatArray:
        """``target`` moved into the reach trapezoid of the measured stance foot (eq. 5.12f)."""
        robot = self.plan.robot
        side = self.plan.sides[phase]
        rot = _rot2(float(self.plan.headings[phase]))
        q = rot.T @ (target[:2] - stance[:2])
        poly = shrink_polygon(robot.reach.for_stance(side), self.reach_margin)
        q = project_to_polygon(q, poly)
        out = np.array(target, dtype=float)
        out[:2] = stance[:2] + rot @ q
        return out

    def _clamp_to_region(self, target: FloatArray, ref: FloatArray, name: str) -> FloatArray:
        region = self.regions.get(name)
        if region is None:
            return ref
        xy = target[:2]
        if not _point_in_region(region, xy, self.region_margin):
            if not _point_in_region(region, ref[:2], self.region_margin):
                # the plan's own footstep is nearer the edge than the margin: the nearest point
                # of the region moved in by the margin (the plan's footstep if there is none)
                inner = inset_polygon(region.vertices, self.region_margin)
                if inner is None:
                    return ref
                xy = project_to_polygon(xy, inner)
                return np.array([xy[0], xy[1], float(region.height_at(xy))])
            # bisect on the segment from the planned footstep (inside) to the corrected one
            lo, hi = 0.0, 1.0
            for _ in range(20):
                mid = 0.5 * (lo + hi)
                if _point_in_region(region, ref[:2] + mid * (xy - ref[:2]), self.region_margin):
                    lo = mid
                else:
                    hi = mid
            xy = ref[:2] + lo * (xy - ref[:2])
        return np.array([xy[0], xy[1], float(region.height_at(xy))])


@dataclass
class MPCAdjuster(PlanFollower):
    """The MPC of document 000 eq. (5.19) as the walking controller's footstep / torque source.

    Every control tick of a single support it solves eq. (5.19) from the measured ALIP state:
    the remaining ankle torques and the next footstep, tracking the plan's next footstep (W) and
    the plan's state after the next reset (Q_f). The footstep is then kept in its planned region
    and frozen late in the swing as for :class:`PlanFollower` (whose helpers it reuses); the
    torque of the current tick is applied by the stance ankle.

    Attributes:
        control_dt: the walker's control period [s] (the MPC runs once per tick).
        weights: MPC weights.
        freeze_after: as for :class:`PlanFollower`, later by default: on flat ground
            (20 x 0.2 m) freezing at 0.7 T_ss left every footstep short and the robot 0.6 m
            from the goal; at 0.9 it reached it with a 0.014 m mean footstep error.
        capture_stop: off: the MPC's terminal term (Q_f toward the plan's final state at rest)
            places the last footstep.
        torque_limits: semi-axes ``(U_x, U_y)`` [N m] of the MPC's torque ellipse
            (:func:`footfall.control.mpc.build_mpc`); None = the plan's ``U_max`` ball
            (eq. 5.19e). :func:`walk` passes :func:`sole_torque_limits`.
        hold_frozen: once the footstep is frozen, keep applying the torque of the solution it
            was frozen with (the MPC's torque block is the plan's node interval, 0.1 s, so that
            solution already holds one torque for the rest of the single support) instead of
            re-solving. Re-solving with the footstep free returned torques for a footstep the
            swing foot no longer went to (on discrete_steps N = 20 the stance ankle torque
            jumped from -14.6 to +5.1 N m at the first frozen tick before a step down).
            Re-solving with the footstep fixed there is consistent but, with 1-4 ticks left,
            the torque barely moves the state and the solve spends the whole ellipse on it: a
            CoP command of -0.064 m at the last tick (measured -0.019 m), which the double
            support's rear-ankle ramp then held at the heel edge. Holding, together with
            :attr:`WalkOptions.passive_landing`, reached 5 goals in the battery of cached-plan
            walks (discrete_steps N = 13/16/18/20, flat_long, flat, turn; 2 before) and 24 of 24
            seeded 20 N pushes on discrete_steps N = 18 (19 before); re-solving with the
            footstep fixed reached 5 goals but 19 of 24.
        footstep_in_region: solve the MPC with the next footstep kept in its planned region
            (``region_margin`` inside, :meth:`footfall.control.mpc.MPC.solve_in_polygon`)
            instead of clamping the document's unconstrained footstep afterwards, so the ankle
            torque makes up for a correction the region does not allow.
    """

    control_dt: float = 0.01
    freeze_after: float = 0.9
    weights: MPCWeights = field(default_factory=MPCWeights)
    capture_stop: bool = False
    torque_limits: tuple[float, float] | None = None
    footstep_in_region: bool = True
    hold_frozen: bool = True
    mpc: MPC = field(init=False, repr=False)
    _frozen_torque: dict[int, FloatArray] = field(default_factory=dict, repr=False)

    def __post_init__(self) -> None:
        super().__post_init__()
        mdl = build_mpc(self.plan.robot, self.weights, self.control_dt, None, self.torque_limits)
        self.mpc = MPC(mdl)

    def update(
        self, t: float, state: FloatArray, stance: FloatArray, phase: int
    ) -> tuple[FloatArray, FloatArray]:
        """See :class:`FootstepAdjuster`."""
        plan = self.plan
        mdl = self.mpc.model
        k_s = min(max(round(t / mdl.control_dt), 0), mdl.n_ticks - 1)
        ref_next = np.array(plan.footsteps[phase + 1])
        x_next = plan.states[phase + 1, 0] if phase + 1 < plan.n_steps else plan.final_state
        # Solve in the stance foot's heading frame: the ALIP and the cost are isotropic, so this
        # changes nothing but the orientation of the torque ellipse, whose long axis must lie
        # along the sole.
        rot = _rot2(float(plan.headings[phase]))
        rot4 = np.kron(np.eye(2), rot)
        region = self.regions.get(plan.regions[phase + 1])
        args = (
            k_s,
            rot4.T @ state,
            _rotate_xy(rot.T, stance),
            _rotate_xy(rot.T, ref_next),
            rot4.T @ x_next,
        )
        if phase in self._frozen and self.hold_frozen:
            return self._frozen[phase], self._frozen_torque[phase]
        if self.footstep_in_region and region is not None and phase not in self._frozen:
            a, b = region.halfspaces()
            sol = self.mpc.solve_in_polygon(*args, a @ rot, b - self.region_margin)
        else:
            sol = self.mpc.solve(*args)
        u = rot @ sol.torques[0]
        if phase in self._frozen:
            return self._frozen[phase], u
        if self.capture_stop and phase == plan.n_steps - 1:
            target = np.array(ref_next)
            target[:2] = self.stop_target(t, state, stance, phase, u)
        else:
            target = _rotate_xy(rot, sol.next_footstep)
        target = self._legal(target, ref_next, stance, phase)
        target = self._maybe_freeze(t, phase, target)
        if phase in self._frozen:
            self._frozen_torque[phase] = u
        return target, u


def _rot2(theta: float) -> FloatArray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def _rotate_xy(rot: FloatArray, p: FloatArray) -> FloatArray:
    """``p`` (3,) with its horizontal part multiplied by ``rot`` (2, 2); height unchanged."""
    out = np.array(p, dtype=float)
    out[:2] = rot @ out[:2]
    return out


def sole_torque_limits(robot: BipedParams) -> tuple[float, float]:
    """Ankle torque semi-axes ``(U_x, U_y)`` [N m] that keep the CoP on the sole.

    ``U_MAX_FOOT_SHARE`` of the weight times half the sole width (roll torque ``u_x`` moves the
    CoP across the foot) and half the sole length (pitch torque ``u_y`` moves it along). The
    planner keeps the document's smaller ball ``U_max`` (a cost on torque as much as a limit);
    the walker's MPC may use the sole's length.
    """
    weight = U_MAX_FOOT_SHARE * robot.mass * robot.g
    return (weight * robot.foot_width / 2.0, weight * robot.foot_length / 2.0)


# ============================================================================= geometry helpers
def shrink_polygon(vertices: FloatArray, margin: float) -> FloatArray:
    """Convex CCW polygon (n, 2) moved ``margin`` [m] inward toward its centroid (scaled).

    Scaling about the centroid is enough for the reach trapezoid (a small margin, a fat shape);
    a margin larger than the polygon leaves its centroid.
    """
    v = np.asarray(vertices, dtype=float)
    c = v.mean(axis=0)
    r = float(np.min(np.linalg.norm(v - c, axis=1)))
    scale = max(0.0, 1.0 - margin / r) if r > 0 else 0.0
    return np.asarray(c + (v - c) * scale)


def project_to_polygon(q: FloatArray, vertices: FloatArray) -> FloatArray:
    """Closest point (2,) of a convex CCW polygon (n, 2) to ``q`` (itself when inside)."""
    v = np.asarray(vertices, dtype=float)
    nxt = np.roll(v, -1, axis=0)
    edge = nxt - v
    # inside when left of every CCW edge
    cross = edge[:, 0] * (q[1] - v[:, 1]) - edge[:, 1] * (q[0] - v[:, 0])
    if np.all(cross >= 0.0):
        return np.array(q, dtype=float)
    best, best_d = np.array(q, dtype=float), math.inf
    for a, e in zip(v, edge, strict=True):
        s = float(np.clip((q - a) @ e / (e @ e), 0.0, 1.0))
        p = a + s * e
        dist = float(np.linalg.norm(q - p))
        if dist < best_d:
            best, best_d = p, dist
    return best


def smoothstep(s: float) -> float:
    """Quintic 0 -> 1 on [0, 1] with zero velocity and acceleration at both ends."""
    s = min(1.0, max(0.0, s))
    return s * s * s * (10.0 + s * (-15.0 + 6.0 * s))


def foot_rotation(normal: ArrayLike, heading: float) -> FloatArray:
    """Rotation (3, 3) of a sole lying on a plane with ``normal`` and pointing along ``heading``.

    Columns: the heading direction projected onto the plane, the lateral axis, the normal.
    """
    n = np.asarray(normal, dtype=float)
    h = np.array([math.cos(heading), math.sin(heading), 0.0])
    x = h - (h @ n) * n
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(n, x), n])


def swing_reference(
    tau: float,
    start: FloatArray,
    target: FloatArray,
    apex: float,
    rise: float = 0.35,
    descend: float = 0.65,
    stance: FloatArray | None = None,
    side_clearance: float = 0.0,
) -> tuple[FloatArray, float]:
    """Swing sole position (3,) [m] at phase share ``tau`` and the horizontal progress in [0, 1].

    The sole rises to ``apex`` in the first ``rise`` share of the swing, moves horizontally during
    ``SWING_MOVE`` and descends from the ``descend`` share on, so it crosses every step edge at
    the apex height; every profile is a quintic smoothstep (zero velocity at lift-off and
    touchdown). With the ``stance`` sole centre (3,) [m] the horizontal path bows sideways, away
    from it, so that it passes the stance sole centre at least ``side_clearance`` [m] apart
    (:func:`swing_bow`; beyond the document).
    """
    s_h = smoothstep((tau - SWING_MOVE[0]) / (SWING_MOVE[1] - SWING_MOVE[0]))
    xy = start[:2] + (target[:2] - start[:2]) * s_h
    if stance is not None and side_clearance > 0.0:
        bow, s_pass = swing_bow(start, target, stance, side_clearance)
        if s_h <= s_pass:
            w = math.sin(0.5 * math.pi * s_h / s_pass) if s_pass > 0.0 else 1.0
        else:
            w = math.sin(0.5 * math.pi * (1.0 - s_h) / (1.0 - s_pass)) if s_pass < 1.0 else 1.0
        xy = xy + bow * w
    if tau < rise:
        z = start[2] + (apex - start[2]) * smoothstep(tau / rise)
    elif tau < descend:
        z = apex
    else:
        z = apex + (target[2] - apex) * smoothstep((tau - descend) / (1.0 - descend))
    return np.array([xy[0], xy[1], z]), s_h


def swing_bow(
    start: FloatArray, target: FloatArray, stance: FloatArray, clearance: float
) -> tuple[FloatArray, float]:
    """Sideways bow of a swing path that passes the stance sole centre too closely.

    The straight horizontal path ``start -> target`` passes ``stance`` (all (2,) or (3,) [m],
    horizontal parts used) at the share ``s`` in [0, 1] of its length where ``stance`` projects
    onto it, at the distance ``d``. When ``s`` is strictly inside the path and ``d <
    clearance``, the path must move ``clearance - d`` further from ``stance`` there, along the
    path's normal pointing away from it (the swing foot's side of the path when ``stance`` lies
    on it, the left of the path).
    :func:`swing_reference` adds ``bow * w(s_h)`` with ``w`` a quarter sine rising from 0 at the
    start to 1 at ``s`` and falling back to 0 at the target, so lift-off and touchdown points are
    unchanged.

    Returns:
        ``(bow (2,) [m], s)``: the bow at its peak (zero when none is needed) and where it peaks.
    """
    p0, p1, c = (np.asarray(v, dtype=float)[:2] for v in (start, target, stance))
    e = p1 - p0
    length = float(np.linalg.norm(e))
    if length < 1e-9:
        return np.zeros(2), 0.5
    u = e / length
    s = float((c - p0) @ u) / length
    if not 0.0 < s < 1.0:
        return np.zeros(2), min(max(s, 0.0), 1.0)
    normal = np.array([-u[1], u[0]])  # left of the path
    side = float((p0 - c) @ normal)
    d = abs(side)
    if d >= clearance:
        return np.zeros(2), s
    away = normal if side >= 0.0 else -normal
    return away * (clearance - d), s


def swing_shares(rise_height: float, fall_height: float, t_ss: float) -> tuple[float, float]:
    """Rise-until and descend-from shares of a swing that lifts the sole by ``rise_height`` and
    lowers it by ``fall_height`` [m] in ``t_ss`` [s].

    Each vertical motion takes at least ``SWING_SHARES[0]`` of the swing (the sole must clear the
    ground before it moves, else it scuffs) and longer when its quintic profile's peak
    acceleration ``5.77 h / T^2`` would exceed ``SWING_ACC_MAX``, up to half the swing (a swing
    leg lifted 0.2 m within 0.14 s unloaded the stance foot on the discrete steps).
    """
    lo, hi = SWING_SHARES

    def share(h: float) -> float:
        need = math.sqrt(QUINTIC_PEAK_ACC * max(h, 0.0) / SWING_ACC_MAX) / t_ss
        return min(max(need, lo), hi)

    return share(rise_height), 1.0 - share(fall_height)


#: the horizontal swing motion runs between these shares of the swing
SWING_MOVE = (0.1, 0.9)
#: shortest and longest share of the swing for the rise (and for the descent)
SWING_SHARES = (0.35, 0.5)
#: peak vertical acceleration of the swing sole the shares aim at [m/s^2] (a 0.05 m rise in
#: 0.35 x 0.4 s needs 15)
SWING_ACC_MAX = 15.0
#: peak acceleration of the quintic smoothstep over a unit distance and duration
QUINTIC_PEAK_ACC = 10.0 / math.sqrt(3.0)


def terrain_height_along(
    regions: tuple[Region, ...],
    start: FloatArray,
    target: FloatArray,
    half_length: float,
    half_width: float,
) -> float:
    """Highest region surface under the sole swept from ``start`` to ``target`` [m].

    The swept area is approximated by the segment start -> target extended by ``half_length``
    at both ends (heel behind the start, toe beyond the target) and widened by ``half_width``
    on both sides: a region counts when a sample of the extended segment lies within
    ``half_width`` of it. (Widening by the half length as well counted blocks the toe never
    reaches: a step onto a block 0.08 m before a higher one swung 0.15 m too high, and the swing
    leg's acceleration lifted the stance foot off its block.)
    """
    d = target[:2] - start[:2]
    length = float(np.linalg.norm(d))
    u = d / length if length > 1e-9 else np.zeros(2)
    n_samples = max(16, math.ceil((length + 2.0 * half_length) / 0.01) + 1)
    pts = start[:2] + np.outer(np.linspace(-half_length, length + half_length, n_samples), u)
    best = max(float(start[2]), float(target[2]))
    for r in regions:
        near = np.asarray(r.signed_distance(pts)) <= half_width
        if np.any(near):
            best = max(best, float(np.max(r.height_at(pts[near]))))
    return best


class CoMHeight:
    """CoM height reference over the footsteps: the 3-D linear inverted pendulum's constraint planes.

    The CoM moves on the planes through the points ``P_j + (0, 0, z_H)`` above consecutive
    footsteps: between footsteps ``j`` and ``j + 1`` the plane rises with gradient
    ``g_j = (z_{j+1} - z_j) d_j / |d_j|^2`` (``d_j`` the horizontal step), level across it. Every
    plane used while standing on ``P_j`` (the one from the previous step behind the foot, the one
    to the next step ahead of it) passes through ``z_j + z_H`` above the stance foot, so the
    horizontal CoM motion is exactly the pendulum of height ``z_H`` of eq. (5.1) (Kajita et al.,
    2001: on such a plane the leg force along foot -> CoM adds no horizontal acceleration the ALIP
    does not have), and consecutive supports share the plane between their feet, so the height is
    continuous through double support. The kink above each footstep is rounded over
    ``+-kink`` [m] of progress, where the CoM is nearly above the foot and the vertical
    acceleration of the rounding hardly pushes it horizontally.

    A height that rises in *time* (from one mid single support to the next) pushes the CoM forward
    whenever it rises ahead of the stance foot: on the discrete steps the walking speed grew from
    0.62 to 1.0 m/s within two step-ups and the robot fell.
    """

    def __init__(self, footsteps: FloatArray, z_h: float, kink: float = 0.05) -> None:
        p = np.asarray(footsteps, dtype=float)
        self.points = p
        self.z_h = float(z_h)
        self.kink = float(kink)
        n = p.shape[0]
        self.grad = np.zeros((n + 1, 2))  # grad[j + 1]: plane from footstep j to j + 1
        for j in range(n - 1):
            d = p[j + 1, :2] - p[j, :2]
            d2 = float(d @ d)
            if d2 > 1e-6:
                self.grad[j + 1] = (p[j + 1, 2] - p[j, 2]) * d / d2
        self.ahead = np.zeros((n, 2))  # walking direction through each footstep
        for j in range(n):
            d = p[min(j + 1, n - 1), :2] - p[max(j - 1, 0), :2]
            norm = float(np.linalg.norm(d))
            self.ahead[j] = d / norm if norm > 1e-6 else 0.0

    def __call__(self, support: int, c_xy: ArrayLike) -> float:
        """Reference CoM height [m] while standing on footstep ``support`` (0..N; in double
        support the footstep being stepped onto) with the horizontal CoM at ``c_xy`` (2,) [m]."""
        j = min(max(support, 0), self.points.shape[0] - 1)
        r = np.asarray(c_xy, dtype=float)[:2] - self.points[j, :2]
        w = smoothstep((float(r @ self.ahead[j]) + self.kink) / (2.0 * self.kink))
        slope = (1.0 - w) * self.grad[j] + w * self.grad[j + 1]
        return float(self.points[j, 2]) + self.z_h + float(slope @ r)


# ============================================================================= the simulator
class BipedSim:
    """MuJoCo model + data of a biped on a scene's terrain, with handles resolved by name.

    ``model_params`` is any :class:`~footfall.sim.biped.model.WalkerModel`: our biped
    (:class:`BipedModel`, the default) or e.g. :class:`footfall.sim.biped.g1.G1Model`; its MJCF
    names its elements as :mod:`footfall.sim.biped.names` does. ``settings`` go to its ``mjcf``
    (None: the model's defaults).
    """

    def __init__(
        self,
        scene: Scene,
        model_params: WalkerModel | None = None,
        settings: BipedSimSettings | None = None,
    ) -> None:
        mujoco = require_mujoco()
        self.mujoco = mujoco
        self.params: WalkerModel = model_params if model_params is not None else BipedModel()
        xml = self.params.mjcf(terrain_xml(scene.terrain), settings)
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        m = self.model
        obj = mujoco.mjtObj

        def ident(kind: Any, name: str) -> int:
            i = int(mujoco.mj_name2id(m, kind, name))
            if i < 0:
                raise FootfallError(f"biped model has no element named {name!r}")
            return i

        self.pelvis = ident(obj.mjOBJ_BODY, nm.PELVIS_BODY)
        self.torso = ident(obj.mjOBJ_BODY, nm.TORSO_BODY)
        self.root_adr = int(m.jnt_qposadr[ident(obj.mjOBJ_JOINT, nm.ROOT_JOINT)])
        self.sides = (Side.LEFT, Side.RIGHT)
        self.sole_sites = {s: ident(obj.mjOBJ_SITE, nm.sole_site(s)) for s in self.sides}
        self.joint_qpos = np.array(
            [
                m.jnt_qposadr[ident(obj.mjOBJ_JOINT, nm.joint(s, j))]
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.joint_dof = np.array(
            [
                m.jnt_dofadr[ident(obj.mjOBJ_JOINT, nm.joint(s, j))]
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.actuators = np.array(
            [
                ident(obj.mjOBJ_ACTUATOR, nm.actuator(s, j))
                for s in self.sides
                for j in nm.LEG_JOINTS
            ]
        )
        self.foot_of_geom: dict[int, Side] = {}
        for s in self.sides:
            for k in range(len(nm.FOOT_CORNERS)):
                self.foot_of_geom[ident(obj.mjOBJ_GEOM, nm.corner_geom(s, k))] = s
        self.body_geoms = {
            ident(obj.mjOBJ_GEOM, nm.PELVIS_GEOM),
            ident(obj.mjOBJ_GEOM, nm.TORSO_GEOM),
        }
        self._kp = np.array(m.actuator_gainprm[self.actuators, 0])
        self._bias = np.array(m.actuator_biasprm[self.actuators, :3])
        self.mass = float(np.sum(m.body_mass))
        self.weight = self.mass * float(-m.opt.gravity[2])
        self._f6 = np.zeros(6)

    def set_standing(self, left: FloatArray, right: FloatArray, heading: float) -> None:
        """Nominal posture with the soles at ``left``/``right`` (3,) [m], then forward kinematics."""
        d = self.data
        d.qpos[:] = 0.0
        d.qvel[:] = 0.0
        mid = 0.5 * (np.asarray(left) + np.asarray(right))
        d.qpos[self.root_adr : self.root_adr + 3] = (
            mid[0],
            mid[1],
            mid[2] + self.params.pelvis_height,
        )
        d.qpos[self.root_adr + 3 : self.root_adr + 7] = (
            math.cos(heading / 2),
            0.0,
            0.0,
            math.sin(heading / 2),
        )
        q = self.params.nominal_joints()
        d.qpos[self.joint_qpos] = q
        d.ctrl[self.actuators] = q
        self.mujoco.mj_kinematics(self.model, d)
        # a model whose nominal soles are not straight below the pelvis (the G1's reach forward of
        # its ankles) is moved so that their midpoint is the feet's; ours: no shift (<= 1e-9 m)
        shift = mid - 0.5 * (self.sole(Side.LEFT)[0] + self.sole(Side.RIGHT)[0])
        if float(np.max(np.abs(shift))) > 1e-9:
            d.qpos[self.root_adr : self.root_adr + 3] += shift
        self.mujoco.mj_forward(self.model, d)

    def ankle_actuators(self, side: Side) -> NDArray[np.int_]:
        """Indices into ``actuators`` of the ``side`` ankle (pitch, roll)."""
        base = len(nm.LEG_JOINTS) * self.sides.index(side)
        return np.array([base + ANKLE_PITCH, base + ANKLE_ROLL])

    def set_ankle_torque_mode(self, side: Side, torque: bool) -> None:
        """Switch the ``side`` ankle servos to torque (ctrl = joint torque [N m]) or position mode.

        A MuJoCo position actuator is ``gain * ctrl + bias`` with gain ``kp`` and bias
        ``(0, -kp, -kv)``; torque mode is gain 1 and only a small damping ``ANKLE_TORQUE_DAMPING``.
        """
        for j in self.ankle_actuators(side):
            a = self.actuators[j]
            if torque:
                self.model.actuator_gainprm[a, 0] = 1.0
                self.model.actuator_biasprm[a, :3] = (0.0, 0.0, -ANKLE_TORQUE_DAMPING)
            else:
                self.model.actuator_gainprm[a, 0] = self._kp[j]
                self.model.actuator_biasprm[a, :3] = self._bias[j]

    def sole(self, side: Side) -> tuple[FloatArray, FloatArray]:
        """Measured sole centre (3,) [m] and rotation (3, 3) of the ``side`` foot."""
        sid = self.sole_sites[side]
        return np.array(self.data.site_xpos[sid]), np.array(self.data.site_xmat[sid]).reshape(3, 3)

    def com_state(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """CoM position (3,) [m], velocity (3,) [m/s], angular momentum about the CoM (3,)."""
        self.mujoco.mj_subtreeVel(self.model, self.data)
        b = self.pelvis
        d = self.data
        return (
            np.array(d.subtree_com[b]),
            np.array(d.subtree_linvel[b]),
            np.array(d.subtree_angmom[b]),
        )

    def contacts(self) -> tuple[dict[Side, tuple[FloatArray, FloatArray]], bool]:
        """Per foot, contact points (n, 3) and forces on the robot (n, 3) [N]; body-hit flag."""
        d, m = self.data, self.model
        pts: dict[Side, list[FloatArray]] = {s: [] for s in self.sides}
        frc: dict[Side, list[FloatArray]] = {s: [] for s in self.sides}
        body_hit = False
        for i in range(d.ncon):
            c = d.contact[i]
            g1, g2 = int(c.geom[0]), int(c.geom[1])
            if g1 in self.body_geoms or g2 in self.body_geoms:
                body_hit = True
                continue
            if g1 in self.foot_of_geom:
                side, sign = self.foot_of_geom[g1], -1.0
            elif g2 in self.foot_of_geom:
                side, sign = self.foot_of_geom[g2], 1.0
            else:
                continue
            self.mujoco.mj_contactForce(m, d, i, self._f6)
            # the contact frame's rows are (normal, tangent1, tangent2) and the force acts from
            # geom1 on geom2: on the robot as is when the foot is geom2, reversed otherwise
            pts[side].append(np.array(c.pos))
            frc[side].append(sign * (c.frame.reshape(3, 3).T @ self._f6[:3]))
        out = {
            s: (np.array(pts[s]).reshape(-1, 3), np.array(frc[s]).reshape(-1, 3))
            for s in self.sides
        }
        return out, body_hit


def sole_cop(
    points: FloatArray, forces: FloatArray, sole_pos: FloatArray, sole_rot: FloatArray
) -> tuple[FloatArray, float] | None:
    """Centre of pressure of a foot in its sole frame.

    The contact points lie (to within the contact penetration) on the sole plane, so the CoP is
    the normal-force-weighted mean of the points; it is returned relative to the sole centre in
    the foot's (x forward, y left) axes.

    Args:
        points: contact points (n, 3) [m], world.
        forces: contact forces on the foot (n, 3) [N], world.
        sole_pos: sole centre (3,) [m].
        sole_rot: sole rotation (3, 3), columns x, y, normal.

    Returns:
        ``(offset (2,) [m], normal force [N])`` or None without a pushing contact.
    """
    if points.shape[0] == 0:
        return None
    fn = forces @ sole_rot[:, 2]
    total = float(np.sum(fn))
    if total <= 0.0:
        return None
    cop = (fn @ points) / total
    local = sole_rot.T @ (cop - sole_pos)
    return local[:2], total


# ============================================================================= result
@dataclass(frozen=True)
class WalkResult:
    """Measurements of one simulated walk (arrays sampled every control tick, T samples).

    Attributes:
        t: time since the start of the walk, shape (T,) [s].
        phase: single-support phase index per tick, -1 outside single support, shape (T,).
        com: measured CoM, shape (T, 3) [m].
        com_ref: reference CoM sent to the IK, shape (T, 3) [m].
        zmp_offset: stance-foot CoP relative to the sole centre in the foot frame, shape (T, 2)
            [m] (NaN outside single support or without contact).
        zmp_planned: the ZMP offset of the adjuster's commanded torque, shape (T, 2) [m].
        feet: measured sole centres (left, right), shape (T, 2, 3) [m].
        landed: measured sole centre after each planned footstep 1..N landed, shape (N, 3) [m]
            (NaN if never reached).
        targets: the commanded (corrected) footsteps 1..N, shape (N, 3) [m].
        planned: the plan's footsteps 1..N, shape (N, 3) [m].
        n_planned: the plan's N; entries beyond it are stopping steps.
        fell: whether a fall was detected.
        fall_time: when [s] (NaN if none).
        metrics: summary numbers (:func:`summarise`).
        timing: wall-clock seconds per part: ``control`` (measurement, adjuster, references),
            ``ik``, ``physics``, ``render``.
        sim_time: simulated time [s].
        video: path of the MP4 or None; video_note says why there is none.
    """

    t: FloatArray
    phase: NDArray[np.int_]
    com: FloatArray
    com_ref: FloatArray
    zmp_offset: FloatArray
    zmp_planned: FloatArray
    feet: FloatArray
    landed: FloatArray
    targets: FloatArray
    planned: FloatArray
    n_planned: int
    fell: bool
    fall_time: float
    metrics: dict[str, Any]
    timing: dict[str, float]
    sim_time: float
    video: Path | None = None
    video_note: str = ""


# ============================================================================= controller
class _IK:
    """mink differential IK on a kinematic copy of the model (its own MjData)."""

    def __init__(self, sim: BipedSim) -> None:
        import mink

        self.mink = mink
        self.sim = sim
        self.config = mink.Configuration(sim.model)
        self.config.update(sim.data.qpos.copy())
        self.feet = {
            s: mink.FrameTask(
                nm.sole_site(s),
                "site",
                position_cost=FOOT_POSITION_COST,
                orientation_cost=FOOT_ORIENTATION_COST,
            )
            for s in sim.sides
        }
        self.com = mink.ComTask(cost=COM_COST)
        self.torso = mink.FrameTask(
            nm.TORSO_BODY, "body", position_cost=0.0, orientation_cost=TORSO_ORIENTATION_COST
        )
        self.posture = mink.PostureTask(sim.model, cost=POSTURE_COST)
        self.posture.set_target(sim.data.qpos.copy())
        self.hold = mink.PostureTask(sim.model, cost=0.0)
        self.hold.set_target(sim.data.qpos.copy())
        self.tasks = [*self.feet.values(), self.com, self.torso, self.posture, self.hold]
        self.limits = [mink.ConfigurationLimit(sim.model)]
        self.failures = 0

    def solve(
        self,
        feet: dict[Side, tuple[FloatArray, FloatArray]],
        com: FloatArray,
        torso_yaw: float,
        dt: float,
        iterations: int,
        q_meas: FloatArray | None = None,
        com_axes: tuple[bool, bool, bool] = (True, True, True),
        hold: NDArray[np.int_] | None = None,
    ) -> FloatArray:
        """Joint set points (12,) [rad] for sole poses, CoM (3,) [m] and torso yaw [rad].

        Args:
            q_meas: measured configuration (nq,); given, the IK starts from it every tick, so
                torso orientation and swing-foot pose are fed back (closed loop); None: the IK
                integrates its own kinematic copy (open loop).
            com_axes: which CoM coordinates are tasks (a torque-driven stance ankle leaves the
                horizontal CoM to the pendulum).
            hold: joint indices into ``BipedSim.joint_qpos`` kept at their measured angles
                (joints that are not position servoed, such as a torque-driven ankle).
        """
        mink = self.mink
        if q_meas is not None:
            self.config.update(q_meas)
            self.hold.set_target(q_meas)
        cost = np.zeros(self.sim.model.nv)
        if hold is not None and q_meas is not None:
            cost[self.sim.joint_dof[hold]] = HOLD_COST
        self.hold.set_cost(cost)
        self.com.set_cost(COM_COST * np.asarray(com_axes, dtype=float))
        for s, (pos, rot) in feet.items():
            self.feet[s].set_target(
                mink.SE3.from_rotation_and_translation(mink.SO3.from_matrix(rot), pos)
            )
        self.com.set_target(com)
        c, s_ = math.cos(torso_yaw / 2), math.sin(torso_yaw / 2)
        self.torso.set_target(
            mink.SE3.from_rotation_and_translation(
                mink.SO3(np.array([c, 0.0, 0.0, s_])), np.zeros(3)
            )
        )
        for _ in range(iterations):
            try:
                vel = mink.solve_ik(
                    self.config,
                    self.tasks,
                    dt,
                    solver="daqp",
                    damping=IK_DAMPING,
                    limits=self.limits,
                )
            except mink.NoSolutionFound:
                # infeasible limits (e.g. after a fall): keep the last set points
                self.failures += 1
                break
            self.config.integrate_inplace(vel, dt)
        return np.array(self.config.q[self.sim.joint_qpos])


def _ds_propagator(alip: ALIP, dt: float) -> FloatArray:
    """Exact one-tick map of [x (4); d (3); w (3)] for the double-support ALIP (eq. 5.8-5.10).

    The contact point moves by ``d`` (its displacement from the old foot) at constant velocity
    ``w``; measured from the old foot this is the single-support ALIP driven by ``E d``.
    """
    m = np.zeros((10, 10))
    m[:4, :4] = alip.A
    m[:4, 4:7] = alip.E
    m[4:7, 7:10] = np.eye(3)
    return np.asarray(expm(m * dt))


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
    ds_map = _ds_propagator(alip, dt)
    z_h = robot.com_height
    n = plan.n_steps
    t_ss, t_ds = robot.t_ss, robot.t_ds
    t_step = t_ss + t_ds

    sim.set_standing(scene.start.left, scene.start.right, scene.start.heading)
    ik = _IK(sim)
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
                rot = _blend_rot(swing_rot0, rot1 @ _pitch_about_y(-opts.heel_strike), s_h)
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


def ankle_joint_torque(
    u: FloatArray, sole_rot: FloatArray, weight: float, params: WalkerModel
) -> FloatArray:
    """Ankle (pitch, roll) joint torques [N m] that make the ground exert the ALIP torque ``u``.

    ``u = (tau_x, tau_y)`` is the torque of the ground on the robot about the sole centre
    (eq. 5.3). The foot is light, so the ankle joints pass it on: a hinge torque acts ``+tau`` on
    the child (the foot) and ``-tau`` on the parent, hence joint torque = ``-u`` expressed in the
    foot's axes. Each component is clipped so that the CoP stays ``SOLE_TORQUE_SHARE`` inside
    the contact rectangle of the sole (a larger torque would only tip the foot).

    When the sole centre is not straight below the ankle axes (``params.ankle_offset`` = (dx, dy)
    in the foot frame, e.g. the G1's sole reaches further forward than back), the normal force
    ``weight`` on the sole centre adds its moment about the ankle: ``(dx, dy, -h) x (0, 0, F_n)
    = (dy F_n, -dx F_n)``, so the joints add ``(+dx F_n, -dy F_n)`` (pitch, roll). Ours: (0, 0).
    """
    local = sole_rot[:2, :2].T @ np.asarray(u, dtype=float)
    lim_x = SOLE_TORQUE_SHARE * weight * (params.foot_width / 2 - params.corner_radius)
    lim_y = SOLE_TORQUE_SHARE * weight * (params.foot_length / 2 - params.corner_radius)
    tau_x = float(np.clip(local[0], -lim_x, lim_x))
    tau_y = float(np.clip(local[1], -lim_y, lim_y))
    dx, dy = params.ankle_offset
    return np.array([-tau_y + dx * weight, -tau_x - dy * weight])


def _pitch_about_y(angle: float) -> FloatArray:
    """Rotation (3, 3) by ``angle`` [rad] about the y axis (in a sole frame: toe down for > 0)."""
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def _blend_rot(r0: FloatArray, r1: FloatArray, s: float) -> FloatArray:
    """Rotation between ``r0`` (s = 0) and ``r1`` (s = 1) along the geodesic."""
    from scipy.spatial.transform import Rotation, Slerp

    if s <= 0.0:
        return r0
    if s >= 1.0:
        return r1
    slerp = Slerp([0.0, 1.0], Rotation.from_matrix(np.stack([r0, r1])))
    return np.asarray(slerp([s]).as_matrix()[0])


def summarise(
    res: WalkResult, scene: Scene, plan: FootstepPlan, params: WalkerModel, t_steps_end: float
) -> dict[str, Any]:
    """Summary metrics of a walk.

    Keys: ``fell``, ``fall_time_s``, ``reached_goal``, ``goal_error_m``, ``time_to_goal_s`` (when
    the last footstep landed, NaN if it did not), ``steps_planned``, ``steps_landed``,
    ``footstep_error_m`` / ``footstep_error_vs_target_m`` (mean and max horizontal distance of the
    landed sole centres from the plan / from the commanded footsteps), ``zmp`` (single-support
    stance-foot CoP offset from the sole centre: mean and max norm [m], mean |x| and |y|, share of
    ticks at a sole edge, share inside the sole), ``zmp_commanded`` (the adjuster's torque as a
    ZMP, before the sole clip), ``zmp_plan`` (the plan's own torques) and ``per_step`` (per phase: mean and max offset norm, at-edge share).
    """
    n = res.n_planned
    ss = (res.phase >= 0) & (res.phase < n)
    z = res.zmp_offset[ss]
    ok = ~np.isnan(z[:, 0])
    z = z[ok]
    half = np.array(
        [
            params.foot_length / 2 - params.corner_radius,
            params.foot_width / 2 - params.corner_radius,
        ]
    )
    sole_half = np.array([params.foot_length / 2, params.foot_width / 2])

    def stats(a: FloatArray) -> dict[str, float]:
        if a.shape[0] == 0:
            return {
                "mean": math.nan,
                "max": math.nan,
                "mean_abs_x": math.nan,
                "mean_abs_y": math.nan,
            }
        nrm = np.linalg.norm(a, axis=1)
        return {
            "mean": float(np.mean(nrm)),
            "max": float(np.max(nrm)),
            "mean_abs_x": float(np.mean(np.abs(a[:, 0]))),
            "mean_abs_y": float(np.mean(np.abs(a[:, 1]))),
        }

    zs = stats(z)
    if z.shape[0]:
        at_edge = np.any(np.abs(z) >= half - EDGE_TOL, axis=1)
        zs["at_edge_share"] = float(np.mean(at_edge))
        zs["inside_share"] = float(np.mean(np.all(np.abs(z) <= sole_half, axis=1)))
    zs["samples"] = int(z.shape[0])
    zp = res.zmp_planned[ss]
    zp = zp[~np.isnan(zp[:, 0])]
    per_step = []
    for i in range(n):
        sel = (res.phase == i) & ~np.isnan(res.zmp_offset[:, 0])
        a = res.zmp_offset[sel]
        if a.shape[0] == 0:
            continue
        nrm = np.linalg.norm(a, axis=1)
        per_step.append(
            {
                "phase": i,
                "region": plan.regions[i],
                "mean": float(np.mean(nrm)),
                "max": float(np.max(nrm)),
                "at_edge_share": float(np.mean(np.any(np.abs(a) >= half - EDGE_TOL, axis=1))),
            }
        )
    npl = res.n_planned
    landed, planned, targets = res.landed[:npl], res.planned[:npl], res.targets[:npl]
    done = ~np.isnan(landed[:, 0])
    err_plan = np.linalg.norm((landed - planned)[done, :2], axis=1)
    err_tgt = np.linalg.norm((landed - targets)[done, :2], axis=1)
    err_z = np.abs((landed - planned)[done, 2])

    def mm(a: FloatArray) -> dict[str, float]:
        return {
            "mean": float(np.mean(a)) if a.size else math.nan,
            "max": float(np.max(a)) if a.size else math.nan,
        }

    final_mid = 0.5 * (res.feet[-1, 0] + res.feet[-1, 1])
    goal_err = float(np.linalg.norm(final_mid[:2] - scene.goal.position[:2]))
    all_landed = bool(np.all(done))
    reached = (not res.fell) and all_landed and goal_err <= GOAL_TOL
    return {
        "fell": res.fell,
        "fall_time_s": res.fall_time if res.fell else None,
        "reached_goal": reached,
        "goal_error_m": goal_err,
        "time_to_goal_s": t_steps_end if (all_landed and not res.fell) else None,
        "steps_planned": npl,
        "stop_steps": int(res.landed.shape[0] - npl),
        "steps_landed": int(np.sum(done)),
        "footstep_error_m": mm(err_plan),
        "footstep_height_error_m": mm(err_z),
        "footstep_error_vs_target_m": mm(err_tgt),
        "zmp": zs,
        "zmp_commanded": stats(zp),
        "zmp_plan": stats(plan.zmp_offsets()[:n].reshape(-1, 2)),
        "per_step": per_step,
        "sim_time_s": res.sim_time,
        "wall_time_s": res.timing.get("total", math.nan),
    }
