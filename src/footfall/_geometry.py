"""Planar convex-polygon helpers shared by the reach trapezoid and the terrain regions.

All polygons are arrays of shape (V, 2) [m], vertices in order, the last edge closing back to the
first vertex. "CCW" means a positive signed (shoelace) area.
"""

from __future__ import annotations

import itertools
import math

import numpy as np
from numpy.typing import ArrayLike

from footfall._typing import FloatArray
from footfall.errors import InputError

#: turning angles smaller than this [rad] count as straight (collinear vertices are allowed)
ANGLE_TOL = 1e-9
#: polygon edges shorter than this [m] have no reliable direction (near-repeated vertices)
EDGE_TOL = 1e-9


def rot2(theta: float) -> FloatArray:
    """2-D rotation matrix Rot(theta) (2, 2) of eq. (5.13): ``rot2(theta) @ v`` turns ``v`` by
    ``theta`` [rad] counter-clockwise."""
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def project_to_polygon(q: FloatArray, vertices: FloatArray) -> FloatArray:
    """Closest point (2,) of a convex CCW polygon (V, 2) to ``q`` (2,) [m] (``q`` itself inside)."""
    v = np.asarray(vertices, dtype=float)
    nxt = np.roll(v, -1, axis=0)
    edge = nxt - v
    # inside when left of every CCW edge
    cross = edge[:, 0] * (q[1] - v[:, 1]) - edge[:, 1] * (q[0] - v[:, 0])
    if np.all(cross >= 0.0):
        return np.array(q, dtype=float)
    best, best_d = np.array(q, dtype=float), math.inf
    for a, e in zip(v, edge, strict=True):
        s = float(np.clip((q - a) @ e / (e @ e), 0.0, 1.0))
        p = a + s * e
        dist = float(np.linalg.norm(q - p))
        if dist < best_d:
            best, best_d = p, dist
    return best


