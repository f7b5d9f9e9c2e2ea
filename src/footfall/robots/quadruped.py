"""Quadruped robot files: a quadruped described as data (YAML), its model a URDF or MJCF, turned
into the :class:`~footfall.quadruped.robot.QuadrupedRobot` document 001's gait plans for and the
MuJoCo model walks (needs ``footfall[sim]``).

The schema, every key optional but ``name``, ``kind`` and ``model``::

    name: go2
    kind: quadruped
    model: {package: example-robot-data, path: .../go2_description/urdf/go2.urdf}
    # model: robots/my_dog.urdf  # ... or a path, relative to this file (.urdf, .xml or .mjcf)
    base: base                   # the floating base link [default: the model's root link]
    legs:                        # per leg, the ab/ad, hip pitch and knee joints, from the base
      LF: [FL_hip_joint, FL_thigh_joint, FL_calf_joint]
      RF: [...]
      RH: [...]
      LH: [...]                  # [default: found: the chains from the base to the lowest link
                                 #  of each quadrant (front/hind x left/right)]
    foot_radius: 0.022           # the point foot's sphere [m] [default: from its geometry]
    knees: backward              # forward, backward, inward (front back, hind forward) or
                                 # outward, when the knee's limits allow both bends
                                 # [default: what the limits allow, else inward]
    torque_limit: [23.7, 23.7, 45.4]   # ab/ad, pitch, knee [N m] [default: the model's]
    stance_height: 0.29          # body (base origin) height above the feet [m]
                                 # [default: STANCE_SHARE of the longest leg]

Every leg must turn about the base's x axis (ab/ad), then about y (hip pitch, knee), at zero
joint angles: the leg of document 001, with offsets between the joints (checked; anything else
is an error that says what was found). The foot is the lowest collision sphere below the knee
(its centre and radius), else the origin of the lowest link below the knee with the distance
down to its collision geometry as the radius.

The gait follows the robot's size (:mod:`footfall.quadruped.scaling`): step length, swing height
and the ground's lengths scale with the stance height against document 001's 0.6 m, the periods
with its square root (equal Froude number). The stance height's default, ``STANCE_SHARE`` of the
longest leg, leaves the legs room to shift the body over the support triangles on 20 degree
slopes (0.75 did not, for Solo-12 and ANYmal C).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from pydantic import Field

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.quadruped.robot import LEGS, Leg, LegGeometry, QuadrupedRobot
from footfall.robots.build import RawModel, body_chain, geom_points, hinges, raw_model
from footfall.robots.file import MODEL_FORMATS, PackageFileSpec, resolve_model
from footfall.terrain.scene import StrictSpec, read_yaml, validate_yaml

#: default stance height: this share of the longest sagittal leg length
STANCE_SHARE = 0.65
#: an axis within this angle [rad] of x (ab/ad) or y (pitch, knee) counts as that axis
AXIS_TOL = 1e-3
KNEES = ("forward", "backward", "inward", "outward")
#: the foot's radius from its geometry must lie in this range [m], else the file must give it
FOOT_RADIUS_RANGE = (0.003, 0.1)


@dataclass(frozen=True)
class QuadrupedFile:
    """A quadruped robot file, validated (see the module docstring)."""

    name: str
    model: Path
    base: str | None = None
    legs: tuple[tuple[str, str, str], ...] | None = None
    foot_radius: float | None = None
    knees: str | None = None
    torque_limit: tuple[float, float, float] | None = None
    stance_height: float | None = None
    source: str = "<robot file>"
    package: tuple[str, str] | None = None

    @property
    def format(self) -> str:
        """``urdf`` or ``mjcf``."""
        return MODEL_FORMATS[Path(self.model).suffix.lower()]


class _Legs(StrictSpec):
    LF: list[str] = Field(min_length=3, max_length=3)
    RF: list[str] = Field(min_length=3, max_length=3)
    RH: list[str] = Field(min_length=3, max_length=3)
    LH: list[str] = Field(min_length=3, max_length=3)


class _Spec(StrictSpec):
    name: str = Field(min_length=1, max_length=64)
    kind: str
    model: str | PackageFileSpec
    base: str | None = Field(default=None, max_length=200)
    legs: _Legs | None = None
    foot_radius: float | None = None
    knees: str | None = None
    torque_limit: list[float] | None = Field(default=None, min_length=3, max_length=3)
    stance_height: float | None = None


def is_quadruped_file(text: str | Path) -> bool:
    """Whether YAML text (or a file, read bounded) is a quadruped robot file (``kind:
    quadruped``)."""
    data, _ = read_yaml(text)
    return isinstance(data, dict) and data.get("kind") == "quadruped"


def parse_quadruped_file(text: str | Path, source: str, base: Path | None) -> QuadrupedFile:
    """A :class:`QuadrupedFile` from YAML text or a path (``base``: folder of relative paths)."""
    data, loc = read_yaml(text)
    spec = validate_yaml(_Spec, data, loc)
    if spec.kind != "quadruped":
        raise InputError("kind", spec.kind, "quadruped")
    model, package = resolve_model(spec.model, base)
    if model.suffix.lower() not in MODEL_FORMATS:
        raise InputError("model", str(model), "a URDF (.urdf) or MJCF (.xml, .mjcf) file")
    if spec.knees is not None and spec.knees not in KNEES:
        raise InputError("knees", spec.knees, f"one of {', '.join(KNEES)}")
    for key in ("foot_radius", "stance_height"):
        v = getattr(spec, key)
        if v is not None and not (math.isfinite(v) and v > 0.0):
            raise InputError(key, v, "a positive length [m]")
    if spec.torque_limit is not None and not all(
        math.isfinite(v) and v > 0.0 for v in spec.torque_limit
    ):
        raise InputError("torque_limit", spec.torque_limit, "three positive torques [N m]")
    legs = None
    if spec.legs is not None:
        legs = tuple(tuple(getattr(spec.legs, leg.value)) for leg in LEGS)
    return QuadrupedFile(
        name=spec.name,
        model=model,
        base=spec.base,
        legs=legs,
        foot_radius=spec.foot_radius,
        knees=spec.knees,
        torque_limit=None if spec.torque_limit is None else tuple(spec.torque_limit),  # type: ignore[arg-type]
        stance_height=spec.stance_height,
        source=source,
        package=package,
    )


# ------------------------------------------------------------------------------------- built-ins
def builtin_quadruped_names() -> list[str]:
    """``document`` (document 001's robot) and the shipped quadruped files."""
    folder = resources.files("footfall.robots").joinpath("builtin", "quadrupeds")
    return ["document", *sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml"))]


def resolve_quadruped(source: str | Path) -> QuadrupedRobot:
    """The quadruped ``source`` names: ``document``, a built-in name or a robot file path."""
    if isinstance(source, Path) or str(source).endswith((".yaml", ".yml")):
        path = Path(source)
        if not path.is_file():
            raise InputError("robot", str(source), "an existing quadruped robot file (.yaml)")
        if not is_quadruped_file(path):
            raise InputError(
                "robot",
                str(source),
                "a quadruped robot file (kind: quadruped; a humanoid's file goes to footfall "
                "walk, plan or compare --robot)",
            )
        return quadruped_robot(parse_quadruped_file(path, str(path), path.parent))
    names = builtin_quadruped_names()
    if source == "document":
        return QuadrupedRobot()
    if source not in names:
        raise InputError("robot", source, f"one of {', '.join(names)} or a robot file (.yaml)")
    text = resources.files("footfall.robots").joinpath("builtin", "quadrupeds", f"{source}.yaml")
    return quadruped_robot(parse_quadruped_file(text.read_text(), f"{source}.yaml", None))


# ------------------------------------------------------------------------------- the derivation
def _quadrant(x: float, y: float) -> Leg:
    if x >= 0.0:
        return Leg.LF if y >= 0.0 else Leg.RF
    return Leg.LH if y >= 0.0 else Leg.RH


def find_quadruped_legs(raw: RawModel) -> tuple[tuple[str, str, str], ...]:
    """The three hinge joints of each leg in ``LEGS`` order: from the base to the lowest body of
    each quadrant (front/hind x left/right of the base origin).

    Raises:
        InputError: a quadrant with no body, or a chain of another number of hinges.
    """
    import mujoco

    m, d = raw.model, raw.data
    base = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, raw.base))
    below = [b for b in range(1, m.nbody) if b != base and base in _ancestors(m, b)]
    lowest: dict[Leg, tuple[float, int]] = {}
    for b in below:
        rel = d.xpos[b] - d.xpos[base]
        pts = geom_points(raw, b)
        z = float(pts[:, 2].min()) if pts.size else float(d.xpos[b][2])
        leg = _quadrant(float(rel[0]), float(rel[1]))
        if leg not in lowest or z < lowest[leg][0] - 1e-9:
            lowest[leg] = (z, b)
    out = []
    for leg in LEGS:
        if leg not in lowest:
            raise InputError("legs", None, f"a leg in the {leg.value} quadrant (no body there)")
        chain = body_chain(m, lowest[leg][1], base)
        joints = [str(m.joint(j).name) for j in hinges(m, chain)]
        if len(joints) != 3:
            raise InputError(
                f"legs.{leg.value}",
                joints,
                "3 hinge joints from the base to the foot (ab/ad, hip pitch, knee); name them in "
                "the robot file's legs",
            )
        out.append((joints[0], joints[1], joints[2]))
    return tuple(out)


