"""A robot file's model as the walker's MuJoCo model (needs ``footfall[sim]``).

Two models are made from the URDF (or MJCF) a robot file names:

- the **raw model** (:func:`raw_model`): the file as it is, collision geometry included (mesh files
  found through their ``package://`` paths), every joint kept, a free base. It is read to find
  the legs (:func:`find_legs`), the sole (:func:`sole_from_geometry`) and the body boxes.
- the **walker model** (:func:`walker_spec`): the inertials kept, visual and collision geometry
  dropped (no mesh is read), every joint but the twelve leg joints fixed at zero, the leg joints
  and their links renamed to :mod:`footfall.robots.names` (an axis along -x, -y or -z is turned
  around, its range negated, so every joint turns about +x, +y or +z as on footfall's own biped),
  a free joint ``root`` on the base, four contact spheres at the corners of each sole, a sole site
  at its centre on the contact plane, pelvis and torso boxes that collide with the terrain (for
  fall detection; the bodies' collision geometry's bounding boxes), position servos with the
  model's effort limits and a stick figure for videos.

Finding the legs: the two lowest bodies of the model standing at zero joint angles, one either
side, walked up to the nearest body with a hinge joint (the foot: the ankle roll link); the hinge
joints between the base and a foot are its leg. Six are expected; the first three (from the base)
are the hip, named by the axis they turn about (z yaw, x roll, y pitch), then the knee (y), then
the ankle, named by axis. Anything else is an error that says which names to give in the file.
"""

from __future__ import annotations

import functools
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from footfall._mjcf import require_mujoco
from footfall._typing import FloatArray
from footfall.errors import FootfallError, InputError
from footfall.models.biped import Side
from footfall.robots import names as nm
from footfall.robots.file import LEG_JOINT_ROLES, LegJoints, RobotFile, Sole

#: points of the collision geometry within this height of the lowest make the sole [m]
SOLE_BAND = 0.003
#: the roles of the hip joints by the axis they turn about
_HIP_AXIS_ROLE = {0: "hip_roll", 1: "hip_pitch", 2: "hip_yaw"}
_ANKLE_AXIS_ROLE = {0: "ankle_roll", 1: "ankle_pitch"}
#: radius of the visual capsules between joints [m]
LINK_RADIUS = 0.025
#: colours (RGBA) of the links, feet and the pelvis and torso boxes
_GREY, _DARK, _BLUE = [0.7, 0.7, 0.72, 1.0], [0.15, 0.15, 0.15, 1.0], [0.25, 0.35, 0.6, 1.0]


# ------------------------------------------------------------------------------------ the raw model
class ModelSource(Protocol):
    """What the raw model is read from: a humanoid's or a quadruped's robot file."""

    @property
    def model(self) -> Path: ...

    @property
    def base(self) -> str | None: ...

    @property
    def format(self) -> str: ...


def _resolve_packages(text: str, model: Path) -> str:
    """URDF text with every ``package://NAME/`` replaced by the folder named NAME that holds the
    model file (the layout of ROS packages and example-robot-data)."""

    def folder(name: str) -> str:
        for parent in model.resolve().parents:
            if parent.name == name:
                return str(parent) + "/"
        raise InputError(
            "model",
            str(model),
            f"a file inside a folder named {name!r} (its meshes say package://{name}/)",
        )

    return re.sub(r"package://([^/\"']+)/", lambda m: folder(m.group(1)), text)


def _urdf_root(rf: ModelSource) -> ET.Element:
    try:
        text = rf.model.read_text()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError("model", str(rf.model), f"a readable URDF file ({e})") from None
    try:
        root = ET.fromstring(_resolve_packages(text, rf.model))
    except ET.ParseError as e:
        raise InputError("model", str(rf.model), f"a valid URDF (XML: {e})") from None
    if root.tag != "robot":
        raise InputError("model", str(rf.model), "a URDF (a <robot> element)")
    # a <mujoco> extension of another setup is replaced by ours: visual geometry kept (MuJoCo's
    # URDF reader decides that while parsing; the walker model removes it itself), fixed links
    # kept as bodies, and inertias that break the triangle inequality balanced (MuJoCo refuses
    # them otherwise; some published URDFs have them)
    for ext in root.findall("mujoco"):
        root.remove(ext)
    ET.SubElement(ET.SubElement(root, "mujoco"), "compiler").attrib.update(
        {"discardvisual": "false", "fusestatic": "false", "balanceinertia": "true"}
    )
    return root


