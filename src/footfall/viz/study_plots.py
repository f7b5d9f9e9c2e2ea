"""Figures of a section 5.5 study (``footfall study``): fragility curves, ZMP-offset distributions
and paired planner differences. Inputs are plain dicts (the study's rows and statistics as
``dataclasses.asdict``), so this module depends on nothing above it."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from footfall.viz._mpl import plt, save

_STYLE = {"smallest": "-", "equal": "--"}


def _grid(n: int) -> tuple[Any, Any]:
    fig, axes = plt.subplots(
        1, max(1, n), figsize=(5 * max(1, n), 4), squeeze=False, constrained_layout=True
    )
    return fig, axes[0]


def plot_fragility(points: Sequence[dict[str, Any]], path: Path) -> Path:
    """Success rate against push impulse with Wilson 95 % bands, one panel per scene, one line
    per planner and step mode (solid: smallest N, dashed: equal N)."""
    scenes = list(dict.fromkeys(p["scene"] for p in points))
    fig, axes = _grid(len(scenes))
    for ax, scene in zip(axes, scenes, strict=False):
        keys = list(dict.fromkeys((p["planner"], p["mode"]) for p in points if p["scene"] == scene))
        drawn: set[tuple[object, ...]] = set()
        for planner, mode in keys:
            pts = sorted(
                (
                    p
                    for p in points
                    if (p["scene"], p["planner"], p["mode"]) == (scene, planner, mode)
                ),
                key=lambda p: p["impulse"],
            )
            # the same walks in both modes (the reactive planner's) are drawn once
            same = (planner, *((p["impulse"], p["walks"], p["successes"]) for p in pts))
            if same in drawn:
                continue
            drawn.add(same)
            x = np.array([p["impulse"] for p in pts])
            y = np.array([p["successes"] / p["walks"] if p["walks"] else np.nan for p in pts])
            lo = np.array([p["lo"] for p in pts])
            hi = np.array([p["hi"] for p in pts])
            (line,) = ax.plot(
                x, y, _STYLE.get(mode, "-"), marker="o", label=f"{planner} ({mode} N)"
            )
            ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.15)
        ax.set_title(scene)
        ax.set_xlabel("push impulse [N s]")
        ax.set_ylabel("success rate (95 % Wilson band)")
        ax.set_ylim(-0.02, 1.02)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    return save(fig, path)


def plot_zmp_distributions(
    rows: Sequence[dict[str, Any]], impulse: float, mode: str, path: Path
) -> Path:
    """Box plots of the per-walk mean single-support ZMP offset of the successful walks at
    ``impulse`` in step mode ``mode``, per scene and planner."""
    flag = "smallest_n" if mode == "smallest" else "equal_n"
    sel = [
        r
        for r in rows
        if r[flag] and r["push_impulse"] == impulse and r["error"] is None and r["success"]
    ]
    scenes = list(dict.fromkeys(r["scene"] for r in sel)) or ["(no successful walks)"]
    fig, axes = _grid(len(scenes))
    for ax, scene in zip(axes, scenes, strict=False):
        planners = list(dict.fromkeys(r["planner"] for r in sel if r["scene"] == scene))
        data = [
            [1000 * r["zmp_offset_mean"] for r in sel if r["scene"] == scene and r["planner"] == p]
            for p in planners
        ]
        if data:
            ax.boxplot(
                data,
                tick_labels=[f"{p}\n(n = {len(d)})" for p, d in zip(planners, data, strict=True)],
            )
        ax.set_title(f"{scene}: push {impulse:g} N s, {mode} N")
        ax.set_ylabel("mean single-support ZMP offset [mm]")
        ax.grid(alpha=0.3, axis="y")
    return save(fig, path)


def plot_paired(pairs: Sequence[dict[str, Any]], path: Path) -> Path:
    """Mean paired ZMP-offset difference (planner - baseline) with its 95 % bootstrap CI, one
    row per scene, step mode and baseline; left of 0: the planner is lower."""
    fig, ax = plt.subplots(figsize=(7, 0.5 * max(3, len(pairs)) + 1), constrained_layout=True)
    labels = []
    for i, p in enumerate(pairs):
        d, lo, hi = (1000 * p[k] for k in ("zmp_diff", "zmp_lo", "zmp_hi"))
        ax.errorbar([d], [i], xerr=[[max(0.0, d - lo)], [max(0.0, hi - d)]], fmt="o", capsize=4)
        labels.append(
            f"{p['scene']} {p['mode']} N: {p['planner']} - {p['baseline']} (n = {p['pairs']})"
        )
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_yticks(range(len(labels)), labels, fontsize=8)
    ax.invert_yaxis()
    ax.set_xlabel("paired difference of the mean single-support ZMP offset [mm] (95 % CI)")
    ax.grid(alpha=0.3, axis="x")
    return save(fig, path)
