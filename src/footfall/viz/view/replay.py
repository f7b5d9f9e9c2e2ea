"""Read a walk's ``replay.npz`` (:mod:`footfall.sim.replay` writes it) and pose its robot.

The file is read with ``allow_pickle=False``: only numeric and text arrays, never code. The joint
positions become body poses through MuJoCo's forward kinematics of the recorded MJCF, and the
model's geoms become triangle meshes (boxes, capsules, spheres, cylinders, ellipsoids through
``trimesh``; mesh geoms from the compiled model's own vertices), so the page needs neither the
simulation nor the robot's files.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from footfall._io import regular_file
from footfall._typing import FloatArray
from footfall.errors import InputError

#: what this reader understands (``footfall.sim.replay.REPLAY_FORMAT``)
REPLAY_FORMAT = "footfall-replay-1"
#: a replay file larger than this [bytes] is refused (a 20 s biped walk is ~0.1 MB)
MAX_REPLAY_BYTES = 200_000_000
#: frames a replay may hold (an hour at 30 Hz)
MAX_FRAMES = 108_000
#: MuJoCo geom types (``mjtGeom``) drawn from the model
PLANE, HFIELD, SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = 0, 1, 2, 3, 4, 5, 6, 7
#: half extent [m] of an infinite plane geom when drawn
PLANE_HALF = 4.0


@dataclass(frozen=True)
class Replay:
    """The arrays of a replay file.

    Attributes:
        kind: ``biped`` or ``quadruped``.
        t: frame times, shape (F,) [s].
        qpos: MuJoCo joint positions per frame, shape (F, nq).
        model_xml: the MJCF the walk compiled.
        scene_yaml: the walked scene as a scene file ("" when not recorded).
        traces: measurements per frame, each with F rows (see :mod:`footfall.sim.replay`).
    """

    kind: str
    t: FloatArray
    qpos: FloatArray
    model_xml: str
    scene_yaml: str = ""
    traces: dict[str, NDArray[Any]] = field(default_factory=dict)


@dataclass(frozen=True)
class Mesh:
    """A triangle mesh: vertices (V, 3) [m] in its own frame, faces (T, 3), colour (three ints
    in 0..255), opacity (0..1); ``name`` is its node in the page."""

    name: str
    vertices: FloatArray
    faces: NDArray[np.int32]
    rgb: tuple[int, int, int]
    opacity: float = 1.0


@dataclass(frozen=True)
class GeomMesh:
    """One geom of the model: ``mesh`` in the frame of body ``body`` (an index into
    :attr:`RobotMotion.bodies`; -1: the world, a fixed geom)."""

    body: int
    mesh: Mesh


@dataclass(frozen=True)
class RobotMotion:
    """The robot of a replay: its geoms and its bodies' poses at every frame.

    Attributes:
        t: frame times, shape (F,) [s].
        bodies: names of the moving bodies that carry geoms, length B.
        pos: body positions, shape (F, B, 3) [m]; wxyz: body orientations, shape (F, B, 4).
        geoms: the meshes of the robot's geoms (``body >= 0``) and of the world's (``-1``).
    """

    t: FloatArray
    bodies: tuple[str, ...]
    pos: FloatArray
    wxyz: FloatArray
    geoms: tuple[GeomMesh, ...]


def _text(data: Any, key: str, path: Path) -> str:
    arr = data[key]
    if arr.dtype.kind != "U" or arr.ndim != 0:
        raise InputError(f"{path}:{key}", str(arr.dtype), "a text entry")
    return str(arr)


def read_replay(path: Path) -> Replay:
    """The replay in ``path``; a file that is not one (or of another format) is an
    :class:`InputError` naming it."""
    regular_file(path, "replay file", MAX_REPLAY_BYTES)
    try:
        with np.load(path, allow_pickle=False) as data:
            keys = set(data.files)
            missing = {"format", "kind", "t", "qpos", "model_xml"} - keys
            if missing:
                raise InputError(
                    "replay file", str(path), f"a footfall replay (no {sorted(missing)})"
                )
            fmt = _text(data, "format", path)
            if fmt != REPLAY_FORMAT:
                raise InputError(f"{path}:format", fmt, REPLAY_FORMAT)
            t = np.asarray(data["t"], dtype=float)
            qpos = np.asarray(data["qpos"], dtype=float)
            traces = {k.removeprefix("trace/"): data[k] for k in keys if k.startswith("trace/")}
            replay = Replay(
                kind=_text(data, "kind", path),
                t=t,
                qpos=qpos,
                model_xml=_text(data, "model_xml", path),
                scene_yaml=_text(data, "scene_yaml", path) if "scene_yaml" in keys else "",
                traces=traces,
            )
    except (OSError, ValueError, EOFError, zipfile.BadZipFile, KeyError) as e:
        if isinstance(e, InputError):
            raise
        raise InputError("replay file", str(path), f"a readable .npz replay ({e})") from None
    _check_shapes(replay, path)
    return replay


def _check_shapes(r: Replay, path: Path) -> None:
    n = r.t.shape[0] if r.t.ndim == 1 else -1
    if n < 1 or n > MAX_FRAMES or not np.all(np.isfinite(r.t)) or np.any(np.diff(r.t) < 0):
        raise InputError(f"{path}:t", r.t.shape, f"1 to {MAX_FRAMES} ascending finite times")
    if r.qpos.ndim != 2 or r.qpos.shape[0] != n or not np.all(np.isfinite(r.qpos)):
        raise InputError(f"{path}:qpos", r.qpos.shape, f"({n}, nq) finite joint positions")
    for name, arr in r.traces.items():
        if arr.shape[:1] != (n,) or arr.dtype.kind not in "fiub":
            raise InputError(f"{path}:trace/{name}", arr.shape, f"{n} numeric rows")


def _mujoco() -> Any:
    try:
        import mujoco
    except ImportError:
        raise InputError(
            "mujoco", "not installed", "pip install 'footfall[sim]' to show a walk's robot"
        ) from None
    return mujoco


def robot_motion(replay: Replay) -> RobotMotion:
    """Body poses at every frame (MuJoCo forward kinematics of the recorded model) and the
    model's geoms as meshes."""
    mujoco = _mujoco()
    try:
        model = mujoco.MjModel.from_xml_string(replay.model_xml)
    except ValueError as e:
        raise InputError(
            "replay model_xml", str(e)[:200], "an MJCF model MuJoCo compiles"
        ) from None
    if replay.qpos.shape[1] != model.nq:
        raise InputError("replay qpos", replay.qpos.shape, f"{model.nq} columns (the model's nq)")
    data = mujoco.MjData(model)
    bodies = sorted({int(b) for b in model.geom_bodyid if b > 0})
    index = {b: i for i, b in enumerate(bodies)}
    n = replay.t.shape[0]
    pos = np.empty((n, len(bodies), 3))
    wxyz = np.empty((n, len(bodies), 4))
    for f in range(n):
        data.qpos[:] = replay.qpos[f]
        mujoco.mj_kinematics(model, data)
        pos[f] = data.xpos[bodies]
        wxyz[f] = data.xquat[bodies]
    geoms = tuple(
        g
        for i in range(model.ngeom)
        if (g := geom_mesh(model, i, index.get(int(model.geom_bodyid[i]), -1))) is not None
    )
    names = tuple(
        mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}" for b in bodies
    )
    return RobotMotion(replay.t, names, pos, wxyz, geoms)