def _ancestors(m: Any, b: int) -> list[int]:
    out = []
    while b > 0:
        b = int(m.body_parentid[b])
        out.append(b)
    return out


def _segment_inertia(m: Any, d: Any, bodies: list[int]) -> tuple[float, FloatArray, FloatArray]:
    """Mass, centre of mass (3,) and inertia about it in world axes (3, 3) of ``bodies``."""
    mass = float(sum(m.body_mass[b] for b in bodies))
    if mass <= 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    com = sum(m.body_mass[b] * d.xipos[b] for b in bodies) / mass
    inertia = np.zeros((3, 3))
    for b in bodies:
        rot = d.ximat[b].reshape(3, 3)
        r = d.xipos[b] - com
        inertia += rot @ np.diag(m.body_inertia[b]) @ rot.T
        inertia += m.body_mass[b] * (float(r @ r) * np.eye(3) - np.outer(r, r))
    return mass, np.asarray(com, dtype=float), inertia


def _six(inertia: FloatArray) -> tuple[float, ...]:
    i = inertia
    return (i[0, 0], i[1, 1], i[2, 2], i[0, 1], i[0, 2], i[1, 2])


def _subtree(m: Any, root: int) -> list[int]:
    return [b for b in range(m.nbody) if b == root or root in _ancestors(m, b)]