def _spec_from(rf: ModelSource, root: ET.Element | None) -> Any:
    mujoco = require_mujoco()
    try:
        if rf.format == "urdf":
            assert root is not None
            spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
        else:
            spec = mujoco.MjSpec.from_file(str(rf.model))
    except Exception as e:  # MuJoCo's parser errors: a file the user handed in
        raise InputError("model", str(rf.model), f"a model MuJoCo can read ({e})") from None
    spec.compiler.fusestatic = False  # fixed links stay bodies: the torso, the sole links
    return spec


def _base_name(rf: ModelSource, spec: Any) -> str:
    roots = [b for b in spec.worldbody.bodies]
    if rf.base is not None:
        if spec.body(rf.base) is None:
            raise InputError("base", rf.base, "a link of the model")
        return rf.base
    if len(roots) != 1:
        raise InputError(
            "base", None, f"the floating base link named (the model has {len(roots)} root bodies)"
        )
    return str(roots[0].name)


@dataclass(frozen=True)
class RawModel:
    """The model as its file has it, compiled standing upright at zero joint angles.

    Attributes:
        model: the compiled MuJoCo model.
        data: its data after forward kinematics.
        base: the base body's name.
        dropped: mesh files left out (MuJoCo cannot read them).
    """

    model: Any
    data: Any
    base: str
    dropped: tuple[str, ...] = ()
    repaired: tuple[str, ...] = ()


def _repair_inertias(root: ET.Element) -> list[str]:
    """Links whose URDF inertia is not positive definite (a placeholder such as every entry
    0.001), their products of inertia dropped so that MuJoCo compiles the model; the links."""
    keys = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")
    repaired = []
    for link in root.findall("./link"):
        e = link.find("inertial/inertia")
        if e is None:
            continue
        try:
            xx, yy, zz, xy, xz, yz = (float(e.get(k, "0")) for k in keys)
        except ValueError:
            continue  # MuJoCo's parser names the bad number
        tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        if not np.all(np.isfinite(tensor)) or np.linalg.eigvalsh(tensor)[0] > 0.0:
            continue
        if min(xx, yy, zz) <= 0.0:
            continue  # nothing to keep: MuJoCo's error stands
        for k in keys[3:]:
            e.set(k, "0")
        repaired.append(str(link.get("name")))
    return repaired


#: mesh files MuJoCo reads; geometry in other files (Collada, ...) is left out of the raw model
MESH_SUFFIXES = (".stl", ".obj", ".msh")
#: meshes MuJoCo refuses to decode are left out one by one, at most this many
MAX_DROPPED_MESHES = 64


