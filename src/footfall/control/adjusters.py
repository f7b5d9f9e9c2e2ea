"""Footstep / ankle-torque sources of a walking controller (document 000, eq. 5.10, 5.12, 5.19).

A walking controller asks its :class:`FootstepAdjuster` once per control tick for the next
footstep and the ankle torque to apply now, given the measured ALIP state (eq. 5.1) about the
stance foot. :class:`PlanFollower` follows the plan's footsteps and torques with one-step ALIP foot
placement (through the reset map, eq. 5.10) and capture-point feedback; :class:`MPCAdjuster`
re-solves the MPC of eq. (5.19) every tick. Both keep the footstep inside its planned region and
freeze it late in the swing. Arrays in, arrays out: nothing here knows about a simulator.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from footfall._geometry import inset_polygon, project_to_polygon, rot2
from footfall._typing import FloatArray
from footfall.control.horizon_regions import HORIZON_MODE, HorizonRegions
from footfall.control.mpc import MPC, MPCWeights, build_mpc
from footfall.control.region_mpc import RegionMPC, RegionRows, region_rows, regions_in_reach
from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning.plan import FootstepPlan
from footfall.terrain.region import Region

#: extra footsteps after the plan's last one, onto the plan's final footholds (the goal stance),
#: corrected by foot placement toward zero momentum: they absorb the momentum the walk ends with
#: and finish a walk whose last steps the MPC shortened
STOP_STEPS = 2
#: share of the half foot width the planner's ankle-torque bound may use: U_max = share * m g * w/2
#: keeps the planned ZMP (eq. 5.12d) inside the sole in every direction, with a margin
U_MAX_FOOT_SHARE = 0.8
#: share of the sole's contact rectangle the commanded ankle torque may use (CoP margin)
SOLE_TORQUE_SHARE = 0.9
#: corrected footsteps stay this far inside the reach trapezoid [m]; the planners use its
#: boundary (the first lateral step of the reactive plan lies on it), so no margin
REACH_MARGIN = 0.0
#: ways the MPC adjuster keeps the footstep on the terrain (:attr:`MPCAdjuster.region_aware`)
REGION_MODES = ("off", "planned", "nearby", HORIZON_MODE)


def check_region_mode(value: object) -> str:
    """``value`` if it is one of :data:`REGION_MODES`, else :class:`InputError` naming
    ``region_aware``."""
    if not isinstance(value, str) or value not in REGION_MODES:
        raise InputError("region_aware", value, f"one of {', '.join(REGION_MODES)}")
    return value


#: shortest time to touchdown the MPC's step timing may leave, as a share of what the planned
#: single support has left: the swing runs at most 1 / 0.7 = 1.43 times as fast as planned (at
#: 0.5 Alexander's heavy legs landed 20 cm off the commanded footstep and it fell)
TIMING_MIN_SHARE = 0.7
#: the step timing moves a touchdown only in this first share of the single support: moved
#: later, the sole is already descending and lands late (the biped's discrete_steps walk pushed
#: forward at 20 % of a support at 0.2 m/s fell when its next support was shortened at 58 %)
TIMING_UNTIL = 0.5
#: eq. (5.19a) cost a shorter single support must save (0.5: a 22 cm footstep deviation at the
#: default W). Unpushed walks cost 0.01-0.1 and differ by up to 0.1 between touchdown times; a
#: 0.3 m/s push makes the cost 1-30
TIMING_MARGIN = 0.5

#: another region is chosen over the preferred one when its eq. (5.19a) cost is lower by more
#: than this: the cost of a 10 cm footstep deviation at the default W (MPCWeights.w = 10)
SWITCH_MARGIN = 0.1


@dataclass(frozen=True)
class RegionChoice:
    """Where the region-aware MPC adjuster put one footstep (its last decision in the phase).

    Attributes:
        phase: single-support phase i (the footstep is p_{i+1}).
        planned: the plan's region of the footstep.
        region: the region chosen ("" when no region had a footstep the sole fits: the plan's
            footstep is used).
        reason: see :class:`footfall.control.region_mpc.RegionSolution`.
        method: how the QP was solved (:data:`footfall.control.region_mpc.METHODS`).
        correction_m: horizontal distance of the footstep from the plan's [m].
        candidates: the regions whose QPs were solved.
    """

    phase: int
    planned: str
    region: str
    reason: str
    method: str
    correction_m: float
    candidates: tuple[str, ...]

    def to_dict(self) -> dict[str, object]:
        """The fields by name (JSON-ready)."""
        return {
            "phase": self.phase,
            "planned": self.planned,
            "region": self.region,
            "reason": self.reason,
            "method": self.method,
            "correction_m": self.correction_m,
            "candidates": list(self.candidates),
        }


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
            final step always is, so the robot ends in a legal stance). Off by default: the
            MuJoCo walker's lateral recovery needs steps narrower than the trapezoid's minimum
            width.
        reach_margin: with ``limit_reach``, every corrected footstep stays this far inside the
            reach trapezoid of the measured stance foot (``BipedParams.reach``) [m].
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

    def extend_stop(self, extra: int) -> None:
        """Append ``extra`` stopping steps to the plan (:func:`extend_plan`: each foot steps
        onto its final foothold again) while the walk is under way: the walker asks for them
        when its stopping steps landed far from the goal (``WalkOptions.walk_on``). The capture
        stop moves to the new last step."""
        self.plan = extend_plan(self.plan, extra)

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
        rot = rot2(float(self.plan.headings[phase]))
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
        freeze_after: as for :class:`PlanFollower`, later by default: the MPC's footstep keeps
            improving late in the swing, and freezing early left every footstep short.
        capture_stop: the last footstep by the capture point (:meth:`stop_target`, then kept
            in its region), in every ``region_aware`` mode; off: the MPC's terminal term (Q_f
            toward the plan's final state at rest) places it. The walker turns it on
            (``WalkOptions.capture_stop``). Unlike :class:`PlanFollower`'s, this footstep is not
            moved into the reach trapezoid (only with ``limit_reach``): a capture point on the
            stance foot's far side makes the feet cross, and moved into the trapezoid the G1
            fell in two such walks that had ended standing (benchmarks/RESULTS.md, "another
            stopping step").
        torque_limits: semi-axes ``(U_x, U_y)`` [N m] of the MPC's torque ellipse
            (:func:`footfall.control.mpc.build_mpc`); None = the plan's ``U_max`` ball
            (eq. 5.19e). The MuJoCo walker passes :func:`sole_torque_limits`.
        hold_frozen: once the footstep is frozen, keep applying the torque of the solution it
            was frozen with (the MPC's torque block is the plan's node interval, so that solution
            already holds one torque for the rest of the single support) instead of re-solving.
            Re-solving with the footstep free returns torques for a footstep the swing foot no
            longer goes to; re-solving with it fixed, with a few ticks left the torque barely
            moves the state and the solve spends the whole torque ellipse on it.
        footstep_in_region: solve the MPC with the next footstep kept in its planned region
            (``region_margin`` inside, :meth:`footfall.control.mpc.MPC.solve_in_polygon`)
            instead of clamping the document's unconstrained footstep afterwards, so the ankle
            torque makes up for a correction the region does not allow.
        region_aware: ``off`` (the above); ``planned``: the next footstep is kept in its planned
            region inset exactly by the sole at its planned heading plus ``landing_margin``
            (:class:`footfall.control.region_mpc.RegionMPC`; ``region_margin`` is then unused);
            ``nearby``: as ``planned``, and when that region has no footstep the sole fits, or
            another region within reach (its polygon meets the reach trapezoid of the stance
            foot, its height within ``step_height_max``) costs less by ``switch_margin``, the
            footstep goes there; ``horizon``: as ``planned``, in the region the short-horizon
            footstep MIQP chooses from the measured state, three footsteps ahead
            (:class:`footfall.control.horizon_regions.HorizonRegions`, 50 Hz; the last choice,
            else the plan's region, where it has none). :attr:`choices` records each phase's
            decision.
        landing_margin: extra inset [m] of the regions beyond the sole (``region_aware``).
        switch_margin: cost margin of a region switch (``nearby``).
        step_timing: choose the touchdown time with the footstep, against the MPC's own cost
            (beyond document 000, whose single support has a fixed length; dairlib's ALIP
            footstep MPC does the same). At every tick before the footstep freezes, eq. (5.19)
            is solved as if the single support ended ``j`` ticks sooner (the condensed problem
            of tick ``k_s + j``, which has ``j`` ticks less to go) for every ``j`` that leaves
            at least ``timing_min_share`` of the planned time to touchdown; the touchdown moves
            forward when one of them costs less than the fixed timing by more than
            ``timing_margin``. Only shortening: the MPC is precomputed for the planned T_ss.
            The walker reads the time gained with :meth:`take_advance` and moves its clock.
            Never on the last stopping step (its footstep is the capture stop's).
        timing_min_share: the shortest time to touchdown the timing may leave, as a share of
            the time the planned single support has left (the swing runs at most
            ``1 / timing_min_share`` times as fast as planned).
        timing_until: the touchdown moves only while the single support (on the moved clock)
            is in this first share of T_ss.
        timing_margin: cost of eq. (5.19a) a shorter single support must save.
        timing_stride: ticks between the touchdown times compared (the latest allowed one is
            always compared).
    """

    control_dt: float = 0.01
    freeze_after: float = 0.9
    weights: MPCWeights = field(default_factory=MPCWeights)
    capture_stop: bool = False
    torque_limits: tuple[float, float] | None = None
    footstep_in_region: bool = True
    hold_frozen: bool = True
    region_aware: str = "off"
    landing_margin: float = 0.0
    switch_margin: float = SWITCH_MARGIN
    step_timing: bool = False
    timing_min_share: float = TIMING_MIN_SHARE
    timing_margin: float = TIMING_MARGIN
    timing_until: float = TIMING_UNTIL
    timing_stride: int = 2
    mpc: MPC = field(init=False, repr=False)
    #: ticks each phase's single support was shortened by (``step_timing``)
    saved_ticks: dict[int, int] = field(default_factory=dict, repr=False)
    _advance: float = field(default=0.0, repr=False)
    choices: dict[int, RegionChoice] = field(default_factory=dict, repr=False)
    _frozen_torque: dict[int, FloatArray] = field(default_factory=dict, repr=False)
    _nearby: dict[int, tuple[str, ...]] = field(default_factory=dict, repr=False)
    _frames: dict[int, tuple[FloatArray, FloatArray]] = field(default_factory=dict, repr=False)
    _row_cache: dict[tuple[int, str], tuple[FloatArray, RegionRows]] = field(
        default_factory=dict, repr=False
    )

    def __post_init__(self) -> None:
        check_region_mode(self.region_aware)
        if not (math.isfinite(self.landing_margin) and self.landing_margin >= 0.0):
            raise InputError("landing_margin", self.landing_margin, "a finite number >= 0 [m]")
        if not (math.isfinite(self.switch_margin) and self.switch_margin >= 0.0):
            raise InputError("switch_margin", self.switch_margin, "a finite number >= 0")
        if not (math.isfinite(self.timing_min_share) and 0.0 < self.timing_min_share <= 1.0):
            raise InputError("timing_min_share", self.timing_min_share, "a share in (0, 1]")
        if not (math.isfinite(self.timing_until) and 0.0 <= self.timing_until <= 1.0):
            raise InputError("timing_until", self.timing_until, "a share in [0, 1]")
        if not (math.isfinite(self.timing_margin) and self.timing_margin >= 0.0):
            raise InputError("timing_margin", self.timing_margin, "a finite number >= 0")
        if isinstance(self.timing_stride, bool) or not (
            isinstance(self.timing_stride, int) and self.timing_stride >= 1
        ):
            raise InputError("timing_stride", self.timing_stride, "an integer >= 1 [ticks]")
        super().__post_init__()
        mdl = build_mpc(self.plan.robot, self.weights, self.control_dt, None, self.torque_limits)
        self.mpc = MPC(mdl)
        self.region_mpc = RegionMPC(self.mpc)
        self.horizon: HorizonRegions | None = None
        if self.region_aware == HORIZON_MODE:
            regions = tuple(self.regions.values())
            self.horizon = HorizonRegions(self.plan, regions, mdl.control_dt, self.torque_limits)

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
        rot, rot4 = self._stance_frame(phase)
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
        if (
            self.step_timing
            and phase not in self._frozen
            and not (self.capture_stop and phase == plan.n_steps - 1)
        ):
            k_new = self._touchdown_tick(phase, args, stance)
            if k_new > k_s:
                self._advance += (k_new - k_s) * mdl.control_dt
                self.saved_ticks[phase] = self.saved_ticks.get(phase, 0) + k_new - k_s
                k_s = k_new
                t = k_s * mdl.control_dt
                args = (k_s, *args[1:])
        if self.region_aware != "off" and phase not in self._frozen:
            target, u = self._region_aware(t, phase, args, rot, state, stance, ref_next)
            if self.capture_stop and phase == plan.n_steps - 1:
                target = np.array(target, dtype=float)
                target[:2] = self.stop_target(t, state, stance, phase, u)
                target = self._legal(target, ref_next, stance, phase)
            target = self._maybe_freeze(t, phase, target)
            if phase in self._frozen:
                self._frozen_torque[phase] = u
            return target, u
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

    def take_advance(self) -> float:
        """Seconds the touchdown moved forward since the last call (``step_timing``); the
        walker moves its clock by them. 0.0 without ``step_timing``."""
        out, self._advance = self._advance, 0.0
        return out

    def _touchdown_tick(
        self,
        phase: int,
        args: tuple[int, FloatArray, FloatArray, FloatArray, FloatArray],
        stance: FloatArray,
    ) -> int:
        """The tick of the MPC's condensed problem to solve now (``step_timing``): ``k_s``, or
        a later one whose shorter time to touchdown costs less by ``timing_margin``.

        The cost of a touchdown time is eq. (5.19a)'s optimum with the footstep in the region
        it is in now (the region chosen earlier in this support, else the planned one), or
        unconstrained when the regions do not hold it. Every cost is >= 0, so when the fixed
        timing costs ``timing_margin`` or less no other is solved. The MPC's warm starts and
        counters are left as they were (:meth:`RegionMPC.probe`): the solve that is applied
        runs as it would have.
        """
        mdl = self.mpc.model
        k_s, x_r, ps_r, pr_r, xn_r = args
        m = mdl.n_ticks
        elapsed = k_s - self.saved_ticks.get(phase, 0)  # ticks really spent in this support
        # the swing may run at most 1 / timing_min_share times as fast as planned: the ticks
        # left keep that share of what the planned single support has left
        left = math.ceil(self.timing_min_share * (m - elapsed) - 1e-9)
        k_hi = min(m - 1, m - left)
        if k_s >= self.timing_until * m or k_hi <= k_s:
            return k_s
        theta = np.concatenate([x_r, pr_r[:2] - ps_r[:2], xn_r])
        rows = None
        if self.region_aware != "off" or self.footstep_in_region:
            name = self.choices[phase].region if phase in self.choices else ""
            name = name or self.plan.regions[phase + 1]
            if name in self.regions:
                rot, _ = self._stance_frame(phase)
                heading = float(self.plan.headings[phase + 1])
                rows = self._rows(phase, name, stance, heading, rot)

        def cost(k: int) -> float:
            if rows is not None:
                return self.region_mpc.solve_region(k, theta, ps_r, pr_r, rows).cost
            sol = self.mpc.solve_theta(k, theta, ps_r, pr_r)
            if sol.fallback:
                return math.inf
            d = sol.next_footstep[:2] - ps_r[:2]
            return mdl.cost(k, np.concatenate([sol.torques.ravel(), d]), theta)

        with self.region_mpc.probe():
            now = cost(k_s)
            if not now > self.timing_margin:  # nothing to save
                return k_s
            ticks = list(range(k_s + self.timing_stride, k_hi + 1, self.timing_stride))
            if not ticks or ticks[-1] != k_hi:
                ticks.append(k_hi)
            costs = [cost(k) for k in ticks]
        best = int(np.argmin(costs))
        return ticks[best] if costs[best] < now - self.timing_margin else k_s

    def _stance_frame(self, phase: int) -> tuple[FloatArray, FloatArray]:
        """The stance heading's rotation (2, 2) of ``phase`` and its ALIP-state form (4, 4)
        (``kron(I_2, rot)``: positions and momenta turn alike), made once per phase."""
        if phase not in self._frames:
            rot = rot2(float(self.plan.headings[phase]))
            self._frames[phase] = (rot, np.asarray(np.kron(np.eye(2), rot), dtype=float))
        return self._frames[phase]

    def _region_aware(
        self,
        t: float,
        phase: int,
        args: tuple[int, FloatArray, FloatArray, FloatArray, FloatArray],
        rot: FloatArray,
        state: FloatArray,
        stance: FloatArray,
        ref_next: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """Footstep and torque of the region-aware MPC (``region_aware`` planned / nearby /
        horizon); ``state`` (4,) is the measured ALIP state, ``args`` the MPC's in the stance
        heading's frame."""
        plan = self.plan
        k_s, x_r, ps_r, pr_r, xn_r = args
        planned = plan.regions[phase + 1]
        first = self.choices[phase].region if phase in self.choices else planned
        first = first or planned
        if self.horizon is not None:
            mdl = self.mpc.model
            time_left = (mdl.n_ticks - k_s) * mdl.control_dt
            first = self.horizon.choose(phase, k_s, time_left, state, stance) or first
        names = [first]
        if self.region_aware == "nearby":
            names += [n for n in self._regions_nearby(phase, stance) if n != first]
        heading = float(plan.headings[phase + 1])
        cands = [self._rows(phase, n, stance, heading, rot) for n in names if n in self.regions]
        theta = np.concatenate([x_r, pr_r[:2] - ps_r[:2], xn_r])
        if not cands:  # the plan's region is unknown: the document's unconstrained MPC
            sol = self.mpc.solve_theta(k_s, theta, ps_r, pr_r)
            return _rotate_xy(rot, sol.next_footstep), rot @ sol.torques[0]
        reason = "planned" if cands[0].name == planned else "kept"
        rs = self.region_mpc.solve(k_s, theta, ps_r, pr_r, cands, self.switch_margin, reason)
        u = rot @ rs.solution.torques[0]
        if rs.region:
            target = _rotate_xy(rot, rs.solution.next_footstep)
            target[2] = float(self.regions[rs.region].height_at(target[:2]))
        else:  # no region fits the sole: the plan's footstep, which the planner kept inside
            target = np.array(ref_next, dtype=float)
        self.choices[phase] = RegionChoice(
            phase=phase,
            planned=planned,
            region=rs.region,
            reason=rs.reason,
            method=rs.method,
            correction_m=float(np.linalg.norm(target[:2] - ref_next[:2])),
            candidates=tuple(c.name for c in cands),
        )
        if self.limit_reach:
            target = self._limit_reach(target, stance, phase)
        return target, u

    def _rows(
        self, phase: int, name: str, stance: FloatArray, heading: float, rot: FloatArray
    ) -> RegionRows:
        """The rows of region ``name`` for ``phase``, rebuilt only when the stance foot moved."""
        key = (phase, name)
        hit = self._row_cache.get(key)
        if hit is None or not np.array_equal(hit[0], stance):
            rows = region_rows(
                self.regions[name], stance, heading, self.plan.robot, self.landing_margin, rot
            )
            hit = (np.array(stance, dtype=float), rows)
            self._row_cache[key] = hit
        return hit[1]

    def _regions_nearby(self, phase: int, stance: FloatArray) -> tuple[str, ...]:
        """Regions within reach of the stance foot of ``phase`` (once per phase)."""
        if phase not in self._nearby:
            plan = self.plan
            self._nearby[phase] = regions_in_reach(
                tuple(self.regions.values()),
                stance,
                float(plan.headings[phase]),
                plan.sides[phase],
                plan.robot,
            )
        return self._nearby[phase]


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