@dataclass(frozen=True)
class QuadrupedDerivation:
    """What :func:`derive_quadruped` found: the robot and the facts it was made of."""

    robot: QuadrupedRobot
    joints: tuple[tuple[str, str, str], ...]
    foot_radius: float
    knees: str
    stance_height: float
    dropped: tuple[str, ...]
    repaired: tuple[str, ...] = ()


def _axis_sign(axis: FloatArray, want: int, name: str) -> float:
    a = axis / np.linalg.norm(axis)
    if abs(abs(a[want]) - 1.0) > AXIS_TOL:
        raise InputError(
            f"joint {name}",
            tuple(round(float(v), 3) for v in a),
            f"an axis along the base's {'xyz'[want]} at zero angles (ab/ad about x, hip pitch and "
            "knee about y: the leg of document 001)",
        )
    return 1.0 if a[want] > 0 else -1.0


def _branch(geo: LegGeometry, leg: Leg, knees: str | None, height: float) -> tuple[float, str]:
    """The knee branch: the one the limits allow, else the file's ``knees``, else inward."""
    from footfall.quadruped.kinematics import leg_ik

    target = np.array([0.0, geo.lateral, -height])
    ok = {}
    for br in (1.0, -1.0):
        try:
            q = leg_ik(_one_leg_robot(_with_branch(geo, br)), target, leg)
        except InputError:
            continue
        knee_x = _knee_x(geo, q)
        ok[br] = "forward" if knee_x > 0.0 else "backward"
    if not ok:
        raise InputError(
            "stance_height", round(height, 4), f"a stance leg {leg.value} reaches within limits"
        )
    want = knees
    if want == "inward":
        want = "backward" if leg.is_front else "forward"
    elif want == "outward":
        want = "forward" if leg.is_front else "backward"
    if len(ok) == 1:
        br, bend = next(iter(ok.items()))
        if want is not None and bend != want:
            raise InputError("knees", knees, f"a knee bend leg {leg.value}'s limits allow ({bend})")
        return br, bend
    if want is None:
        want = "backward" if leg.is_front else "forward"  # inward
    return next(br for br, bend in ok.items() if bend == want), want