def _drop_meshes(root: ET.Element, keep: Any) -> list[str]:
    """Remove the ``<visual>`` and ``<collision>`` elements whose mesh file ``keep(file)``
    refuses; the files left out."""
    dropped = []
    for link in root.findall("./link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                mesh = e.find("geometry/mesh")
                if mesh is not None and not keep(mesh.get("filename", "")):
                    link.remove(e)
                    dropped.append(mesh.get("filename", ""))
    return dropped


def raw_model(rf: ModelSource) -> RawModel:
    """The model as its file has it (visual and collision geometry and every joint kept), with a
    free base, at zero joint angles: what :func:`find_legs`, :func:`sole_from_geometry` and
    :func:`body_box` read. Meshes MuJoCo cannot read (another format, or a file its decoder
    refuses) are left out of it (``RawModel.dropped``); what they would have given must then come
    from the robot file (a sole, say)."""
    mujoco = require_mujoco()
    root = _urdf_root(rf) if rf.format == "urdf" else None
    dropped: list[str] = []
    repaired: list[str] = []
    if root is not None:
        dropped += _drop_meshes(root, lambda f: f.lower().endswith(MESH_SUFFIXES))
        repaired = _repair_inertias(root)
    for _ in range(MAX_DROPPED_MESHES):
        spec = _spec_from(rf, root)
        base = _base_name(rf, spec)
        body = spec.body(base)
        if not any(j.type == mujoco.mjtJoint.mjJNT_FREE for j in body.joints):
            body.add_freejoint()
        try:
            model = spec.compile()
            break
        except Exception as e:
            bad = re.search(r"mesh file '([^']+)'|in STL file '([^']+)'", str(e))
            if root is None or bad is None:
                raise InputError("model", str(rf.model), f"a model MuJoCo compiles ({e})") from None
            name = Path(bad.group(1) or bad.group(2)).name
            dropped += _drop_meshes(root, lambda f, name=name: Path(f).name != name)
    else:
        raise InputError("model", str(rf.model), "a model with fewer unreadable meshes")
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    return RawModel(model, data, base, tuple(dropped), tuple(repaired))


def body_chain(m: Any, body: int, base: int) -> list[int]:
    """Bodies from ``base`` (excluded) down to ``body`` (included)."""
    chain = []
    while body != base:
        if body <= 0:
            raise InputError("base", None, "a base above both feet")
        chain.append(body)
        body = int(m.body_parentid[body])
    return chain[::-1]


def hinges(m: Any, bodies: list[int]) -> list[int]:
    """The hinge joints of ``bodies``, in their order (a body's joints in the model's order)."""
    mujoco = require_mujoco()
    out = []
    for b in bodies:
        for j in range(int(m.body_jntadr[b]), int(m.body_jntadr[b] + m.body_jntnum[b])):
            if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
                out.append(j)
    return out


def _lowest_z(raw: RawModel, body: int) -> float:
    """Lowest point of ``body``'s collision geometry (its origin without any) [m]."""
    pts = geom_points(raw, body)
    return float(pts[:, 2].min()) if pts.size else float(raw.data.xpos[body][2])


def find_legs(raw: RawModel) -> LegJoints:
    """The six leg joints of each side in ``LEG_JOINT_ROLES`` order (module docstring).

    Raises:
        InputError: no two legs, a leg of another joint count, or joints whose axes do not
            name them (each message says what to give in the robot file).
    """
    mujoco = require_mujoco()
    m, d = raw.model, raw.data
    base = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, raw.base))
    below = [b for b in range(1, m.nbody) if _is_below(m, b, base)]
    feet: dict[Side, int] = {}
    for side in Side:
        cand = [b for b in below if side.sign * float(d.xpos[b][1] - d.xpos[base][1]) > 0.02]
        if not cand:
            raise InputError("legs", None, f"a {side.value} leg (no body on that side)")
        low = min(cand, key=lambda b: _lowest_z(raw, b))
        chain = body_chain(m, low, base)
        # the foot: the lowest body with a hinge joint on the way up
        while chain and not hinges(m, [chain[-1]]):
            chain.pop()
        feet[side] = chain[-1] if chain else low
    out: dict[Side, tuple[str, ...]] = {}
    for side, foot in feet.items():
        joints = hinges(m, body_chain(m, foot, base))
        names = [str(m.joint(j).name) for j in joints]
        if len(joints) != len(LEG_JOINT_ROLES):
            raise InputError(
                f"legs.{side.value}",
                names,
                f"{len(LEG_JOINT_ROLES)} hinge joints from the base to the foot; name them in the "
                f"robot file's legs: ({', '.join(LEG_JOINT_ROLES)})",
            )
        out[side] = _roles(m, d, joints, side)
    return LegJoints(out[Side.LEFT], out[Side.RIGHT])


def _is_below(m: Any, body: int, base: int) -> bool:
    while body > 0:
        if body == base:
            return True
        body = int(m.body_parentid[body])
    return False


