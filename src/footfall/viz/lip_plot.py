"""Figures of the LIP walk, drawn like document 004's figures 2-5."""

from __future__ import annotations

from pathlib import Path

from footfall.planning.lip_walk import LipWalk
from footfall.viz._mpl import plt, save


def plot_lip_walk(walk: LipWalk, path: Path, title: str = "LIP walk", dt: float = 0.01) -> Path:
    """Top view: CoM path (line), actual footholds (circles), ideal footholds (crosses).

    Args:
        walk: the generated walk.
        path: PNG file to write.
        title: figure title.
        dt: sampling period of the CoM path [s].
    """
    traj = walk.com_trajectory(dt)
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    ax.plot(traj["x"], traj["y"], "-", lw=1.5, label="CoM")
    ax.plot(
        walk.footholds[:, 0], walk.footholds[:, 1], "o", mfc="none", ms=8, label="actual foothold"
    )
    ax.plot(
        walk.ideal_footholds[:, 0], walk.ideal_footholds[:, 1], "x", ms=8, label="ideal foothold"
    )
    for i, (x, y) in enumerate(walk.footholds):
        ax.annotate(str(i), (x, y), textcoords="offset points", xytext=(4, 4), fontsize=7)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return save(fig, path)
