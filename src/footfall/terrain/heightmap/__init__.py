"""Convex planar regions from a height map, so an elevation map feeds the planner.

Pipeline (:func:`regions_from_heightmap`):

1. spike cells (one cell far above or below all eight neighbours) are counted and treated as
   unknown; too many is an error;
2. local plane fit and slope / roughness filter, plane extraction and growth into planar
   segments (:mod:`.segment`);
3. per segment: one-cell bumps opened, one-cell gaps and two-cell notches whose heights fit its
   plane closed, its outline along cell edges simplified, eroded by the foot margin and split
   into convex pieces (:mod:`.polygons`), pieces smaller than ``min_area`` or thinner than
   ``min_width`` dropped;
4. per convex piece: the least-squares plane (eq. 5.15) of the segment's cells inside it or
   within ``PLANE_HALO_WINDOWS`` fit windows of it.

:func:`scene_from_heightmap` wraps the regions into a validated :class:`~footfall.terrain.Scene`
with a start stance and a goal placed on them. :func:`rasterize_scene` goes the other way. The
image and polygon work needs the ``terrain`` extra (scikit-image, shapely), imported lazily.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from footfall._geometry import rot2
from footfall._typing import FloatArray
from footfall._validate import check_fields, finite, finite_vector, non_negative, positive
from footfall.errors import InputError, MissingExtraError
from footfall.models.biped import BipedParams, Side
from footfall.terrain.heightmap.grid import (
    MAX_CELLS,
    HeightMap,
    check_heights,
    load_heightmap,
    rasterize_scene,
)
from footfall.terrain.region import MIN_NORMAL_Z, Region
from footfall.terrain.scene import Goal, Scene, Start
from footfall.terrain.terrain import MAX_REGIONS, Terrain

__all__ = [
    "MAX_CELLS",
    "HeightMap",
    "HeightmapOptions",
    "HeightmapResult",
    "check_heights",
    "load_heightmap",
    "place_pose",
    "rasterize_scene",
    "regions_from_heightmap",
    "scene_from_heightmap",
]


#: widest local fit window [cells]: the fit's arrays grow with its square, and a plane fitted over
#: more than a hundred cells is no longer local
MAX_WINDOW = 101
#: the plane of a convex piece is fitted to its segment's cells within this many fit windows of
#: it: an 8 cm strip under 1 cm noise alone fixes its cross tilt to ~3 deg, with the halo ~0.3 deg
PLANE_HALO_WINDOWS = 2


def _require_extra() -> None:
    """Raise :class:`MissingExtraError` unless the ``terrain`` extra is installed."""
    try:
        import shapely  # noqa: F401
        import skimage  # noqa: F401
    except ImportError as e:
        raise MissingExtraError(
            f"height maps need the 'terrain' extra ({e.name} is missing): "
            'pip install "footfall[terrain]"'
        ) from None


@dataclass(frozen=True)
class HeightmapOptions:
    """Settings of :func:`regions_from_heightmap`.

    Attributes:
        max_slope_deg: steepest traversable plane [deg], in (0, 78].
        roughness: largest RMS residual [m] of a cell's local plane fit for it to seed a segment.
        plane_tolerance: largest distance [m] of a cell's height from its segment's plane.
        window: side of the local fit window [cells], odd, >= 3.
        margin: foot margin [m] by which each segment is eroded before decomposition (0: none;
            the planner's own ``region_margin`` does the same at plan time).
        min_area: smallest segment or convex piece kept [m^2].
        min_width: thinnest convex piece kept [m], as twice its area over its perimeter (the
            width of a long strip): no foot fits on a sliver and its plane is poorly determined.
        max_spike_fraction: most spike cells (fraction of known cells) before the map is refused.
        spike_height: a cell more than this [m] above or below all eight neighbours is a spike.
    """

    max_slope_deg: float = 30.0
    roughness: float = 0.02
    plane_tolerance: float = 0.03
    window: int = 5
    margin: float = 0.0
    min_area: float = 0.005
    min_width: float = 0.04
    max_spike_fraction: float = 0.01
    spike_height: float = 0.3

    def __post_init__(self) -> None:
        check_fields(
            self,
            positive,
            ("roughness", "plane_tolerance", "min_area", "min_width", "spike_height"),
        )
        check_fields(self, non_negative, ("margin", "max_spike_fraction"))
        slope = positive("max_slope_deg", self.max_slope_deg)
        max_slope = math.degrees(math.acos(MIN_NORMAL_Z))
        if slope > max_slope:
            raise InputError("max_slope_deg", slope, f"a slope in (0, {max_slope:.1f}] deg")
        object.__setattr__(self, "max_slope_deg", slope)
        w = self.window
        if isinstance(w, bool) or not isinstance(w, int | np.integer) or w < 3 or w % 2 == 0:
            raise InputError("window", w, "an odd whole number of cells >= 3")
        if w > MAX_WINDOW:
            raise InputError("window", w, f"an odd whole number of cells in 3..{MAX_WINDOW}")
        if self.max_spike_fraction > 1.0:
            raise InputError("max_spike_fraction", self.max_spike_fraction, "a fraction in [0, 1]")


@dataclass(frozen=True, eq=False)
class HeightmapResult:
    """What :func:`regions_from_heightmap` found.

    Attributes:
        map: the input height map.
        regions: the convex planar regions, named ``s<segment>`` or ``s<segment>_<piece>``.
        segment_of_region: (R,) the segment (label) each region was cut from.
        labels: (H, W) int, the segment of each cell, 0 on none.
        smooth_cells: (H, W) bool, cells that passed the slope and roughness filter.
        spikes: (H, W) bool, cells taken as spikes (treated as unknown).
        options: the options used.
    """

    map: HeightMap
    regions: tuple[Region, ...]
    segment_of_region: np.ndarray
    labels: np.ndarray
    smooth_cells: np.ndarray
    spikes: np.ndarray
    options: HeightmapOptions = field(default_factory=HeightmapOptions)


def _spikes(z: FloatArray, height: float) -> np.ndarray:
    """Cells more than ``height`` above (or below) every known one of their eight neighbours."""
    from scipy import ndimage

    fp = np.ones((3, 3), dtype=bool)
    fp[1, 1] = False
    hi = ndimage.maximum_filter(
        np.where(np.isnan(z), -np.inf, z), footprint=fp, mode="constant", cval=-np.inf
    )
    lo = ndimage.minimum_filter(
        np.where(np.isnan(z), np.inf, z), footprint=fp, mode="constant", cval=np.inf
    )
    with np.errstate(invalid="ignore"):
        up = np.isfinite(hi) & (z - hi > height)
        down = np.isfinite(lo) & (lo - z > height)
    return up | down


def _piece_plane(cells_xy: FloatArray, cells_z: FloatArray) -> tuple[FloatArray, float]:
    """Unit normal (c > 0) and offset of the least-squares plane ``z = a x + b y + c0``."""
    a = np.column_stack([cells_xy, np.ones(len(cells_z))])
    (gx, gy, c0), *_ = np.linalg.lstsq(a, cells_z, rcond=None)
    n = np.array([-gx, -gy, 1.0])
    norm = float(np.linalg.norm(n))
    return n / norm, -float(c0) / norm


def regions_from_heightmap(
    heightmap: HeightMap, options: HeightmapOptions | None = None
) -> HeightmapResult:
    """Convex planar regions of a height map (module doc: spikes, segments, pieces, planes).

    Args:
        heightmap: the map (heights (H, W) [m], NaN unknown).
        options: the settings (defaults: :class:`HeightmapOptions`).

    Raises:
        InputError: too many spikes, or no traversable planar region at all.
        MissingExtraError: the ``terrain`` extra is not installed (also an ImportError).
    """
    _require_extra()
    from footfall.terrain.heightmap import segment

    opts = HeightmapOptions() if options is None else options
    if not isinstance(heightmap, HeightMap):
        raise InputError("heightmap", type(heightmap).__name__, "a HeightMap")
    res = heightmap.resolution
    z = np.array(heightmap.heights)
    spikes = _checked_spikes(z, opts)
    z[spikes] = np.nan
    # fit in coordinates relative to the map's median height (no cancellation far from z = 0)
    z_ref = float(np.nanmedian(z))
    seg = segment.segment(
        z - z_ref,
        res,
        window=opts.window,
        max_slope_deg=opts.max_slope_deg,
        roughness=opts.roughness,
        plane_tolerance=opts.plane_tolerance,
        min_cells=max(3, math.ceil(opts.min_area / res**2)),
    )
    labels = _tidy_labels(seg.labels)
    regions, owner = _convex_regions(heightmap, z, labels, seg.planes, z_ref, opts)
    if not regions:
        raise InputError(
            "heights",
            f"a {z.shape[0]} x {z.shape[1]} map with no planar patch",
            f"terrain with planar areas of at least {opts.min_area} m^2, slope <= "
            f"{opts.max_slope_deg} deg and roughness <= {opts.roughness} m",
        )
    if len(regions) > MAX_REGIONS:
        raise InputError(
            "heights", f"a map giving {len(regions)} regions", f"at most {MAX_REGIONS}"
        )
    regions = _name_regions(regions, owner)
    return HeightmapResult(
        map=heightmap,
        regions=tuple(regions),
        segment_of_region=np.array(owner),
        labels=labels,
        smooth_cells=seg.smooth_cells,
        spikes=spikes,
        options=opts,
    )


def _checked_spikes(z: FloatArray, opts: HeightmapOptions) -> np.ndarray:
    """The spike cells of ``z``; :class:`InputError` when more than the options allow."""
    spikes = _spikes(z, opts.spike_height)
    n_known = int(np.count_nonzero(~np.isnan(z)))
    if spikes.sum() > opts.max_spike_fraction * n_known:
        i, j = np.argwhere(spikes)[0]
        raise InputError(
            "heights",
            f"{int(spikes.sum())} spike cells of {n_known} (e.g. [{i}, {j}] = {z[i, j]:g} m)",
            f"at most {opts.max_spike_fraction:.0%} cells more than {opts.spike_height} m away "
            "from all their neighbours (raise --max-spikes or filter the map)",
        )
    return spikes


def _convex_regions(
    heightmap: HeightMap,
    z: FloatArray,
    labels: np.ndarray,
    planes: FloatArray,
    z_ref: float,
    opts: HeightmapOptions,
) -> tuple[list[Region], list[int]]:
    """Convex regions of every segment (module doc, steps 3-4) and the segment of each."""
    import shapely

    from footfall.terrain.heightmap import polygons

    res = heightmap.resolution
    gx, gy = heightmap.cell_centres()
    regions: list[Region] = []
    owner: list[int] = []
    for k, box, mask in _segment_masks(labels, planes, z - z_ref, res, opts.plane_tolerance):
        sub_origin = np.array([gx[box][0, 0], gy[box][0, 0]])
        outline = polygons.cells_outline(mask, res, sub_origin)
        cells = (labels[box] == k) & ~np.isnan(z[box])
        cxy = np.column_stack([gx[box][cells], gy[box][cells]])
        cz = z[box][cells]
        for part in polygons.clean_outline(outline, res, opts.margin, opts.min_area):
            for piece in polygons.convex_pieces(part, res, opts.min_area, opts.min_width):
                if piece.area < opts.min_area or polygons.width(piece) < opts.min_width:
                    continue
                # the segment's cells in and around the piece: a thin strip alone pins its tilt
                # across its width poorly, and the segment is one plane within tolerance anyway
                halo = shapely.buffer(piece, PLANE_HALO_WINDOWS * opts.window * res)
                near = shapely.contains_xy(halo, cxy[:, 0], cxy[:, 1])
                normal, offset = _piece_plane(cxy[near], cz[near])
                if normal[2] < math.cos(math.radians(opts.max_slope_deg)):
                    continue
                vertices = polygons.ccw_vertices(piece, res)
                regions.append(Region(f"s{k}", normal, offset, vertices))
                owner.append(k)
    return regions, owner


def _tidy_labels(labels: np.ndarray) -> np.ndarray:
    """Segments opened by a 3 x 3 square: no one-cell bumps, no parts thinner than 3 cells.

    Noise makes the border between two segments meeting at a crease jagged by a cell or two; a
    bump would otherwise cost a convex piece or a sliver. Rectangles and 45-degree staircases
    are unchanged.
    """
    from scipy import ndimage

    square = np.ones((3, 3), dtype=bool)
    out = np.zeros_like(labels)
    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is not None:
            mask = np.pad(labels[box] == k, 1)
            opened = ndimage.binary_opening(mask, structure=square)[1:-1, 1:-1]
            out[box][opened] = k
    return out


def _segment_masks(
    labels: np.ndarray, planes: FloatArray, z: FloatArray, resolution: float, tol: float
) -> Iterator[tuple[int, tuple[slice, slice], np.ndarray]]:
    """Per segment ``k``: a box around it and the cells its outline takes, ``(k, box, mask)``.

    Besides its own cells, a segment takes (closing by a 3 x 3 square) one-cell holes and
    notches no other segment holds, known or not (a noisy or missing cell), and (closing by a
    5 x 5 square) notches up to two cells wide whose known heights lie within ``tol`` of its
    plane, even where a neighbour holds them: where two planes meet at a crease the border is
    jagged by noise, and either plane is right there. Across a step, heights do not fit.
    """
    from scipy import ndimage

    from footfall.terrain.heightmap.segment import plane_height

    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        if box is None:
            continue
        grow = tuple(
            slice(max(s.start - 2, 0), min(s.stop + 2, n))
            for s, n in zip(box, labels.shape, strict=True)
        )
        lab = labels[grow]
        mask = lab == k
        rows, cols = np.mgrid[grow[0], grow[1]]
        # segment planes are in grid coordinates (x = r * column, y = r * row)
        gap = np.abs(z[grow] - plane_height(planes[k - 1], resolution * cols, resolution * rows))
        with np.errstate(invalid="ignore"):
            fits = gap <= tol  # False where z is unknown (NaN)
        pad = ((2, 2), (2, 2))
        c3 = ndimage.binary_closing(np.pad(mask, pad), np.ones((3, 3)))[2:-2, 2:-2] & (lab == 0)
        c5 = ndimage.binary_closing(np.pad(mask | c3, pad), np.ones((5, 5)))[2:-2, 2:-2] & fits
        yield k, (grow[0], grow[1]), mask | c3 | c5


def _name_regions(regions: list[Region], owner: list[int]) -> list[Region]:
    count = {k: owner.count(k) for k in owner}
    seen: dict[int, int] = {}
    out = []
    for r, k in zip(regions, owner, strict=True):
        seen[k] = seen.get(k, 0) + 1
        name = f"s{k}" if count[k] == 1 else f"s{k}_{seen[k]}"
        out.append(Region(name, r.normal, r.offset, r.vertices))
    return out


def place_pose(terrain: Terrain, fld: str, pose: Any) -> tuple[FloatArray, float]:
    """``(x, y[, yaw])`` as a point (3,) [m] on the terrain and a heading [rad].

    The height is that of the highest region whose polygon contains ``(x, y)``.
    """
    p = finite_vector(fld, pose)
    if p.shape[0] not in (2, 3):
        raise InputError(fld, list(p), "x,y or x,y,yaw (yaw in rad)")
    xy = p[:2]
    zs = [float(r.height_at(xy)) for r in terrain if float(r.signed_distance(xy)) <= 0.0]
    if not zs:
        name, gap, _ = terrain.nearest(np.array([xy[0], xy[1], 0.0]))
        raise InputError(
            fld,
            [float(v) for v in p],
            f"a point on a recovered region (nearest is {name!r}, {gap:.3f} m away in plan view)",
        )
    return np.array([xy[0], xy[1], max(zs)]), float(p[2]) if p.shape[0] == 3 else 0.0


def _default_start(terrain: Terrain) -> FloatArray:
    """The point deepest inside the largest region, heading 0."""
    import shapely
    from shapely.ops import polylabel

    big = max(terrain, key=lambda r: r.area)
    c = polylabel(shapely.Polygon(big.vertices), tolerance=1e-3)
    return np.array([c.x, c.y, 0.0])


def scene_from_heightmap(
    heightmap: HeightMap,
    options: HeightmapOptions | None = None,
    *,
    start: Any = None,
    goal: Any = None,
    robot: BipedParams | None = None,
    name: str = "heightmap",
    description: str = "",
) -> tuple[Scene, HeightmapResult]:
    """A validated scene of the regions recovered from ``heightmap``.

    Args:
        heightmap: the map.
        options: segmentation settings.
        start: ``(x, y[, yaw])`` [m, m, rad] of the midpoint between the start feet; the feet
            stand ``robot.stance_width`` apart across the heading, the right one standing (as in
            the built-in scenes). Default: inside the largest region, heading 0.
        goal: ``(x, y[, yaw])`` of the goal (midpoint of the final feet). Default: the start.
        robot: robot parameters (default :class:`BipedParams`).
        name: scene name.
        description: one line for humans (default: says where it came from).

    Raises:
        InputError: a start foot or the goal off every recovered region, or as
            :func:`regions_from_heightmap`.
    """
    result = regions_from_heightmap(heightmap, options)
    robot = BipedParams() if robot is None else robot
    terrain = Terrain(result.regions)
    mid, yaw = place_pose(terrain, "start", _default_start(terrain) if start is None else start)
    half = 0.5 * robot.stance_width * (rot2(yaw) @ np.array([0.0, 1.0]))
    feet = {}
    for side, sign in ((Side.LEFT, 1.0), (Side.RIGHT, -1.0)):
        feet[side], _ = place_pose(terrain, f"start.{side.value}", mid[:2] + sign * half)
    g, g_yaw = place_pose(terrain, "goal", [mid[0], mid[1], yaw] if goal is None else goal)
    h, w = heightmap.shape
    desc = description or (
        f"{len(terrain)} regions from a {h} x {w} height map at {heightmap.resolution:g} m"
    )
    scene = Scene(
        name=name,
        description=desc,
        robot=robot,
        terrain=terrain,
        start=Start(
            left=feet[Side.LEFT],
            right=feet[Side.RIGHT],
            heading=finite("start", yaw),
            stance=Side.RIGHT,
        ),
        goal=Goal(position=g, heading=g_yaw),
    )
    return scene, result