def _roles(m: Any, d: Any, joints: list[int], side: Side) -> tuple[str, ...]:
    """The joints ordered as ``LEG_JOINT_ROLES`` from their place in the chain and axes."""
    axes = [int(np.argmax(np.abs(d.xaxis[j]))) for j in joints]
    role: dict[str, int] = {}
    for j, ax in zip(joints[:3], axes[:3], strict=True):
        role.setdefault(_HIP_AXIS_ROLE[ax], j)
    if axes[3] == 1:
        role["knee"] = joints[3]
    for j, ax in zip(joints[4:], axes[4:], strict=True):
        if ax in _ANKLE_AXIS_ROLE:
            role.setdefault(_ANKLE_AXIS_ROLE[ax], j)
    if len(role) != len(LEG_JOINT_ROLES):
        found = ", ".join(
            f"{m.joint(j).name} about {'xyz'[a]}" for j, a in zip(joints, axes, strict=True)
        )
        raise InputError(
            f"legs.{side.value}",
            found,
            "three hip joints about z, x and y, a knee about y and two ankle joints about y and "
            f"x; name them in the robot file's legs: ({', '.join(LEG_JOINT_ROLES)})",
        )
    return tuple(str(m.joint(role[r]).name) for r in LEG_JOINT_ROLES)


# ------------------------------------------------------------------------------- geometry -> sole
def geom_points(raw: RawModel, body: int, frame: int | None = None) -> FloatArray:
    """Points (n, 3) of the collision geometry (the visual geometry without any) of ``body`` and
    of the bodies fixed to it, in the world (or in body ``frame``'s frame) [m]: mesh vertices,
    box corners, points around spheres, capsules and cylinders."""
    mujoco = require_mujoco()
    m, d = raw.model, raw.data
    bodies = [body] + [b for b in range(1, m.nbody) if _fixed_to(m, b, body)]
    pts: list[FloatArray] = []
    g = mujoco.mjtGeom
    ring = np.array([[math.cos(a), math.sin(a)] for a in np.linspace(0, 2 * math.pi, 16, False)])
    mine = [gi for gi in range(m.ngeom) if int(m.geom_bodyid[gi]) in bodies]
    colliding = [gi for gi in mine if (m.geom_contype[gi] | m.geom_conaffinity[gi]) != 0]
    # the collision geometry; a body without any is drawn by its visual geometry
    for gi in colliding or mine:
        t, size = m.geom_type[gi], m.geom_size[gi]
        if t == g.mjGEOM_MESH:
            k = int(m.geom_dataid[gi])
            local = m.mesh_vert[m.mesh_vertadr[k] : m.mesh_vertadr[k] + m.mesh_vertnum[k]]
        elif t == g.mjGEOM_BOX:
            local = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
            local = local * size[:3]
        elif t == g.mjGEOM_SPHERE:
            r = size[0]
            local = np.vstack([np.c_[r * ring, np.zeros(16)], [[0, 0, -r], [0, 0, r]]])
            # the sphere's footprint: its bottom point and its radius around it, at the bottom
            local = np.vstack([local, np.c_[r * ring, np.full(16, -r)]])
        elif t in (g.mjGEOM_CAPSULE, g.mjGEOM_CYLINDER):
            r, h = size[0], size[1]
            cap = r if t == g.mjGEOM_CAPSULE else 0.0
            local = np.vstack(
                [np.c_[r * ring, np.full(16, z)] for z in (-h, h)]
                + [[[0, 0, -h - cap], [0, 0, h + cap]]]
            )
        else:
            continue
        pts.append(local @ d.geom_xmat[gi].reshape(3, 3).T + d.geom_xpos[gi])
    if not pts:
        return np.zeros((0, 3))
    world = np.vstack(pts)
    if frame is None:
        return world
    return (world - d.xpos[frame]) @ d.xmat[frame].reshape(3, 3)


def _fixed_to(m: Any, body: int, root: int) -> bool:
    """Whether ``body`` hangs from ``root`` through bodies without joints."""
    while body > 0 and body != root:
        if m.body_jntnum[body] > 0:
            return False
        body = int(m.body_parentid[body])
    return body == root


def largest_rectangle(points: FloatArray, grid: int = 64) -> tuple[float, float, float, float]:
    """The largest axis-aligned rectangle ``(x0, x1, y0, y1)`` inside the convex hull of the 2-D
    ``points`` (n, 2) [m]: over candidate x-intervals on a grid, the hull's vertical extent is
    concave above and convex below, so the rectangle's y-range is set by its two ends."""
    from footfall._geometry import convex_hull

    hull = convex_hull(points)
    if hull.shape[0] < 3:
        raise InputError("sole", hull.tolist(), "a contact patch of non-zero area")
    xs = np.linspace(hull[:, 0].min(), hull[:, 0].max(), grid)
    lo, hi = np.array([_extent(hull, x) for x in xs]).T
    best = (0.0, 0.0, 0.0, 0.0)
    area = 0.0
    for i in range(grid):
        for k in range(i + 1, grid):
            y0, y1 = max(lo[i], lo[k]), min(hi[i], hi[k])
            a = (xs[k] - xs[i]) * (y1 - y0)
            if a > area:
                area, best = a, (float(xs[i]), float(xs[k]), float(y0), float(y1))
    return best


