"""A ``footfall.terrain`` scene as MuJoCo geoms, so that the planner and the simulator see one world.

Each convex region (document 000, eq. 5.15-5.18) becomes one solid whose top face is exactly the
region's polygon on its plane:

- a horizontal rectangle -> a box reaching down to a common base level;
- a tilted rectangle with one horizontal edge (a ramp) -> a box of thickness ``RAMP_THICKNESS``
  rotated onto the plane;
- any other convex polygon -> a convex mesh prism (top face on the plane, vertical sides).

Nothing is placed where there is no region: gaps are holes.
"""

from __future__ import annotations

import numpy as np

from footfall._mjcf import fmt as _fmt
from footfall._typing import FloatArray
from footfall.robots import names as nm
from footfall.terrain.region import Region
from footfall.terrain.terrain import Terrain


def _f(*values: float | np.floating) -> str:
    # 9 digits: tilted region boxes must match their planes to well below 1e-6 m
    return _fmt(*values, digits=9)


#: depth of the terrain solids below the lowest region [m]
BASE_DEPTH = 0.5
#: thickness of a tilted (ramp) box measured along its normal [m]
RAMP_THICKNESS = 0.3
#: tolerance [m] / [rad] for recognising rectangles and horizontal edges
SHAPE_TOL = 1e-9


def _rectangle_axes(corners: FloatArray) -> tuple[FloatArray, FloatArray] | None:
    """Edge vectors (u, v) of a 3-D rectangle given by 4 CCW corners, or None if not one."""
    if corners.shape[0] != 4:
        return None
    u = corners[1] - corners[0]
    v = corners[3] - corners[0]
    parallelogram = np.allclose(corners[2], corners[0] + u + v, atol=1e-7)
    if not parallelogram or abs(float(u @ v)) > 1e-7 * np.linalg.norm(u) * np.linalg.norm(v):
        return None
    return u, v


def _quat_from_axes(x: FloatArray, y: FloatArray, z: FloatArray) -> FloatArray:
    """Unit quaternion (w, x, y, z) of the rotation whose columns are the axes x, y, z."""
    r = np.column_stack([x, y, z])
    w = np.sqrt(max(0.0, 1.0 + r[0, 0] + r[1, 1] + r[2, 2])) / 2.0
    qx = np.sqrt(max(0.0, 1.0 + r[0, 0] - r[1, 1] - r[2, 2])) / 2.0
    qy = np.sqrt(max(0.0, 1.0 - r[0, 0] + r[1, 1] - r[2, 2])) / 2.0
    qz = np.sqrt(max(0.0, 1.0 - r[0, 0] - r[1, 1] + r[2, 2])) / 2.0
    qx = np.copysign(qx, r[2, 1] - r[1, 2])
    qy = np.copysign(qy, r[0, 2] - r[2, 0])
    qz = np.copysign(qz, r[1, 0] - r[0, 1])
    q = np.array([w, qx, qy, qz])
    return q / np.linalg.norm(q)


def region_solid(region: Region, base: float) -> tuple[str, str]:
    """``(asset_xml, geom_xml)`` of the solid under ``region`` reaching down to ``base`` [m]."""
    name = nm.region_geom(region.name)
    bits = (
        f'contype="{nm.TERRAIN_CONTYPE}" conaffinity="{nm.TERRAIN_CONAFFINITY}" '
        f'group="{nm.TERRAIN_GROUP}"'
    )
    top = np.asarray(region.vertices3d)
    axes = _rectangle_axes(top)
    if axes is not None and region.is_flat:
        u, v = axes
        z = float(top[0, 2])
        centre = top.mean(axis=0)
        half = (np.linalg.norm(u) / 2, np.linalg.norm(v) / 2, (z - base) / 2)
        q = _quat_from_axes(u / half[0] / 2, v / half[1] / 2, np.array([0.0, 0.0, 1.0]))
        pos = (centre[0], centre[1], (z + base) / 2)
        return "", (
            f'<geom name="{name}" type="box" size="{_f(*half)}" pos="{_f(*pos)}" '
            f'quat="{_f(*q)}" material="terrain" {bits}/>'
        )
    if axes is not None:
        u, v = axes
        if abs(u[2]) <= SHAPE_TOL or abs(v[2]) <= SHAPE_TOL:
            n = np.asarray(region.normal)
            ex, ey = u / np.linalg.norm(u), v / np.linalg.norm(v)
            if float(np.cross(ex, ey) @ n) < 0.0:
                ey = -ey
            half = (np.linalg.norm(u) / 2, np.linalg.norm(v) / 2, RAMP_THICKNESS / 2)
            # the box's top face is the region: its centre lies half a thickness below the plane
            pos = top.mean(axis=0) - n * RAMP_THICKNESS / 2
            q = _quat_from_axes(ex, ey, n)
            return "", (
                f'<geom name="{name}" type="box" size="{_f(*half)}" pos="{_f(*pos)}" '
                f'quat="{_f(*q)}" material="terrain" {bits}/>'
            )
    # general convex polygon: a prism; MuJoCo collides with the convex hull of the mesh vertices
    bottom = np.column_stack([region.vertices, np.full(len(region.vertices), base)])
    verts = np.vstack([top, bottom])
    mesh = f"{nm.REGION_MESH_PREFIX}{region.name}"
    asset = f'<mesh name="{mesh}" vertex="{_f(*verts.ravel())}"/>'
    return asset, (f'<geom name="{name}" type="mesh" mesh="{mesh}" material="terrain" {bits}/>')


def terrain_xml(terrain: Terrain) -> tuple[str, str]:
    """``(asset_xml, worldbody_xml)`` of all regions of ``terrain`` (see the module docstring)."""
    lowest = min(float(np.min(r.vertices3d[:, 2])) for r in terrain.regions)
    base = lowest - BASE_DEPTH
    assets, geoms = [], []
    for region in terrain.regions:
        a, g = region_solid(region, base)
        if a:
            assets.append(a)
        geoms.append(g)
    return "\n    ".join(assets), "\n    ".join(geoms)
