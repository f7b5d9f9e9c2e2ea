"""ZMP stability criterion of document 001, sec. 1.1-1.2 (eq. 1-8).

All polygons are 2-D (horizontal projections onto the x-y plane of ``{W}``) with shape (N, 2) [m];
support polygons are returned counter-clockwise.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from footfall._geometry import monotone_chain
from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.models.lip import GRAVITY

#: points closer than this [m] count as the same point when building a hull
_GEOM_EPS = 1e-12


def _cross(o: Sequence[float], a: Sequence[float], b: Sequence[float]) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def support_polygon(points: ArrayLike) -> FloatArray:
    """Convex hull of the horizontal projections of the stance feet (sec. 1.1).

    Args:
        points: contact points, shape (N, 2) or (N, 3) [m]; only x and y are used.

    Returns:
        Hull vertices counter-clockwise without repetition, shape (K, 2), K <= N. Collinear
        points are dropped, so two or more collinear feet give a segment (K = 2).
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[0] == 0 or pts.shape[1] < 2:
        raise InputError("points", pts.shape, "an array of shape (N, 2) or (N, 3), N >= 1")
    hull = monotone_chain([(float(x), float(y)) for x, y in pts[:, :2].tolist()], _GEOM_EPS)
    return np.array(hull)


def _point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    ab = b - a
    denom = float(ab @ ab)
    t = 0.0 if denom <= _GEOM_EPS else float(np.clip((p - a) @ ab / denom, 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def stability_margin(zmp: ArrayLike, polygon: ArrayLike) -> float:
    """Signed stability margin S_m of a ZMP in a convex support polygon, eq. (8).

    Implements eq. (8) of document 001, ``S_m = min(S_m1, S_m2, S_m3)``, generalised to any convex
    polygon: inside, the shortest distance from the ZMP to the polygon's edges (positive); outside,
    minus the Euclidean distance to the polygon (negative). A polygon of fewer than three vertices
    (a segment or point) has no interior, so its margin is minus the distance (0 on it).

    Args:
        zmp: ZMP position, shape (2,) or (3,) [m]; only x and y are used.
        polygon: convex polygon vertices, shape (K, 2) [m], either orientation.

    Returns:
        Signed margin [m].
    """
    p = np.asarray(zmp, dtype=float)[:2]
    poly = support_polygon(polygon)
    k = poly.shape[0]
    if k == 1:
        return -float(np.linalg.norm(p - poly[0]))
    if k == 2:
        return -_point_segment_distance(p, poly[0], poly[1])
    # a handful of vertices: Python floats are faster here than numpy's per-call overhead
    px, py = float(p[0]), float(p[1])
    vs = poly.tolist()
    signed = []
    for (ax, ay), (bx, by) in zip(vs, vs[1:] + vs[:1], strict=True):
        ex, ey = bx - ax, by - ay
        length = math.sqrt(ex * ex + ey * ey)
        # CCW polygon: the inward normal of edge (a -> b) is the edge rotated by +90 degrees.
        signed.append((px - ax) * (-ey / length) + (py - ay) * (ex / length))
    if min(signed) >= 0.0:
        return float(min(signed))
    return -min(_point_segment_distance(p, poly[i], poly[(i + 1) % k]) for i in range(k))


def stability_margins(points: ArrayLike, polygon: ArrayLike) -> FloatArray:
    """Vectorised :func:`stability_margin` of many points in one polygon, shape (N,) [m]."""
    pts = np.asarray(points, dtype=float).reshape(-1, np.shape(points)[-1])[:, :2]
    poly = support_polygon(polygon)
    k = poly.shape[0]
    if k < 3:
        return np.array([stability_margin(p, poly) for p in pts])
    a = poly
    b = np.roll(poly, -1, axis=0)
    edges = b - a
    lengths = np.linalg.norm(edges, axis=1)
    normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1) / lengths[:, None]
    rel = pts[:, None, :] - a[None, :, :]
    signed = np.einsum("nkj,kj->nk", rel, normals)
    inside = np.all(signed >= 0.0, axis=1)
    tt = np.clip(np.einsum("nkj,kj->nk", rel, edges) / (lengths**2)[None, :], 0.0, 1.0)
    nearest = a[None] + tt[..., None] * edges[None]
    dist = np.linalg.norm(pts[:, None, :] - nearest, axis=2).min(axis=1)
    return np.where(inside, signed.min(axis=1), -dist)


def zmp_from_com(
    com: ArrayLike, com_acc: ArrayLike, z_p: float | ArrayLike = 0.0, g: float = GRAVITY
) -> FloatArray:
    """ZMP of a point-mass robot from its CoM motion, eq. (7).

    Implements eq. (7) of document 001:
    ``x_p = x_c - (z_c - z_p) xdd_c / (zdd_c + g)`` and the same for y.

    Args:
        com: CoM position p_c, shape (3,) or (T, 3) [m].
        com_acc: CoM acceleration, shape (3,) or (T, 3) [m/s^2].
        z_p: height of the ground plane on which the ZMP is sought [m], scalar or shape (T,).
        g: gravity [m/s^2].

    Returns:
        ZMP (x_p, y_p), shape (2,) or (T, 2) [m].
    """
    c = np.asarray(com, dtype=float)
    a = np.asarray(com_acc, dtype=float)
    zp = np.asarray(z_p, dtype=float)
    denom = a[..., 2] + g
    if np.any(denom <= 0.0):
        raise InputError("com_acc", "zdd_c <= -g", "vertical acceleration above -g (feet loaded)")
    scale = (c[..., 2] - zp) / denom
    return np.stack([c[..., 0] - scale * a[..., 0], c[..., 1] - scale * a[..., 1]], axis=-1)


def zmp_from_momentum(
    mass: float,
    com: ArrayLike,
    p_dot: ArrayLike,
    l_dot: ArrayLike,
    z_p: float | ArrayLike = 0.0,
    g: float = GRAVITY,
) -> FloatArray:
    """ZMP from the rates of linear and angular momentum, eq. (5).

    Implements eq. (5) of document 001 (derived from eq. 1-4 by setting the horizontal components
    of the moment about the ZMP to zero):
    ``x_p = (M g x_c + z_p Pdot_x - Ldot_y) / (M g + Pdot_z)``,
    ``y_p = (M g y_c + z_p Pdot_y + Ldot_x) / (M g + Pdot_z)``,
    with the angular momentum ``L`` taken about the origin of ``{W}``.

    Args:
        mass: total mass M [kg].
        com: CoM position, shape (3,) or (T, 3) [m].
        p_dot: rate of linear momentum, shape (3,) or (T, 3) [N].
        l_dot: rate of angular momentum about the origin of ``{W}``, shape (3,) or (T, 3) [N m].
        z_p: ground height of the ZMP [m], scalar or shape (T,).
        g: gravity [m/s^2].

    Returns:
        ZMP (x_p, y_p), shape (2,) or (T, 2) [m].
    """
    c = np.asarray(com, dtype=float)
    pd = np.asarray(p_dot, dtype=float)
    ld = np.asarray(l_dot, dtype=float)
    zp = np.asarray(z_p, dtype=float)
    mg = mass * g
    den = mg + pd[..., 2]
    if np.any(den <= 0.0):
        raise InputError("p_dot", "Pdot_z <= -M g", "M g + Pdot_z > 0 (feet loaded)")
    x = (mg * c[..., 0] + zp * pd[..., 0] - ld[..., 1]) / den
    y = (mg * c[..., 1] + zp * pd[..., 1] + ld[..., 0]) / den
    return np.stack([x, y], axis=-1)


def centre_of_pressure(
    positions: ArrayLike, forces: ArrayLike, z_p: float = 0.0
) -> tuple[FloatArray, float]:
    """Centre of pressure on the horizontal plane ``z = z_p`` from point contact forces.

    The point where the contact forces have no horizontal moment; it equals the ZMP of eq. (4)-(5)
    because the contact wrench balances gravity and the momentum rates (eq. 2-3). Contacts need
    not be coplanar (feet on a slope): a force applied at height ``z_i`` also contributes
    ``-(z_i - z_p) f_x`` to the moment.

    Args:
        positions: contact points in ``{W}``, shape (N, 3) [m].
        forces: contact forces on the robot in ``{W}``, shape (N, 3) [N].
        z_p: height of the reference plane [m].

    Returns:
        ``(cop, f_z)``: CoP (x, y) of shape (2,) [m] and the total vertical force [N]
        (CoP is NaN when ``f_z <= 0``).
    """
    r = np.asarray(positions, dtype=float).reshape(-1, 3)
    f = np.asarray(forces, dtype=float).reshape(-1, 3)
    fz = float(f[:, 2].sum())
    if fz <= 0.0:
        return np.array([np.nan, np.nan]), fz
    dz = r[:, 2] - z_p
    x = float((r[:, 0] * f[:, 2] - dz * f[:, 0]).sum() / fz)
    y = float((r[:, 1] * f[:, 2] - dz * f[:, 1]).sum() / fz)
    return np.array([x, y]), fz


def incentre(triangle: ArrayLike) -> tuple[FloatArray, float]:
    """Incentre and inradius of a triangle: the point of largest stability margin (sec. 1.2).

    By eq. (8) the margin of a point is its distance to the nearest side, which is largest
    (equal to the inradius) at the incentre ``(a A + b B + c C) / (a + b + c)`` with ``a, b, c``
    the lengths of the sides opposite ``A, B, C``.

    Args:
        triangle: vertices, shape (3, 2) [m].

    Returns:
        ``(centre, radius)``: incentre shape (2,) [m] and inradius [m].
    """
    t = np.asarray(triangle, dtype=float)[:, :2]
    if t.shape != (3, 2):
        raise InputError("triangle", t.shape, "three 2-D vertices, shape (3, 2)")
    a = np.linalg.norm(t[1] - t[2])
    b = np.linalg.norm(t[2] - t[0])
    c = np.linalg.norm(t[0] - t[1])
    per = a + b + c
    area = 0.5 * abs(_cross(t[0], t[1], t[2]))
    if area <= _GEOM_EPS:
        raise InputError("triangle", t.tolist(), "a non-degenerate triangle")
    centre = (a * t[0] + b * t[1] + c * t[2]) / per
    return centre, float(2.0 * area / per)


def line_intersection(p1: ArrayLike, p2: ArrayLike, q1: ArrayLike, q2: ArrayLike) -> FloatArray:
    """Intersection of the lines p1-p2 and q1-q2 (2-D), shape (2,) [m].

    Used for the document's point ``I = BD ∩ AC1`` (sec. 1.3, fig. 4).
    """
    a = np.asarray(p1, dtype=float)[:2]
    b = np.asarray(p2, dtype=float)[:2]
    c = np.asarray(q1, dtype=float)[:2]
    d = np.asarray(q2, dtype=float)[:2]
    r, s = b - a, d - c
    den = r[0] * s[1] - r[1] * s[0]
    if abs(den) <= _GEOM_EPS:
        raise InputError("lines", (a.tolist(), b.tolist()), "two non-parallel lines")
    t = ((c[0] - a[0]) * s[1] - (c[1] - a[1]) * s[0]) / den
    return a + t * r


def clip_convex(subject: ArrayLike, clip: ArrayLike) -> FloatArray:
    """Intersection of two convex polygons (Sutherland-Hodgman), CCW, shape (K, 2) [m].

    Returns an empty (0, 2) array when they do not overlap.
    """
    out = support_polygon(subject)
    cl = support_polygon(clip)
    for i in range(cl.shape[0]):
        a, b = cl[i], cl[(i + 1) % cl.shape[0]]
        if out.shape[0] == 0:
            break
        inp = out
        pts: list[FloatArray] = []
        for j in range(inp.shape[0]):
            cur, nxt = inp[j], inp[(j + 1) % inp.shape[0]]
            cur_in = _cross(a, b, cur) >= -_GEOM_EPS
            nxt_in = _cross(a, b, nxt) >= -_GEOM_EPS
            if cur_in:
                pts.append(cur)
            if cur_in != nxt_in:
                pts.append(line_intersection(cur, nxt, a, b))
        out = np.array(pts) if pts else np.zeros((0, 2))
    if out.shape[0] >= 3:
        return support_polygon(out)
    return out