def _extent(hull: FloatArray, x: float) -> tuple[float, float]:
    """Lowest and highest y of the convex polygon ``hull`` at abscissa ``x``."""
    ys = []
    n = hull.shape[0]
    for i in range(n):
        (x0, y0), (x1, y1) = hull[i], hull[(i + 1) % n]
        if min(x0, x1) - 1e-12 <= x <= max(x0, x1) + 1e-12:
            ys.append(y0 if x1 == x0 else y0 + (y1 - y0) * (x - x0) / (x1 - x0))
            if x1 == x0:
                ys.append(y1)
    return (min(ys), max(ys)) if ys else (0.0, 0.0)


def sole_from_geometry(raw: RawModel, foot: str, radius: float = 0.005) -> Sole:
    """The sole of the ``foot`` link: the largest axis-aligned rectangle (foot frame) inside the
    footprint of its collision geometry's lowest points (within ``SOLE_BAND``; its visual
    geometry's when it has no collision geometry), on the plane through the lowest point.

    Raises:
        InputError: the foot has no collision geometry (give ``sole:`` in the robot file).
    """
    mujoco = require_mujoco()
    b = int(mujoco.mj_name2id(raw.model, mujoco.mjtObj.mjOBJ_BODY, foot))
    pts = geom_points(raw, b, frame=b)
    if pts.shape[0] == 0:
        raise InputError(
            "sole", foot, "a foot with geometry, or the sole: rectangle in the robot file"
        )
    z = float(pts[:, 2].min())
    band = pts[pts[:, 2] <= z + SOLE_BAND, :2]
    x0, x1, y0, y1 = largest_rectangle(band)
    return Sole((x0, x1), (y0, y1), z, radius)


def body_box(raw: RawModel, body: str, subtree: bool = False) -> tuple[FloatArray, FloatArray]:
    """``(centre (3,), half sizes (3,))`` [m] in ``body``'s frame of the bounding box of its
    collision geometry (and that of the bodies fixed to it, or with ``subtree`` of every body
    below it); the box of its inertia when it has none."""
    mujoco = require_mujoco()
    m = raw.model
    b = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, body))
    if subtree:
        parts = [geom_points(raw, c, frame=b) for c in range(1, m.nbody) if _is_below(m, c, b)]
        pts = np.vstack([p for p in parts if p.size] or [np.zeros((0, 3))])
    else:
        pts = geom_points(raw, b, frame=b)
    if pts.shape[0]:
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        return (lo + hi) / 2.0, np.maximum((hi - lo) / 2.0, 0.01)
    # a uniform box of the body's mass and principal inertia: I_x = m (b^2 + c^2) / 3 ...
    i, mass = np.asarray(m.body_inertia[b]), max(float(m.body_mass[b]), 1e-6)
    sq = np.maximum(3.0 / (2.0 * mass) * (i.sum() - 2.0 * i), 1e-6)
    return np.asarray(m.body_ipos[b], dtype=float), np.sqrt(sq)


# --------------------------------------------------------------------------------- walker model
@dataclass(frozen=True)
class Layout:
    """What the walker model is built from, beyond the robot file: found or given legs, their
    foot links (left, right), the sole, the pelvis and torso boxes (each ``(centre (3,), half
    sizes (3,))`` in its body's frame) and the torso body's name."""

    legs: LegJoints
    feet: tuple[str, str]
    sole: Sole
    torso: str
    pelvis_box: tuple[tuple[float, ...], tuple[float, ...]]
    torso_box: tuple[tuple[float, ...], tuple[float, ...]]


