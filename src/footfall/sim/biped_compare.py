"""Document 000 section 5.5 run in MuJoCo: planners x scenes x seeded pushes -> ZMP-offset table.

:func:`plan_for_walk` makes (or loads from a JSON cache) the plan of a scene for the model-derived
robot; :func:`random_push` draws a seeded push; :func:`compare_mujoco` walks every combination and
returns one row per walk; :func:`compare_table` aggregates the rows per scene and planner (mean
and max single-support ZMP offset, success rate), which is the table of section 5.5.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from footfall._validate import non_negative
from footfall.errors import InputError
from footfall.planning.plan import FootstepPlan, PlannerOptions, check_planner_name
from footfall.sim.biped_model import (
    SWING_MAX,
    WALK_HEADING_SEGMENTS,
    BipedModel,
    WalkerModel,
    planner_params,
)
from footfall.sim.biped_walk import RISER_LANDING_TOLERANCE, Push, WalkOptions, WalkResult, walk
from footfall.sim.plan_cache import cache_key, load_plan, save_plan, scene_fingerprint
from footfall.terrain.edges import inset_riser_edges
from footfall.terrain.scene import Scene, builtin_scene

#: robots the walker can walk (``footfall walk --robot``): our biped and the Unitree G1 of
#: example-robot-data (``footfall[robots]``)
ROBOTS = ("biped", "g1")
#: pushes last this long [s]
PUSH_DURATION = 0.1
#: a push starts at a random single support between these shares of the walk
PUSH_WINDOW = (0.3, 0.7)


def robot_model(name: str) -> WalkerModel:
    """The walker model called ``name`` (one of :data:`ROBOTS`), with its default settings.

    Raises:
        InputError: for an unknown name.
        FootfallError: for ``g1`` without ``example-robot-data`` installed.
    """
    if name == "biped":
        return BipedModel()
    if name == "g1":
        from footfall.sim.g1_model import G1Model, g1_urdf_path

        g1_urdf_path()  # fail here, with the extra to install, rather than at the first use
        return G1Model()
    raise InputError("robot", name, f"one of {', '.join(ROBOTS)}")


def plan_for_walk(
    scene: Scene,
    planner: str,
    n_steps: int | None = None,
    time_limit: float = 300.0,
    cache_dir: Path | None = None,
    model: WalkerModel | None = None,
    robot_aware: bool = True,
    heading_segments: int | None = None,
) -> FootstepPlan:
    """The plan of ``scene`` for the MuJoCo biped or another walker model (robot parameters from
    :func:`planner_params`).

    With ``robot_aware`` (the default) the optimising planners (miqcqp, kinematic) also get the
    options beyond the document that this robot needs (:func:`walk_planner_options`): the reach
    set in both feet's frames and the swing bound ``SWING_MAX`` (measured on our biped, used for
    every walker model). The reactive planner cannot honour them and plans without.
    ``robot_aware=False`` plans the document's problem (with the region margin only).

    ``heading_segments``: L of the miqcqp and kinematic plans (eq. 5.12g-h); None:
    ``WALK_HEADING_SEGMENTS`` (64) for robot-aware plans, the document's 16 otherwise. Each
    segment's linear reach (eq. 5.12f) holds for every heading in it, so a heading held on a
    breakpoint (a straight walk at theta = 0 sits on the one between two 22.5 deg segments) gets
    the trapezoid intersected with its copy rotated a whole segment away: from a right stance
    foot, a left step at the inner width 0.12 m may reach 0.342 m forward in the segment below 0
    but not forward at all (-0.024 m) in the one above. With both reach frames each foot's segment
    must serve its incoming and its outgoing step, which need opposite segments, so straight
    robot-aware plans alternate 0.12 and about 0.24 m wide steps and drift sideways
    (stairs_slope_gap N = 16: to y = 0.39 m). 64 segments (5.6 deg) lose at most 4 cm of width
    there (0.329 m forward at 0.16 m); the plans take longer (stairs_slope_gap N = 16: 38 s
    instead of 4 s).

    With ``cache_dir`` the plan is stored as ``plan_<scene>_<planner>.json`` (another robot than
    our biped: ``plan_<scene>_<planner>_<robot name>.json``) and reused while the scene, planner,
    N, robot parameters and planner options are unchanged and the scene's contents too (its
    regions after the riser insets, start, goal: :func:`scene_fingerprint`; MIQCQP plans take
    minutes).

    Beyond the document: the plan is made on the scene's regions with their riser edges moved in
    by ``RISER_LANDING_TOLERANCE`` (:func:`footfall.terrain.edges.inset_riser_edges`) and with a
    ``region_margin`` of half the sole length: footsteps stay half a sole plus the tolerance from
    the edge of a tread below a riser (a step down lands there) and half a sole from other edges.
    """
    from footfall.planning.run import make_plan

    check_planner_name(planner)
    robot = planner_params(model, base=scene.robot)
    # the sole is not a point: keep its centre half a foot length inside every region, so the
    # whole sole stands on the block (at the plan's headings, which stay near the scene's)
    margin = robot.foot_length / 2.0
    scene = replace(scene, terrain=inset_riser_edges(scene.terrain, RISER_LANDING_TOLERANCE))
    aware = walk_planner_options(planner) if robot_aware else {}
    if heading_segments is None:
        heading_segments = WALK_HEADING_SEGMENTS if robot_aware else PlannerOptions.heading_segments
    opts = PlannerOptions(
        time_limit=time_limit, region_margin=margin, heading_segments=heading_segments, **aware
    )
    key = cache_key(
        scene_fingerprint(scene),
        planner,
        n_steps,
        robot,
        margin,
        opts.reach_both_frames,
        opts.swing_max,
        opts.heading_segments,
    )
    suffix = "" if model is None or model.name == "biped" else f"_{model.name}"
    path = (
        cache_dir / f"plan_{scene.name}_{planner}{suffix}.json" if cache_dir is not None else None
    )
    if path is not None:
        cached = load_plan(path, robot, key, margin)
        if cached is not None:
            return cached
    plan = make_plan(scene, planner, n_steps, opts, robot)
    if path is not None and plan.has_solution:
        save_plan(path, plan, scene.name, key)
    return plan


def walk_planner_options(planner: str) -> dict[str, Any]:
    """The :class:`PlannerOptions` beyond the document that the MuJoCo biped's walks use.

    ``reach_both_frames``: with eq. (5.12f) alone the minimum-N plans stretch their reach by
    zig-zagging the headings (turn: 0, 22.5, 0, 30, 60, 90 deg; discrete_steps N = 13: up to
    22.5 deg on block2) and the legs cross or the swing gets long. ``swing_max``: the swing bound
    ``SWING_MAX`` measured for this robot (see there). The reactive planner gets neither (it
    refuses both).
    """
    check_planner_name(planner)
    if planner == "reactive":
        return {}
    return {"reach_both_frames": True, "swing_max": SWING_MAX}


def random_push(seed: int, magnitude: float, plan: FootstepPlan, options: WalkOptions) -> Push:
    """A horizontal push of ``magnitude`` [N] in a seeded random direction, lasting
    ``PUSH_DURATION``, starting mid single support of a seeded step in ``PUSH_WINDOW`` of the walk.
    """
    magnitude = non_negative("push", magnitude)
    rng = np.random.default_rng(seed)
    n = plan.n_steps
    lo, hi = (max(0, int(f * n)) for f in PUSH_WINDOW)
    step = int(rng.integers(lo, max(lo + 1, hi)))
    robot = plan.robot
    t0 = (
        options.settle_time
        + options.shift_time
        + step * (robot.t_ss + robot.t_ds)
        + 0.25 * robot.t_ss
    )
    angle = float(rng.uniform(0.0, 2.0 * math.pi))
    force = magnitude * np.array([math.cos(angle), math.sin(angle), 0.0])
    return Push(start=t0, duration=PUSH_DURATION, force=force)


def walk_row(scene: Scene, planner: str, seed: int, push: float, res: WalkResult) -> dict[str, Any]:
    """One row of the comparison for a finished walk."""
    m = res.metrics
    return {
        "scene": scene.name,
        "planner": planner,
        "seed": seed,
        "push_N": push,
        "fell": m["fell"],
        "reached_goal": m["reached_goal"],
        "steps_landed": m["steps_landed"],
        "steps_planned": m["steps_planned"],
        "zmp_mean_m": m["zmp"]["mean"],
        "zmp_max_m": m["zmp"]["max"],
        "zmp_at_edge_share": m["zmp"].get("at_edge_share", math.nan),
        "footstep_error_mean_m": m["footstep_error_m"]["mean"],
        "time_to_goal_s": m["time_to_goal_s"],
        "wall_time_s": m["wall_time_s"],
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
            plan = plan_for_walk(
                scene,
                planner,
                n,
                time_limit,
                cache_dir,
                robot_aware=robot_aware,
                heading_segments=heading_segments,
            )
            plan_time = time.perf_counter() - t0
            if not plan.has_solution:
                rows.append({"scene": name, "planner": planner, "plan_status": plan.status.value})
                continue
            for seed in seeds:
                opts = WalkOptions()
                pushes = (random_push(seed, push, plan, opts),) if push > 0 else ()
                res = walk(scene, plan, WalkOptions(pushes=pushes))
                row = walk_row(scene, planner, seed, push, res)
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
    with csv_path.open("w", newline="") as fh:
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
    md_path.write_text("\n".join(md))
    fig_path = out / "compare_mujoco.png"
    _plot_mujoco_table(table, fig_path)
    return [csv_path, md_path, fig_path]


def _plot_mujoco_table(table: Sequence[dict[str, Any]], path: Path) -> None:
    from footfall.viz._mpl import plt

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
    fig.savefig(path, dpi=110)
    plt.close(fig)
