"""MJCF of the document-001 quadruped, generated from :class:`QuadrupedRobot` (no downloads).

The model mirrors the planner's assumptions: hip ab/ad and hip pitch axes meet at the hip, thigh
and shank are straight links of the robot's lengths, masses sit at the hip and at the link
midpoints (explicit ``<inertial>``), the foot is a sphere whose centre is the planner's foot point.
Joints are driven by position actuators.

Scenes: a plane sloped by ``slope`` rising along +x (``slope_scene``), a flight of stairs
(``stairs_scene``), or any :mod:`footfall.quadruped.ground` (``ground_scene``: also side slopes and
varying slopes, the latter as a chain of thin boxes). The foot-centre plane of the planner passes through the world origin, so the
ground plane is placed one foot radius below it along its normal.

MuJoCo notes (measured for this issue): angles are in radians only with
``<compiler angle="radian"/>``; robot geoms would collide with each other without the
contype/conaffinity bits of :mod:`footfall.sim.quadruped.names`; feet creep down a 15 degree slope with the
default pyramidal cone, which ``cone="elliptic" impratio="10"`` stops.
"""

from __future__ import annotations

import math
from dataclasses import replace
from xml.sax.saxutils import quoteattr

import numpy as np

from footfall._mjcf import (
    SimSettings,
    box_inertia,
    fmt,
    mjcf_document,
    mjcf_preamble,
    position_actuator,
)
from footfall._validate import positive
from footfall.errors import InputError
from footfall.quadruped.ground import PlaneGround, QuadrupedGround, VaryingSlope
from footfall.quadruped.robot import DOCUMENT_LINK_RADII, JOINT_NAMES, LEGS, QuadrupedRobot
from footfall.sim.quadruped import names as nm

#: joint axes in the parent body frame, in ``JOINT_NAMES`` order (ab/ad about x, pitch/knee about y)
_JOINT_AXES = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 1.0, 0.0))


def _quat_about_y(angle: float) -> tuple[float, float, float, float]:
    return math.cos(angle / 2.0), 0.0, math.sin(angle / 2.0), 0.0


def slope_floor_xml(slope: float, foot_radius: float) -> str:
    """Sloped ground plane rising along +x by ``slope`` [rad]."""
    # the plane's normal n = (-sin b, 0, cos b); place it r below the foot-centre plane
    n = np.array([-math.sin(slope), 0.0, math.cos(slope)])
    pos = -foot_radius * n
    return (
        f'<geom name="{nm.FLOOR_GEOM}" type="plane" size="40 8 0.1" pos="{fmt(*pos)}" '
        f'quat="{fmt(*_quat_about_y(-slope))}" material="ground" '
        f'contype="{nm.GROUND_CONTYPE}" conaffinity="{nm.GROUND_CONAFFINITY}"/>'
    )


def side_slope_floor_xml(ground: PlaneGround, foot_radius: float) -> str:
    """Plane of ``ground`` (a slope with a side slope), one foot radius below its foot-centre
    plane (which passes through the origin)."""
    n = ground.normal(0.0, 0.0)
    pos = -foot_radius * n
    return (
        f'<geom name="{nm.FLOOR_GEOM}" type="plane" size="40 8 0.1" pos="{fmt(*pos)}" '
        f'zaxis="{fmt(*n)}" material="ground" '
        f'contype="{nm.GROUND_CONTYPE}" conaffinity="{nm.GROUND_CONAFFINITY}"/>'
    )


#: length of one plank of a varying slope [m] (the inclination changes by well under 1 degree)
PLANK_LENGTH = 0.05
#: thickness of a plank [m]
PLANK_THICKNESS = 0.1