def revolve(profile: FloatArray, sections: int = 16) -> tuple[FloatArray, NDArray[np.int32]]:
    """The surface of revolution about z of ``profile`` (P, 2) rows ``(radius, z)`` from bottom
    to top: P rings of ``sections`` vertices, triangles facing outward."""
    theta = np.linspace(0.0, 2.0 * np.pi, sections, endpoint=False)
    r, z = profile[:, :1], profile[:, 1:]
    verts = np.stack(
        [r * np.cos(theta), r * np.sin(theta), np.broadcast_to(z, (len(profile), sections))],
        axis=-1,
    ).reshape(-1, 3)
    k, i = np.meshgrid(np.arange(len(profile) - 1), np.arange(sections), indexing="ij")
    a = k * sections + i
    b = k * sections + (i + 1) % sections
    faces = np.concatenate(
        [np.stack([a, b, a + sections], -1), np.stack([b, b + sections, a + sections], -1)]
    )
    return verts, faces.reshape(-1, 3).astype(np.int32)


def _arc(lo: float, hi: float, n: int = 5) -> FloatArray:
    """(cos, sin) of ``n`` latitudes from ``lo`` to ``hi`` [rad]."""
    phi = np.linspace(lo, hi, n)
    return np.column_stack([np.cos(phi), np.sin(phi)])


