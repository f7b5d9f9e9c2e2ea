"""Document 000 section 5.5 run in MuJoCo: planners x scenes x seeded pushes -> ZMP-offset table.

:func:`compare_mujoco` plans every scene and planner for the walker
(:func:`footfall.sim.biped.plans.plan_for_walk`), walks each plan once per seed with a seeded push
and returns one row per walk; :func:`compare_table` aggregates the rows per scene and planner (mean
and max single-support ZMP offset, success rate), which is the table of section 5.5.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import atomic_open, write_text
from footfall.errors import InputError
from footfall.planning.run import SearchMonitor
from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.plans import plan_for_walk, random_push
from footfall.sim.biped.result import WalkResult
from footfall.sim.biped.walk import walk
from footfall.terrain.scene import Scene, builtin_scene
from footfall.viz.compare_plots import plot_mujoco_table


def walk_row(scene: Scene, planner: str, seed: int, push: float, res: WalkResult) -> dict[str, Any]:
    """One row of the comparison for a finished walk."""
    m = res.metrics
    return {
        "scene": scene.name,
        "planner": planner,
        "seed": seed,
        "push_N": push,
        "fell": m.fell,
        "reached_goal": m.reached_goal,
        "steps_landed": m.steps_landed,
        "steps_planned": m.steps_planned,
        "zmp_mean_m": m.zmp.mean,
        "zmp_max_m": m.zmp.max,
        "zmp_at_edge_share": m.zmp.at_edge_share if m.zmp.at_edge_share is not None else math.nan,
        "footstep_error_mean_m": m.footstep_error_m.mean,
        "time_to_goal_s": m.time_to_goal_s,
        "wall_time_s": m.wall_time_s,
    }


def compare_mujoco(
    scenes: Sequence[str] = ("discrete_steps", "stairs_slope_gap"),
    planners: Sequence[str] = ("miqcqp", "kinematic", "reactive"),
    seeds: Sequence[int] = (0, 1, 2),
    push: float = 30.0,
    n_steps: dict[tuple[str, str], int] | None = None,
    time_limit: float = 300.0,
    cache_dir: Path | None = None,
    progress: Callable[[str], None] | None = None,
    robot_aware: bool = True,
    heading_segments: int | None = None,
    controller: str = "wbc",
    monitor_for: Callable[[str], AbstractContextManager[SearchMonitor | None]] | None = None,
) -> list[dict[str, Any]]:
    """Walk every scene x planner x seed in MuJoCo with a seeded push; one row per walk.

    Args:
        scenes: built-in scene names.
        planners: planner names.
        seeds: push seeds (each seed is one walk with its own push).
        push: push magnitude [N] (0 = no push).
        n_steps: N per (scene, planner) for the optimising planners; missing = smallest N.
        time_limit: planner time limit [s].
        cache_dir: folder for cached plans (strongly advised for miqcqp).
        progress: called with a line of text after each walk.
        robot_aware: plan miqcqp/kinematic with the options beyond the document
            (:func:`plan_for_walk`); False: the document's problem.
        heading_segments: L of the miqcqp and kinematic plans (:func:`plan_for_walk`; None: its
            default).
        controller: the walker's whole-body controller (``WalkOptions.controller``).
        monitor_for: ``monitor_for(title)`` gives a context manager yielding the monitor of a
            plan's smallest-N search (``footfall plan``'s progress lines); None: silent.

    Returns:
        Rows of :func:`walk_row` plus ``plan_status`` and ``plan_time_s``; a scene/planner
        without a plan gives one row with ``plan_status`` and no walk numbers.
    """
    if not seeds:
        raise InputError("seeds", list(seeds), "at least one seed")
    rows: list[dict[str, Any]] = []
    for name in scenes:
        scene = builtin_scene(name)
        for planner in planners:
            n = (n_steps or {}).get((name, planner))
            t0 = time.perf_counter()
            title = f"{name} with {planner}"
            with monitor_for(title) if monitor_for else nullcontext() as monitor:
                plan = plan_for_walk(
                    scene,
                    planner,
                    n,
                    time_limit,
                    cache_dir,
                    robot_aware=robot_aware,
                    heading_segments=heading_segments,
                    monitor=monitor,
                )
            plan_time = time.perf_counter() - t0
            if not plan.has_solution:
                rows.append({"scene": name, "planner": planner, "plan_status": plan.status.value})
                continue
            for seed in seeds:
                opts = WalkOptions(controller=controller)
                pushes = (random_push(seed, push, plan, opts),) if push > 0 else ()
                res = walk(scene, plan, WalkOptions(controller=controller, pushes=pushes))
                row = walk_row(scene, planner, seed, push, res)
                row["controller"] = controller
                row["plan_status"] = plan.status.value
                row["plan_time_s"] = plan_time
                rows.append(row)
                if progress is not None:
                    progress(
                        f"{name} {planner} seed {seed}: fell={row['fell']} "
                        f"zmp mean {row['zmp_mean_m']:.3f} m"
                    )
    return rows


def compare_table(rows: Sequence[dict[str, Any]]) -> list[dict[str, Any]]:
    """Per (scene, planner): walks, success rate (goal reached without a fall), mean of the
    per-walk mean single-support ZMP offset and max over walks of the max offset [m]."""
    out: list[dict[str, Any]] = []
    keys = sorted({(r["scene"], r["planner"]) for r in rows})
    for scene, planner in keys:
        rs = [r for r in rows if r["scene"] == scene and r["planner"] == planner and "fell" in r]
        if not rs:
            out.append({"scene": scene, "planner": planner, "walks": 0})
            continue
        mean = [r["zmp_mean_m"] for r in rs if not math.isnan(r["zmp_mean_m"])]
        mx = [r["zmp_max_m"] for r in rs if not math.isnan(r["zmp_max_m"])]
        out.append(
            {
                "scene": scene,
                "planner": planner,
                "walks": len(rs),
                "success_rate": float(np.mean([r["reached_goal"] for r in rs])),
                "fall_rate": float(np.mean([r["fell"] for r in rs])),
                "zmp_mean_m": float(np.mean(mean)) if mean else math.nan,
                "zmp_max_m": float(np.max(mx)) if mx else math.nan,
            }
        )
    return out


def write_mujoco_outputs(
    out: Path, rows: Sequence[dict[str, Any]], table: Sequence[dict[str, Any]], header: str
) -> list[Path]:
    """Write compare_mujoco.csv (one row per walk), compare_mujoco.md (the table of section 5.5
    with the verdict on document 000's claim) and compare_mujoco.png; return the paths."""
    import csv

    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "compare_mujoco.csv"
    fields = list(dict.fromkeys(k for r in rows for k in r))
    with atomic_open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        w.writerows(rows)
    md = [
        "# Planner comparison in MuJoCo (document 000, section 5.5)",
        "",
        header,
        "",
        "| scene | planner | walks | success | falls | mean ZMP offset [mm] | max ZMP offset [mm] |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in table:
        if r["walks"] == 0:
            md.append(f"| {r['scene']} | {r['planner']} | 0 (no plan) | | | | |")
            continue
        md.append(
            f"| {r['scene']} | {r['planner']} | {r['walks']} | {100 * r['success_rate']:.0f}% "
            f"| {100 * r['fall_rate']:.0f}% | {1000 * r['zmp_mean_m']:.1f} "
            f"| {1000 * r['zmp_max_m']:.1f} |"
        )
    md += ["", "## Document 000's claim", ""]
    for scene in dict.fromkeys(r["scene"] for r in table):
        by = {r["planner"]: r for r in table if r["scene"] == scene and r["walks"] > 0}
        ok = {p: r for p, r in by.items() if r["success_rate"] > 0}
        if "miqcqp" not in by or len(by) < 2:
            md.append(f"- {scene}: cannot be judged (no MIQCQP walk or no baseline walked).")
        elif "miqcqp" not in ok:
            md.append(
                f"- {scene}: cannot be judged: no MIQCQP walk reached the goal (each fell or "
                "stopped short), so its ZMP numbers do not describe walking the plan."
            )
        else:
            ours = by["miqcqp"]["zmp_mean_m"]
            others = {p: r["zmp_mean_m"] for p, r in by.items() if p != "miqcqp"}
            verdict = "holds" if all(ours < v for v in others.values()) else "does NOT hold"
            txt = ", ".join(f"{p} {1000 * v:.1f} mm" for p, v in others.items())
            md.append(f"- {scene}: the claim {verdict}: miqcqp {1000 * ours:.1f} mm vs {txt}.")
    md.append("")
    md_path = out / "compare_mujoco.md"
    write_text(md_path, "\n".join(md))
    fig_path = plot_mujoco_table(table, out / "compare_mujoco.png")
    return [csv_path, md_path, fig_path]


def steps_per_pair(
    scenes: Sequence[str], planners: Sequence[str], n_steps: int | dict[str, int] | None
) -> dict[tuple[str, str], int] | None:
    """Footsteps N per (scene, planner) for the horizon planners, from one N for every scene or
    one per scene name; None where nothing was asked (the reactive planner walks to the goal)."""
    if n_steps is None:
        return None
    pairs = {
        (sc, p): n_steps if isinstance(n_steps, int) else n_steps[sc]
        for sc in scenes
        for p in planners
        if p != "reactive" and (isinstance(n_steps, int) or sc in n_steps)
    }
    return pairs or None


def describe(trials: int, force: float, push_duration: float) -> str:
    """The header of compare_mujoco.md: how many walks and which push."""
    return (
        f"{trials} walks per scene and planner, each with one push of {force:g} N for "
        f"{push_duration:g} s ({force * push_duration:g} N s) in a seeded random direction mid "
        "single support in 30-70 % of the walk; plans cached in plans/."
    )


def summary_lines(table: Sequence[dict[str, Any]]) -> list[str]:
    """One console line per (scene, planner) of the MuJoCo table."""
    return [
        f"{r['scene']:>18} {r['planner']:>9}: mean ZMP {1000 * r['zmp_mean_m']:.1f} mm, "
        f"max {1000 * r['zmp_max_m']:.1f} mm, success {100 * r['success_rate']:.0f}% "
        f"({r['walks']} walks)"
        if r["walks"]
        else f"{r['scene']:>18} {r['planner']:>9}: no plan"
        for r in table
    ]
