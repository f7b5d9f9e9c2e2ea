"""Regions recovered from a height map, drawn over the map."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.patches import Polygon

from footfall.terrain.heightmap import HeightmapResult
from footfall.terrain.scene import Scene
from footfall.viz._mpl import plt, save


def plot_heightmap_regions(result: HeightmapResult, path: Path, scene: Scene | None = None) -> Path:
    """Draw the height map with the recovered convex regions on top, beside the segments.

    Left: the heights (unknown cells white), every region outlined and named. Right: the planar
    segments (one colour each, grey where a cell is known but on no segment), the regions filled
    by their plane's slope. With ``scene``, its start feet and goal are marked on both.

    Args:
        result: what :func:`footfall.terrain.heightmap.regions_from_heightmap` returned.
        path: the PNG to write.
        scene: the scene built from ``result`` (optional).

    Returns:
        ``path``.
    """
    hm = result.map
    h, w = hm.shape
    r = hm.resolution
    extent = (
        hm.origin[0] - r / 2,
        hm.origin[0] + r * (w - 0.5),
        hm.origin[1] - r / 2,
        hm.origin[1] + r * (h - 0.5),
    )
    wide = w >= h
    fig, axes = plt.subplots(
        2 if wide else 1, 1 if wide else 2, figsize=(10, 8) if wide else (12, 6), squeeze=False
    )
    ax_map, ax_seg = axes.ravel()
    im = ax_map.imshow(hm.heights, origin="lower", extent=extent, cmap="viridis")
    fig.colorbar(im, ax=ax_map, label="z [m]", shrink=0.8)
    known = ~np.isnan(hm.heights)
    seg = np.where(result.labels > 0, (result.labels - 1) % 20, np.nan)
    ax_seg.imshow(np.where(known, 0.0, np.nan), origin="lower", extent=extent, cmap="Greys",
                  vmin=0.0, vmax=4.0)  # fmt: skip
    ax_seg.imshow(seg, origin="lower", extent=extent, cmap="tab20", vmin=0, vmax=19, alpha=0.6)
    slope_norm = plt.Normalize(0.0, max(5.0, result.options.max_slope_deg))
    for region in result.regions:
        v = region.vertices
        ax_map.add_patch(Polygon(v, closed=True, fill=False, ec="w", lw=1.2))
        ax_map.add_patch(Polygon(v, closed=True, fill=False, ec="k", lw=0.5))
        colour = plt.get_cmap("magma")(slope_norm(region.slope_deg))
        ax_seg.add_patch(Polygon(v, closed=True, fc=colour, ec="k", lw=0.8, alpha=0.35))
        c = region.centroid
        ax_map.annotate(region.name, (c[0], c[1]), ha="center", va="center", fontsize=6)
    if scene is not None:
        for ax in (ax_map, ax_seg):
            for foot, mark in ((scene.start.left, "^"), (scene.start.right, "v")):
                ax.plot(foot[0], foot[1], mark, color="tab:red", ms=7)
            g = scene.goal.position
            ax.plot(g[0], g[1], "*", color="gold", mec="k", ms=12)
    n_seg = int(result.labels.max())
    ax_map.set_title(f"height map {h} x {w} at {r:g} m, {len(result.regions)} convex regions",
                     fontsize=9)  # fmt: skip
    ax_seg.set_title(f"{n_seg} planar segments; regions shaded by slope (0-"
                     f"{slope_norm.vmax:g} deg)", fontsize=9)  # fmt: skip
    for ax in (ax_map, ax_seg):
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
    fig.tight_layout()
    return save(fig, path)
