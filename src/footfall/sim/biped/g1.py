"""The Unitree G1 humanoid of ``example-robot-data`` as a walker model (issue 7, beyond the document).

Optional extra: ``pip install 'footfall[robots]'`` (the ``example-robot-data`` wheel bundles the
G1's URDF, ``g1_29dof_rev_1_0.urdf``). :func:`g1_spec` builds a MuJoCo model from that URDF through
``mujoco.MjSpec``:

- the URDF's inertials are kept as they are (total 33.3 kg); its visual and collision geometry
  (STL meshes, small spheres) is dropped, so no mesh file is read;
- the 12 leg joints stay, renamed to :mod:`footfall.sim.biped.names` (``left_hip_yaw`` ...
  ``right_ankle_roll``); every other revolute joint (waist yaw / roll / pitch, arms, wrists) is
  made fixed at its zero angle, so the walker drives the same 12 joints as on our biped and the
  whole-body IK cannot swing the arms to move the CoM;
- a free joint ``root`` on the ``pelvis``; ``torso_link`` is renamed ``torso``;
- each foot gets a flat sole: four contact spheres at the URDF's four foot collision spheres
  (heel x = -0.05 m, y = +-0.025 m; toe x = 0.12 m, y = +-0.03 m; z = -0.03 m; radius 5 mm in
  the ankle-roll link), a visual sole box and the sole site at the centre of the heel-toe
  rectangle on the contact plane. The sole centre lies 35 mm ahead of the ankle axes
  (:attr:`G1Model.ankle_offset`, which the walker's ankle torque accounts for);
- a pelvis box and a torso box collide with the terrain only (fall detection, as on our biped);
  thin capsules between the joints are visual only;
- a position servo on each leg joint: force limit = the URDF's ``effort`` (88 / 139 N m at the
  hips and knees, 35 N m at the ankles), ``kp = effort / servo_saturation`` (the error at which
  the servo saturates), ``kv = kp * servo_damping_time``.

Beyond the document: the nominal posture is solved numerically (:func:`g1_nominal_posture`): the
pelvis upright at ``nominal_pelvis_height`` above flat soles ``stance_width`` apart, knees bent,
the soles moved forward until the whole-body CoM lies above the sole centres.
"""

from __future__ import annotations

import functools
import importlib.metadata
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import check_fields, non_negative, positive
from footfall.errors import FootfallError, InputError, MissingExtraError
from footfall.models.biped import Side
from footfall.sim.biped import names as nm
from footfall.sim.biped.model import require_mujoco

#: the distribution and the G1's URDF inside its cmeel prefix
ERD_DISTRIBUTION = "example-robot-data"
G1_URDF = "cmeel.prefix/share/example-robot-data/robots/g1_description/urdf/g1_29dof_rev_1_0.urdf"
#: the extra that installs it
ROBOTS_EXTRA = "pip install 'footfall[robots]'"
#: URDF names of the G1's torso link and of its leg joints (``<side>_<LEG_JOINTS name>_joint``)
G1_TORSO_LINK = "torso_link"
G1_JOINT_SUFFIX = "_joint"
#: the G1's foot collision spheres in the ankle-roll link frame (URDF): heel x, toe x, heel half
#: width, toe half width, height, radius [m]
G1_HEEL_X, G1_TOE_X = -0.05, 0.12
G1_HEEL_HALF_WIDTH, G1_TOE_HALF_WIDTH = 0.025, 0.03
G1_SPHERE_Z, G1_SPHERE_RADIUS = -0.03, 0.005
#: pelvis and torso collision boxes for fall detection: (centre (3,), half sizes (3,)) in the
#: pelvis / torso_link frames [m], enclosing the URDF's meshes roughly
PELVIS_BOX = ((0.0, 0.0, -0.05), (0.07, 0.11, 0.06))
TORSO_BOX = ((0.0, 0.0, 0.2), (0.08, 0.11, 0.16))
#: radius of the visual capsules between joints [m]
LINK_RADIUS = 0.025
#: the nominal posture solve: residual tolerance [m, rad]
POSTURE_TOL = 1e-9


