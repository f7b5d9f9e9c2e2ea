"""Convex planar terrain regions (document 000, section 5.3.2.2, eq. 5.15-5.18).

A region is a convex polygon lying on the plane ``n_r . p + d_r = 0`` (eq. 5.15). A footstep
``p = [x, y, z]`` is in the region iff it is on the plane (two inequalities, eq. 5.16-5.17) and its
horizontal projection is inside the counter-clockwise 2-D polygon (one inequality per edge,
eq. 5.18). Both sets of rows together form ``A_r p <= b_r`` of eq. (5.12i).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike

from footfall._geometry import as_points, convexity_defect, outward_halfspaces, signed_area
from footfall._typing import FloatArray
from footfall.errors import SceneError

#: largest distance [m] of a 3-D vertex from its fitted plane for the polygon to count as planar
PLANAR_TOL = 1e-6
#: smallest accepted horizontal area [m^2]
MIN_AREA = 1e-6
#: consecutive vertices closer than this [m] are duplicates
DUPLICATE_TOL = 1e-9
#: smallest accepted vertical component of the unit normal: |c| >= 0.2 is a slope of at most
#: ~78.5 deg; steeper planes have a nearly degenerate horizontal projection (and nobody stands
#: on them)
MIN_NORMAL_Z = 0.2


#: most vertices of one region's polygon (each is a row of the region constraint, eq. 5.18)
MAX_VERTICES = 256
#: longest name of a region or a scene [characters]: names go into plans, titles and figures
MAX_NAME = 200
#: a name: a non-empty line of at most MAX_NAME printable characters
NAME_EXPECTED = f"a non-empty line of at most {MAX_NAME} printable characters"


def valid_name(name: object) -> bool:
    """Whether ``name`` is a non-empty line of at most :data:`MAX_NAME` printable characters."""
    return (
        isinstance(name, str)
        and bool(name.strip())
        and len(name) <= MAX_NAME
        and name.isprintable()
    )


def _error(name: str, attr: str, value: object, expected: str) -> SceneError:
    # Field is "region '<name>' <attr>" so that the scene loader can map <attr> to a YAML line.
    return SceneError(f"region {name!r} {attr}", value, expected)


@dataclass(frozen=True, eq=False)
class Region:
    """A named convex planar polygon on which a foot may stand.

    Attributes:
        name: unique name within a terrain.
        normal: unit plane normal ``n_r = [a, b, c]`` (3,) with ``c > 0`` (eq. 5.15).
        offset: plane offset ``d_r`` [m]: points ``p`` on the region satisfy ``n_r . p + d_r = 0``.
        vertices: counter-clockwise horizontal projection of the polygon (V, 2) [m], V >= 3
            (eq. 5.18).
        reordered: True when the input vertices were clockwise and have been reversed.

    Construction normalises the normal (and the offset with it) and validates everything; a
    :class:`~footfall.errors.SceneError` names the region and what is wrong.
    """

    name: str
    normal: FloatArray
    offset: float
    vertices: FloatArray
    reordered: bool = False

    def __post_init__(self) -> None:
        name = self.name
        if not valid_name(name):
            raise SceneError("region name", name, NAME_EXPECTED)
        try:
            n = np.array(self.normal, dtype=float)
            d = float(self.offset)
        except (TypeError, ValueError):
            raise _error(name, "normal", self.normal, "3 numbers and a numeric offset") from None
        if n.shape != (3,) or not np.all(np.isfinite(n)):
            raise _error(name, "normal", self.normal, "3 finite numbers [a, b, c]")
        if not np.isfinite(d):
            raise _error(name, "offset", self.offset, "a finite number [m]")
        norm = float(np.linalg.norm(n))
        if norm < 1e-12:
            raise _error(name, "normal", n.tolist(), "a non-zero vector")
        n, d = n / norm, d / norm
        # The sign of (n, d) is arbitrary; fix c > 0 so that "upward" is unambiguous.
        if n[2] < 0.0:
            n, d = -n, -d
        if n[2] < MIN_NORMAL_Z:
            slope = float(np.degrees(np.arccos(np.clip(n[2], -1.0, 1.0))))
            raise _error(
                name,
                "normal",
                n.round(6).tolist(),
                f"a walkable plane with |c| >= {MIN_NORMAL_Z} (slope <= 78 deg); this plane is "
                f"{slope:.1f} deg from horizontal (nearly vertical)",
            )
        try:
            v = np.array(self.vertices, dtype=float)
        except (TypeError, ValueError):
            raise _error(name, "vertices", self.vertices, "a list of [x, y] points [m]") from None
        if v.ndim != 2 or v.shape[1] != 2:
            raise _error(
                name, "vertices", self.vertices, "a list of [x, y] points [m], shape (V, 2)"
            )
        if not 3 <= v.shape[0] <= MAX_VERTICES:
            raise _error(
                name,
                "vertices",
                f"{v.shape[0]} vertices",
                f"at least 3 and at most {MAX_VERTICES} vertices",
            )
        if not np.all(np.isfinite(v)):
            raise _error(name, "vertices", v.tolist(), "finite coordinates (no NaN or inf)")
        gaps = np.linalg.norm(np.roll(v, -1, axis=0) - v, axis=1)
        if np.any(gaps <= DUPLICATE_TOL):
            j = int(np.argmax(gaps <= DUPLICATE_TOL))
            raise _error(
                name,
                "vertices",
                v.tolist(),
                f"distinct consecutive vertices (vertex {j} repeats the next one in plan view)",
            )
        area = signed_area(v)
        if abs(area) <= MIN_AREA:
            raise _error(
                name,
                "vertices",
                v.tolist(),
                f"a horizontal area > {MIN_AREA} m^2 (degenerate polygon)",
            )
        reordered = bool(self.reordered)
        if area < 0.0:
            v = v[::-1].copy()
            reordered = True
        defect = convexity_defect(v)
        if defect is not None:
            raise _error(name, "vertices", v.tolist(), f"a convex polygon, but {defect}")
        n.setflags(write=False)
        v.setflags(write=False)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "offset", d)
        object.__setattr__(self, "vertices", v)
        object.__setattr__(self, "reordered", reordered)

    # ----------------------------------------------------------------------------- constructors
    @classmethod
    def from_plane(
        cls, name: str, normal: ArrayLike, offset: float, vertices2d: ArrayLike
    ) -> Region:
        """Region on the plane ``normal . p + offset = 0`` (eq. 5.15) over a polygon (V, 2) [m]."""
        return cls(
            name, np.asarray(normal, dtype=float), offset, np.asarray(vertices2d, dtype=float)
        )

    @classmethod
    def from_height(cls, name: str, z: float, vertices2d: ArrayLike) -> Region:
        """Horizontal region at height ``z`` [m]: normal ``[0, 0, 1]``, offset ``-z``."""
        try:
            zf = float(z)
        except (TypeError, ValueError):
            raise _error(name, "height", z, "a finite number [m]") from None
        if not np.isfinite(zf):
            raise _error(name, "height", z, "a finite number [m]")
        return cls(name, np.array([0.0, 0.0, 1.0]), -zf, np.asarray(vertices2d, dtype=float))

    @classmethod
    def from_3d(cls, name: str, vertices3d: ArrayLike) -> Region:
        """Region from the 3-D corners (V, 3) [m] of a planar convex polygon.

        The plane is the least-squares fit through the vertices (the right singular vector of the
        centred points with the smallest singular value); every vertex must lie within
        ``PLANAR_TOL`` of it. The polygon is the horizontal projection of the vertices.
        """
        try:
            p = np.array(vertices3d, dtype=float)
        except (TypeError, ValueError):
            raise _error(name, "vertices", vertices3d, "a list of [x, y, z] points [m]") from None
        if p.ndim != 2 or p.shape[1] != 3:
            raise _error(
                name, "vertices", vertices3d, "a list of [x, y, z] points [m], shape (V, 3)"
            )
        if p.shape[0] < 3:
            raise _error(name, "vertices", p.tolist(), "at least 3 vertices")
        if not np.all(np.isfinite(p)):
            raise _error(name, "vertices", p.tolist(), "finite coordinates (no NaN or inf)")
        centre = p.mean(axis=0)
        _, sv, vt = np.linalg.svd(p - centre)
        if sv[1] <= 1e-9:
            raise _error(
                name, "vertices", p.tolist(), "points spanning a plane (they are collinear)"
            )
        n = vt[2]
        # SVD round-off leaves ~1e-17 tilt on flat polygons; snap it so they are exactly horizontal.
        n = np.where(np.abs(n) < 1e-12, 0.0, n)
        d = -float(n @ centre)
        resid = float(np.max(np.abs(p @ n + d)))
        if resid > PLANAR_TOL:
            raise _error(
                name,
                "vertices",
                p.tolist(),
                f"coplanar points (a vertex is {resid:.2e} m off the best-fit plane, "
                f"tolerance {PLANAR_TOL} m)",
            )
        return cls(name, n, d, p[:, :2])

    # ----------------------------------------------------------------------------- geometry
    def height_at(self, xy: ArrayLike) -> float | FloatArray:
        """Height ``z = -(a x + b y + d) / c`` [m] of the plane at ``xy`` (2,) or (N, 2) (eq. 5.15).

        The plane is extended beyond the polygon; use :meth:`contains` to test membership.
        """
        pts, single = as_points(xy)
        a, b, c = self.normal
        z = -(a * pts[:, 0] + b * pts[:, 1] + self.offset) / c
        return float(z[0]) if single else z

    def halfspaces(self) -> tuple[FloatArray, FloatArray]:
        """Edge constraints ``A xy <= b`` of the horizontal polygon (eq. 5.18).

        Row ``j`` is ``(n_j^2D)^T xy <= (n_j^2D)^T v_j`` for the edge ``v_j -> v_{j+1}`` with its
        outward unit normal ``n_j^2D``.

        Returns:
            ``(A, b)`` of shapes (V, 2) and (V,).
        """
        return outward_halfspaces(self.vertices)

    def plane_rows(self) -> tuple[FloatArray, FloatArray]:
        """Plane equality as two inequalities ``[n; -n] p <= [-d; d]`` (eq. 5.16-5.17).

        Returns:
            ``(A, b)`` of shapes (2, 3) and (2,).
        """
        return np.vstack([self.normal, -self.normal]), np.array([-self.offset, self.offset])

    def signed_distance(self, xy: ArrayLike) -> float | FloatArray:
        """``max_j (A xy - b)_j`` [m] for ``xy`` (2,) or (N, 2): <= 0 inside the horizontal polygon.

        Outside, it is a lower bound on the true distance to the polygon (exact next to an edge).
        """
        pts, single = as_points(xy)
        a, b = self.halfspaces()
        s = np.max(pts @ a.T - b, axis=1)
        return float(s[0]) if single else s

    def contains(self, p: ArrayLike, tol: float = 1e-6) -> bool:
        """Whether ``p`` (3,) [m] is inside the polygon and on the plane, within ``tol``."""
        q = np.asarray(p, dtype=float)
        if q.shape != (3,) or not np.all(np.isfinite(q)):
            return False
        on_plane = abs(float(self.normal @ q) + self.offset) <= tol
        return on_plane and float(self.signed_distance(q[:2])) <= tol

    @cached_property
    def vertices3d(self) -> FloatArray:
        """Polygon corners lifted onto the plane, shape (V, 3) [m]."""
        z = self.height_at(self.vertices)
        out = np.column_stack([self.vertices, z])
        out.setflags(write=False)
        return out

    @cached_property
    def area(self) -> float:
        """Horizontal (projected) area [m^2]."""
        return signed_area(self.vertices)

    @cached_property
    def centroid(self) -> FloatArray:
        """Area centroid of the horizontal polygon lifted onto the plane, shape (3,) [m]."""
        v = self.vertices
        nxt = np.roll(v, -1, axis=0)
        cross = v[:, 0] * nxt[:, 1] - nxt[:, 0] * v[:, 1]
        a6 = 3.0 * float(np.sum(cross))
        cxy = np.array(
            [np.sum((v[:, 0] + nxt[:, 0]) * cross), np.sum((v[:, 1] + nxt[:, 1]) * cross)]
        )
        cxy /= a6
        out = np.array([cxy[0], cxy[1], self.height_at(cxy)])
        out.setflags(write=False)
        return out

    @property
    def slope_deg(self) -> float:
        """Inclination of the plane from horizontal [deg]."""
        return float(np.degrees(np.arccos(np.clip(self.normal[2], -1.0, 1.0))))

    @property
    def is_flat(self) -> bool:
        """Whether the plane is horizontal (normal exactly ``[0, 0, 1]``)."""
        return bool(self.normal[0] == 0.0 and self.normal[1] == 0.0)
