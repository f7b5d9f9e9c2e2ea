"""From a segment's cells to convex polygons: outline, foot margin, convex decomposition.

The outline of a segment is the union of its cells as squares (its boundary runs along cell
edges, half a cell beyond the outermost cell centres: the best estimate of where the terrain
edge is, which lies somewhere between two cell centres). It is simplified by less than half a
cell, so no polygon reaches a cell centre its segment does not hold, eroded by the foot margin,
and split into convex pieces by recursive cuts: at a reflex vertex, one of its two edges is
extended into the polygon until it leaves it, cutting the polygon in two (the classic cut that
removes that reflex angle, exact on rectilinear outlines); of all such cuts the one cutting off
the smallest part goes first, so a border left jagged by noise is peeled off in thin strips (the
caller drops pieces too thin for a foot) and the body stays whole. A part with a hole (an
occluded patch) is first cut across the hole (no cut from a hole's vertex splits it). Touching
pieces whose union is convex are merged at the end. An L gives two pieces.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from footfall._geometry import drop_collinear
from footfall._typing import FloatArray

#: relative area slack for "the union of two pieces is convex" (union area vs its hull's area)
CONVEX_REL_TOL = 1e-9
#: simplification tolerance as a fraction of a cell: below one half, an outline never reaches
#: the centre of a cell outside its segment
SIMPLIFY_CELLS = 0.45
#: shortest candidate cuts tried at each step of the decomposition
CUTS_TRIED = 6
#: most convex pieces of one segment (each is a region: binaries of the planner)
MAX_PIECES = 32
#: a vertex this close to the line through its neighbours [cells] is dropped from a region
VERTEX_TOL_CELLS = 1e-6


def cells_outline(mask: np.ndarray, resolution: float, origin: FloatArray) -> Any:
    """Union (a shapely geometry) of the squares of the cells of ``mask`` (H, W).

    Cell ``[i, j]`` is the square of side ``resolution`` centred at ``origin + (j, i) * r``.
    Runs of cells along each row become one rectangle before the union (a few per row).
    """
    import shapely

    padded = np.zeros((mask.shape[0], mask.shape[1] + 2), dtype=np.int8)
    padded[:, 1:-1] = mask
    d = np.diff(padded, axis=1)
    rows_s, cols_s = np.nonzero(d == 1)  # run starts at column cols_s
    _, cols_e = np.nonzero(d == -1)  # run ends before column cols_e
    r = resolution
    x0 = origin[0] + (cols_s - 0.5) * r
    x1 = origin[0] + (cols_e - 0.5) * r
    y0 = origin[1] + (rows_s - 0.5) * r
    boxes = shapely.box(x0, y0, x1, y0 + r)
    return shapely.union_all(boxes, grid_size=r * 1e-6)


def clean_outline(geom: Any, resolution: float, margin: float, min_area: float) -> list[Any]:
    """Simplified outline polygons of ``geom`` eroded by ``margin`` [m], each of area >= ``min_area``."""
    import shapely

    geom = shapely.simplify(geom, SIMPLIFY_CELLS * resolution, preserve_topology=True)
    if margin > 0.0:
        geom = shapely.buffer(geom, -margin, join_style="mitre")
    polys = [g for g in shapely.get_parts(geom) if g.geom_type == "Polygon"]
    return [p for p in polys if p.area >= min_area]


def _is_convex(poly: Any) -> bool:
    return bool(
        len(poly.interiors) == 0 and poly.area >= poly.convex_hull.area * (1 - CONVEX_REL_TOL)
    )


def _reflex_rays(poly: Any) -> list[tuple[FloatArray, FloatArray]]:
    """``(vertex, direction)`` of the cuts at every reflex vertex: the extensions of its two edges
    into the polygon (either one removes the reflex angle there)."""
    import shapely

    poly = shapely.orient_polygons(poly)  # exterior CCW, holes CW: the inside is on the left
    rays = []
    for ring in (poly.exterior, *poly.interiors):
        v = np.asarray(ring.coords, dtype=float)[:-1]
        prev, nxt = np.roll(v, 1, axis=0), np.roll(v, -1, axis=0)
        d_in, d_out = v - prev, nxt - v
        cross = d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0]
        scale = np.linalg.norm(d_in, axis=1) * np.linalg.norm(d_out, axis=1)
        for j in np.nonzero(cross < -1e-12 * scale)[0]:
            rays.append((v[j], d_in[j] / np.linalg.norm(d_in[j])))
            rays.append((v[j], -d_out[j] / np.linalg.norm(d_out[j])))
    return rays


def _cut_line(poly: Any, origin: FloatArray, direction: FloatArray, span: float) -> Any:
    """The segment from ``origin`` along ``direction`` to where it first meets the boundary again
    (a little beyond, so that it splits cleanly), or None."""
    import shapely

    ray = shapely.LineString([origin, origin + span * direction])
    hits = shapely.get_parts(shapely.intersection(ray, poly.boundary))
    ahead = [float(np.dot(np.asarray(c) - origin, direction)) for g in hits for c in g.coords]
    ahead = [t for t in ahead if t > 1e-9 * span]
    if not ahead:
        return None
    return shapely.LineString([origin, origin + direction * (min(ahead) + 1e-7 * span)])


def _split(poly: Any, line: Any) -> list[Any]:
    from shapely.ops import split

    parts = [g for g in split(poly, line).geoms if g.area > 0.0]
    return parts if len(parts) >= 2 else []


def width(poly: Any) -> float:
    """Twice the area over the perimeter [m]: the width of a long strip, half the side of a square."""
    return float(2.0 * poly.area / poly.length) if poly.length > 0 else 0.0


def convex_pieces(
    poly: Any, resolution: float, min_area: float = 0.0, min_width: float = 0.0
) -> list[Any]:
    """Convex polygons (shapely) covering ``poly`` but for parts smaller than ``min_area`` [m^2]
    or thinner than ``min_width`` [m] (see module doc).

    At every step the non-convex part is cut along the edge extension at a reflex vertex that
    cuts off the smallest part; parts too small or thin are dropped at once; then touching
    pieces whose union is convex are merged. At most ``MAX_PIECES`` pieces are kept.
    """
    import shapely

    span = 4.0 * float(np.hypot(*np.subtract(poly.bounds[2:], poly.bounds[:2]))) + resolution
    todo = [shapely.simplify(poly, 0.0)]
    done: list[Any] = []
    while todo and len(done) < MAX_PIECES:
        p = todo.pop()
        if p.area < min_area or width(p) < min_width:
            continue
        if _is_convex(p):
            done.append(p)
            continue
        if p.interiors:  # no cut from a hole's vertex splits a polygon: cut across the hole
            hole = max(p.interiors, key=lambda r: shapely.Polygon(r).area)
            cx = shapely.Polygon(hole).centroid.x
            y0, y1 = p.bounds[1] - resolution, p.bounds[3] + resolution
            todo.extend(
                shapely.simplify(q, 0.0)
                for q in _split(p, shapely.LineString([(cx, y0), (cx, y1)]))
            )
            continue
        # the shortest cuts are tried (a cut off a notch is short), the smallest part wins
        lines = [_cut_line(p, o, d, span) for o, d in _reflex_rays(p)]
        lines = sorted((ln for ln in lines if ln is not None), key=lambda ln: ln.length)
        best: list[Any] = []
        for line in lines[:CUTS_TRIED]:
            parts = _split(p, line)
            if parts and (not best or min(q.area for q in parts) < min(q.area for q in best)):
                best = parts
        if not best:  # no clean cut (round-off): give up on this part rather than loop
            continue
        todo.extend(shapely.simplify(q, 0.0) for q in best)
    return _merge_convex(done, resolution)


def _merge_convex(pieces: list[Any], resolution: float) -> list[Any]:
    """Merge touching pieces, largest first, while their union stays convex."""
    import shapely

    pieces = sorted(pieces, key=lambda q: -q.area)
    merged = True
    while merged:
        merged = False
        for a in range(len(pieces)):
            for b in range(a + 1, len(pieces)):
                if shapely.intersection(pieces[a], pieces[b]).length <= 1e-6 * resolution:
                    continue
                u = shapely.union(pieces[a], pieces[b], grid_size=resolution * 1e-6)
                if u.geom_type == "Polygon" and _is_convex(u):
                    pieces[a] = shapely.simplify(u, 0.0)
                    del pieces[b]
                    merged = True
                    break
            if merged:
                break
    return pieces


def ccw_vertices(poly: Any, resolution: float) -> FloatArray:
    """Counter-clockwise vertices (V, 2) of a polygon's exterior, without the closing repeat and
    without vertices within ``VERTEX_TOL_CELLS`` cells of the line through their neighbours.

    Cuts and merges leave such vertices on straight edges (and repeats a round-off apart): each
    would be a zero-length or duplicate region row, and three collinear corners define no plane."""
    import shapely

    poly = shapely.orient_polygons(poly)  # exterior counter-clockwise
    vertices = np.asarray(poly.exterior.coords, dtype=float)[:-1]
    return drop_collinear(vertices, VERTEX_TOL_CELLS * resolution)