@functools.cache
def g1_urdf_path() -> Path:
    """Path of the G1's URDF in the installed ``example-robot-data`` distribution.

    Raises:
        MissingExtraError: when ``example-robot-data`` is not installed (naming the extra).
    """
    try:
        dist = importlib.metadata.distribution(ERD_DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError:
        raise MissingExtraError(
            f"the Unitree G1 model needs the {ERD_DISTRIBUTION!r} package: {ROBOTS_EXTRA}"
        ) from None
    path = Path(str(dist.locate_file(G1_URDF)))
    if not path.is_file():
        raise MissingExtraError(
            f"{ERD_DISTRIBUTION} {dist.version} has no {G1_URDF}: {ROBOTS_EXTRA} (>= 6.0)"
        )
    return path


def g1_urdf_efforts(path: Path | None = None) -> dict[str, float]:
    """``effort`` limit [N m] of every revolute URDF joint, by URDF joint name."""
    root = ET.parse(path if path is not None else g1_urdf_path()).getroot()
    return {
        j.get("name", ""): float(lim.get("effort", "nan"))
        for j in root.findall("./joint")
        if j.get("type") == "revolute" and (lim := j.find("limit")) is not None
    }


def urdf_joint(side: Side, name: str) -> str:
    """The G1's URDF name of our leg joint ``name`` (one of ``LEG_JOINTS``), e.g. ``left_knee_joint``."""
    return nm.joint(side, name) + G1_JOINT_SUFFIX


@dataclass(frozen=True)
class G1Model:
    """Settings of the G1 walker model; its geometry and masses come from the URDF.

    Attributes:
        stance_width: lateral distance between the sole centres in the nominal posture [m]; the
            built-in scenes start with the feet 0.2 m apart (our biped's hip width), the G1's hip
            roll joints are 0.233 m apart, so its hips roll in by ~2 degrees.
        nominal_pelvis_height: pelvis origin above the soles in the walking posture [m] (straight
            legs: 0.79 m; 0.66 m bends the knees as much as our biped's 0.65 of 0.79 m).
        servo_saturation: joint error at which a leg servo reaches its URDF effort limit [rad]
            (``kp = effort / servo_saturation``).
        servo_damping_time: ``kv / kp`` of the leg servos [s] (ours: 100 / 5000 = 0.02 s).
        armature: rotor inertia added to each leg joint [kg m^2] (the URDF has none).
        joint_damping: viscous damping of each leg joint [N m s / rad].
        timestep: physics step [s].
        friction: sliding friction between the soles and the ground.
        impratio: frictional to normal constraint impedance ratio (elliptic cone).
    """

    stance_width: float = 0.20
    nominal_pelvis_height: float = 0.66
    servo_saturation: float = 0.05
    servo_damping_time: float = 0.02
    armature: float = 0.02
    joint_damping: float = 0.5
    timestep: float = 0.002
    friction: float = 1.0
    impratio: float = 10.0

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive,
            (
                "stance_width",
                "nominal_pelvis_height",
                "servo_saturation",
                "servo_damping_time",
                "timestep",
                "friction",
                "impratio",
            ),
            prefix="g1.",
        )
        check_fields(self, non_negative, ("armature", "joint_damping"), prefix="g1.")

    # ------------------------------------------------------------------ WalkerModel
    @property
    def name(self) -> str:
        """``"g1"``."""
        return "g1"

    @property
    def pelvis_height(self) -> float:
        """Pelvis origin above the soles in the nominal posture [m]."""
        return self.nominal_pelvis_height

    @property
    def foot_length(self) -> float:
        """Sole contact rectangle length: heel to toe sphere centres plus a radius each end [m]."""
        return G1_TOE_X - G1_HEEL_X + 2.0 * G1_SPHERE_RADIUS

    @property
    def foot_width(self) -> float:
        """Sole contact rectangle width: the narrower (heel) sphere pair plus a radius each side
        [m]; the toe spheres are 5 mm further out, so the rectangle lies inside the contacts."""
        return 2.0 * (G1_HEEL_HALF_WIDTH + G1_SPHERE_RADIUS)

    @property
    def corner_radius(self) -> float:
        """Radius of the corner contact spheres [m] (the URDF's)."""
        return G1_SPHERE_RADIUS

    @property
    def ankle_offset(self) -> tuple[float, float]:
        """Sole centre relative to the ankle axes in the foot frame (x, y) [m]."""
        return (0.5 * (G1_HEEL_X + G1_TOE_X), 0.0)

    def nominal_joints(self) -> FloatArray:
        """Joint angles (12,) [rad] of the nominal posture (:func:`g1_nominal_posture`)."""
        return np.array(g1_nominal_posture(self))

    def mjcf(self, terrain: tuple[str, str] = ("", ""), settings: Any = None) -> str:
        """MJCF text of the G1 on ``terrain`` (``(asset_xml, worldbody_xml)``).

        Raises:
            InputError: when ``settings`` is given: the G1's physics and servo settings are
                fields of :class:`G1Model` (gains come from the URDF's effort limits).
        """
        if settings is not None:
            raise InputError(
                "settings", settings, "None for the G1 (set the fields of G1Model instead)"
            )
        return _with_terrain(_g1_xml(self), terrain)