def _torso_name(rf: RobotFile, raw: RawModel, legs: LegJoints) -> str:
    """The body kept upright: the file's, else the base's child with the heaviest subtree off the
    legs (the upper body), else the base."""
    mujoco = require_mujoco()
    m = raw.model
    if rf.torso is not None:
        if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, rf.torso) < 0:
            raise InputError("torso", rf.torso, "a link of the model")
        return rf.torso
    base = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, raw.base))
    leg_bodies = {int(m.jnt_bodyid[m.joint(j).id]) for s in Side for j in legs.of(s)}
    kids = [
        c
        for c in range(1, m.nbody)
        if int(m.body_parentid[c]) == base and not any(_is_below(m, lb, c) for lb in leg_bodies)
    ]
    if not kids:
        return raw.base
    return str(m.body(max(kids, key=lambda c: float(m.body_subtreemass[c]))).name)


def layout(rf: RobotFile) -> Layout:
    """The legs, sole, torso and boxes of ``rf``: as its file gives them, else derived from the
    raw model."""
    raw = raw_model(rf)
    legs = rf.legs if rf.legs is not None else find_legs(raw)
    m = raw.model
    mujoco = require_mujoco()
    for side in Side:
        for j in legs.of(side):
            if mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, j) < 0:
                raise InputError(f"legs.{side.value}", j, "a joint of the model")
    feet = tuple(str(m.body(int(m.jnt_bodyid[m.joint(legs.of(s)[-1]).id])).name) for s in Side)
    sole = rf.sole if rf.sole is not None else sole_from_geometry(raw, feet[0])
    torso = _torso_name(rf, raw, legs)
    pelvis_box = body_box(raw, raw.base)
    torso_box = body_box(raw, torso, subtree=torso != raw.base)
    return Layout(
        legs=legs,
        feet=(feet[0], feet[1]),
        sole=sole,
        torso=torso,
        pelvis_box=tuple(tuple(float(v) for v in a) for a in pelvis_box),  # type: ignore[arg-type]
        torso_box=tuple(tuple(float(v) for v in a) for a in torso_box),  # type: ignore[arg-type]
    )


def _prepared_urdf(rf: RobotFile, lay: Layout) -> ET.Element:
    """The URDF without visual and collision geometry, every joint but the legs' fixed."""
    root = _urdf_root(rf)
    for link in root.findall("./link"):
        for tag in ("visual", "collision"):
            for e in link.findall(tag):
                link.remove(e)
    legs = {j for s in Side for j in lay.legs.of(s)}
    for j in root.findall("./joint"):
        if j.get("name", "") not in legs and j.get("type") in (
            "revolute",
            "continuous",
            "prismatic",
        ):
            j.set("type", "fixed")
    return root


def walker_spec(rf: RobotFile, lay: Layout) -> Any:
    """The walker's MuJoCo spec of ``rf`` (module docstring); no terrain."""
    mujoco = require_mujoco()
    if rf.format != "urdf":
        raise InputError(
            "model", str(rf.model), "a URDF (MJCF models are read for inspection only)"
        )
    spec = _spec_from(rf, _prepared_urdf(rf, lay))
    spec.compiler.discardvisual = False  # keep the stick figure and boxes added below
    spec.modelname = f"footfall_{rf.name}"
    ph = rf.physics
    spec.option.timestep = ph.timestep
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_IMPLICITFAST
    spec.option.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
    spec.option.impratio = ph.impratio
    spec.visual.global_.offwidth = 1280
    spec.visual.global_.offheight = 720
    base = _base_name(rf, spec)
    _add_trunk(mujoco, spec, base, lay)
    for side in Side:
        _add_leg(mujoco, spec, rf, lay, side)
    _add_sticks(mujoco, spec)
    return spec


_ROBOT_COL = {"contype": nm.ROBOT_CONTYPE, "conaffinity": nm.ROBOT_CONAFFINITY}
_VISUAL = {"contype": 0, "conaffinity": 0, "group": nm.ROBOT_GROUP}


