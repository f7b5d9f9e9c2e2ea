"""Top and side views of a terrain (regions of document 000, eq. 5.15-5.18)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.axes import Axes
from matplotlib.cm import ScalarMappable
from matplotlib.colors import Colormap, Normalize
from matplotlib.patches import Polygon
from matplotlib.tri import Triangulation

from footfall._geometry import convex_hull
from footfall._io import save_figure
from footfall.terrain.scene import Scene
from footfall.terrain.terrain import Terrain


def height_norm(terrain: Terrain) -> Normalize:
    """Colour normalisation spanning the terrain's heights [m] (never zero-width)."""
    lo, hi = terrain.bounds()[:, 2]
    if hi - lo < 1e-3:
        lo, hi = lo - 0.05, hi + 0.05
    return Normalize(vmin=float(lo), vmax=float(hi))


def plot_terrain(
    ax: Axes,
    terrain: Terrain,
    *,
    cmap: str | Colormap = "viridis",
    norm: Normalize | None = None,
    labels: bool = True,
) -> ScalarMappable:
    """Top view: every region filled with its height as colour, outlined, optionally labelled.

    Tilted regions are shaded per vertex (Gouraud), so a slope shows its gradient.

    Args:
        ax: axes to draw into (x, y in metres; the aspect is set equal).
        terrain: the terrain.
        cmap: colour map for the height.
        norm: height normalisation; by default spans the terrain's heights.
        labels: write each region's name at its centroid.

    Returns:
        A ScalarMappable of the height colouring, for ``fig.colorbar(..., label="z [m]")``.
    """
    norm = height_norm(terrain) if norm is None else norm
    sm = ScalarMappable(norm=norm, cmap=cmap)
    for region in terrain:
        v3 = region.vertices3d
        n = len(v3)
        # A fan from vertex 0 triangulates any convex polygon.
        tris = np.array([[0, j, j + 1] for j in range(1, n - 1)])
        tri = Triangulation(v3[:, 0], v3[:, 1], tris)
        ax.tripcolor(tri, v3[:, 2], shading="gouraud", cmap=sm.cmap, norm=norm)
        ax.add_patch(Polygon(region.vertices, closed=True, fill=False, ec="k", lw=0.8))
        if labels:
            c = region.centroid
            ax.annotate(region.name, (c[0], c[1]), ha="center", va="center", fontsize=7, alpha=0.8)
    lo, hi = terrain.bounds()
    pad = 0.05 * max(hi[0] - lo[0], hi[1] - lo[1])
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    return sm


def plot_terrain_side(
    ax: Axes,
    terrain: Terrain,
    *,
    cmap: str | Colormap = "viridis",
    norm: Normalize | None = None,
    alpha: float = 0.6,
) -> list[Any]:
    """Side view (x against z): each region drawn as a block from its outline down to a floor.

    The block of a region is the convex hull in the x-z plane of its corners and of two floor points
    below its x extent, so flat regions appear as boxes and slopes as wedges.

    Args:
        ax: axes to draw into (x and z in metres).
        terrain: the terrain.
        cmap: colour map for the height (same as the top view for a shared colour bar).
        norm: height normalisation; by default spans the terrain's heights.
        alpha: fill opacity (overlapping regions stay visible).

    Returns:
        The patches added.
    """
    norm = height_norm(terrain) if norm is None else norm
    sm = ScalarMappable(norm=norm, cmap=cmap)
    lo, hi = terrain.bounds()
    floor = float(lo[2]) - 0.1
    patches: list[Any] = []
    for region in terrain:
        xz = region.vertices3d[:, [0, 2]]
        pts = np.vstack([xz, [[xz[:, 0].min(), floor], [xz[:, 0].max(), floor]]])
        hull = convex_hull(pts)
        colour = sm.cmap(float(norm(float(region.centroid[2]))))
        patch = Polygon(hull, closed=True, fc=colour, ec="k", lw=0.8, alpha=alpha)
        ax.add_patch(patch)
        patches.append(patch)
    ax.set_xlim(float(lo[0]) - 0.1, float(hi[0]) + 0.1)
    ax.set_ylim(floor, float(hi[2]) + 0.3)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    return patches


def plot_scene(scene: Scene, path: Path, dpi: int = 120) -> Path:
    """Draw ``scene`` to ``path``: top view (regions coloured by height, start feet, goal with its
    heading) above a side view (x against z); return the path."""
    import matplotlib.pyplot as plt

    fig, (ax_top, ax_side) = plt.subplots(
        2, 1, figsize=(9, 8), gridspec_kw={"height_ratios": [3, 1]}, constrained_layout=True
    )
    mappable = plot_terrain(ax_top, scene.terrain)
    plot_terrain_side(ax_side, scene.terrain)
    for foot, mark in ((scene.start.left, "^"), (scene.start.right, "v")):
        ax_top.plot(foot[0], foot[1], mark, color="tab:red", ms=8)
        ax_side.plot(foot[0], foot[2], mark, color="tab:red", ms=8)
    goal = scene.goal.position
    heading = scene.goal.heading
    ax_top.plot(goal[0], goal[1], "*", color="gold", mec="k", ms=14)
    ax_top.arrow(
        goal[0], goal[1], 0.2 * np.cos(heading), 0.2 * np.sin(heading), width=0.01, color="k"
    )
    ax_side.plot(goal[0], goal[2], "*", color="gold", mec="k", ms=14)
    ax_top.set_title(f"{scene.name}: {scene.description}", fontsize=9)
    fig.colorbar(mappable, ax=ax_top, label="z [m]", shrink=0.8)
    return save_figure(fig, path, dpi=dpi)