# ============================================================================= building
def _sole_corners() -> list[tuple[float, float, float]]:
    """Corner sphere centres in the ankle-roll link frame, in ``FOOT_CORNERS`` order."""
    out = []
    for cx, cy in nm.FOOT_CORNERS:
        x = G1_TOE_X if cx > 0 else G1_HEEL_X
        half = G1_TOE_HALF_WIDTH if cx > 0 else G1_HEEL_HALF_WIDTH
        out.append((x, cy * half, G1_SPHERE_Z))
    return out


def _prepared_urdf(path: Path) -> str:
    """URDF text without visual / collision geometry, with every non-leg joint fixed."""
    root = ET.parse(path).getroot()
    for link in root.findall("./link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    legs = {urdf_joint(s, j) for s in (Side.LEFT, Side.RIGHT) for j in nm.LEG_JOINTS}
    found = set()
    for j in root.findall("./joint"):
        name = j.get("name", "")
        if name in legs:
            found.add(name)
        elif j.get("type") in ("revolute", "continuous", "prismatic"):
            j.set("type", "fixed")
    if found != legs:
        raise FootfallError(f"{path} lacks the G1 leg joints {sorted(legs - found)}")
    return ET.tostring(root, encoding="unicode")


#: colours of the G1's geoms (RGBA): links, feet, pelvis and torso boxes
_GREY, _DARK, _BLUE = [0.7, 0.7, 0.72, 1.0], [0.15, 0.15, 0.15, 1.0], [0.25, 0.35, 0.6, 1.0]
#: contact bits of the robot's colliding geoms, and of its visual-only geoms
_ROBOT_COL = {"contype": nm.ROBOT_CONTYPE, "conaffinity": nm.ROBOT_CONAFFINITY}
_VISUAL = {"contype": 0, "conaffinity": 0, "group": nm.ROBOT_GROUP}


def g1_spec(params: G1Model | None = None) -> Any:
    """The G1 as a ``mujoco.MjSpec`` named as :mod:`footfall.sim.biped.names` (see the module
    docstring)."""
    mujoco = require_mujoco()
    p = params if params is not None else G1Model()
    path = g1_urdf_path()
    efforts = g1_urdf_efforts(path)
    spec = mujoco.MjSpec.from_string(_prepared_urdf(path))
    spec.modelname = "footfall_g1"
    # keep the fixed links (torso_link) as bodies: the walker needs the torso's orientation
    spec.compiler.fusestatic = False
    # the URDF importer discards geoms that collide with nothing: keep the visual capsules
    spec.compiler.discardvisual = False
    spec.option.timestep = p.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = p.impratio
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 720
    _add_trunk(mujoco, spec)
    for side in (Side.LEFT, Side.RIGHT):
        _add_leg(mujoco, spec, p, side, efforts)
    _add_sticks(mujoco, spec)
    return spec


def _add_trunk(mujoco: Any, spec: Any) -> None:
    """Free joint and tracking camera on the pelvis; pelvis and torso boxes, renamed as ours."""
    pelvis = spec.body(nm.PELVIS_BODY)
    pelvis.add_freejoint(name=nm.ROOT_JOINT)
    cam = pelvis.add_camera(
        name=nm.TRACK_CAMERA, mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM, pos=[0.3, -2.6, 0.6]
    )
    cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
    cam.alt.xyaxes = [1.0, 0.0, 0.0, 0.0, 0.2, 1.0]
    torso = spec.body(G1_TORSO_LINK)
    torso.name = nm.TORSO_BODY
    for body, geom, (centre, half) in (
        (pelvis, nm.PELVIS_GEOM, PELVIS_BOX),
        (torso, nm.TORSO_GEOM, TORSO_BOX),
    ):
        body.add_geom(
            name=geom,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=list(centre),
            size=list(half),
            rgba=_BLUE,
            group=nm.ROBOT_GROUP,
            **_ROBOT_COL,
        )


def _add_leg(mujoco: Any, spec: Any, p: G1Model, side: Side, efforts: dict[str, float]) -> None:
    """The ``side`` leg's joints and position servos renamed as ours, and its foot's contact
    spheres, sole site and visual sole box."""
    for name in nm.LEG_JOINTS:
        j = spec.joint(urdf_joint(side, name))
        effort = efforts[urdf_joint(side, name)]
        j.name = nm.joint(side, name)
        j.armature = p.armature
        j.damping[0] = p.joint_damping  # MuJoCo 4: (linear, quadratic, cubic) coefficients
        body = j.parent
        body.name = nm.link_body(side, name)
        kp = effort / p.servo_saturation
        act = spec.add_actuator(
            name=nm.actuator(side, name),
            target=nm.joint(side, name),
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
        )
        act.set_to_position(kp=kp, kv=kp * p.servo_damping_time)
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [-effort, effort]
    foot = spec.body(nm.foot_body(side))
    r = G1_SPHERE_RADIUS
    for k, pos in enumerate(_sole_corners()):
        foot.add_geom(
            name=nm.corner_geom(side, k),
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[r, 0, 0],
            pos=list(pos),
            rgba=_DARK,
            friction=[p.friction, 0.02, 0.002],
            solref=[0.004, 1.0],
            group=nm.ROBOT_GROUP,
            **_ROBOT_COL,
        )
    sole_z = G1_SPHERE_Z - r
    dx, _ = p.ankle_offset
    foot.add_site(name=nm.sole_site(side), pos=[dx, 0.0, sole_z], size=[0.01, 0, 0])
    foot.add_geom(
        name=nm.foot_geom(side),
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=[dx, 0.0, sole_z + 0.01],
        size=[p.foot_length / 2, G1_TOE_HALF_WIDTH + r, 0.01],
        rgba=_DARK,
        **_VISUAL,
    )


def _add_sticks(mujoco: Any, spec: Any) -> None:
    """A stick figure for videos: a capsule from each body to each of its children."""
    for body in spec.bodies:
        if body.name in ("world", nm.PELVIS_BODY) or body.parent is None:
            continue
        for child in body.bodies:
            d = np.asarray(child.pos, dtype=float)
            if float(np.linalg.norm(d)) < 2.0 * LINK_RADIUS:
                continue
            body.add_geom(
                type=mujoco.mjtGeom.mjGEOM_CAPSULE,
                fromto=[0.0, 0.0, 0.0, *d.tolist()],
                size=[LINK_RADIUS, 0, 0],
                rgba=_GREY,
                **_VISUAL,
            )


@functools.cache
def _g1_xml(params: G1Model) -> str:
    """MJCF text of :func:`g1_spec` (cached: building reads and parses the URDF)."""
    return str(g1_spec(params).to_xml())


#: the terrain's grid material (the region geoms of :mod:`terrain_mjcf` use ``material="terrain"``)
_TERRAIN_ASSETS = (
    '<texture name="grid" type="2d" builtin="checker" rgb1="0.55 0.6 0.55" rgb2="0.45 0.5 0.45" '
    'width="512" height="512"/>'
    '<material name="terrain" texture="grid" texrepeat="4 4" texuniform="true"/>'
)


def _with_terrain(robot_xml: str, terrain: tuple[str, str]) -> str:
    """``robot_xml`` with the terrain's assets and geoms and a light added."""
    root = ET.fromstring(robot_xml)
    asset_xml, world_xml = terrain
    extra = ET.fromstring(
        f"<mujoco><asset>{_TERRAIN_ASSETS}{asset_xml}</asset><worldbody>"
        '<light pos="0 -3 6" dir="0 0.4 -1" directional="true"/>'
        f"{world_xml}</worldbody></mujoco>"
    )
    for tag in ("asset", "worldbody"):
        dest = root.find(tag)
        if dest is None:
            dest = ET.SubElement(root, tag)
        src = extra.find(tag)
        assert src is not None
        # terrain first in the world body: the robot keeps its body order
        for i, e in enumerate(list(src)):
            dest.insert(i, e)
    return ET.tostring(root, encoding="unicode")


# ============================================================================= nominal posture
@functools.cache
def g1_nominal_posture(params: G1Model) -> tuple[float, ...]:
    """Nominal joint angles (12,) [rad] of the G1, left then right leg in ``LEG_JOINTS`` order.

    Unknowns: hip roll, hip pitch, knee, ankle pitch and ankle roll of each leg and the common
    forward position x_s of the soles (hip yaw is zero). Equations: each sole site is flat (its x
    and y axes horizontal), ``nominal_pelvis_height`` below the upright pelvis, at x_s and at
    +-``stance_width / 2``; the whole-body CoM lies at x_s. Solved by bounded least squares
    (11 equations, 11 unknowns) to ``POSTURE_TOL``.

    Raises:
        InputError: when no such posture exists within the joint limits.
    """
    from scipy.optimize import least_squares

    mujoco = require_mujoco()
    model = mujoco.MjModel.from_xml_string(_g1_xml(params))
    data = mujoco.MjData(model)
    obj = mujoco.mjtObj
    sides = (Side.LEFT, Side.RIGHT)
    jid = {
        (s, j): mujoco.mj_name2id(model, obj.mjOBJ_JOINT, nm.joint(s, j))
        for s in sides
        for j in nm.LEG_JOINTS
    }
    sites = {s: mujoco.mj_name2id(model, obj.mjOBJ_SITE, nm.sole_site(s)) for s in sides}
    pelvis = mujoco.mj_name2id(model, obj.mjOBJ_BODY, nm.PELVIS_BODY)
    moving = ("hip_roll", "hip_pitch", "knee", "ankle_pitch", "ankle_roll")
    keys = [(s, j) for s in sides for j in moving]
    h = params.nominal_pelvis_height

    def pose(z: FloatArray) -> None:
        data.qpos[:] = 0.0
        data.qpos[3] = 1.0  # pelvis upright at the origin (free joint: position, quaternion)
        for key, v in zip(keys, z[:-1], strict=True):
            data.qpos[model.jnt_qposadr[jid[key]]] = v
        mujoco.mj_kinematics(model, data)
        mujoco.mj_comPos(model, data)

    def residual(z: FloatArray) -> FloatArray:
        pose(z)
        xs = z[-1]
        res = []
        for s in sides:
            pos = data.site_xpos[sites[s]]
            rot = data.site_xmat[sites[s]].reshape(3, 3)
            res += [pos[0] - xs, pos[1] - s.sign * params.stance_width / 2, pos[2] + h]
            res += [rot[2, 0], rot[2, 1]]
        res.append(data.subtree_com[pelvis][0] - xs)
        return np.array(res)

    lo = [float(model.jnt_range[jid[k]][0]) for k in keys] + [-0.5]
    hi = [float(model.jnt_range[jid[k]][1]) for k in keys] + [0.5]
    z0 = np.clip(np.array([0.0, -0.3, 0.6, -0.3, 0.0] * 2 + [0.0]), lo, hi)
    sol = least_squares(residual, z0, bounds=(lo, hi), xtol=1e-15, ftol=1e-15, gtol=1e-15)
    err = float(np.max(np.abs(residual(sol.x))))
    if not sol.success or err > POSTURE_TOL:
        raise InputError(
            "g1.nominal_pelvis_height / g1.stance_width",
            (h, params.stance_width),
            f"a posture the legs reach with flat soles (residual {err:.2g} m)",
        )
    q = np.zeros(12)
    for key, v in zip(keys, sol.x[:-1], strict=True):
        s, j = key
        q[6 * sides.index(s) + nm.LEG_JOINTS.index(j)] = v
    return tuple(float(v) for v in q)
