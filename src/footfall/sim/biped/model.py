"""MJCF of the footfall biped, generated from :class:`BipedModel` (no downloads).

A ~30 kg humanoid lower body for document 000's validation (section 5.5): a pelvis carrying a torso
box, two 6-DoF legs (hip yaw / roll / pitch, knee, ankle pitch / roll, axes as in
:data:`footfall.robots.names.LEG_JOINT_AXES`) and flat rectangular feet. The ankle axes sit
straight above the sole centre, which is the footstep point of the planner and the ALIP contact
point. Each foot touches the ground through four small spheres at the sole corners; the foot box is
visual only. Joints are driven by position actuators (PD servos).

The planner's :class:`~footfall.models.biped.BipedParams` are *derived* from this model
(:func:`planner_params`): mass and CoM height come from MuJoCo at the nominal walking posture.

MuJoCo notes (as for the quadruped): angles in radians need ``<compiler angle="radian"/>``; robot
geoms collide only with terrain through the contype/conaffinity bits of
:mod:`footfall.robots.names`; ``cone="elliptic"`` with a high ``impratio`` keeps the feet from
creeping on the slope.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np

from footfall._mjcf import (
    TERRAIN_MATERIAL,
    SimSettings,
    box_inertia,
    fmt,
    mjcf_document,
    mjcf_preamble,
    position_actuator,
    require_mujoco,
    rod_inertia,
)
from footfall._typing import FloatArray
from footfall._validate import check_fields, non_negative, positive
from footfall.control.adjusters import U_MAX_FOOT_SHARE
from footfall.errors import InputError
from footfall.models.biped import BipedParams, ReachTrapezoid, Side
from footfall.robots import names as nm

#: the planner's swing bound L_swing for this biped [m] (``PlannerOptions.swing_max``, beyond the
#: document; :func:`footfall.sim.biped.plans.plan_for_walk` uses it): the longest swing this biped
#: has walked (the measured range, benchmarks/RESULTS.md "Biped walk"), not a tuning knob
SWING_MAX = 0.70

#: Heading segments L (eq. 5.12g-h) of the robot-aware miqcqp / kinematic plans this biped walks
#: (the document's problem and the :class:`PlannerOptions` default: 16). See
#: :func:`footfall.sim.biped.plans.plan_for_walk`: with 16, straight plans with both reach frames
#: alternate narrow and wide steps and drift sideways.
WALK_HEADING_SEGMENTS = 64


@dataclass(frozen=True)
class BipedSimSettings(SimSettings):
    """:class:`SimSettings` with gains and limits for the 30 kg biped (see the base for fields)."""

    kp: float = 5000.0
    kv: float = 100.0
    torque_limit: float = 300.0
    armature: float = 0.02


class WalkerModel(Protocol):
    """What the walker (:mod:`footfall.sim.biped.walk`) and :func:`planner_params` need of a robot.

    (our biped) and :class:`footfall.robots.model.RobotModel` (a robot file's humanoid, e.g. the G1 of
    ``example-robot-data``) implement it. The MJCF must name its elements as
    :mod:`footfall.robots.names` does (pelvis, torso, 12 leg joints and their position
    actuators, sole sites, four corner contact geoms per foot, pelvis and torso geoms).
    """

    @property
    def name(self) -> str:
        """Short robot name (``footfall walk --robot``, plan cache file names)."""
        ...

    @property
    def pelvis_height(self) -> float:
        """Pelvis body origin above the soles in the nominal posture [m]."""
        ...

    @property
    def foot_length(self) -> float:
        """Sole contact rectangle length (x) [m]; corners at +-(length/2 - corner_radius)."""
        ...

    @property
    def foot_width(self) -> float:
        """Sole contact rectangle width (y) [m]."""
        ...

    @property
    def corner_radius(self) -> float:
        """Radius of the contact spheres at the sole corners [m]."""
        ...

    @property
    def stance_width(self) -> float:
        """Lateral distance between the sole centres in the nominal posture [m]."""
        ...

    @property
    def ankle_offset(self) -> tuple[float, float]:
        """Sole centre relative to the ankle axes, (x, y) in the foot frame [m] (ours: 0, 0)."""
        ...

    def nominal_joints(self) -> FloatArray:
        """Joint angles (12,) [rad] of the nominal posture, left then right leg, LEG_JOINTS order."""
        ...

    def mjcf(self, terrain: tuple[str, str] = ("", ""), settings: Any = None) -> str:
        """MJCF text of the robot on ``terrain`` (``(asset_xml, worldbody_xml)``)."""
        ...


@dataclass(frozen=True)
class BipedModel:
    """Link dimensions, masses and joint limits of the biped (SI units, radians).

    Attributes:
        pelvis_mass: pelvis mass [kg]; the pelvis is the floating base.
        pelvis_size: pelvis box full size (x, y, z) [m].
        torso_mass: torso mass [kg].
        torso_size: torso box full size (x, y, z) [m].
        torso_offset: height of the torso centre above the pelvis centre [m].
        hip_width: lateral distance between the two hip joints [m]; also the planner's nominal
            stance width.
        hip_drop: depth of the hip joints below the pelvis centre [m].
        hip_link_mass: mass of each of the two small hip links (yaw, roll) of a leg [kg].
        thigh_length: hip pitch axis to knee axis [m].
        thigh_mass: [kg].
        shank_length: knee axis to ankle axis [m].
        shank_mass: [kg].
        ankle_height: ankle axes above the sole [m].
        foot_mass: [kg].
        foot_length: sole length (x) [m].
        foot_width: sole width (y) [m].
        corner_radius: radius of the contact spheres at the sole corners [m].
        nominal_hip_height: height of the hip joints above the soles in the walking posture [m]
            (knees bent, so the legs can lengthen when stepping up).
        joint_range: (lower, upper) limits per joint of ``LEG_JOINTS`` [rad], same for both legs
            (roll and yaw limits are mirrored for the right leg). The ankle pitch reaches -1.3 rad
            of dorsiflexion (Talos: -1.27): stepping down 0.18 m, the rear ankle sat at a -1.0
            limit in double support, the rear foot's heel lifted and the landing foot never took
            the weight (``discrete_steps``).
    """

    pelvis_mass: float = 8.0
    pelvis_size: tuple[float, float, float] = (0.12, 0.22, 0.08)
    torso_mass: float = 14.0
    torso_size: tuple[float, float, float] = (0.14, 0.24, 0.30)
    torso_offset: float = 0.22
    hip_width: float = 0.20
    hip_drop: float = 0.05
    hip_link_mass: float = 0.4
    thigh_length: float = 0.34
    thigh_mass: float = 1.6
    shank_length: float = 0.34
    shank_mass: float = 1.0
    ankle_height: float = 0.06
    foot_mass: float = 0.6
    foot_length: float = 0.20
    foot_width: float = 0.10
    corner_radius: float = 0.008
    nominal_hip_height: float = 0.60
    joint_range: tuple[tuple[float, float], ...] = (
        (-0.6, 0.6),
        (-0.4, 0.6),
        (-1.9, 0.9),
        (0.05, 2.4),
        (-1.3, 1.0),
        (-0.5, 0.5),
    )

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive,
            (
                "pelvis_mass",
                "torso_mass",
                "torso_offset",
                "hip_width",
                "hip_link_mass",
                "thigh_length",
                "thigh_mass",
                "shank_length",
                "shank_mass",
                "ankle_height",
                "foot_mass",
                "foot_length",
                "foot_width",
                "corner_radius",
                "nominal_hip_height",
            ),
            prefix="model.",
        )
        object.__setattr__(self, "hip_drop", non_negative("model.hip_drop", self.hip_drop))
        for name in ("pelvis_size", "torso_size"):
            v = getattr(self, name)
            if len(v) != 3:
                raise InputError(f"model.{name}", v, "3 box dimensions (x, y, z) [m]")
            object.__setattr__(self, name, tuple(positive(f"model.{name}", float(c)) for c in v))
        if len(self.joint_range) != len(nm.LEG_JOINTS):
            raise InputError("model.joint_range", self.joint_range, "6 (lower, upper) pairs")
        for name, (lo, hi) in zip(nm.LEG_JOINTS, self.joint_range, strict=True):
            if not lo < hi:
                raise InputError(f"model.joint_range[{name}]", (lo, hi), "lower < upper [rad]")
        if 2.0 * self.corner_radius >= min(self.foot_length, self.foot_width):
            raise InputError("model.corner_radius", self.corner_radius, "< half the foot width")
        if self.corner_radius >= self.ankle_height:
            raise InputError("model.corner_radius", self.corner_radius, "< ankle_height")
        leg = self.thigh_length + self.shank_length
        if not self.ankle_height < self.nominal_hip_height < self.ankle_height + leg:
            raise InputError(
                "model.nominal_hip_height",
                self.nominal_hip_height,
                f"between ankle_height and ankle_height + thigh + shank ({self.ankle_height + leg})",
            )

    @property
    def total_mass(self) -> float:
        """Sum of all link masses [kg]."""
        leg = 2 * self.hip_link_mass + self.thigh_mass + self.shank_mass + self.foot_mass
        return self.pelvis_mass + self.torso_mass + 2.0 * leg

    def leg_angles(self, hip_height: float) -> tuple[float, float, float]:
        """(hip pitch, knee, ankle pitch) [rad] of a leg with the hip ``hip_height`` [m] straight
        above a flat foot, torso upright (law of cosines in the sagittal plane).

        Raises:
            InputError: when the height is out of the leg's reach.
        """
        d = hip_height - self.ankle_height
        l1, l2 = self.thigh_length, self.shank_length
        if not abs(l1 - l2) < d < l1 + l2:
            raise InputError("hip_height", hip_height, f"in ({abs(l1 - l2)}, {l1 + l2}) + ankle")
        knee = math.pi - math.acos((l1 * l1 + l2 * l2 - d * d) / (2.0 * l1 * l2))
        # the thigh leans forward by a, the shank back so that the ankle ends below the hip
        a = math.acos((l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d))
        return -a, knee, knee - a

    def nominal_joints(self) -> FloatArray:
        """Joint angles (12,) of the nominal posture, left leg then right leg in LEG_JOINTS order."""
        hp, kn, ap = self.leg_angles(self.nominal_hip_height)
        leg = np.array([0.0, 0.0, hp, kn, -ap, 0.0])
        return np.concatenate([leg, leg])

    @property
    def pelvis_height(self) -> float:
        """Pelvis centre above the soles in the nominal posture [m]."""
        return self.nominal_hip_height + self.hip_drop

    @property
    def name(self) -> str:
        """``"biped"``."""
        return "biped"

    @property
    def stance_width(self) -> float:
        """Lateral distance between the sole centres in the nominal posture: ``hip_width`` [m]."""
        return self.hip_width

    @property
    def ankle_offset(self) -> tuple[float, float]:
        """Sole centre relative to the ankle axes in the foot frame: straight below, (0, 0) [m]."""
        return (0.0, 0.0)

    def mjcf(
        self, terrain: tuple[str, str] = ("", ""), settings: BipedSimSettings | None = None
    ) -> str:
        """:func:`biped_mjcf` of this model."""
        return biped_mjcf(self, terrain, settings)


def _joint_range(p: BipedModel, side: Side, index: int) -> tuple[float, float]:
    lo, hi = p.joint_range[index]
    # roll and yaw limits are given for the left leg; the right leg is its mirror image
    if side is Side.RIGHT and nm.LEG_JOINTS[index] in ("hip_yaw", "hip_roll", "ankle_roll"):
        return -hi, -lo
    return lo, hi


def _leg_xml(p: BipedModel, s: BipedSimSettings, side: Side) -> str:
    y = side.sign * p.hip_width / 2.0
    r = p.corner_radius
    hl = fmt(*box_inertia(p.hip_link_mass, 0.06, 0.06, 0.06))
    ti = fmt(*rod_inertia(p.thigh_mass, p.thigh_length, 0.04))
    si = fmt(*rod_inertia(p.shank_mass, p.shank_length, 0.035))
    foot_h = 0.03
    fi = fmt(*box_inertia(p.foot_mass, p.foot_length, p.foot_width, foot_h))
    nocol = 'contype="0" conaffinity="0"'
    col = f'contype="{nm.ROBOT_CONTYPE}" conaffinity="{nm.ROBOT_CONAFFINITY}"'

    def jnt(i: int) -> str:
        lo, hi = _joint_range(p, side, i)
        return (
            f'<joint name="{nm.joint(side, nm.LEG_JOINTS[i])}" axis="{nm.LEG_JOINT_AXES[i]}" '
            f'range="{fmt(lo, hi)}"/>'
        )

    corners = "\n".join(
        f'              <geom name="{nm.corner_geom(side, k)}" type="sphere" size="{r:.6g}" '
        f'pos="{fmt(cx * (p.foot_length / 2 - r), cy * (p.foot_width / 2 - r), -p.ankle_height + r)}" '
        f'material="foot" friction="{s.friction:.6g} 0.02 0.002" {col}/>'
        for k, (cx, cy) in enumerate(nm.FOOT_CORNERS)
    )
    link = nm.link_body
    return f"""
      <body name="{link(side, "hip_yaw")}" pos="{fmt(0.0, y, -p.hip_drop)}">
        {jnt(0)}
        <inertial pos="0 0 0" mass="{p.hip_link_mass:.6g}" diaginertia="{hl}"/>
        <body name="{link(side, "hip_roll")}">
          {jnt(1)}
          <inertial pos="0 0 0" mass="{p.hip_link_mass:.6g}" diaginertia="{hl}"/>
          <geom type="sphere" size="0.045" material="joint" {nocol}/>
          <body name="{link(side, "hip_pitch")}">
            {jnt(2)}
            <inertial pos="0 0 {-p.thigh_length / 2:.6g}" mass="{p.thigh_mass:.6g}"
                      diaginertia="{ti}"/>
            <geom type="capsule" fromto="0 0 0 0 0 {-p.thigh_length:.6g}" size="0.04"
                  material="leg" {nocol}/>
            <body name="{link(side, "knee")}" pos="0 0 {-p.thigh_length:.6g}">
              {jnt(3)}
              <inertial pos="0 0 {-p.shank_length / 2:.6g}" mass="{p.shank_mass:.6g}"
                        diaginertia="{si}"/>
              <geom type="capsule" fromto="0 0 0 0 0 {-p.shank_length:.6g}" size="0.035"
                    material="leg" {nocol}/>
              <body name="{link(side, "ankle_pitch")}" pos="0 0 {-p.shank_length:.6g}">
                {jnt(4)}
                <inertial pos="0 0 0" mass="0.05" diaginertia="1e-5 1e-5 1e-5"/>
                <body name="{nm.foot_body(side)}">
                  {jnt(5)}
                  <inertial pos="0 0 {-p.ankle_height + foot_h / 2:.6g}"
                            mass="{p.foot_mass:.6g}" diaginertia="{fi}"/>
                  <geom name="{nm.foot_geom(side)}" type="box"
                        size="{fmt(p.foot_length / 2, p.foot_width / 2, foot_h / 2)}"
                        pos="0 0 {-p.ankle_height + foot_h / 2:.6g}" material="foot" {nocol}/>
{corners}
                  <site name="{nm.sole_site(side)}" pos="0 0 {-p.ankle_height:.6g}" size="0.01"/>
                </body>
              </body>
            </body>
          </body>
        </body>
      </body>"""


def biped_mjcf(
    params: BipedModel | None = None,
    terrain: tuple[str, str] = ("", ""),
    settings: BipedSimSettings | None = None,
) -> str:
    """MJCF text of the biped on a terrain.

    Args:
        params: link parameters (default :class:`BipedModel`).
        terrain: ``(asset_xml, worldbody_xml)`` of the terrain (see
            :func:`footfall.sim.biped.terrain_mjcf.terrain_xml`); empty = no ground at all.
        settings: physics and actuator settings.

    Returns:
        The MJCF document. The robot's ankle-pitch joint carries 0.05 kg (axis hub), which is
        why the ``total_mass`` of the model exceeds :attr:`BipedModel.total_mass` by 0.1 kg.
    """
    p = params if params is not None else BipedModel()
    s = settings if settings is not None else BipedSimSettings()
    asset_xml, world_xml = terrain
    pi = fmt(*box_inertia(p.pelvis_mass, *p.pelvis_size))
    ti = fmt(*box_inertia(p.torso_mass, *p.torso_size))
    legs = "".join(_leg_xml(p, s, side) for side in (Side.LEFT, Side.RIGHT))
    actuators = "\n    ".join(
        position_actuator(nm.actuator(side, j), f'"{nm.joint(side, j)}"', s)
        for side in (Side.LEFT, Side.RIGHT)
        for j in nm.LEG_JOINTS
    )
    preamble = mjcf_preamble(s, 0.5, f'solref="0.004 1" group="{nm.ROBOT_GROUP}"', 2048)
    col = f'contype="{nm.ROBOT_CONTYPE}" conaffinity="{nm.ROBOT_CONAFFINITY}"'
    world = f"""{world_xml}
    <body name="{nm.PELVIS_BODY}" pos="0 0 {p.pelvis_height:.6g}">
      <freejoint name="{nm.ROOT_JOINT}"/>
      <camera name="{nm.TRACK_CAMERA}" mode="trackcom" pos="0.3 -2.6 0.6"
              xyaxes="1 0 0 0 0.2 1"/>
      <inertial pos="0 0 0" mass="{p.pelvis_mass:.6g}" diaginertia="{pi}"/>
      <geom name="{nm.PELVIS_GEOM}" type="box" size="{fmt(*(c / 2 for c in p.pelvis_size))}"
            material="body" {col}/>
      <body name="{nm.TORSO_BODY}" pos="0 0 {p.torso_offset:.6g}">
        <inertial pos="0 0 0" mass="{p.torso_mass:.6g}" diaginertia="{ti}"/>
        <geom name="{nm.TORSO_GEOM}" type="box" size="{fmt(*(c / 2 for c in p.torso_size))}"
              material="body" {col}/>
      </body>{legs}
    </body>"""
    return mjcf_document(
        nm.MODEL_NAME, preamble, f"{TERRAIN_MATERIAL}\n    {asset_xml}", world, actuators
    )


@dataclass(frozen=True)
class ModelInfo:
    """Quantities of the compiled model at the nominal posture, measured by MuJoCo.

    Attributes:
        mass: total mass [kg].
        com_height: CoM height above the soles, feet flat side by side [m].
        com_offset: horizontal CoM offset from the midpoint of the soles, (2,) [m].
    """

    mass: float
    com_height: float
    com_offset: tuple[float, float]


def measure_model(params: WalkerModel | None = None) -> ModelInfo:
    """Compile the model without terrain and measure its mass and nominal CoM height.

    The pelvis is placed upright at ``pelvis_height`` with the joints at ``nominal_joints()``;
    the CoM is the pelvis subtree's (the whole robot), relative to the midpoint of the two sole
    sites.
    """
    mujoco = require_mujoco()
    p: WalkerModel = params if params is not None else BipedModel()
    model = mujoco.MjModel.from_xml_string(p.mjcf())
    data = mujoco.MjData(model)
    root = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, nm.ROOT_JOINT)]
    data.qpos[root : root + 3] = (0.0, 0.0, p.pelvis_height)
    data.qpos[root + 3 : root + 7] = (1.0, 0.0, 0.0, 0.0)
    q = p.nominal_joints()
    for i, side in enumerate((Side.LEFT, Side.RIGHT)):
        for j, name in enumerate(nm.LEG_JOINTS):
            jid = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, nm.joint(side, name))
            data.qpos[model.jnt_qposadr[jid]] = q[6 * i + j]
    mujoco.mj_forward(model, data)
    pelvis = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, nm.PELVIS_BODY)
    com = np.array(data.subtree_com[pelvis])
    soles = [
        data.site_xpos[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_SITE, nm.sole_site(s))]
        for s in (Side.LEFT, Side.RIGHT)
    ]
    mid = 0.5 * (soles[0] + soles[1])
    return ModelInfo(
        mass=float(np.sum(model.body_mass)),
        com_height=float(com[2] - mid[2]),
        com_offset=(float(com[0] - mid[0]), float(com[1] - mid[1])),
    )


#: the swing of the longest step (``SWING_MAX``) may ask the hip pitch for at most this share of its
#: torque limit: on the G1 (88 N m) T_ss = 0.4 s needs 54 % and saturated the swing hip in 15-18 %
#: of the physics steps, 0.45 s: 6 %, 0.5 s: 1 % (benchmarks/RESULTS.md, "Robots from their
#: files"); footfall's biped at 0.4 s: 10 %
SWING_TORQUE_SHARE = 0.4
#: ... and its moment on the body at most this times the moment the stance sole holds,
#: ``m g foot_length / 2``: our biped walks at 1.09 (T_ss = 0.4 s), the G1 fell at 1.73 (0.4 s)
#: and walked at 1.11 (0.5 s)
SWING_MOMENT_RATIO = 1.1


def swing_time(
    inertia: float,
    hip_height: float,
    hip_torque: float,
    mass: float,
    foot_length: float,
    swing_length: float = SWING_MAX,
    g: float = 9.81,
) -> float:
    """The shortest single support T_ss [s] in which the walker's swing of ``swing_length`` D
    [m] (a quintic over the ``SWING_MOVE`` share of T_ss, peak acceleration ``5.77 D / T^2``)
    asks the hip pitch (``hip_torque`` [N m], inf: no limit) for at most ``SWING_TORQUE_SHARE``
    of its limit and moves the body with at most ``SWING_MOMENT_RATIO`` times the sole's moment
    ``m g foot_length / 2``.

    The swing's hip torque is ``inertia * a / hip_height``: the leg (``inertia`` [kg m^2] about
    its hip) swung by its foot's acceleration ``a`` ``hip_height`` [m] below the hip; the same
    moment acts back on the body, where the stance sole and the ALIP's CoM motion take it.
    """
    from footfall.sim.biped.references import QUINTIC_PEAK_ACC, SWING_MOVE

    cap = SWING_MOMENT_RATIO * mass * g * foot_length / 2.0
    if math.isfinite(hip_torque):
        cap = min(cap, SWING_TORQUE_SHARE * hip_torque)
    t_move = math.sqrt(QUINTIC_PEAK_ACC * swing_length * inertia / (hip_height * cap))
    return t_move / (SWING_MOVE[1] - SWING_MOVE[0])


def planner_params(
    params: WalkerModel | None = None, base: BipedParams | None = None
) -> BipedParams:
    """The planner's robot parameters derived from the MuJoCo model (ours or a robot file's).

    Mass and CoM height are measured (:func:`measure_model`); stance width and foot size are the
    model's; the ankle-torque bound is ``U_MAX_FOOT_SHARE * m g * foot_width / 2`` (or the base's,
    if smaller) so that a planned ZMP always lies inside the sole.

    A robot file's model (``robot_limits``) also sets what its legs allow: the reach trapezoid
    and step height derived by inverse kinematics (:func:`footfall.robots.derive.derive_reach`),
    T_ss no shorter than :func:`swing_time` of its swing leg (rounded up to 10 ms), and U_max no
    larger than the ankle joints can give beyond the moment of the weight on the sole centre's
    offset from the ankle axes. Footfall's own biped keeps the base's (the document's) timing
    and reach. Everything else (T_ds, heading limits) comes from ``base`` (default
    :class:`BipedParams`).
    """
    p: WalkerModel = params if params is not None else BipedModel()
    b = base if base is not None else BipedParams()
    info = measure_model(p)
    u_max = min(b.u_max, U_MAX_FOOT_SHARE * info.mass * b.g * p.foot_width / 2.0)
    derived: dict[str, Any] = {}
    limits = getattr(p, "robot_limits", None)
    if limits is not None:
        reach, leg = limits()
        weight = info.mass * b.g
        dx, dy = p.ankle_offset
        pitch, roll = leg.ankle_torque
        u_max = min(u_max, pitch - abs(dx) * weight, roll - abs(dy) * weight)
        if u_max <= 0.0:
            raise InputError(
                "robot.ankle_torque",
                leg.ankle_torque,
                f"ankle torque limits above the weight's moment ({abs(dx) * weight:.3g} N m)",
            )
        t_need = swing_time(
            leg.inertia, leg.hip_height, leg.hip_torque, info.mass, p.foot_length, SWING_MAX, b.g
        )
        derived = {
            "t_ss": max(b.t_ss, math.ceil(t_need * 100.0 - 1e-9) / 100.0),
            "reach": ReachTrapezoid(np.array(reach.vertices, dtype=float)),
            "step_height_max": reach.step_height_max,
        }
    return replace(
        b,
        mass=info.mass,
        com_height=info.com_height,
        stance_width=p.stance_width,
        foot_length=p.foot_length,
        foot_width=p.foot_width,
        u_max=u_max,
        **derived,
    )
