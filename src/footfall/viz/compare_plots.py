"""Figures of the planner comparisons of document 000, section 5.5 (reduced-order and MuJoCo)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from footfall.viz._mpl import plt, save


def plot_compare(rows: list[dict[str, Any]], out: Path) -> list[Path]:
    """Box plots of the per-trial mean and max single-support ZMP offset per scene and planner."""
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    planners = list(dict.fromkeys(r["planner"] for r in rows))
    paths = []
    for key, label in (("zmp_offset_mean", "mean"), ("zmp_offset_max", "max")):
        fig, axes = plt.subplots(
            1,
            max(1, len(scenes)),
            figsize=(4.5 * max(1, len(scenes)), 4),
            squeeze=False,
            constrained_layout=True,
        )
        for ax, scene in zip(axes[0], scenes, strict=False):
            data = [
                [
                    1000 * r[key]
                    for r in rows
                    if r["scene"] == scene and r["planner"] == p and r[key] is not None
                ]
                for p in planners
            ]
            ax.boxplot(data, tick_labels=planners)
            ax.set_title(scene)
            ax.set_ylabel(f"{label} single-support ZMP offset [mm]")
        paths.append(save(fig, out / f"compare_zmp_{label}.png"))
    return paths


def plot_mujoco_table(table: Sequence[dict[str, Any]], path: Path) -> Path:
    """Bars of the mean and max single-support ZMP offset per scene and planner of the MuJoCo
    comparison (rows of :func:`footfall.experiments.compare_mujoco.compare_table`), with each
    planner's success rate."""
    scenes = list(dict.fromkeys(r["scene"] for r in table))
    fig, axes = plt.subplots(1, len(scenes), figsize=(4.5 * len(scenes), 3.6), squeeze=False)
    for ax, scene in zip(axes[0], scenes, strict=True):
        rs = [r for r in table if r["scene"] == scene and r["walks"] > 0]
        names = [r["planner"] for r in rs]
        mean = [1000 * r["zmp_mean_m"] for r in rs]
        mx = [1000 * r["zmp_max_m"] for r in rs]
        xs = np.arange(len(rs))
        ax.bar(xs - 0.2, mean, 0.4, label="mean")
        ax.bar(xs + 0.2, mx, 0.4, label="max")
        for x, r in zip(xs, rs, strict=True):
            ax.annotate(f"{100 * r['success_rate']:.0f}% ok", (x, max(mx) * 1.02), ha="center")
        ax.set_xticks(xs, names)
        ax.set_ylabel("single-support ZMP offset [mm]")
        ax.set_title(scene)
        ax.legend(loc="lower right")
    fig.tight_layout()
    return save(fig, path)