def box(half: FloatArray) -> tuple[FloatArray, NDArray[np.int32]]:
    """A box of half extents ``half`` (3,) [m] centred at the origin, faces outward."""
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    faces = [(a, b, c) for a, b, c, _ in quads] + [(a, c, d) for a, _, c, d in quads]
    return corners * half, np.array(faces, dtype=np.int32)


def primitive(gtype: int, size: FloatArray) -> tuple[FloatArray, NDArray[np.int32]] | None:
    """A MuJoCo primitive geom of half sizes ``size`` (3,) as a mesh centred at its origin, its
    axis along z (None for a height field or a mesh)."""
    half_pi = np.pi / 2
    if gtype == BOX:
        return box(size)
    if gtype == PLANE:  # infinite sides (size 0) are drawn PLANE_HALF wide
        hx, hy = (s if s > 0 else PLANE_HALF for s in size[:2])
        return box(np.array([hx, hy, 5e-4]))
    if gtype in (SPHERE, ELLIPSOID):
        verts, faces = revolve(_arc(-half_pi, half_pi, 9))
        return verts * (size if gtype == ELLIPSOID else size[0]), faces
    if gtype == CAPSULE:
        r, h = size[0], size[1]
        lower = _arc(-half_pi, 0.0) * r - [0.0, h]
        upper = _arc(0.0, half_pi) * r + [0.0, h]
        return revolve(np.vstack([lower, upper]))
    if gtype == CYLINDER:
        r, h = size[0], size[1]
        return revolve(np.array([[0.0, -h], [r, -h], [r, h], [0.0, h]]))
    return None


def _trimesh() -> Any:
    try:
        import trimesh
    except ImportError:
        raise InputError("trimesh", "not installed", "pip install 'footfall[view]'") from None
    return trimesh


def _model_mesh(model: Any, i: int) -> tuple[FloatArray, NDArray[np.int32]]:
    """Mesh geom ``i``'s compiled vertices and faces, through ``trimesh`` (which merges the
    duplicate vertices MuJoCo keeps per face and drops degenerate faces)."""
    trimesh = _trimesh()
    m = int(model.geom_dataid[i])
    v0, nv = int(model.mesh_vertadr[m]), int(model.mesh_vertnum[m])
    f0, nf = int(model.mesh_faceadr[m]), int(model.mesh_facenum[m])
    mesh = trimesh.Trimesh(model.mesh_vert[v0 : v0 + nv], model.mesh_face[f0 : f0 + nf])
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int32)


def geom_mesh(model: Any, i: int, body: int) -> GeomMesh | None:
    """Geom ``i`` of a compiled MuJoCo model as a mesh in its body's frame (None: not drawn,
    e.g. a height field or an invisible geom)."""
    gtype = int(model.geom_type[i])
    rgba = np.array(model.geom_rgba[i], dtype=float)
    if model.geom_matid[i] >= 0:
        rgba = np.array(model.mat_rgba[model.geom_matid[i]], dtype=float)
    if rgba[3] <= 0.0:
        return None
    if gtype == MESH:
        verts, faces = _model_mesh(model, i)
    else:
        shape = primitive(gtype, np.array(model.geom_size[i], dtype=float))
        if shape is None:
            return None
        verts, faces = shape
    rot = np.zeros(9)
    _mujoco().mju_quat2Mat(rot, np.array(model.geom_quat[i], dtype=float))
    verts = verts @ rot.reshape(3, 3).T + np.asarray(model.geom_pos[i], dtype=float)
    rgb = tuple(round(255 * float(c)) for c in np.clip(rgba[:3], 0.0, 1.0))
    return GeomMesh(body, Mesh(f"geom{i}", verts, faces, (rgb[0], rgb[1], rgb[2]), float(rgba[3])))
