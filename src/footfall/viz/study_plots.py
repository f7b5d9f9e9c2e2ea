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


def fragility_curves(points: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """The curves of :func:`plot_fragility`: per scene, planner and step mode, sorted by impulse,
    with a label that names the mode and N; a curve whose walks are another mode's too (the same
    N, so the same walks) is one curve labelled with both modes, never dropped.

    Returns:
        dicts with scene, planner, modes (list), label, impulse, rate, lo, hi (lists).
    """
    curves: list[dict[str, Any]] = []
    by_walks: dict[tuple[object, ...], dict[str, Any]] = {}
    keys = dict.fromkeys((p["scene"], p["planner"], p["mode"]) for p in points)
    for scene, planner, mode in keys:
        pts = sorted(
            (p for p in points if (p["scene"], p["planner"], p["mode"]) == (scene, planner, mode)),
            key=lambda p: p["impulse"],
        )
        n = pts[0].get("n_steps", 0)
        same = (scene, planner, n, *((p["impulse"], p["walks"], p["successes"]) for p in pts))
        if same in by_walks:
            by_walks[same]["modes"].append(mode)
            continue
        curve = {
            "scene": scene,
            "planner": planner,
            "modes": [mode],
            "n_steps": n,
            "impulse": [p["impulse"] for p in pts],
            "rate": [p["successes"] / p["walks"] if p["walks"] else float("nan") for p in pts],
            "lo": [p["lo"] for p in pts],
            "hi": [p["hi"] for p in pts],
        }
        by_walks[same] = curve
        curves.append(curve)
    for c in curves:
        order = sorted(c["modes"], key=lambda m: (m != "smallest", m))
        n_text = f" = {c['n_steps']}" if c["n_steps"] else ""
        c["label"] = f"{c['planner']} ({' = '.join(order)} N{n_text})"
    return curves


def plot_fragility(points: Sequence[dict[str, Any]], path: Path) -> Path:
    """Success rate against push impulse with Wilson 95 % intervals (bands, and error bars so a
    single impulse shows its interval too), one panel per scene, one line per planner and step
    mode with its N (solid: smallest N, dashed: equal N; a curve that is both modes' walks is
    drawn once, labelled with both)."""
    curves = fragility_curves(points)
    scenes = list(dict.fromkeys(c["scene"] for c in curves))
    fig, axes = _grid(len(scenes))
    for ax, scene in zip(axes, scenes, strict=False):
        for c in (c for c in curves if c["scene"] == scene):
            x, y = np.array(c["impulse"]), np.array(c["rate"])
            lo, hi = np.array(c["lo"]), np.array(c["hi"])
            (line,) = ax.plot(x, y, _STYLE.get(c["modes"][0], "-"), marker="o", label=c["label"])
            ax.fill_between(x, lo, hi, color=line.get_color(), alpha=0.15)
            yerr = np.vstack([np.clip(y - lo, 0, None), np.clip(hi - y, 0, None)])
            ax.errorbar(x, y, yerr=yerr, fmt="none", ecolor=line.get_color(), capsize=3)
        ax.set_title(scene)
        ax.set_xlabel("push impulse [N s]")
        ax.set_ylabel("success rate (95 % Wilson interval)")
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


def plot_terrain_paired(pairs: Sequence[dict[str, Any]], path: Path) -> Path:
    """The tested quantity of a family study: per family, step mode and baseline, the mean over
    terrains of the per-terrain paired ZMP-offset difference (planner - baseline) with its
    cluster-bootstrap 95 % CI (filled), and the same on the terrains whose plans are all proven
    (open, below it); each row names its sample (terrains T, seed pairs n)."""
    fig, ax = plt.subplots(figsize=(8, 0.6 * max(3, len(pairs)) + 1), constrained_layout=True)
    labels = []
    for i, p in enumerate(pairs):
        for k, (prefix, style, dy) in enumerate((("", "o", -0.12), ("proven_", "s", 0.12))):
            d, lo, hi = (1000 * p[prefix + key] for key in ("diff", "lo", "hi"))
            if not np.isfinite(d):
                continue
            xerr = [[max(0.0, d - lo)], [max(0.0, hi - d)]] if np.isfinite(lo) else None
            ax.errorbar(
                [d],
                [i + dy],
                xerr=xerr,
                fmt=style,
                mfc="C0" if k == 0 else "white",
                color="C0",
                capsize=3,
                label=(
                    ("all terrains" if k == 0 else "terrains with proven plans") if i == 0 else None
                ),
            )
        labels.append(
            f"{p['family']} {p['mode']} N: {p['planner']} - {p['baseline']}\n"
            f"T = {p['terrains']} (proven {p['proven_terrains']}), n = {p['pairs']}"
        )
    ax.axvline(0.0, color="k", lw=0.8)
    ax.set_yticks(range(len(labels)), labels, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel(
        "mean over terrains of the paired ZMP-offset difference [mm] (cluster bootstrap 95 % CI)"
    )
    ax.grid(alpha=0.3, axis="x")
    if pairs:
        ax.legend(fontsize=7, loc="best")
    return save(fig, path)