def varying_slope_xml(
    ground: VaryingSlope, foot_radius: float, x_range: tuple[float, float]
) -> str:
    """A varying slope over ``x_range`` [m] as a chain of thin boxes ("planks") whose top faces
    form the polyline through the ground points under foot centres every :data:`PLANK_LENGTH`:
    the ground is the foot-centre curve offset by one foot radius along its normal."""
    x0, x1 = x_range
    n = max(2, math.ceil((x1 - x0) / PLANK_LENGTH) + 1)
    xs = np.linspace(x0, x1, n)
    pts = []
    for x in xs:
        b = ground.inclination(float(x))
        pts.append(
            (
                x + foot_radius * math.sin(b),
                ground.centre_height(float(x)) - foot_radius * math.cos(b),
            )
        )
    parts = []
    for k in range(n - 1):
        (ax, az), (bx, bz) = pts[k], pts[k + 1]
        length = math.hypot(bx - ax, bz - az)
        phi = math.atan2(bz - az, bx - ax)
        # box centre half a thickness below the segment's midpoint, along its normal
        cx = 0.5 * (ax + bx) + 0.5 * PLANK_THICKNESS * math.sin(phi)
        cz = 0.5 * (az + bz) - 0.5 * PLANK_THICKNESS * math.cos(phi)
        name = nm.FLOOR_GEOM if k == 0 else f"{nm.PLANK_GEOM_PREFIX}{k}"
        parts.append(
            f'<geom name="{name}" type="box" size="{fmt(length / 2, 8.0, PLANK_THICKNESS / 2)}" '
            f'pos="{fmt(cx, 0.0, cz)}" quat="{fmt(*_quat_about_y(-phi))}" material="ground" '
            f'contype="{nm.GROUND_CONTYPE}" conaffinity="{nm.GROUND_CONAFFINITY}"/>'
        )
    return "\n    ".join(parts)


def stairs_xml(
    rise: float,
    run: float,
    steps: int,
    width: float,
    start_x: float,
    foot_radius: float,
    landing: float = 0.0,
) -> str:
    """A flat floor and ``steps`` boxes rising by ``rise`` every ``run`` metres from ``start_x``;
    the top step reaches ``landing`` metres further (a landing)."""
    rise = positive("stairs.rise", rise)
    run = positive("stairs.run", run)
    if steps < 1:
        raise InputError("stairs.steps", steps, "an integer >= 1")
    parts = [
        f'<geom name="{nm.FLOOR_GEOM}" type="plane" size="40 8 0.1" pos="0 0 {-foot_radius:.6g}" '
        f'material="ground" contype="{nm.GROUND_CONTYPE}" '
        f'conaffinity="{nm.GROUND_CONAFFINITY}"/>'
    ]
    for k in range(steps):
        top = (k + 1) * rise - foot_radius
        x0 = start_x + k * run
        # each box reaches from the floor to its tread and to the end of the flight (landing)
        length = (steps - k) * run + landing
        parts.append(
            f'<geom name="{nm.STAIR_GEOM_PREFIX}{k}" type="box" '
            f'size="{fmt(length / 2, width / 2, (top + foot_radius) / 2)}" '
            f'pos="{fmt(x0 + length / 2, 0.0, (top - foot_radius) / 2)}" material="stairs" '
            f'contype="{nm.GROUND_CONTYPE}" conaffinity="{nm.GROUND_CONAFFINITY}"/>'
        )
    return "\n    ".join(parts)


def robot_settings(robot: QuadrupedRobot, friction: float | None = None) -> SimSettings:
    """Physics settings for ``robot``: the defaults (made for document 001's 100 kg, 0.6 m robot)
    scaled by its mass ratio ``m`` and size ``k`` (its stance height over 0.6 m) as their units
    scale at the same Froude number (times by ``sqrt(k)``): rotor armature [kg m^2] by ``m k^2``,
    joint damping and servo damping [N m s / rad] by ``m k^1.5``, servo stiffness [N m / rad] by
    ``m k``. The document's robot gets the defaults."""
    base = SimSettings()
    if robot.legs is not None:
        m = robot.total_mass / QuadrupedRobot().total_mass
        k = robot.stance_height / QuadrupedRobot().stance_height
        base = replace(
            base,
            armature=base.armature * m * k * k,
            joint_damping=base.joint_damping * m * k**1.5,
            kp=base.kp * m * k,
            kv=base.kv * m * k**1.5,
        )
    return base if friction is None else replace(base, friction=friction)