def signed_area(vertices: FloatArray) -> float:
    """Shoelace signed area [m^2] of a polygon (V, 2): > 0 for counter-clockwise order."""
    x, y = vertices[:, 0], vertices[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def turning_angles(vertices: FloatArray) -> FloatArray:
    """Signed turning angle [rad] at every vertex (V,), positive for a left (CCW) turn.

    Entry ``j`` is the angle from edge ``j-1 -> j`` to edge ``j -> j+1``.
    """
    edges = np.roll(vertices, -1, axis=0) - vertices
    prev = np.roll(edges, 1, axis=0)
    cross = prev[:, 0] * edges[:, 1] - prev[:, 1] * edges[:, 0]
    dot = np.einsum("ij,ij->i", prev, edges)
    return np.arctan2(cross, dot)


def convexity_defect(vertices: FloatArray) -> str | None:
    """Why a CCW polygon (V, 2) is not convex, or None when it is.

    A simple CCW polygon is convex iff it never turns right. Summing the turning angles to exactly
    2 pi also rejects self-intersecting "stars" (a pentagram turns left everywhere but winds twice),
    and a turn of +-pi (an edge doubling back on itself) is rejected as a degenerate spike.
    """
    ang = turning_angles(vertices)
    for j, a in enumerate(ang):
        if abs(abs(a) - np.pi) < 1e-9:
            return f"the boundary doubles back on itself at vertex {j}"
        if a < -ANGLE_TOL:
            return f"it turns clockwise (reflex angle) at vertex {j}"
    total = float(np.sum(ang))
    if abs(total - 2.0 * np.pi) > 1e-6:
        return f"the boundary winds {total / (2 * np.pi):.2f} times (self-intersecting)"
    return None


def drop_collinear(vertices: FloatArray, tol: float) -> FloatArray:
    """The polygon (V, 2) without the vertices that lie within ``tol`` [m] of the line through
    their two neighbours (collinear or repeated vertices), removed one at a time, the nearest to
    its line first, until none is left or three vertices remain.

    Removing a vertex of a convex polygon leaves a polygon inside it; the region rows built from
    the result (eq. 5.18) then have no zero-length or duplicate edge."""
    v = np.asarray(vertices, dtype=float)
    while v.shape[0] > 3:
        prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
        chord = nxt - prev
        cross = chord[:, 0] * (v[:, 1] - prev[:, 1]) - chord[:, 1] * (v[:, 0] - prev[:, 0])
        length = np.linalg.norm(chord, axis=1)
        # distance to the chord's line; a vertex whose neighbours coincide is a spike: drop it
        dist = np.where(length > 0.0, np.abs(cross) / np.where(length > 0.0, length, 1.0), 0.0)
        j = int(np.argmin(dist))
        if dist[j] > tol:
            break
        v = np.delete(v, j, axis=0)
    return v


def outward_halfspaces(vertices: FloatArray) -> tuple[FloatArray, FloatArray]:
    """Half-spaces ``A q <= b`` of a convex CCW polygon (V, 2) (eq. 5.18).

    For the edge ``v_j -> v_{j+1}`` of a CCW polygon the interior lies to the left, so the outward
    normal is the edge direction turned right, ``(e_y, -e_x)``; rows are normalised to unit length
    so that ``A q - b`` is a true Euclidean distance to each edge line.

    Returns:
        ``(A, b)`` of shapes (V, 2) and (V,).
    """
    edges = np.roll(vertices, -1, axis=0) - vertices
    normals = np.stack([edges[:, 1], -edges[:, 0]], axis=1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    b = np.einsum("ij,ij->i", normals, vertices)
    return normals, b


def point_segment_distance(p: FloatArray, a: FloatArray, b: FloatArray) -> float:
    """Euclidean distance [m] from point ``p`` (2,) to the segment ``a``-``b``."""
    ab = b - a
    denom = float(np.dot(ab, ab))
    t = 0.0 if denom == 0.0 else float(np.clip(np.dot(p - a, ab) / denom, 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * ab)))


def polygons_intersect(p: FloatArray, q: FloatArray, tol: float = 1e-9) -> bool:
    """Whether two convex CCW polygons overlap or touch (separating-axis theorem)."""
    for poly, other in ((p, q), (q, p)):
        a, b = outward_halfspaces(poly)
        # An edge normal separates the two iff every vertex of `other` lies strictly outside it.
        if np.any(np.min(other @ a.T - b, axis=0) > tol):
            return False
    return True


def point_polygon_distance(p: FloatArray, poly: FloatArray) -> float:
    """Euclidean distance [m] from point ``p`` (2,) to a convex CCW polygon; 0 inside it."""
    a, b = outward_halfspaces(poly)
    if float(np.max(a @ p - b)) <= 0.0:
        return 0.0
    nxt = np.roll(poly, -1, axis=0)
    return float(min(point_segment_distance(p, u, v) for u, v in zip(poly, nxt, strict=True)))


def polygon_distance(p: FloatArray, q: FloatArray) -> float:
    """Minimum Euclidean distance [m] between two convex CCW polygons; 0 when they overlap.

    For disjoint convex polygons the closest pair involves a vertex of one and an edge of the other.
    """
    if polygons_intersect(p, q):
        return 0.0
    best = np.inf
    for poly, other in ((p, q), (q, p)):
        # every vertex of poly against every edge a -> b of other at once (point_segment_distance)
        a = np.asarray(other, dtype=float)
        ab = np.roll(a, -1, axis=0) - a
        ap = np.asarray(poly, dtype=float)[:, None, :] - a[None, :, :]
        denom = np.einsum("ej,ej->e", ab, ab)
        t = np.einsum("vej,ej->ve", ap, ab) / np.where(denom > 0.0, denom, 1.0)
        t = np.where(denom > 0.0, np.clip(t, 0.0, 1.0), 0.0)
        best = min(best, float(np.min(np.linalg.norm(ap - t[..., None] * ab, axis=2))))
    return float(best)


def inset_polygon(vertices: FloatArray, margin: float) -> FloatArray | None:
    """Convex CCW polygon (n, 2) with every edge moved ``margin`` [m] inward (parallel).

    Its vertices are the intersections of consecutive moved edges; None when the inset polygon
    is empty or loses an edge (then those intersections are not all inside every moved edge).
    """
    v = np.asarray(vertices, dtype=float)
    a, b = outward_halfspaces(v)
    b = b - margin
    n = a.shape[0]
    pts = np.empty((n, 2))
    for j in range(n):
        m = np.array([a[j - 1], a[j]])
        if abs(float(np.linalg.det(m))) < 1e-12:
            return None
        pts[j] = np.linalg.solve(m, np.array([b[j - 1], b[j]]))
    if np.any(pts @ a.T - b > 1e-9) or signed_area(pts) <= 0.0:
        return None
    return pts


def as_points(xy: ArrayLike) -> tuple[FloatArray, bool]:
    """Return ``xy`` as an (N, 2) float array and whether a single point (2,) was given."""
    arr = np.asarray(xy, dtype=float)
    single = arr.ndim == 1
    pts = np.atleast_2d(arr)
    if pts.shape[-1] < 2:
        raise InputError("points", arr.shape, "an array of shape (2,) or (N, 2) or wider")
    return pts[:, :2], single


def clip_halfplane(poly: FloatArray, a: FloatArray, b: float, tol: float = 1e-12) -> FloatArray:
    """Part of a convex CCW polygon (V, 2) with ``a . q <= b`` (Sutherland-Hodgman, one plane).

    ``a`` (2,) need not be a unit vector; ``a = 0`` keeps everything when ``b >= 0`` and nothing
    otherwise. Returns a convex CCW polygon (W, 2), possibly with fewer than 3 vertices (empty or
    degenerate); consecutive vertices closer than ``tol`` [m] are merged.
    """
    p = np.asarray(poly, dtype=float)
    s = p @ np.asarray(a, dtype=float) - float(b)
    out: list[FloatArray] = []
    n = p.shape[0]
    for j in range(n):
        k = (j + 1) % n
        if s[j] <= 0.0:
            out.append(p[j])
        if (s[j] < 0.0 < s[k]) or (s[k] < 0.0 < s[j]):
            t = s[j] / (s[j] - s[k])
            out.append(p[j] + t * (p[k] - p[j]))
    kept: list[FloatArray] = []
    for q in out:
        if not kept or float(np.linalg.norm(q - kept[-1])) > tol:
            kept.append(q)
    if len(kept) > 1 and float(np.linalg.norm(kept[0] - kept[-1])) <= tol:
        kept.pop()
    return np.array(kept, dtype=float).reshape(-1, 2)


def cross3(a: FloatArray, b: FloatArray) -> FloatArray:
    """``np.cross`` of two 3-vectors (3,), written out: numpy's general version costs ~15 us a
    call, which adds up in per-sample loops."""
    return np.array(
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    )


def rotation_log(r: FloatArray) -> FloatArray:
    """Rotation vector (3,) [rad] (axis times angle in [0, pi]) of the rotation matrix ``r``.

    The angle is ``atan2(|w| / 2, (tr r - 1) / 2)`` with ``w`` the vector of ``r - r^T``
    (accurate at every angle, unlike ``acos`` of the trace near 0 and pi); near a half turn,
    where ``w`` vanishes, the axis comes from the symmetric part of ``r``.
    """
    w = np.array([r[2, 1] - r[1, 2], r[0, 2] - r[2, 0], r[1, 0] - r[0, 1]])
    s = 0.5 * math.sqrt(float(w @ w))  # sin(angle)
    c = 0.5 * (float(r[0, 0] + r[1, 1] + r[2, 2]) - 1.0)  # cos(angle)
    angle = math.atan2(s, c)
    if angle < 1e-9:
        return 0.5 * w
    if c > -0.9:
        return (angle / (2.0 * s)) * w
    # near a half turn w is small: the axis a comes from the symmetric part of
    # r = cos I + sin [a]x + (1 - cos) a a^T, i.e. a a^T = ((r + r^T) / 2 - cos I) / (1 - cos),
    # and its sign from w = 2 sin a
    rr = np.asarray(r, dtype=float)
    b = (0.5 * (rr + rr.T) - c * np.eye(3)) / (1.0 - c)
    k = int(np.argmax(np.diag(b)))
    axis = b[:, k] / math.sqrt(max(float(b[k, k]), 1e-300))
    axis /= float(np.linalg.norm(axis))
    if float(axis @ w) < 0.0:
        axis = -axis
    return angle * axis


def rotation_exp(v: FloatArray) -> FloatArray:
    """Rotation matrix (3, 3) of the rotation vector ``v`` (3,) [rad] (Rodrigues' formula)."""
    x, y, z = (float(c) for c in v)
    angle = math.sqrt(x * x + y * y + z * z)
    k = np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
    if angle < 1e-12:
        return np.eye(3) + k
    return (
        np.eye(3)
        + (math.sin(angle) / angle) * k
        + ((1.0 - math.cos(angle)) / (angle * angle)) * (k @ k)
    )


def convex_hull(points: ArrayLike) -> FloatArray:
    """Convex hull (V, 2) of ``points`` (M, 2) [m], CCW. Degenerate inputs give 1 (a point) or 2
    (a segment) vertices.

    Qhull (scipy) for the general case; Andrew's monotone chain when Qhull refuses (fewer than
    three points, all collinear).
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if pts.shape[0] >= 3:
        from scipy.spatial import ConvexHull, QhullError

        try:
            return pts[ConvexHull(pts).vertices]  # CCW in 2-D
        except QhullError:
            pass
    hull = monotone_chain([(float(x), float(y)) for x, y in pts])
    return np.array(hull, dtype=float).reshape(-1, 2)


def monotone_chain(
    points: list[tuple[float, float]], eps: float = 0.0
) -> list[tuple[float, float]]:
    """Convex hull of ``points`` (Python floats [m]) by Andrew's monotone chain, CCW, without
    repeated end point. Points within ``eps`` of each other in both coordinates count as one and
    vertices whose turn is at most ``eps`` (collinear) are dropped; one or two points come back
    as they are (deduplicated). Python floats on purpose: for the handful of points of a support
    polygon, numpy's per-call overhead costs more than the hull."""
    xy = sorted(points)
    p = xy[:1] + [
        b for a, b in itertools.pairwise(xy) if abs(b[0] - a[0]) > eps or abs(b[1] - a[1]) > eps
    ]
    if len(p) <= 2:
        return p

    def turn(o: tuple[float, float], a: tuple[float, float], b: tuple[float, float]) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: list[tuple[float, float]] = []
    for pt in p:
        while len(lower) >= 2 and turn(lower[-2], lower[-1], pt) <= eps:
            lower.pop()
        lower.append(pt)
    upper: list[tuple[float, float]] = []
    for pt in p[::-1]:
        while len(upper) >= 2 and turn(upper[-2], upper[-1], pt) <= eps:
            upper.pop()
        upper.append(pt)
    hull = lower[:-1] + upper[:-1]
    return hull if len(hull) >= 2 else [p[0], p[-1]]


def minkowski_sum(p: FloatArray, q: FloatArray) -> FloatArray:
    """Minkowski sum ``{a + b : a in p, b in q}`` (V, 2) of two convex CCW polygons (points and
    segments allowed).

    Two polygons: their edges merged by angle, each polygon's walk starting at its lowest (then
    leftmost) vertex, where the edge angles increase from 0 to 2 pi. Otherwise the hull of the
    pairwise vertex sums.
    """
    p, q = np.asarray(p, dtype=float), np.asarray(q, dtype=float)
    if p.shape[0] < 3 or q.shape[0] < 3:
        return convex_hull((p[:, None, :] + q[None, :, :]).reshape(-1, 2))
    edges, origin = [], np.zeros(2)
    for poly in (p, q):
        start = int(np.lexsort((poly[:, 0], poly[:, 1]))[0])
        poly = np.roll(poly, -start, axis=0)
        origin = origin + poly[0]
        edges.append(np.roll(poly, -1, axis=0) - poly)
    e = np.vstack(edges)
    angle = np.arctan2(e[:, 1], e[:, 0]) % (2.0 * math.pi)
    e = e[np.argsort(angle, kind="stable")]
    return origin + np.vstack([np.zeros(2), np.cumsum(e[:-1], axis=0)])


def clip_rows(poly: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """Part of a convex polygon (V, 2) (or point, or segment) with ``a q <= b`` for every row of
    ``a`` (R, 2) and ``b`` (R,); (0, 2) when empty. Vectorised Sutherland-Hodgman per row."""
    p = np.asarray(poly, dtype=float)
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if p.shape[0] == 0:
        return p
    # only the rows that cut off a vertex need clipping (the others keep the whole polygon)
    cutting = np.flatnonzero(np.max(p @ a.T - b, axis=0) > 0.0)
    for j in cutting:
        if p.shape[0] == 0:
            break
        s = p @ a[j] - b[j]
        inside = s <= 0.0
        if inside.all():
            continue
        if not inside.any():
            return np.zeros((0, 2))
        nxt = np.arange(1, p.shape[0] + 1)
        nxt[-1] = 0
        # edge e -> e+1 crosses the line where its ends lie strictly on opposite sides
        edge = np.flatnonzero(s * s[nxt] < 0.0)
        t = s[edge] / (s[edge] - s[nxt[edge]])
        hits = p[edge] + t[:, None] * (p[nxt[edge]] - p[edge])
        # vertex e (if kept) comes before the crossing on edge e -> e+1: order by 2e, 2e + 1
        keys = np.concatenate([2 * np.flatnonzero(inside), 2 * edge + 1])
        p = np.vstack([p[inside], hits])[np.argsort(keys)]
    return p


def distance_to_convex(x: FloatArray, poly: FloatArray) -> float:
    """Euclidean distance [m] from ``x`` (2,) to a convex CCW polygon (V, 2), segment or point
    (0 inside); infinite for an empty one. Degenerate (zero-area) polygons are measured by their
    edges, so a sliver never gives NaN."""
    v = np.asarray(poly, dtype=float)
    if v.shape[0] == 0:
        return math.inf
    if v.shape[0] == 1:
        return float(np.linalg.norm(x - v[0]))
    nxt = np.roll(v, -1, axis=0)
    edges = nxt - v
    length = np.linalg.norm(edges, axis=1)
    # CCW: inside when on the left of every edge (signed distance >= -EDGE_TOL) and the polygon
    # has an area; edges shorter than EDGE_TOL (near-repeated vertices) have no reliable
    # direction and are left out (their neighbours bound the polygon there)
    real = length > EDGE_TOL
    cross = edges[real, 0] * (x[1] - v[real, 1]) - edges[real, 1] * (x[0] - v[real, 0])
    if real.sum() >= 3 and signed_area(v) > 0.0 and np.all(cross >= -EDGE_TOL * length[real]):
        return 0.0
    return float(min(point_segment_distance(x, a, b) for a, b in zip(v, nxt, strict=True)))
