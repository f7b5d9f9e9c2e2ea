"""The page's scene as data: pure functions from what was loaded to meshes, lines, points and
labels with names, colours and poses, and the camera that frames them.

Nothing here talks to a browser: :mod:`footfall.viz.view.payload` packs these nodes for the page.
Node names are paths (``/scene/regions/007``, ``/plan/footsteps/003``): the page lists them in
its state, where the tests count regions and footsteps by them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.models.biped import Side
from footfall.planning.plan import FootstepPlan
from footfall.terrain.region import Region
from footfall.terrain.scene import Scene
from footfall.viz.view.replay import Mesh, RobotMotion

#: node name prefixes (the tests count children of these)
REGIONS, FOOTSTEPS, LANDED = "/scene/regions", "/plan/footsteps", "/walk/landed"
#: thickness of a region's slab below its surface [m]
SLAB = 0.03
#: soles float this far above their region so they are not hidden in it [m]
LIFT = 0.004
#: colours (RGB 0..255)
LEFT_RGB, RIGHT_RGB, LANDED_RGB = (52, 120, 219), (231, 76, 60), (40, 40, 40)
COM_RGB, COP_RGB, ZMP_RGB, PUSH_RGB = (142, 68, 173), (241, 196, 15), (39, 174, 96), (230, 126, 34)
START_RGB, GOAL_RGB = (46, 204, 113), (155, 89, 182)
#: viridis from 0.15 to 0.85 of its range (matplotlib's values, RGB 0..255)
VIRIDIS = np.array(
    [[71, 45, 123], [59, 82, 139], [44, 114, 142], [33, 145, 140], [40, 174, 128],
     [94, 201, 98], [173, 220, 48]],
    dtype=float,
)  # fmt: skip
#: how far the camera looks down [rad] and the share of the picture kept free at the edges
CAMERA_ELEVATION, CAMERA_MARGIN = math.radians(30.0), 0.06
#: terrain farther than this from the plan and the robot is left out of the framing [m]
FRAME_PAD = 0.6


@dataclass(frozen=True)
class Lines:
    """Line segments (S, 2, 3) [m] of one colour."""

    name: str
    segments: FloatArray
    rgb: tuple[int, int, int]


@dataclass(frozen=True)
class Label:
    """A text label at ``position`` (3,) [m]."""

    name: str
    text: str
    position: FloatArray


def height_colours(heights: FloatArray) -> list[tuple[int, int, int]]:
    """A colour per height, dark blue (lowest) to yellow-green (highest) along viridis (mid-scale
    when all are equal)."""
    h = np.asarray(heights, dtype=float)
    span = float(np.ptp(h)) if h.size else 0.0
    s = (h - h.min()) / span if span > 1e-9 else np.full(h.shape, 0.5)
    rgb = [np.interp(s, np.linspace(0.0, 1.0, len(VIRIDIS)), VIRIDIS[:, c]) for c in range(3)]
    return [(int(r), int(g), int(b)) for r, g, b in zip(*rgb, strict=True)]


def _prism(top: FloatArray, depth: float) -> tuple[FloatArray, NDArray[np.int32]]:
    """A slab under the convex polygon ``top`` (V, 3), counter-clockwise seen from above:
    its top face, its sides down to ``depth`` below."""
    v = top.shape[0]
    bottom = top - np.array([0.0, 0.0, depth])
    verts = np.vstack([top, bottom])
    faces = [(0, i, i + 1) for i in range(1, v - 1)]
    faces += [(v, v + i + 1, v + i) for i in range(1, v - 1)]
    for i in range(v):
        j = (i + 1) % v
        faces += [(i, v + i, j), (j, v + i, v + j)]
    return verts, np.array(faces, dtype=np.int32)


def region_meshes(scene: Scene) -> list[Mesh]:
    """One slab per region, its top on the region's plane, coloured by its mean height."""
    regions = scene.terrain.regions
    tops = [r.vertices3d for r in regions]
    colours = height_colours(np.array([t[:, 2].mean() for t in tops]))
    return [
        Mesh(f"{REGIONS}/{i:03d}", *_prism(top, SLAB), colours[i]) for i, top in enumerate(tops)
    ]


