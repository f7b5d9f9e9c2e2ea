"""Options of the MuJoCo biped's walking controller (:mod:`footfall.sim.biped.walk`) and the checks
of what it is asked to walk."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from footfall._validate import check_fields, non_negative, positive
from footfall.control.adjusters import STOP_STEPS, check_region_mode
from footfall.control.horizon_regions import HORIZON_MODE
from footfall.errors import InputError
from footfall.models.biped import BipedParams, Side
from footfall.planning.plan import FootstepPlan
from footfall.sim.biped.metrics import GOAL_TOL
from footfall.sim.biped.model import BipedModel, WalkerModel, measure_model
from footfall.sim.biped.wbc import WbcGains
from footfall.sim.disturbance import Push
from footfall.terrain.scene import Scene
from footfall.terrain.terrain import LANDING_Z_TOL

#: landing error [m] the walk leaves room for at riser edges (:mod:`footfall.terrain.edges`):
#: landings fall short of their targets, and a heel landing on the edge of the tread above a
#: step down tips the foot
RISER_LANDING_TOLERANCE = 0.04
#: the mass [kg] of footfall's biped as planned (:func:`~footfall.sim.biped.model
#: .planner_params`), on which the walker's MPC weights were chosen: other robots get its ankle
#: torque weight scaled by their mass (``WalkOptions.torque_weight_mass``)
WEIGHTS_MASS = 30.1
#: the walk's whole-body controllers (``WalkOptions.controller``)
CONTROLLERS = ("servo", "wbc")
#: a plan's robot mass and CoM height may differ this much (relative) from the walker model's
#: (:func:`~footfall.sim.biped.model.planner_params` measures them: 0.0 exactly)
PLAN_ROBOT_RTOL = 0.01
#: ``WalkOptions.walk_on``: stopping steps the walker may add to reach the goal
WALK_ON = 4
#: ``WalkOptions.walk_on_distance`` [m]: the goal tolerance of the walk's metrics
WALK_ON_DISTANCE = GOAL_TOL
#: ``WalkOptions.leg_momentum`` when not given and the adjuster gets the CoM-velocity estimate
LEG_MOMENTUM = 0.5
#: ``WalkOptions.step_timing``'s default: on. Against off over the same plans and push cases (six
#: push protocols on four robots and seeded batteries; benchmarks/RESULTS.md, "The MPC chooses the
#: touchdown time"): 9 walks gained, 2 lost, no protocol level that passed before lost
STEP_TIMING = True
#: how far a start sole's corner may stand beyond every region [m] (the walker stands on the
#: whole sole: past this, a robot standing still tips over the edge)
START_OVERHANG_TOL = 0.01


@dataclass(frozen=True)
class WalkOptions:
    """Options of the walking controller.

    Attributes:
        controller: ``wbc`` (the default): the whole-body inverse-dynamics QP
            (:mod:`footfall.sim.biped.wbc`) drives every joint by torque, the ALIP torque being
            the stance foot's commanded centre of pressure; ``servo``: differential IK (``mink``)
            whose joint angles are the set points of position servos, the stance ankle
            torque-driven with the ALIP torque. ``wbc`` walked 4 N s pushes on discrete_steps and
            stairs_slope_gap far more often (benchmarks/RESULTS.md, "Whole-body control").
        wbc_gains: gains and weights of the ``wbc`` controller's tasks.
        control_dt: control period (measurement, adjuster, reference, IK) [s]; a multiple of the
            physics step. The whole-body QP of ``wbc`` runs at every physics step (500 Hz) from
            the measured state, with this period's references.
        ik_iterations: differential-IK QP solves per control tick.
        swing_clearance: height of the swing sole above the highest region it passes over [m].
        heel_strike: the swing sole turns toe-up by this angle [rad] about its lateral axis
            (relative to lying flat on the landing region) as it moves, so it touches down heel
            first and the limp ankle (``passive_landing``) lets it roll flat; beyond the document.
            A sole landing flat meets the ground toe-first (the IK lags) and the CoP stays at the
            toe into the next single support. It trades against push recovery (benchmarks/
            RESULTS.md, "Biped walk"). 0 = land flat.
        swing_side_gap: the swing sole passes the stance sole at least this far apart sideways
            [m]: their centres at least the sole width plus this
            (:func:`~footfall.sim.biped.references.swing_bow`; beyond the
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
        stop_steps: stopping steps after the plan
            (:func:`~footfall.control.adjusters.extend_plan`); the adjuster must answer for phases
            up to ``N + stop_steps - 1`` (:class:`~footfall.control.adjusters.PlanFollower`
            does).
        walk_on: stopping steps the walker may add, two at a time, when the last stopping
            step is about to start and the foot that landed before it lies more than
            ``walk_on_distance`` [m] from its final foothold (a push moved the walk off its
            goal): the robot steps on toward the goal instead of stopping where it is. The
            adjuster must take them (``extend_stop``, as
            :class:`~footfall.control.adjusters.PlanFollower` does); 0: never (the stop as
            planned). A walk whose stopping steps land near the goal is not changed.
        walk_on_distance: see ``walk_on`` [m].
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
            (``L_G + m (c - p) x v``, Gong & Grizzle; eq. 5.1's L) instead of
            ``m z_H (-v_y, v_x)`` from the CoM velocity: the swing leg and torso carry momentum
            the CoM velocity does not show. None: True with ``servo``, False with ``wbc``. The
            torque controller realises the ALIP exactly about the stance foot (the measured
            ``dL/dt`` matches ``m g x + u`` to about 1 N m), but the legs' own momentum about the
            CoM (``L_G_y`` about 1 kg m^2/s at every touchdown of our biped) makes the CoM move
            slower than ``L / (m z_H)`` says: the MPC, told the true momentum, saturated the
            ankle torque every step and the robot fell on stairs_slope_gap (0 of 2 walks);
            told the CoM velocity, it walked 2 of 2 (benchmarks/RESULTS.md, "Whole-body
            control").
        stop_on_fall: end the simulation when a fall is detected.
        landing_margin: the walker's MPC keeps each footstep this much further inside its region
            than the plan did (its ``region_margin``, half the sole length for
            :func:`footfall.sim.biped.plans.plan_for_walk`) [m]: landings fall short of their
            targets, and a heel over a block's edge on a step down tips the landing foot.
        region_aware: how the walker's MPC keeps footsteps on the terrain
            (:attr:`footfall.control.adjusters.MPCAdjuster.region_aware`): ``off`` keeps each
            footstep ``region_margin + landing_margin`` inside its planned region (a uniform
            inset: on stones narrower than twice it, no correction at all); ``planned`` keeps it
            in the planned region inset exactly by the sole plus ``landing_margin``; ``nearby``
            also lets it move to another region within reach when that is cheaper or the planned
            one has no room; ``horizon`` keeps it in the region the short-horizon footstep MIQP
            chooses from the measured state (three footsteps ahead, 50 Hz, judged with the
            MPC's own torque ellipse). With any of them, a swing whose target moves while the
            sole is still rising is raised over the regions under the new path. Default
            ``horizon``: against ``planned``, over the same plans, seeds and protocol cases (box
            biped on discrete_steps and stairs_slope_gap, the G1 and Talos on the x 0.4 steps
            and the G1 on the x 0.4 stairs), 13 walks gained and 2 lost (sign test p = 0.007),
            every push-protocol case at 0.2 m/s on both terrain scenes and 400 of 400 held-out
            4 N s pushes; it costs about a third of the walker's speed on terrain
            (benchmarks/RESULTS.md, "The short-horizon MIQP with the walker's torque ellipse").
            ``planned`` reached the goal in 90 of 90 built-in-scene walks against 70 of 90 with
            ``off`` ("Footsteps on the terrain"). The section 5.5 study runs ``off``, document
            000's MPC, unless its file says otherwise.
        passive_landing: the swing ankle goes limp (torque mode, zero torque) from the first
            contact of the swing sole during its descent until the double support, where the
            landing ankle is passive anyway. A stiff position-servoed ankle that meets the ground
            on the toe holds the foot's angle, and the toe's load lifts the robot and loses
            angular momentum about the new foot at the reset (eq. 5.10).
        closed_loop_ik: start the IK from the measured configuration every tick, so the torso
            orientation, the CoM height and the swing foot are fed back through the joint
            servos; a torque-driven stance ankle is held at its measured angles and its sole at
            its measured pose, leaving the horizontal CoM to the pendulum and the adjuster.
            False: the IK integrates its own kinematic copy (open loop, nothing fed back).
        check_robot: refuse a plan whose robot mass or CoM height differs by more than
            ``PLAN_ROBOT_RTOL`` from the walker model's
            (:func:`~footfall.sim.biped.model.planner_params`): its ALIP motion
            is then another pendulum's. False walks such a plan on purpose (a mismatch study).
        swing_target_rate: the target the swing sole's path heads for moves toward the MPC's
            footstep by at most :func:`~footfall.sim.biped.walk.swing_target_speed` times the
            control period per tick, and the sole lands (and the trace logs its target) where the
            limited target ends up. False: the path follows the MPC's footstep as it is, and a
            footstep moved late in the swing jumps the swing reference (the whole-body
            controller then restarts it with zero velocity). Default True: the G1's push
            protocol on flat_long passed 12/12 at 0.1 m/s and 12/12 at 0.2 m/s against 10/12
            and 6/12 with False, and the biped's held-out 4 N s pushes (wbc, seeds 100-149)
            reached the goal in 93 of 100 against 84 (9 gained, 0 lost, exact McNemar
            p = 0.004). Its cost: the biped's protocol at 0.5 / 0.6 m/s passed 8 / 4 of 12
            against 9 / 10 (the largest level passed stays 0.4 m/s): the strongest pushes need
            corrections faster than the bound. Hence one exception: before the sole moves
            horizontally a footstep the bound could not reach in time is taken at once
            (``BipedWalk._limit_target``), which brought the biped's 0.5 m/s protocol to 11 of 12.
            And later, a footstep more than ``FAST_TARGET_GAP`` (0.1 m) from the target is
            approached at the speed that reaches it by the end of the horizontal move, at most
            twice the bound: over six push protocols, 10 cases gained and 3 lost, Alexander at
            0.3 m/s 6 of 12 instead of 3 (benchmarks/RESULTS.md, "A swing target that can
            catch up").
        leg_momentum: share [0, 1] of the legs' sagittal momentum about the CoM, forecast over
            the rest of each single support by the previous one's measured profile, that the
            MPC's end-of-step prediction carries (:mod:`footfall.sim.biped.leg_momentum`; 0:
            off, document 000's point-mass prediction). Needs the CoM-velocity estimate
            (``true_momentum`` False). None (default): ``LEG_MOMENTUM`` (0.5) with that
            estimate, 0 when the adjuster gets the true momentum (``servo``), which holds the
            legs' momentum already. Measured on and off over the same plans, seeds and push
            cases (benchmarks/RESULTS.md, "The legs' momentum on by default"): over six push
            protocols and six seeded batteries (four robots) 36 walks gained and 11 lost; the
            biped's held-out 4 N s pushes reached the goal in 396 of 400 against 382, the G1's
            0.1 m/s pushes on the x 0.4 steps in 46 of 50 against 42, and the biped's
            discrete_steps protocol passes every case at 0.2 m/s; Alexander (legs 36 % of its
            mass each) lost 2 of 50 random 0.1 m/s pushes and gained 2 protocol cases.
        capture_stop: the last stopping step lands where it leaves the capture point between
            the feet (:meth:`~footfall.control.adjusters.PlanFollower.stop_target`), kept in its
            planned region, instead of where the MPC's terminal term toward the plan's final
            state puts it. With heavy legs the MPC's last steps drifted inward and the robot
            ended on feet it could not stand on: on flat_long with 0.1 m/s pushes (seeds 0-49),
            Talos fell in 24 walks and Alexander in 6; with this, 3 and 0.
        torque_weight_mass: the mass [kg] the MPC's ankle-torque weight ``MPCWeights.r`` is
            given for (``MPCWeights.r_mass``): a robot of mass ``m`` gets ``r (this / m)^2``, the
            same weight on its centre-of-pressure shift as footfall's biped, on which the weights
            were chosen (default :data:`WEIGHTS_MASS`); None: the same ``r`` for every robot.
            With the same ``r``, Talos (90 kg) paid 9x as much for the same CoP shift, moved its
            footsteps 10-22 cm instead and ended its walks 15-20 cm past the goal
            (benchmarks/RESULTS.md, "The ankle's weight per metre of CoP, for every robot").
        step_timing: the MPC chooses the touchdown time with the footstep, against its own cost
            (:attr:`~footfall.control.adjusters.MPCAdjuster.step_timing`: a single support ends
            sooner when that saves eq. (5.19a) cost, only in its first half and never below 0.7
            of the time it had left); the walk's clock moves with it and the swing path is
            re-timed from where it is to land then. It moves nothing in a walk whose MPC cost
            stays below the margin (every unpushed walk measured: bit for bit the same walk).
            Default: see :data:`STEP_TIMING`.
    """

    controller: str = "wbc"
    wbc_gains: WbcGains = field(default_factory=WbcGains)
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
    walk_on: int = WALK_ON
    walk_on_distance: float = WALK_ON_DISTANCE
    com_gain: float = 1.5
    ankle_torque: bool = True
    true_momentum: bool | None = None
    stop_on_fall: bool = True
    closed_loop_ik: bool = True
    landing_margin: float = 0.02
    region_aware: str = HORIZON_MODE
    passive_landing: bool = True
    check_robot: bool = True
    swing_target_rate: bool = True
    leg_momentum: float | None = None
    capture_stop: bool = True
    torque_weight_mass: float | None = WEIGHTS_MASS
    step_timing: bool = STEP_TIMING

    def __post_init__(self) -> None:
        check_region_mode(self.region_aware)
        if self.controller not in CONTROLLERS:
            raise InputError("controller", self.controller, f"one of {', '.join(CONTROLLERS)}")
        if not isinstance(self.wbc_gains, WbcGains):
            raise InputError("wbc_gains", self.wbc_gains, "a WbcGains")
        check_fields(self, positive, ("control_dt", "swing_clearance", "shift_time", "stop_time"))
        check_fields(
            self,
            non_negative,
            (
                "settle_time",
                "hold_time",
                "com_gain",
                "landing_margin",
                "swing_side_gap",
                "heel_strike",
            ),
        )
        fb = non_negative("com_feedback", self.com_feedback)
        if fb > 1.0:
            raise InputError("com_feedback", self.com_feedback, "a share in [0, 1]")
        object.__setattr__(self, "com_feedback", fb)
        if self.true_momentum is not None and not isinstance(self.true_momentum, bool):
            raise InputError("true_momentum", self.true_momentum, "True, False or None")
        if not isinstance(self.capture_stop, bool):
            raise InputError("capture_stop", self.capture_stop, "True or False")
        if not isinstance(self.step_timing, bool):
            raise InputError("step_timing", self.step_timing, "True or False")
        if self.torque_weight_mass is not None:
            tm = positive("torque_weight_mass", self.torque_weight_mass)
            object.__setattr__(self, "torque_weight_mass", tm)
        if self.leg_momentum is None:
            lm = 0.0 if self.uses_true_momentum else LEG_MOMENTUM
        else:
            lm = non_negative("leg_momentum", self.leg_momentum)
        if lm > 1.0:
            raise InputError("leg_momentum", self.leg_momentum, "a share in [0, 1]")
        if lm > 0.0 and self.uses_true_momentum:
            raise InputError(
                "leg_momentum",
                self.leg_momentum,
                "0 when the adjuster is given the true momentum (true_momentum, or servo's "
                "default), which holds the legs' momentum already",
            )
        object.__setattr__(self, "leg_momentum", lm)
        wo = self.walk_on
        if isinstance(wo, bool) or not isinstance(wo, int) or wo < 0 or wo % 2:
            raise InputError("walk_on", wo, "an even integer >= 0 (steps are added in pairs)")
        object.__setattr__(
            self, "walk_on_distance", positive("walk_on_distance [m]", self.walk_on_distance)
        )
        it = self.ik_iterations
        if isinstance(it, bool) or not isinstance(it, int) or it < 1:
            raise InputError("ik_iterations", it, "an integer >= 1")
        pushes = tuple(self.pushes)
        for i, p in enumerate(pushes):
            if not isinstance(p, Push):
                raise InputError(f"pushes[{i}]", p, "a Push")
        object.__setattr__(self, "pushes", pushes)

    @property
    def legs_share(self) -> float:
        """``leg_momentum`` after its default (see the attribute)."""
        return float(self.leg_momentum or 0.0)

    @property
    def uses_true_momentum(self) -> bool:
        """``true_momentum`` after the controller's default (see the attribute)."""
        if self.true_momentum is None:
            return self.controller == "servo"
        return self.true_momentum


def _check_plan_robot(robot: BipedParams, model: WalkerModel | None) -> None:
    """Raise :class:`InputError` when the plan's robot is not the walker model's pendulum (mass
    and CoM height within ``PLAN_ROBOT_RTOL``, see
    :func:`~footfall.sim.biped.model.planner_params`)."""
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


def check_walk_inputs(
    scene: Scene, plan: FootstepPlan, opts: WalkOptions, model: WalkerModel | None
) -> None:
    """Raise :class:`InputError` for a plan the walk cannot follow
    (:func:`footfall.sim.biped.walk.walk` lists why)."""
    if not plan.has_solution or plan.n_steps < 1:
        raise InputError("plan", plan.status.value, "a plan with at least one footstep")
    start_stance = scene.start.stance_foot
    if np.linalg.norm(plan.footsteps[0] - start_stance) > 1e-6:
        raise InputError(
            "plan.footsteps[0]",
            plan.footsteps[0].tolist(),
            f"the scene's start stance foot {start_stance.tolist()}",
        )
    check_start_soles(scene, plan.robot)
    if opts.check_robot:
        _check_plan_robot(plan.robot, model)


def check_start_soles(scene: Scene, robot: BipedParams) -> None:
    """Raise :class:`InputError` when a start sole (``robot``'s foot_length x foot_width at the
    start heading) has a corner more than ``START_OVERHANG_TOL`` outside every region at its
    height (``LANDING_Z_TOL``): the planner needs only the sole centres on the terrain, but the
    walker stands on the soles before its first step."""
    start = scene.start
    c, s = math.cos(start.heading), math.sin(start.heading)
    half_l, half_w = robot.foot_length / 2.0, robot.foot_width / 2.0
    for side in Side:
        foot = np.asarray(start.foot(side), dtype=float)
        worst = 0.0
        for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            dx, dy = sx * half_l, sy * half_w
            corner = foot[:2] + np.array([c * dx - s * dy, s * dx + c * dy])
            gaps = [
                max(0.0, float(r.signed_distance(corner)))
                for r in scene.terrain.regions
                if abs(float(r.height_at(corner)) - float(foot[2])) <= LANDING_Z_TOL
            ]
            worst = max(worst, min(gaps, default=math.inf))
        if worst > START_OVERHANG_TOL:
            raise InputError(
                f"scene.start.{side.value}",
                foot.tolist(),
                f"a start foot whose {robot.foot_length:.3g} x {robot.foot_width:.3g} m sole "
                f"stands on the terrain (a corner is {worst:.3f} m beyond every region, at most "
                f"{START_OVERHANG_TOL} m): move the foot or enlarge its region",
            )
