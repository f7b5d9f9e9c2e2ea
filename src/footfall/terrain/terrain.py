"""A terrain: an ordered collection of uniquely named convex regions (document 000, eq. 5.12i-j)."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from footfall._geometry import inset_polygon, polygon_distance
from footfall._typing import FloatArray
from footfall.errors import SceneError, UnknownNameError
from footfall.terrain.region import Region

#: most regions of a terrain: one binary per region and footstep
MAX_REGIONS = 1000
#: a landed foot stands on a region when its sole centre is inside the region's polygon in plan
#: view and within this height of its surface [m] (a measured sole centre sits a few millimetres
#: above the plane); every plant's report counts footsteps off the terrain by this one test
LANDING_Z_TOL = 0.03


def region_of(regions: Sequence[Region], p: ArrayLike) -> str:
    """Name of the first of ``regions`` that a landed foot at ``p`` [m] stands on, "" for none.

    ``p`` (3,): inside the polygon in plan view and within ``LANDING_Z_TOL`` of the surface;
    ``p`` (2,): plan view only (the reduced-order plant has no heights).
    """
    q = np.asarray(p, dtype=float)
    for r in regions:
        if float(r.signed_distance(q[:2])) <= 0.0 and (
            q.shape[0] == 2 or abs(float(r.height_at(q[:2])) - float(q[2])) <= LANDING_Z_TOL
        ):
            return r.name
    return ""


@dataclass(frozen=True, eq=False)
class Terrain:
    """The walkable regions of a scene; footstep ``i`` must lie in exactly one of them (eq. 5.12j).

    Attributes:
        regions: the regions, in a fixed order (the planner's region index ``r`` is the position
            in this tuple); names are unique.
    """

    regions: tuple[Region, ...]

    def __post_init__(self) -> None:
        regions = tuple(self.regions)
        if not 1 <= len(regions) <= MAX_REGIONS:
            raise SceneError("regions", f"{len(regions)} regions", f"1..{MAX_REGIONS} regions")
        seen: set[str] = set()
        for i, r in enumerate(regions):
            if not isinstance(r, Region):
                raise SceneError(f"regions[{i}]", r, "a Region")
            if r.name in seen:
                raise SceneError(f"regions[{i}].name", r.name, "a name not used by another region")
            seen.add(r.name)
        object.__setattr__(self, "regions", regions)

    def __getitem__(self, name: str) -> Region:
        for r in self.regions:
            if r.name == name:
                return r
        raise UnknownNameError("region", name, f"one of {', '.join(self.names)}")

    def __len__(self) -> int:
        return len(self.regions)

    def __iter__(self) -> Iterator[Region]:
        return iter(self.regions)

    @property
    def names(self) -> list[str]:
        """Region names in order."""
        return [r.name for r in self.regions]

    def index(self, name: str) -> int:
        """Position of the region called ``name`` (raises :class:`UnknownNameError`, a KeyError, if absent)."""
        for i, r in enumerate(self.regions):
            if r.name == name:
                return i
        raise UnknownNameError("region", name, f"one of {', '.join(self.names)}")

    def locate(self, p: ArrayLike, tol: float = 1e-6) -> list[str]:
        """Names of the regions containing the 3-D point ``p`` (3,) [m] (on plane and inside,
        within ``tol``): the exact test of a scene's start feet and goal. Where a landed foot
        stands is :meth:`region_of`."""
        return [r.name for r in self.regions if r.contains(p, tol)]

    def region_of(self, p: ArrayLike) -> str:
        """The region a landed foot at ``p`` (3,) or (2,) [m] stands on (:func:`region_of`)."""
        return region_of(self.regions, p)

    def nearest(self, p: ArrayLike) -> tuple[str, float, float]:
        """Closest region to ``p`` (3,) [m] in plan view.

        Returns:
            ``(name, horizontal_gap, height_error)``: the horizontal distance [m] outside the
            polygon (0 inside) by the edge half-spaces, and ``z - height_at(xy)`` [m].
        """
        q = np.asarray(p, dtype=float)
        best: tuple[str, float, float] | None = None
        for r in self.regions:
            gap = max(0.0, float(r.signed_distance(q[:2])))
            dz = float(q[2] - float(r.height_at(q[:2])))
            key = (gap, abs(dz))
            if best is None or key < (best[1], abs(best[2])):
                best = (r.name, gap, dz)
        assert best is not None  # non-empty by construction
        return best

    def bounds(self) -> FloatArray:
        """Bounding box of all region corners, shape (2, 3): ``[min xyz, max xyz]`` [m]."""
        pts = np.vstack([r.vertices3d for r in self.regions])
        return np.vstack([pts.min(axis=0), pts.max(axis=0)])

    def adjacency(self, reach_radius: float, margin: float = 0.0) -> dict[str, set[str]]:
        """Regions whose horizontal polygons are within ``reach_radius`` [m] of each other.

        A cheap necessary condition for stepping from one region to another (it ignores heights and
        the trapezoid shape): when the goal region is not connected to the start region in this
        graph for the robot's largest step, the scene is infeasible for any number of steps.
        With ``margin`` [m] (footsteps that far inside their regions, the planner's
        ``region_margin``) the polygons are first inset by it; a region too small to hold a
        footstep then has no neighbours.

        Returns:
            For each region name, the set of other region names within the radius.
        """
        radius = float(reach_radius)
        if not np.isfinite(radius) or radius < 0.0:
            raise SceneError("reach_radius", reach_radius, "a finite distance >= 0 [m]")
        m = float(margin)
        if not np.isfinite(m) or m < 0.0:
            raise SceneError("margin", margin, "a finite distance >= 0 [m]")
        adj: dict[str, set[str]] = {r.name: set() for r in self.regions}
        inset = [(r.name, self.inset(r, m)) for r in self.regions]
        polys = [(name, p) for name, p in inset if p is not None]
        if not polys:
            return adj
        # sweep over the bounding boxes sorted by their left edge: only the pairs whose boxes
        # come within the radius (a lower bound on the polygons' distance) are measured, so a
        # terrain of R regions costs O(R log R) plus its near pairs instead of R^2 / 2 pairs
        lo = np.array([p.min(axis=0) for _, p in polys])
        hi = np.array([p.max(axis=0) for _, p in polys])
        order = np.argsort(lo[:, 0], kind="stable")
        lo, hi = lo[order], hi[order]
        polys = [polys[k] for k in order]
        ends = np.searchsorted(lo[:, 0], hi[:, 0] + radius, side="right")
        for a in range(len(polys)):
            cand = np.arange(a + 1, ends[a])
            gap = np.maximum(0.0, np.maximum(lo[cand] - hi[a], lo[a] - hi[cand]))
            na, pa = polys[a]
            for b in cand[np.hypot(gap[:, 0], gap[:, 1]) <= radius]:
                nb, pb = polys[b]
                if polygon_distance(pa, pb) <= radius:
                    adj[na].add(nb)
                    adj[nb].add(na)
        return adj

    @staticmethod
    def inset(region: Region, margin: float) -> FloatArray | None:
        """Horizontal polygon of ``region`` moved ``margin`` [m] in; None if nothing is left."""
        if margin <= 0.0:
            return np.asarray(region.vertices, dtype=float)
        return inset_polygon(region.vertices, margin)