def _knee_x(geo: LegGeometry, q: FloatArray) -> float:
    """The knee's x in the leg frame relative to the line from the pitch point to the foot."""
    t2, t3 = geo.signs[1] * q[1], geo.signs[2] * q[2]
    c2, s2 = math.cos(t2), math.sin(t2)
    k = np.asarray(geo.knee)[[0, 2]]
    kx = c2 * k[0] + s2 * k[1]
    kz = -s2 * k[0] + c2 * k[1]
    f = np.asarray(geo.foot)[[0, 2]]
    c3, s3 = math.cos(t3), math.sin(t3)
    fx, fz = c3 * f[0] + s3 * f[1], -s3 * f[0] + c3 * f[1]
    fx, fz = kx + c2 * fx + s2 * fz, kz - s2 * fx + c2 * fz
    # signed distance of the knee from the pitch-to-foot line, positive ahead of it
    return float((kz * fx - kx * fz) / max(math.hypot(fx, fz), 1e-12))


def _with_branch(geo: LegGeometry, branch: float) -> LegGeometry:
    return replace(geo, branch=branch)


def _one_leg_robot(geo: LegGeometry) -> QuadrupedRobot:
    """A robot of four ``geo`` legs, to run one leg's kinematics on."""
    lo, hi = geo.sagittal_lengths()
    return QuadrupedRobot(stance_height=0.5 * (lo + hi), legs=(geo,) * 4, name="probe")