def sole_polygon(
    centre: FloatArray, heading: float, length: float, width: float, lift: float = LIFT
) -> FloatArray:
    """The sole's corners (4, 3) [m] at ``centre`` turned by ``heading`` [rad]."""
    c, s = math.cos(heading), math.sin(heading)
    hl, hw = length / 2, width / 2
    local = np.array([[hl, hw], [-hl, hw], [-hl, -hw], [hl, -hw]])
    xy = local @ np.array([[c, s], [-s, c]])
    return np.column_stack([xy + centre[:2], np.full(4, centre[2] + lift)])


def _sole(
    name: str,
    centre: FloatArray,
    heading: float,
    plan: FootstepPlan,
    rgb: tuple[int, int, int],
    opacity: float = 1.0,
    region: Region | None = None,
) -> Mesh:
    """A thin sole at ``centre`` (on ``region``'s plane when given, else level)."""
    corners = sole_polygon(centre, heading, plan.robot.foot_length, plan.robot.foot_width)
    if region is not None:
        corners[:, 2] = np.asarray(region.height_at(corners[:, :2])) + LIFT
    verts, faces = _prism(corners, 0.006)
    return Mesh(name, verts, faces, rgb, opacity)


def footstep_nodes(
    plan: FootstepPlan, scene: Scene | None = None
) -> tuple[list[Mesh], list[Label], Lines]:
    """The plan's soles (one per footstep, blue left and red right, on their regions' planes
    when the scene is known), their index and side as labels, and a heading tick from each
    sole's centre."""
    regions = {r.name: r for r in scene.terrain.regions} if scene is not None else {}
    soles, labels, ticks = [], [], []
    for i, (p, th, side) in enumerate(zip(plan.footsteps, plan.headings, plan.sides, strict=True)):
        rgb = LEFT_RGB if side is Side.LEFT else RIGHT_RGB
        region = regions.get(plan.regions[i]) if i < len(plan.regions) else None
        soles.append(_sole(f"{FOOTSTEPS}/{i:03d}", p, float(th), plan, rgb, region=region))
        top = p + np.array([0.0, 0.0, 0.05])
        labels.append(Label(f"/plan/labels/{i:03d}", f"{i} {side.value[0].upper()}", top))
        tip = p + 0.6 * plan.robot.foot_length * np.array([math.cos(th), math.sin(th), 0.0])
        up = np.array([0.0, 0.0, 2 * LIFT])
        ticks.append([p + up, tip + up])
    return soles, labels, Lines("/plan/headings", np.array(ticks).reshape(-1, 2, 3), (20, 20, 20))


def com_path(plan: FootstepPlan) -> Lines:
    """The CoM over the ALIP nodes (eq. 5.1: states relative to the stance footstep ``i``),
    ``com_height`` above that footstep, as a polyline."""
    pts = []
    for i in range(plan.states.shape[0]):
        foot = plan.footsteps[i]
        for x in plan.states[i]:
            pts.append([foot[0] + x[0], foot[1] + x[1], foot[2] + plan.robot.com_height])
    pts_a = np.array(pts).reshape(-1, 3)
    return Lines("/plan/com", polyline(pts_a), COM_RGB)