def _inertial(pos: tuple[float, ...], mass: float, inertia: tuple[float, ...]) -> str:
    """An ``<inertial>`` element (diagonal when the products of inertia are zero)."""
    if any(abs(v) > 0.0 for v in inertia[3:]):
        tensor = f'fullinertia="{fmt(*inertia)}"'
    else:
        tensor = f'diaginertia="{fmt(*inertia[:3])}"'
    return f'<inertial pos="{fmt(*pos)}" mass="{mass:.6g}" {tensor}/>'


def _pos(v: tuple[float, ...]) -> str:
    """A ``pos`` attribute, left out at the origin."""
    return f' pos="{fmt(*v)}"' if any(abs(x) > 0.0 for x in v) else ""


def _leg_xml(robot: QuadrupedRobot, settings: SimSettings, leg_index: int) -> str:
    leg = LEGS[leg_index]
    geo = robot.leg_geometry(leg)
    lo, hi = geo.lower, geo.upper
    r = robot.foot_radius
    hip = robot.hip_offset(leg)
    scale = robot.thigh_length / QuadrupedRobot().thigh_length
    hip_r, thigh_r, shank_r = (scale * v for v in DOCUMENT_LINK_RADII)
    nocol = 'contype="0" conaffinity="0"'
    j = [nm.joint(leg, name) for name in JOINT_NAMES]
    axes = [
        fmt(*(sg * a + 0.0 for a in axis)) for sg, axis in zip(geo.signs, _JOINT_AXES, strict=True)
    ]
    fs = geo.foot
    return f"""
      <body name="{nm.hip_body(leg)}" pos="{fmt(*hip)}">
        <joint name="{j[0]}" axis="{axes[0]}" range="{fmt(lo[0], hi[0])}"/>
        {_inertial(geo.coms[0], geo.masses[0], geo.inertias[0])}
        <geom type="sphere" size="{hip_r:.6g}" material="joint" {nocol}/>
        <body name="{nm.thigh_body(leg)}"{_pos(geo.hfe)}>
          <joint name="{j[1]}" axis="{axes[1]}" range="{fmt(lo[1], hi[1])}"/>
          {_inertial(geo.coms[1], geo.masses[1], geo.inertias[1])}
          <geom type="capsule" fromto="0 0 0 {fmt(*geo.knee)}" size="{thigh_r:.6g}" material="leg"
                {nocol}/>
          <body name="{nm.shank_body(leg)}" pos="{fmt(*geo.knee)}">
            <joint name="{j[2]}" axis="{axes[2]}" range="{fmt(lo[2], hi[2])}"/>
            {_inertial(geo.coms[2], geo.masses[2], geo.inertias[2])}
            <geom type="capsule" fromto="0 0 0 {fmt(*fs)}" size="{shank_r:.6g}" material="leg"
                  {nocol}/>
            <geom name="{nm.foot_geom(leg)}" type="sphere" size="{r:.6g}" pos="{fmt(*fs)}"
                  material="foot" friction="{settings.friction:.6g} 0.02 0.002" priority="1"
                  contype="{nm.ROBOT_CONTYPE}" conaffinity="{nm.ROBOT_CONAFFINITY}"/>
            <site name="{nm.foot_site(leg)}" pos="{fmt(*fs)}" size="0.01"/>
          </body>
        </body>
      </body>"""