def _add_trunk(mujoco: Any, spec: Any, base: str, lay: Layout) -> None:
    pelvis = spec.body(base)
    pelvis.name = nm.PELVIS_BODY
    pelvis.add_freejoint(name=nm.ROOT_JOINT)
    cam = pelvis.add_camera(
        name=nm.TRACK_CAMERA, mode=mujoco.mjtCamLight.mjCAMLIGHT_TRACKCOM, pos=[0.3, -2.6, 0.6]
    )
    cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
    cam.alt.xyaxes = [1.0, 0.0, 0.0, 0.0, 0.2, 1.0]
    torso = pelvis if lay.torso == base else spec.body(lay.torso)
    if torso is not pelvis:
        torso.name = nm.TORSO_BODY
    boxes = [(pelvis, nm.PELVIS_GEOM, lay.pelvis_box), (torso, nm.TORSO_GEOM, lay.torso_box)]
    for body, geom, (centre, half) in boxes:
        body.add_geom(
            name=geom,
            type=mujoco.mjtGeom.mjGEOM_BOX,
            pos=list(centre),
            size=list(half),
            rgba=_BLUE,
            group=nm.ROBOT_GROUP,
            **_ROBOT_COL,
        )
    if torso is pelvis:  # the walker holds "torso" upright: a massless frame on the base
        pelvis.add_body(name=nm.TORSO_BODY)


def _add_leg(mujoco: Any, spec: Any, rf: RobotFile, lay: Layout, side: Side) -> None:
    ph, sole = rf.physics, lay.sole
    for role, urdf_name in zip(LEG_JOINT_ROLES, lay.legs.of(side), strict=True):
        j = spec.joint(urdf_name)
        effort = float(j.actfrcrange[1]) if j.actfrclimited else math.inf
        axis = np.asarray(j.axis, dtype=float)
        k = int(np.argmax(np.abs(axis)))
        if axis[k] < 0.0:  # the same motion about +x/+y/+z: coordinate and range negated
            j.axis = (-axis).tolist()
            lo, hi = j.range
            j.range = [-hi, -lo]
        j.name = nm.joint(side, role)
        j.armature = ph.armature
        j.damping[0] = ph.joint_damping
        j.parent.name = nm.link_body(side, role)
        if not math.isfinite(effort) or effort <= 0.0:
            raise InputError(
                f"legs.{side.value}",
                urdf_name,
                "a joint with an effort (torque) limit in the model",
            )
        kp = effort / ph.servo_saturation
        act = spec.add_actuator(
            name=nm.actuator(side, role),
            target=nm.joint(side, role),
            trntype=mujoco.mjtTrn.mjTRN_JOINT,
        )
        act.set_to_position(kp=kp, kv=kp * ph.servo_damping_time)
        act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
        act.forcerange = [-effort, effort]
    foot = spec.body(nm.foot_body(side))
    r = sole.radius
    y = (sole.y[0], sole.y[1]) if side is Side.LEFT else (-sole.y[1], -sole.y[0])
    for k, (sx, sy) in enumerate(nm.FOOT_CORNERS):
        x = sole.x[1] - r if sx > 0 else sole.x[0] + r
        yy = y[1] - r if sy > 0 else y[0] + r
        foot.add_geom(
            name=nm.corner_geom(side, k),
            type=mujoco.mjtGeom.mjGEOM_SPHERE,
            size=[r, 0, 0],
            pos=[x, yy, sole.z + r],
            rgba=_DARK,
            friction=[ph.friction, 0.02, 0.002],
            solref=[0.004, 1.0],
            group=nm.ROBOT_GROUP,
            **_ROBOT_COL,
        )
    cx, cy = sole.centre
    cy = cy if side is Side.LEFT else -cy
    foot.add_site(name=nm.sole_site(side), pos=[cx, cy, sole.z], size=[0.01, 0, 0])
    foot.add_geom(
        name=nm.foot_geom(side),
        type=mujoco.mjtGeom.mjGEOM_BOX,
        pos=[cx, cy, sole.z + 0.01],
        size=[sole.length / 2, sole.width / 2, 0.01],
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


@functools.lru_cache(maxsize=16)
def walker_xml(rf: RobotFile, lay: Layout) -> str:
    """MJCF text of :func:`walker_spec` (cached: building reads and parses the model file)."""
    try:
        return str(walker_spec(rf, lay).to_xml())
    except FootfallError:
        raise
    except Exception as e:
        raise InputError(
            "model", str(rf.model), f"a model the walker can be built from ({e})"
        ) from None
