"""Planar segments of a height map: local plane fit, traversability, plane extraction, growth.

1. **Local fit.** Every cell gets the least-squares plane ``z = a + g_x u + g_y v`` through the
   known cells of its ``w x w`` window (box sums by correlation, one 3 x 3 solve per cell). Its
   slope is ``atan |g|``, its roughness the RMS residual of the fit.
2. **Seeds.** Cells with slope <= ``max_slope`` and roughness <= ``roughness`` ("smooth cells")
   form connected components; windows straddling a step edge fit badly, so a step separates
   components, but a crease (a floor meeting a ramp) does not.
3. **Planes per component.** Greedy: a few smooth cells deep inside what is left, spread apart,
   each seed a plane (their local fit); a plane is grown over the connected cells whose smoothed
   height lies within ``SMOOTH_FRACTION * plane_tolerance`` and refitted until it settles; the
   plane that grows largest is kept (as in RANSAC, a seed on a crease gives a compromise plane
   that stays small), its cells are removed and the next round starts. Then every smooth cell
   goes to the nearest plane (k-planes) and planes are refitted until that settles, which puts
   the border between a floor and a ramp on the line where their planes meet; planes that fit
   one plane together are merged.
4. **Growth.** Labels expand one cell at a time into the remaining known cells (the rims along
   step edges that the local fit rejected) while the cell's own height is within
   ``plane_tolerance`` of the label's plane: a cell is traversable when it lies on its plane.
   Touching segments that fit one plane together are merged (a pocket of smooth cells fenced off
   by noisy ones).

Smoothed heights (the local fit's value at the cell) are used to decide membership inside smooth
areas, where they are ``w`` times less noisy than raw heights; raw heights decide the rims, where
windows mix two levels. Planes are always fitted to raw heights.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from footfall._typing import FloatArray

#: fraction of a window's cells that must be known for its local fit to count
MIN_WINDOW_FILL = 0.5
#: most refits of a plane while growing it from its seed (it usually settles in 3-6)
GROW_ITERATIONS = 30
#: smoothed heights are ~``window`` times less noisy than raw ones, so they are held to this
#: fraction of ``plane_tolerance``: a plane grows over cells whose smoothed height is that close,
#: and two planes (or segments) merge when the RMS distance of each one's smoothed heights from
#: the plane fitted to both is that small. At the full tolerance a plane through a flight of
#: stairs (every tread within riser / 2 of it) would outgrow each tread's own plane.
SMOOTH_FRACTION = 1.0 / 3.0
#: seeds tried for each plane of a component (the one growing largest is kept)
SEEDS_PER_PLANE = 6
#: most planes looked for in one connected component
MAX_PLANES_PER_COMPONENT = 64
#: most rounds of nearest-plane assignment and refit per component
KPLANES_ITERATIONS = 10
_FOUR = ndimage.generate_binary_structure(2, 1)


@dataclass(frozen=True)
class LocalFit:
    """Per-cell least-squares plane over a window (all arrays (H, W); NaN where not fitted).

    Attributes:
        smooth: fitted height at the cell centre [m].
        grad: ``(g_x, g_y)`` slope of the fit (2, H, W) [m/m].
        slope_deg: inclination ``atan |g|`` [deg].
        rms: RMS residual of the fit [m].
    """

    smooth: FloatArray
    grad: FloatArray
    slope_deg: FloatArray
    rms: FloatArray


def local_fit(z: FloatArray, resolution: float, window: int) -> LocalFit:
    """Least-squares plane of every ``window x window`` neighbourhood of the (H, W) heights ``z``."""
    known = ~np.isnan(z)
    m = known.astype(np.float64)
    z0 = np.where(known, z, 0.0)
    half = window // 2
    off = np.arange(-half, half + 1, dtype=np.float64)
    ku = np.tile(off, (window, 1))  # column offset (x) of each window cell, in cells
    kv = ku.T  # row offset (y)
    ones = np.ones((window, window))

    def box(img: FloatArray, k: FloatArray) -> FloatArray:
        return ndimage.correlate(img, k, mode="constant", cval=0.0)

    s1, su, sv = box(m, ones), box(m, ku), box(m, kv)
    suu, suv, svv = box(m, ku * ku), box(m, ku * kv), box(m, kv * kv)
    sz, suz, svz, szz = box(z0, ones), box(z0, ku), box(z0, kv), box(z0 * z0, ones)
    mat = np.stack([s1, su, sv, su, suu, suv, sv, suv, svv], axis=-1).reshape(*z.shape, 3, 3)
    rhs = np.stack([sz, suz, svz], axis=-1)
    det = np.linalg.det(mat)
    ok = known & (s1 >= max(4.0, MIN_WINDOW_FILL * window * window)) & (det > 1e-6)
    coef = np.full((*z.shape, 3), np.nan)
    coef[ok] = np.linalg.solve(mat[ok], rhs[ok][..., None])[..., 0]
    sse = np.full(z.shape, np.nan)
    sse[ok] = szz[ok] - np.einsum("nk,nk->n", coef[ok], rhs[ok])
    rms = np.sqrt(np.maximum(sse, 0.0) / np.maximum(s1 - 3.0, 1.0))
    grad = np.stack([coef[..., 1], coef[..., 2]]) / resolution
    slope = np.degrees(np.arctan(np.hypot(grad[0], grad[1])))
    return LocalFit(smooth=coef[..., 0], grad=grad, slope_deg=slope, rms=rms)


def fit_plane(x: FloatArray, y: FloatArray, z: FloatArray) -> FloatArray:
    """Least-squares ``z = p0 + p1 (x - x̄) + p2 (y - ȳ)``; returns ``[p0, p1, p2, x̄, ȳ]``."""
    xm, ym = float(x.mean()), float(y.mean())
    u, v = x - xm, y - ym
    # centred normal equations: the constant decouples from the two slopes
    m = np.array([[u @ u, u @ v], [u @ v, v @ v]])
    g = np.linalg.lstsq(m, np.array([u @ z, v @ z]), rcond=None)[0]
    return np.array([float(z.mean()), g[0], g[1], xm, ym])


def plane_height(plane: FloatArray, x: FloatArray, y: FloatArray) -> FloatArray:
    """Height [m] of a :func:`fit_plane` plane at ``(x, y)``."""
    return plane[0] + plane[1] * (x - plane[3]) + plane[2] * (y - plane[4])


@dataclass(frozen=True)
class Segments:
    """Planar segments of a map.

    Attributes:
        labels: (H, W) int, 0 on no segment, ``k`` on segment ``k`` (1-based).
        planes: (K, 5) :func:`fit_plane` planes of the segments (row ``k - 1`` for label ``k``).
        smooth_cells: (H, W) bool, the cells that passed the slope and roughness filter.
    """

    labels: np.ndarray
    planes: FloatArray
    smooth_cells: np.ndarray


def _grow_plane(
    seed: tuple[int, int],
    plane: FloatArray,
    free: np.ndarray,
    x: FloatArray,
    y: FloatArray,
    zs: FloatArray,
    z: FloatArray,
    tol: float,
) -> tuple[np.ndarray, FloatArray]:
    """Cells of ``free`` connected to ``seed`` within ``tol`` of a plane refitted as it grows."""
    region = np.zeros_like(free)
    for _ in range(GROW_ITERATIONS):
        near = free & (np.abs(zs - plane_height(plane, x, y)) <= tol)
        if not near[seed]:
            break
        comp, _ = ndimage.label(near, _FOUR)
        new = comp == comp[seed]
        if np.array_equal(new, region):
            break
        region = new
        if region.sum() >= 3:
            plane = fit_plane(x[region], y[region], z[region])
    if not region.any():
        region[seed] = True
    return region, plane


def _seeds(free: np.ndarray, count: int, spacing: int) -> list[tuple[int, int]]:
    """Up to ``count`` cells of ``free``, deepest inside it first, at least ``spacing`` apart."""
    depth = ndimage.distance_transform_cdt(free, metric="taxicab").astype(np.float64)
    peaks = (depth == ndimage.maximum_filter(depth, size=2 * spacing + 1)) & free
    rows, cols = np.nonzero(peaks)
    order = np.argsort(-depth[rows, cols], kind="stable")[:count]
    return [(int(rows[o]), int(cols[o])) for o in order]


def _component_planes(
    comp: np.ndarray,
    x: FloatArray,
    y: FloatArray,
    z: FloatArray,
    fit: LocalFit,
    tol: float,
    min_cells: int,
) -> list[FloatArray]:
    """Planes of one connected component of smooth cells (greedy seeding, see module doc).

    Each round grows a plane from a few seeds deep inside what is left and keeps the one that
    grows largest: a seed on a crease starts a compromise plane that stays small.
    """
    free = comp.copy()
    planes: list[FloatArray] = []
    zs = fit.smooth
    spacing = max(2, int(np.sqrt(min_cells)))
    while free.sum() >= min_cells and len(planes) < MAX_PLANES_PER_COMPONENT:
        best: tuple[np.ndarray, FloatArray] | None = None
        for seed in _seeds(free, SEEDS_PER_PLANE, spacing):
            plane = np.array([zs[seed], fit.grad[0][seed], fit.grad[1][seed], x[seed], y[seed]])
            region, plane = _grow_plane(seed, plane, free, x, y, zs, z, SMOOTH_FRACTION * tol)
            if best is None or region.sum() > best[0].sum():
                best = (region, plane)
        if best is None:
            break
        region, plane = best
        free &= ~region
        if region.sum() >= min_cells:
            planes.append(plane)
    return planes


def _assign(
    cells: np.ndarray,
    planes: list[FloatArray],
    x: FloatArray,
    y: FloatArray,
    zs: FloatArray,
    tol: float,
) -> np.ndarray:
    """Index (0-based) of the nearest plane within ``tol`` of each cell of ``cells``, -1 if none."""
    dist = np.stack([np.abs(zs[cells] - plane_height(p, x[cells], y[cells])) for p in planes])
    best = np.argmin(dist, axis=0)
    best[np.min(dist, axis=0) > tol] = -1
    out = np.full(cells.shape, -1)
    out[cells] = best
    return out


def _fits_both(
    plane: FloatArray,
    a: np.ndarray,
    b: np.ndarray,
    x: FloatArray,
    y: FloatArray,
    zs: FloatArray,
    rms_max: float,
) -> bool:
    """Whether the cells of ``a`` and, separately, of ``b`` lie within ``rms_max`` (RMS) of
    ``plane``: each side on its own, so a small set is not outvoted by a large one."""
    for cells in (a, b):
        if not cells.any():
            return False
        dev = zs[cells] - plane_height(plane, x[cells], y[cells])
        if np.sqrt(np.mean(dev**2)) > rms_max:
            return False
    return True


def _settle(
    comp: np.ndarray,
    planes: list[FloatArray],
    x: FloatArray,
    y: FloatArray,
    z: FloatArray,
    zs: FloatArray,
    tol: float,
    min_cells: int,
) -> list[FloatArray]:
    """k-planes on one component: nearest plane per cell and refit until the assignment settles
    (boundaries move to where planes cross); planes whose cells together fit one plane within
    ``SMOOTH_FRACTION * tol`` (RMS) are merged (greedy seeding can split one surface between two near-equal planes)."""
    prev = None
    for _ in range(KPLANES_ITERATIONS):
        idx = _assign(comp, planes, x, y, zs, tol)
        sets = [idx == j for j in range(len(planes))]
        sets = [c for c in sets if c.sum() >= min_cells]
        if not sets:
            return []
        merged = True
        while merged and len(sets) > 1:
            merged = False
            for a in range(len(sets)):
                for b in range(a + 1, len(sets)):
                    both = sets[a] | sets[b]
                    p = fit_plane(x[both], y[both], z[both])
                    if _fits_both(p, sets[a], sets[b], x, y, zs, SMOOTH_FRACTION * tol):
                        sets[a] = both
                        del sets[b]
                        merged = True
                        break
                if merged:
                    break
        planes = [fit_plane(x[c], y[c], z[c]) for c in sets]
        if (
            prev is not None
            and len(prev) == len(sets)
            and all(np.array_equal(p, q) for p, q in zip(prev, sets, strict=True))
        ):
            break
        prev = sets
    return planes


def segment(
    z: FloatArray,
    resolution: float,
    *,
    window: int,
    max_slope_deg: float,
    roughness: float,
    plane_tolerance: float,
    min_cells: int,
) -> Segments:
    """Planar segments of the (H, W) heights ``z`` [m] (module doc, steps 1-4)."""
    h, w = z.shape
    x, y = np.meshgrid(resolution * np.arange(w), resolution * np.arange(h))
    fit = local_fit(z, resolution, window)
    with np.errstate(invalid="ignore"):
        smooth = (fit.slope_deg <= max_slope_deg) & (fit.rms <= roughness)
    comps, _ = ndimage.label(smooth, _FOUR)
    labels = np.zeros(z.shape, dtype=np.int64)
    planes: list[FloatArray] = []
    for k, box in enumerate(ndimage.find_objects(comps), start=1):
        if box is None:
            continue
        comp = comps[box] == k
        if comp.sum() < min_cells:
            continue
        xb, yb, zb = x[box], y[box], z[box]
        fit_b = LocalFit(
            fit.smooth[box], fit.grad[:, box[0], box[1]], fit.slope_deg[box], fit.rms[box]
        )
        found = _component_planes(comp, xb, yb, zb, fit_b, plane_tolerance, min_cells)
        if not found:
            continue
        found = _settle(comp, found, xb, yb, zb, fit_b.smooth, plane_tolerance, min_cells)
        idx = _assign(comp, found, xb, yb, fit_b.smooth, plane_tolerance)
        for j, plane in enumerate(found):
            parts, n_parts = ndimage.label(idx == j, _FOUR)
            for q in range(1, n_parts + 1):
                part = parts == q
                if part.sum() < min_cells:
                    continue
                planes.append(plane)
                sub = labels[box]
                sub[part] = len(planes)
    labels = _grow_rims(labels, planes, x, y, z, plane_tolerance, window // 2 + 1)
    labels = _merge_adjacent(labels, x, y, z, fit.smooth, smooth, plane_tolerance)
    final = []
    for k, box in enumerate(ndimage.find_objects(labels), start=1):
        sel = labels[box] == k
        final.append(fit_plane(x[box][sel], y[box][sel], z[box][sel]))
    return Segments(labels=labels, planes=np.array(final).reshape(-1, 5), smooth_cells=smooth)


def _merge_adjacent(
    labels: np.ndarray,
    x: FloatArray,
    y: FloatArray,
    z: FloatArray,
    zs: FloatArray,
    smooth: np.ndarray,
    tol: float,
) -> np.ndarray:
    """Merge touching segments whose cells together fit one plane within ``SMOOTH_FRACTION *
    tol`` (RMS, smoothed heights of smooth cells), smallest first; return labels renumbered 1..K.

    A pocket of smooth cells fenced off by noisy ones forms its own small component and plane;
    once the rims have grown, it touches the surface it belongs to and joins it here."""
    while True:
        pairs: set[tuple[int, int]] = set()
        for la, lb in ((labels[:, :-1], labels[:, 1:]), (labels[:-1, :], labels[1:, :])):
            touch = (la != lb) & (la > 0) & (lb > 0)
            lo, hi = np.minimum(la, lb)[touch].tolist(), np.maximum(la, lb)[touch].tolist()
            pairs.update(zip(lo, hi, strict=True))
        if not pairs:
            break
        size = np.bincount(labels.ravel())
        merged = False
        for a, b in sorted(pairs, key=lambda ab: min(size[ab[0]], size[ab[1]])):
            both = (labels == a) | (labels == b)
            p = fit_plane(x[both], y[both], z[both])
            if _fits_both(
                p, (labels == a) & smooth, (labels == b) & smooth, x, y, zs, SMOOTH_FRACTION * tol
            ):
                labels = np.where(labels == b, a, labels)
                merged = True
                break
        if not merged:
            break
    keep = np.unique(labels[labels > 0])
    lut = np.zeros(int(labels.max()) + 1, dtype=np.int64)
    lut[keep] = np.arange(1, len(keep) + 1)
    return lut[labels]


def _grow_rims(
    labels: np.ndarray,
    planes: list[FloatArray],
    x: FloatArray,
    y: FloatArray,
    z: FloatArray,
    tol: float,
    steps: int,
) -> np.ndarray:
    """Expand labels into unlabelled known cells whose own height is within ``tol`` of the plane."""
    from skimage.segmentation import expand_labels

    if not planes:
        return labels
    p = np.array(planes)
    known = ~np.isnan(z)
    for _ in range(steps):
        grown = expand_labels(labels, distance=1)
        cand = (labels == 0) & (grown > 0) & known
        if not cand.any():
            break
        pk = p[grown[cand] - 1]
        dz = np.abs(
            z[cand] - (pk[:, 0] + pk[:, 1] * (x[cand] - pk[:, 3]) + pk[:, 2] * (y[cand] - pk[:, 4]))
        )
        ok = np.zeros_like(cand)
        ok[cand] = dz <= tol
        if not ok.any():
            break
        labels = np.where(ok, grown, labels)
    return labels
