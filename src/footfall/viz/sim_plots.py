"""Figures of the closed-loop simulation and of the planner comparison (document 000, section 5.5).

The figures read a :class:`~footfall.results.reduced.SimResult`, so that viz never imports the
simulator.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from matplotlib.patches import Polygon

from footfall._geometry import rot2
from footfall.results.reduced import SimResult
from footfall.terrain.terrain import Terrain
from footfall.viz._mpl import plt, save


def _sole(
    ax: Any, foot: np.ndarray, heading: float, length: float, width: float, **kw: Any
) -> None:
    rot = rot2(heading)
    half = np.array([[1, 1], [-1, 1], [-1, -1], [1, -1]]) * np.array([length, width]) / 2
    ax.add_patch(Polygon(foot[:2] + half @ rot.T, closed=True, **kw))


def plot_top(res: SimResult, path: Path, terrain: Terrain | None = None, title: str = "") -> Path:
    """Top view: terrain, planned and landed soles, CoM path and CoP (ZMP) path [m]."""
    fig, ax = plt.subplots(figsize=(10, 5), constrained_layout=True)
    if terrain is not None:
        from footfall.viz.terrain_plot import plot_terrain

        plot_terrain(ax, terrain)
    for k, foot in enumerate(res.plan_footsteps):
        h = res.headings[min(k, res.headings.shape[0] - 1)]
        _sole(ax, foot, h, res.foot_length, res.foot_width, fill=False, ec="0.4", ls="--", lw=0.8)
    for k, foot in enumerate(res.footsteps):
        _sole(ax, foot, res.headings[k], res.foot_length, res.foot_width, fc="tab:blue", alpha=0.25)
    ss = res.single
    ax.plot(res.com[:, 0], res.com[:, 1], "-", color="tab:red", lw=1.5, label="CoM")
    ax.plot(
        res.cop[ss, 0], res.cop[ss, 1], ".", color="k", ms=1.5, label="ZMP (CoP), single support"
    )
    sat = ss & res.saturated
    if sat.any():
        ax.plot(
            res.cop[sat, 0],
            res.cop[sat, 1],
            ".",
            color="tab:orange",
            ms=2,
            label="CoP at sole edge",
        )
    ax.plot(*res.goal, "*", color="gold", mec="k", ms=14, label="goal")
    m = res.metrics
    status = "FELL" if m.fell else ("stopped" if m.stopped else "walked (not at rest)")
    ax.set_title(
        title or f"{res.planner}: {status}, mean ZMP offset {1000 * m.zmp_offset_mean:.1f} mm"
    )
    pts = np.vstack([res.footsteps[:, :2], res.plan_footsteps[:, :2], res.com, res.goal[None]])
    lo, hi = pts.min(axis=0) - 0.3, pts.max(axis=0) + 0.3
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.legend(fontsize=7, loc="best")
    return save(fig, path)


def plot_zmp_offset(res: SimResult, path: Path) -> Path:
    """CoP offset from the stance foot centre, in the foot frame, over time, with the sole limits."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True, constrained_layout=True)
    ss = res.single
    for ax, j, lim, name in (
        (axes[0], 0, res.foot_length / 2, "forward"),
        (axes[1], 1, res.foot_width / 2, "lateral"),
    ):
        off = np.where(ss, res.cop_offset[:, j], np.nan)
        ax.plot(res.t, 1000 * off, lw=1)
        for s in (-1, 1):
            ax.axhline(1000 * s * lim, color="tab:red", ls="--", lw=0.8)
        ax.set_ylabel(f"{name} ZMP offset [mm]")
    axes[0].set_title("ZMP (CoP) offset from the stance foot centre; dashed: sole edges")
    axes[1].set_xlabel("t [s]")
    return save(fig, path)


def plot_torques(res: SimResult, path: Path) -> Path:
    """Commanded and applied ankle torques and their norm, with U_max [N m]."""
    fig, axes = plt.subplots(2, 1, figsize=(9, 5), sharex=True, constrained_layout=True)
    for j, name in ((0, "tau_x"), (1, "tau_y")):
        axes[0].plot(res.t, res.torque_cmd[:, j], lw=1, label=f"{name} command")
        axes[0].plot(res.t, res.torque[:, j], lw=1, ls="--", label=f"{name} applied")
    axes[0].legend(fontsize=7, ncol=2)
    axes[0].set_ylabel("torque [N m]")
    axes[1].plot(res.t, np.linalg.norm(res.torque_cmd, axis=1), lw=1, label="||u|| command")
    axes[1].plot(res.t, np.linalg.norm(res.torque, axis=1), lw=1, ls="--", label="||u|| applied")
    axes[1].axhline(res.u_max, color="tab:red", ls="--", lw=0.8, label="U_max")
    axes[1].set_ylabel("torque norm [N m]")
    axes[1].set_xlabel("t [s]")
    axes[1].legend(fontsize=7)
    return save(fig, path)


def save_sim_figures(res: SimResult, out: Path, terrain: Terrain | None = None) -> list[Path]:
    """Write sim_top.png, sim_zmp.png and sim_torque.png into ``out``."""
    return [
        plot_top(res, out / "sim_top.png", terrain),
        plot_zmp_offset(res, out / "sim_zmp.png"),
        plot_torques(res, out / "sim_torque.png"),
    ]
