"""Per-edge insets of terrain regions: footsteps further from riser edges than from open ones.

Beyond the document: eq. (5.18) keeps a footstep *point* inside a region, and the planner's
``region_margin`` moves every edge in by the same distance (half a sole). A real landing falls a few
centimetres short or long of its target. Where that puts the sole's edge onto a *higher* surface
(the tread above a stair riser, for a foot stepping down onto the tread below) the foot lands
tilted on the riser edge and tips. An edge with nothing next to it (a gap, the side of a block) or
with a lower surface next to it only lets the sole overhang a little: a surface below the tread
cannot tilt the sole. :func:`riser_edge_insets` finds, for every edge, how much further in a
footstep must stay so that a landing error of up to ``tolerance`` keeps the sole off any higher
level, and :func:`inset_riser_edges` returns the regions with their edges moved in by that much.
The planner then plans on the smaller regions with its usual uniform ``region_margin``; the
planner itself does not change.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from footfall._geometry import clip_halfplane, outward_halfspaces, signed_area
from footfall._typing import FloatArray
from footfall._validate import non_negative, positive
from footfall.errors import InputError
from footfall.terrain.region import MIN_AREA, Region
from footfall.terrain.terrain import Terrain

#: a step up of at most this [m] where a neighbour begins is no riser (surfaces meet within it)
RISER_MIN_RISE = 0.005
#: points of a neighbour within this [m] of its nearest point count as its near side
NEAR_TOL = 1e-9
#: a neighbour must cover more than this area [m^2] of the strip outside an edge to count (a
#: region touching the strip only at a corner point or along its side line does not)
CONTACT_AREA_TOL = 1e-9


def _clip(poly: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    for ai, bi in zip(a, b, strict=True):
        poly = clip_halfplane(poly, ai, float(bi))
        if poly.shape[0] < 3:
            break
    return poly


def _area(poly: FloatArray) -> float:
    return signed_area(poly) if poly.shape[0] >= 3 else 0.0


def riser_edge_insets(
    terrain: Terrain, tolerance: float, min_rise: float = RISER_MIN_RISE
) -> dict[str, FloatArray]:
    """How far in [m] each edge of each region must move so a landing error keeps the sole on it.

    For edge ``j`` of region ``r`` (``v_j -> v_{j+1}`` of ``r.vertices``, outward unit normal
    ``n_j``, line ``n_j . q = b_j`` of eq. 5.18) let ``S_j`` be the strip of width ``tolerance``
    just outside the edge: ``0 <= n_j . q - b_j <= tolerance``, between the normals through its
    end points. Another region ``q`` is a *riser neighbour* of the edge where it covers part of
    ``S_j`` (positive area) and, where it begins (its points of ``S_j`` nearest the edge, at
    ``n_j . q - b_j = g``, the gap: 0 for a stair riser), its surface is more than ``min_rise``
    above ``r``'s plane extended (eq. 5.15): a step up, not a change of slope (a ramp leaving a
    floor along the edge is no riser) and not a step down (a lower surface cannot tilt the sole;
    the sole overhangs it as it would an open edge). The inset is ``max(0, tolerance - g)`` over
    the riser neighbours, 0 without one: a sole whose edge is that far inside ``r``'s edge can
    land ``tolerance`` long or short before it reaches the higher level. Other edges (no neighbour, a neighbour on the same plane
    or lower, or one further than ``tolerance``) get 0.

    Args:
        terrain: the regions.
        tolerance: the landing error to allow for [m], >= 0.
        min_rise: steps up to this high [m] are not risers, > 0.

    Returns:
        For every region name, the insets (V,) [m] of its edges in vertex order.

    Raises:
        InputError: on a tolerance or min_rise that is not a finite number in range, or a
            terrain that is not a :class:`Terrain`.
    """
    if not isinstance(terrain, Terrain):
        raise InputError("terrain", terrain, "a footfall.terrain.Terrain")
    tol = non_negative("tolerance", tolerance)
    rise = positive("min_rise", min_rise)
    out: dict[str, FloatArray] = {}
    for r in terrain.regions:
        a, b = outward_halfspaces(r.vertices)
        v = r.vertices
        insets = np.zeros(v.shape[0])
        if tol == 0.0:
            out[r.name] = insets
            continue
        for j in range(v.shape[0]):
            n = a[j]
            e = v[(j + 1) % v.shape[0]] - v[j]
            u = e / float(np.linalg.norm(e))
            # the strip S_j as half-planes: outside the edge, within tol of it, between the ends
            sa = np.array([-n, n, -u, u])
            sb = np.array([-b[j], b[j] + tol, -float(u @ v[j]), float(u @ (v[j] + e))])
            for q in terrain.regions:
                if q is r:
                    continue
                part = _clip(np.asarray(q.vertices, dtype=float), sa, sb)
                if _area(part) <= CONTACT_AREA_TOL:
                    continue
                # where q begins (its part nearest the edge), how far out and how far up or down
                dist = part @ n - b[j]
                gap = max(float(np.min(dist)), 0.0)
                near = part[dist <= gap + NEAR_TOL]
                jump = np.asarray(q.height_at(near)) - np.asarray(r.height_at(near))
                if float(np.max(jump)) > rise:
                    insets[j] = max(insets[j], tol - gap)
        out[r.name] = insets
    return out


def inset_region_edges(region: Region, insets: ArrayLike) -> Region | None:
    """``region`` with edge ``j`` moved ``insets[j]`` [m] inward (parallel), same plane and name.

    Args:
        region: a region with V edges.
        insets: (V,) distances [m], >= 0, in the order of ``region.vertices`` (edge ``j`` is
            ``v_j -> v_{j+1}``).

    Returns:
        The smaller region (an edge may vanish), or None when less than ``MIN_AREA`` is left.
    """
    d = np.asarray(insets, dtype=float)
    v = np.asarray(region.vertices, dtype=float)
    if d.shape != (v.shape[0],) or not np.all(np.isfinite(d)) or np.any(d < 0.0):
        raise InputError(
            f"insets of region {region.name!r}",
            d.tolist(),
            f"{v.shape[0]} finite distances >= 0 [m], one per edge",
        )
    if not np.any(d > 0.0):
        return region
    a, b = outward_halfspaces(v)
    poly = _clip(v, a, b - d)
    if _area(poly) <= MIN_AREA:
        return None
    return Region.from_plane(region.name, region.normal, region.offset, poly)


def inset_riser_edges(
    terrain: Terrain, tolerance: float, min_rise: float = RISER_MIN_RISE
) -> Terrain:
    """The terrain with every region's riser edges moved in by :func:`riser_edge_insets`.

    Regions without a riser edge are returned as they are (the same objects); a region with
    nothing left is dropped. The order of the remaining regions is kept.

    Args:
        terrain: the regions.
        tolerance: the landing error to allow for [m], >= 0.
        min_rise: steps up to this high [m] are not risers, > 0.
    """
    insets = riser_edge_insets(terrain, tolerance, min_rise)
    kept = [inset_region_edges(r, insets[r.name]) for r in terrain.regions]
    # of flat regions the highest keeps its edges; Terrain refuses an empty tuple (SceneError)
    return Terrain(tuple(r for r in kept if r is not None))
