"""Figure of a footstep plan: top view over the terrain and a side view of heights."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.patches import Polygon

from footfall.models.biped import Side
from footfall.planning.plan import FootstepPlan
from footfall.terrain.scene import Scene
from footfall.viz._mpl import plt, save
from footfall.viz.terrain_plot import height_norm, plot_terrain, plot_terrain_side

SIDE_COLOUR = {Side.LEFT: "tab:blue", Side.RIGHT: "tab:red"}


def foot_outline(centre: np.ndarray, heading: float, length: float, width: float) -> np.ndarray:
    """Corners (4, 2) [m] of a rectangular sole centred at ``centre`` along ``heading``."""
    c, s = math.cos(heading), math.sin(heading)
    local = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * [length / 2, width / 2]
    return centre[:2] + local @ np.array([[c, s], [-s, c]])


def plot_plan(plan: FootstepPlan, scene: Scene, path: Path, title: str | None = None) -> Path:
    """Top view (regions by height, numbered oriented feet, CoM path) and side view (x, z)."""
    fig, (ax, side) = plt.subplots(
        2, 1, figsize=(11, 6.5), gridspec_kw={"height_ratios": [2.2, 1]}, constrained_layout=True
    )
    norm = height_norm(scene.terrain)
    sm = plot_terrain(ax, scene.terrain, norm=norm, labels=False)
    plot_terrain_side(side, scene.terrain, norm=norm)
    robot = plan.robot
    for i in range(plan.footsteps.shape[0]):
        p, th, sd = plan.footsteps[i], float(plan.headings[i]), plan.sides[i]
        corners = foot_outline(p, th, robot.foot_length, robot.foot_width)
        ax.add_patch(Polygon(corners, closed=True, fill=False, ec=SIDE_COLOUR[sd], lw=1.5))
        ax.annotate(str(i), p[:2], ha="center", va="center", fontsize=7, color=SIDE_COLOUR[sd])
        side.plot(p[0], p[2], "s", color=SIDE_COLOUR[sd], ms=4)
    if plan.states.shape[0]:
        com = plan.com_positions().reshape(-1, 2)
        ax.plot(com[:, 0], com[:, 1], "-", color="k", lw=1.2, label="CoM (ALIP nodes)")
    g = scene.goal
    ax.plot(g.position[0], g.position[1], "*", color="gold", mec="k", ms=14, label="goal")
    # Frame the walk, not the whole terrain: footsteps and goal plus a margin.
    pts = np.vstack([plan.footsteps[:, :2], g.position[None, :2]]) if plan.has_solution else None
    if pts is not None:
        margin = 0.5
        lo, hi = pts.min(axis=0) - margin, pts.max(axis=0) + margin
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        side.set_xlim(lo[0], hi[0])
    for sd in (Side.LEFT, Side.RIGHT):
        ax.plot([], [], "s", mfc="none", color=SIDE_COLOUR[sd], label=f"{sd.value} foot")
    ax.legend(loc="upper left", fontsize=7)
    ax.set_title(
        title
        or f"{scene.name}: {plan.planner}, {plan.n_steps} steps, {plan.status.value}"
        + (f", objective {plan.objective:.3f}" if math.isfinite(plan.objective) else ""),
        fontsize=9,
    )
    side.set_xlabel("x [m]")
    side.set_ylabel("z [m]")
    fig.colorbar(sm, ax=ax, label="region height z [m]", shrink=0.9, pad=0.01)
    return save(fig, path)