def derive_quadruped(qf: QuadrupedFile) -> QuadrupedDerivation:
    """The :class:`QuadrupedRobot` of a quadruped file (module docstring)."""
    import mujoco

    raw = raw_model(qf)
    m, d = raw.model, raw.data
    joints = qf.legs if qf.legs is not None else find_quadruped_legs(raw)
    base = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, raw.base))
    leg_bodies: set[int] = set()
    raw_legs = []
    radii = []
    for leg, names in zip(LEGS, joints, strict=True):
        ids = []
        for n in names:
            j = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n))
            if j < 0 or m.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE:
                raise InputError(f"legs.{leg.value}", n, "a hinge joint of the model")
            ids.append(j)
        bodies = [int(m.jnt_bodyid[j]) for j in ids]
        seg = [_subtree(m, b) for b in bodies]
        leg_bodies.update(seg[0])
        # the foot: the last link below the knee body (its lowest body), or the knee body
        below_knee = seg[2]
        spheres = [
            g
            for g in range(m.ngeom)
            if int(m.geom_bodyid[g]) in below_knee
            and m.geom_type[g] == mujoco.mjtGeom.mjGEOM_SPHERE
        ]
        if spheres:
            g = min(spheres, key=lambda g: float(d.geom_xpos[g][2] - m.geom_size[g][0]))
            foot, radius = d.geom_xpos[g].copy(), float(m.geom_size[g][0])
        else:
            low = min(below_knee, key=lambda b: float(d.xpos[b][2]))
            foot = d.xpos[low].copy()
            pts = np.concatenate([geom_points(raw, b) for b in below_knee])
            radius = float(foot[2] - pts[:, 2].min()) if pts.size else float("nan")
        radii.append(radius)
        raw_legs.append((leg, names, ids, seg, foot))
    if qf.foot_radius is not None:
        foot_radius = qf.foot_radius
    else:
        foot_radius = float(np.median(radii))
        lo, hi = FOOT_RADIUS_RANGE
        if not lo <= foot_radius <= hi:
            raise InputError(
                "foot_radius",
                None if math.isnan(foot_radius) else round(foot_radius, 4),
                f"the feet's sphere radius in the robot file (the geometry gives none in "
                f"[{lo}, {hi}] m)",
            )
    geos = []
    for leg, names, ids, seg, foot in raw_legs:
        a1, a2, a3 = (d.xanchor[j].copy() for j in ids)
        signs = (
            _axis_sign(d.xaxis[ids[0]], 0, names[0]),
            _axis_sign(d.xaxis[ids[1]], 1, names[1]),
            _axis_sign(d.xaxis[ids[2]], 1, names[2]),
        )
        origin = np.array([a2[0], a1[1], a1[2]])
        parts = [
            [b for b in seg[0] if b not in seg[1]],
            [b for b in seg[1] if b not in seg[2]],
            seg[2],
        ]
        masses, coms, ins = [], [], []
        for part, ref in zip(parts, (origin, a2, a3), strict=True):
            mass, com, inertia = _segment_inertia(m, d, part)
            if mass <= 0.0:
                raise InputError(f"legs.{leg.value}", names, "links with mass")
            masses.append(mass)
            coms.append(tuple(com - ref))
            ins.append(_six(inertia))
        lower, upper = [], []
        torque = []
        for j in ids:
            if m.jnt_limited[j]:
                lower.append(float(m.jnt_range[j][0]))
                upper.append(float(m.jnt_range[j][1]))
            else:
                lower.append(-math.pi)
                upper.append(math.pi)
            if m.jnt_actfrclimited[j]:
                torque.append(float(m.jnt_actfrcrange[j][1]))
        tq = (
            qf.torque_limit
            if qf.torque_limit is not None
            else (tuple(torque) if len(torque) == 3 else None)
        )
        hfe = a2 - origin
        hfe[0] = 0.0
        geos.append(
            LegGeometry(
                origin=tuple(origin - d.xpos[base]),
                hfe=tuple(hfe),
                knee=tuple(a3 - a2),
                foot=tuple(foot - a3),
                signs=signs,
                lower=tuple(lower),  # type: ignore[arg-type]
                upper=tuple(upper),  # type: ignore[arg-type]
                branch=1.0,
                masses=tuple(masses),  # type: ignore[arg-type]
                coms=tuple(coms),
                inertias=tuple(ins),
                torque=tq,  # type: ignore[arg-type]
                joints=tuple(names),
            )
        )
    trunk = [b for b in _subtree(m, base) if b not in leg_bodies]
    body_mass, body_com, body_inertia = _segment_inertia(m, d, trunk)
    longest = min(g.sagittal_lengths()[1] for g in geos)
    height = qf.stance_height if qf.stance_height is not None else STANCE_SHARE * longest
    legs = []
    bends = set()
    for leg, geo in zip(LEGS, geos, strict=True):
        br, bend = _branch(geo, leg, qf.knees, height)
        legs.append(_with_branch(geo, br))
        bends.add((leg.is_front, bend))
    knees = _knees_word(bends)
    lo_box, hi_box = _trunk_box(raw, base)
    size = hi_box - lo_box
    g0 = legs[0]
    robot = QuadrupedRobot(
        body_length=float(size[0]),
        body_width=float(size[1]),
        body_height=float(size[2]),
        hip_spacing_x=float(abs(legs[0].origin[0] - legs[2].origin[0])),
        hip_spacing_y=float(abs(legs[0].origin[1] - legs[1].origin[1])),
        thigh_length=float(np.hypot(g0.knee[0], g0.knee[2])),
        shank_length=float(np.hypot(g0.foot[0], g0.foot[2])),
        foot_radius=foot_radius,
        body_mass=body_mass,
        thigh_mass=g0.masses[1],
        shank_mass=g0.masses[2],
        hip_mass=g0.masses[0],
        stance_height=height,
        legs=tuple(legs),
        body_com=tuple(body_com - d.xpos[base]),
        body_inertia=_six(body_inertia),
        name=qf.name,
    )
    return QuadrupedDerivation(
        robot, tuple(joints), foot_radius, knees, height, raw.dropped, raw.repaired
    )


def _knees_word(bends: set[tuple[bool, str]]) -> str:
    front = {b for f, b in bends if f}
    hind = {b for f, b in bends if not f}
    if len(front) == 1 and len(hind) == 1:
        fb, hb = next(iter(front)), next(iter(hind))
        if fb == hb:
            return fb
        return "inward" if fb == "backward" else "outward"
    return "mixed"


def _trunk_box(raw: RawModel, base: int) -> tuple[FloatArray, FloatArray]:
    """Bounding box of the base's own collision geometry (a 10 cm cube without any) [m]."""
    pts = geom_points(raw, base)
    origin = raw.data.xpos[base]
    if pts.size == 0:
        return origin - 0.05, origin + 0.05
    return pts.min(axis=0) - origin, pts.max(axis=0) - origin


@functools.lru_cache(maxsize=8)
def quadruped_robot(qf: QuadrupedFile) -> QuadrupedRobot:
    """The :class:`QuadrupedRobot` of a quadruped file (derived once per file and process)."""
    return derive_quadruped(qf).robot