def quadruped_mjcf(
    robot: QuadrupedRobot,
    ground_xml: str,
    settings: SimSettings | None = None,
) -> str:
    """MJCF text of the robot on the ground described by ``ground_xml``.

    Args:
        robot: robot parameters.
        ground_xml: worldbody geoms of the terrain (see :func:`slope_floor_xml`,
            :func:`stairs_xml`).
        settings: physics and actuator settings.

    Returns:
        The MJCF document as a string.
    """
    s = settings if settings is not None else SimSettings()
    bi: tuple[float, ...]
    if robot.body_inertia is None:
        bi = (
            *box_inertia(robot.body_mass, robot.body_length, robot.body_width, robot.body_height),
            0.0,
            0.0,
            0.0,
        )
    else:
        bi = robot.body_inertia
    legs = "".join(_leg_xml(robot, s, i) for i in range(len(LEGS)))
    actuators = "\n    ".join(
        position_actuator(
            nm.actuator(leg, jn),
            quoteattr(nm.joint(leg, jn)),
            s if (tq := robot.leg_geometry(leg).torque) is None else replace(s, torque_limit=tq[k]),
        )
        for leg in LEGS
        for k, jn in enumerate(JOINT_NAMES)
    )
    preamble = mjcf_preamble(s, s.joint_damping, 'solref="0.005 1"', 0)
    half = (robot.body_length / 2, robot.body_width / 2, robot.body_height / 2)
    assets = (
        '<material name="ground" texture="grid" texrepeat="8 8" texuniform="true"/>\n'
        '    <material name="stairs" rgba="0.6 0.55 0.5 1"/>'
    )
    world = f"""{ground_xml}
    <body name="{nm.TRUNK_BODY}" pos="0 0 1">
      <freejoint name="{nm.ROOT_JOINT}"/>
      <camera name="{nm.TRACK_CAMERA}" mode="trackcom" pos="0.6 -3.2 0.9"
              xyaxes="1 0 0 0 0.25 1"/>
      {_inertial(robot.body_com, robot.body_mass, bi)}
      <geom name="{nm.TRUNK_GEOM}" type="box" size="{fmt(*half)}" material="body"
            contype="{nm.ROBOT_CONTYPE}" conaffinity="{nm.ROBOT_CONAFFINITY}"/>{legs}
    </body>"""
    return mjcf_document(nm.MODEL_NAME, preamble, assets, world, actuators)


def slope_scene(robot: QuadrupedRobot, slope: float, settings: SimSettings | None = None) -> str:
    """MJCF of the robot on a plane sloped by ``slope`` [rad] rising along +x."""
    return quadruped_mjcf(robot, slope_floor_xml(slope, robot.foot_radius), settings)


def stairs_scene(
    robot: QuadrupedRobot,
    rise: float = 0.1,
    run: float = 0.4,
    steps: int = 6,
    start_x: float = 0.8,
    settings: SimSettings | None = None,
    landing: float = 0.0,
) -> str:
    """MJCF of the robot in front of a flight of ``steps`` stairs (rise/run in metres)."""
    ground = stairs_xml(
        rise, run, steps, 3.0 * robot.body_width, start_x, robot.foot_radius, landing
    )
    return quadruped_mjcf(robot, ground, settings)


def ground_scene(
    robot: QuadrupedRobot,
    ground: QuadrupedGround,
    settings: SimSettings | None = None,
    x_range: tuple[float, float] = (-3.0, 12.0),
) -> str:
    """MJCF of the robot on ``ground`` (:mod:`footfall.quadruped.ground`); a varying slope is
    built over ``x_range`` [m]."""
    r = robot.foot_radius
    if isinstance(ground, PlaneGround):
        if ground.side_slope == 0.0:
            return slope_scene(robot, ground.slope, settings)
        return quadruped_mjcf(robot, side_slope_floor_xml(ground, r), settings)
    if isinstance(ground, VaryingSlope):
        return quadruped_mjcf(robot, varying_slope_xml(ground, r, x_range), settings)
    return stairs_scene(
        robot,
        ground.rise,
        ground.run,
        ground.steps,
        ground.start_x,
        settings,
        landing=ground.landing,
    )