def polyline(points: FloatArray) -> FloatArray:
    """Segments (P - 1, 2, 3) joining consecutive points (P, 3)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if points.shape[0] < 2:
        return np.zeros((0, 2, 3))
    return np.stack([points[:-1], points[1:]], axis=1)


def landed_soles(plan: FootstepPlan, landed: FloatArray) -> Mesh | None:
    """Where the plan's footsteps 1..N landed, as dark translucent soles at the planned
    headings, in one mesh (None: none landed)."""
    soles = [
        _sole(f"{LANDED}/{i:03d}", p, float(plan.headings[i]), plan, LANDED_RGB, 0.55)
        for i, p in enumerate(landed, start=1)
        if i < len(plan.headings) and np.all(np.isfinite(p))
    ]
    return merge(LANDED, soles) if soles else None


def merge(name: str, meshes: list[Mesh]) -> Mesh:
    """One mesh of ``meshes`` (the first one's colour and opacity): a page draws one node
    faster than many."""
    offsets = np.cumsum([0] + [m.vertices.shape[0] for m in meshes[:-1]])
    return Mesh(
        name,
        np.vstack([m.vertices for m in meshes]),
        np.vstack([m.faces + k for m, k in zip(meshes, offsets, strict=True)]).astype(np.int32),
        meshes[0].rgb,
        meshes[0].opacity,
    )


def robot_meshes(motion: RobotMotion, world: bool) -> list[tuple[int, Mesh]]:
    """The robot's geoms merged per body and colour, as ``(body, mesh)`` in the body's frame
    (body -1: the model's fixed geoms, the quadruped's ground, included with ``world``)."""
    groups: dict[tuple[int, tuple[int, int, int], float], list[Mesh]] = {}
    for g in motion.geoms:
        if g.body >= 0 or world:
            groups.setdefault((g.body, g.mesh.rgb, g.mesh.opacity), []).append(g.mesh)
    out = []
    for k, ((body, _, _), meshes) in enumerate(groups.items()):
        parent = f"/robot/{motion.bodies[body]}" if body >= 0 else "/world_geoms"
        out.append((body, merge(f"{parent}/m{k}", meshes)))
    return out


def tube(lines: Lines, radius: float) -> Mesh:
    """``lines`` as thin square tubes of half-width ``radius`` [m] (a line a browser draws as
    thick as asked, at any zoom): 8 corners and 8 triangles per segment."""
    seg = np.asarray(lines.segments, dtype=float).reshape(-1, 2, 3)
    d = seg[:, 1] - seg[:, 0]
    length = np.linalg.norm(d, axis=1, keepdims=True)
    d = np.where(length > 1e-12, d / np.maximum(length, 1e-12), np.array([1.0, 0.0, 0.0]))
    # a side vector: across the segment, horizontal unless the segment is vertical
    helper = np.where(np.abs(d[:, 2:3]) > 0.9, np.array([1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0]))
    a = np.cross(d, helper)
    a /= np.linalg.norm(a, axis=1, keepdims=True)
    b = np.cross(d, a)
    ring = np.stack([a + b, a - b, -a - b, -a + b], axis=1) * radius  # (S, 4, 3)
    verts = np.concatenate([seg[:, :1] + ring, seg[:, 1:] + ring], axis=1)  # (S, 8, 3)
    side = []
    for i in range(4):
        j = (i + 1) % 4
        side += [(i, j, 4 + i), (j, 4 + j, 4 + i)]
    faces = (
        np.array(side, dtype=np.int32)[None]
        + 8 * np.arange(seg.shape[0], dtype=np.int32)[:, None, None]
    )
    return Mesh(lines.name, verts.reshape(-1, 3), faces.reshape(-1, 3), lines.rgb)


def sphere(name: str, radius: float, rgb: tuple[int, int, int], rings: int = 6) -> Mesh:
    """A sphere of ``radius`` [m] about the origin: ``rings`` latitude bands of ``2 rings``
    longitude steps."""
    lat = np.linspace(0.0, math.pi, rings + 1)
    lon = np.linspace(0.0, 2 * math.pi, 2 * rings, endpoint=False)
    la, lo = np.meshgrid(lat, lon, indexing="ij")
    verts = radius * np.stack(
        [np.sin(la) * np.cos(lo), np.sin(la) * np.sin(lo), np.cos(la)], axis=-1
    ).reshape(-1, 3)
    n = 2 * rings
    faces = []
    for i in range(rings):
        for j in range(n):
            a, b = i * n + j, i * n + (j + 1) % n
            faces += [(a, a + n, b), (b, a + n, b + n)]
    return Mesh(name, verts, np.array(faces, dtype=np.int32), rgb)


def start_goal(scene: Scene) -> list[Label]:
    """Labels above the start (between the feet) and the goal."""
    up = np.array([0.0, 0.0, 0.12])
    start = 0.5 * (np.asarray(scene.start.left) + np.asarray(scene.start.right))
    return [
        Label("/scene/start", "start", start + up),
        Label("/scene/goal", "goal", np.asarray(scene.goal.position) + up),
    ]


def push_arrow(at: FloatArray, force: FloatArray, scale: float = 0.004) -> FloatArray:
    """The push as a segment (1, 2, 3) ending at ``at`` [m], ``scale`` m per newton (so it points
    where the push goes and its length reads as its strength)."""
    f = np.asarray(force, dtype=float)
    tail = at - scale * f
    return np.array([[tail, at]])


def support_polygon(feet: FloatArray, contact: NDArray[np.bool_]) -> FloatArray:
    """The closed outline (segments (S, 2, 3)) of the stance feet's convex hull; the feet in
    ``LEGS`` order (lf, rf, rh, lh as the quadruped module numbers them) are sorted by angle
    about their centroid, which for three or four feet is their hull."""
    pts = feet[contact]
    if pts.shape[0] < 2:
        return np.zeros((0, 2, 3))
    c = pts.mean(axis=0)
    order = np.argsort(np.arctan2(pts[:, 1] - c[1], pts[:, 0] - c[0]))
    ring = pts[order]
    return np.stack([ring, np.roll(ring, -1, axis=0)], axis=1)


def body_extents(motion: RobotMotion, every: int = 10) -> FloatArray:
    """Points (P, 3) [m] that enclose the robot over its motion: each body's origin moved by
    the reach of its geoms along the world axes, every ``every`` frames and at the last."""
    reach = np.zeros(len(motion.bodies))
    for g in motion.geoms:
        if g.body >= 0 and g.mesh.vertices.size:
            reach[g.body] = max(reach[g.body], float(np.linalg.norm(g.mesh.vertices, axis=1).max()))
    frames = np.unique(np.r_[np.arange(0, motion.pos.shape[0], every), motion.pos.shape[0] - 1])
    pos = motion.pos[frames].reshape(-1, 1, 3)
    r = np.tile(reach, len(frames)).reshape(-1, 1, 1)
    axes = np.vstack([np.eye(3), -np.eye(3)]).reshape(1, 6, 3)
    return (pos + r * axes).reshape(-1, 3)


def framed_points(terrain: FloatArray, activity: FloatArray, pad: float = FRAME_PAD) -> FloatArray:
    """The points a camera should frame: the plan's and the robot's (``activity``, (P, 3)) and
    the terrain's (T, 3) that lie within ``pad`` [m] of their bounding box (a 3 m wide floor
    under a 1 m walk would leave the walk a speck); the whole terrain when nothing else is
    shown."""
    act = np.asarray(activity, dtype=float).reshape(-1, 3)
    act = act[np.all(np.isfinite(act), axis=1)]
    ter = np.asarray(terrain, dtype=float).reshape(-1, 3)
    if act.shape[0] == 0:
        return ter
    lo, hi = act.min(axis=0) - pad, act.max(axis=0) + pad
    near = np.all((ter >= lo) & (ter <= hi), axis=1)
    return np.vstack([act, ter[near]])


@dataclass(frozen=True)
class Camera:
    """Where the camera is and what it looks at (3,) [m], with its vertical field of view."""

    position: FloatArray
    look_at: FloatArray
    fov: float


def fit_camera(
    points: FloatArray,
    fov: float = math.radians(45.0),
    aspect: float = 16.0 / 9.0,
    elevation: float = CAMERA_ELEVATION,
) -> Camera:
    """The camera that looks at ``points`` (P, 3) across their long horizontal axis from
    ``elevation`` above, at the distance where every point is just inside the picture
    (``CAMERA_MARGIN`` free at the edges): the pinhole bound ``|x| <= z tan(fov/2)`` solved for
    the distance along the view direction."""
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if pts.shape[0] == 0:
        pts = np.zeros((1, 3))
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre = 0.5 * (lo + hi)
    xy = pts[:, :2] - centre[:2]
    # look across the principal horizontal axis (a walk is seen from its side)
    if xy.shape[0] >= 2 and np.ptp(xy) > 1e-9:
        _, vecs = np.linalg.eigh(xy.T @ xy)
        along = vecs[:, -1]
    else:
        along = np.array([1.0, 0.0])
    side = np.array([-along[1], along[0]])
    if side[1] > 0:  # from the -y side (the right of a walk along +x), as the videos do
        side = -side
    # back off a little toward the start so the view is three-quarter, not flat side-on
    horiz = side * math.cos(0.35) - along * math.sin(0.35) * np.sign(along[0] or 1.0)
    u = np.array(
        [horiz[0] * math.cos(elevation), horiz[1] * math.cos(elevation), math.sin(elevation)]
    )
    u /= np.linalg.norm(u)
    right = np.cross(np.array([0.0, 0.0, 1.0]), u)
    right /= np.linalg.norm(right)
    up = np.cross(u, right)
    d = pts - centre
    tan_v = math.tan(fov / 2) * (1.0 - CAMERA_MARGIN)
    tan_h = math.tan(fov / 2) * aspect * (1.0 - CAMERA_MARGIN)
    # depth of p is dist - d.u; need |d.right| <= depth tan_h and |d.up| <= depth tan_v
    need = np.maximum(np.abs(d @ right) / tan_h, np.abs(d @ up) / tan_v) + d @ u
    dist = max(float(need.max()), 0.5)
    return Camera(centre + dist * u, centre, fov)
