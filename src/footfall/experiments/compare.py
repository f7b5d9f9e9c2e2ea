"""The planner comparison of document 000, section 5.5: every planner through the same MPC and plant.

Plans are deterministic, so each (scene, planner) is planned once and kept in the plan cache of
``<out>/plans`` (:mod:`footfall.planning.cache`); the trials vary only the disturbances. Trial ``k`` uses the same seed, hence the
same push (magnitude, direction, time as a fraction of the walk), noise and placement errors, for
every planner (common random numbers), so differences come from the plans.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from footfall._io import atomic_open, write_text
from footfall._validate import check_fields, non_negative, positive
from footfall.control.adjusters import REGION_MODES
from footfall.errors import InputError
from footfall.planning.cache import PlanCache, cached_plan
from footfall.planning.plan import FootstepPlan, PlannerOptions, check_planner_name
from footfall.sim.pushes import Push
from footfall.sim.reduced.closed_loop import SimOptions, simulate
from footfall.terrain.region import Region
from footfall.terrain.scene import Scene

#: metrics written per trial (keys of SimMetrics.to_dict)
TRIAL_FIELDS = (
    "fell",
    "stopped",
    "success",
    "zmp_offset_mean",
    "zmp_offset_rms",
    "zmp_offset_max",
    "saturated_fraction",
    "footstep_dev_mean",
    "footstep_dev_max",
    "footsteps_off_regions",
    "goal_error",
    "steps_taken",
    "mpc_fallbacks",
    "mpc_time_median",
    "wall_time",
)


@dataclass(frozen=True)
class TrialSpec:
    """Disturbances of the compare trials.

    Attributes:
        push_max: push impulses are uniform in [0, push_max] [N s], direction uniform.
        push_duration: length of the push pulse [s].
        noise_pos: state-estimate CoM position noise [m].
        noise_vel: state-estimate CoM velocity noise [m/s].
        placement_error: landing error per axis [m].
        mismatch: true mass and CoM height are scaled by factors uniform in [1 - m, 1 + m].
        control_rate: MPC rate [Hz].
        region_aware: the MPC's footstep region handling (``SimOptions.region_aware``; issue 23);
            ``off`` is document 000's MPC.
    """

    push_max: float = 15.0
    push_duration: float = 0.1
    noise_pos: float = 0.002
    noise_vel: float = 0.02
    placement_error: float = 0.01
    mismatch: float = 0.0
    control_rate: float = 500.0
    region_aware: str = "off"

    def __post_init__(self) -> None:
        if self.region_aware not in REGION_MODES:
            raise InputError("region_aware", self.region_aware, f"one of {', '.join(REGION_MODES)}")
        check_fields(
            self,
            non_negative,
            ("push_max", "noise_pos", "noise_vel", "placement_error", "mismatch"),
        )
        if self.mismatch >= 1.0:
            raise InputError("mismatch", self.mismatch, "a fraction in [0, 1)")
        object.__setattr__(self, "push_duration", positive("push_duration", self.push_duration))
        object.__setattr__(self, "control_rate", positive("control_rate", self.control_rate))

    def options(self, plan: FootstepPlan, seed: int) -> SimOptions:
        """Simulation options of trial ``seed`` for ``plan`` (the push falls inside the walk)."""
        rng = np.random.default_rng([seed, 20251121])
        walk = plan.n_steps * (plan.robot.t_ss + plan.robot.t_ds)
        frac, imp, ang = (
            rng.uniform(0.1, 0.8),
            rng.uniform(0, self.push_max),
            rng.uniform(0, 2 * math.pi),
        )
        scales = rng.uniform(1 - self.mismatch, 1 + self.mismatch, 2)
        push = Push.horizontal(frac * walk, imp, ang, self.push_duration)
        return SimOptions(
            control_rate=self.control_rate,
            noise_pos=self.noise_pos,
            noise_vel=self.noise_vel,
            mass_scale=float(scales[0]),
            com_height_scale=float(scales[1]),
            pushes=(push,) if imp > 0 else (),
            placement_error=self.placement_error,
            seed=seed,
            region_aware=self.region_aware,
        )


def comparison_plan(
    scene: Scene,
    planner: str,
    n_steps: int | None,
    options: PlannerOptions,
    cache: PlanCache | None = None,
) -> FootstepPlan:
    """The plan a comparison walks: :func:`footfall.planning.cache.cached_plan`, except that the
    reactive planner walks until the goal (``n_steps`` is for the horizon planners) and that the
    kinematic planner without ``n_steps`` gets the footstep count of the full-horizon plan (its own
    smallest N ignores the torque the dynamics need): like is compared with like."""
    check_planner_name(planner)
    if planner == "reactive":
        n_steps = None
    elif planner == "kinematic" and n_steps is None:
        full = comparison_plan(scene, "miqcqp", None, options, cache)
        n_steps = full.n_steps if full.has_solution else None
    return cached_plan(scene, planner, n_steps, options, cache=cache)


def run_trial(
    scene_name: str,
    planner: str,
    plan: FootstepPlan,
    spec: TrialSpec,
    seed: int,
    goal: Any,
    regions: Sequence[Region] | None = None,
) -> dict[str, Any]:
    """One seeded trial; returns a CSV row (a fall is a row with ``fell = True``); ``regions``
    (the scene's) add the region metrics and are needed by ``spec.region_aware``."""
    res = simulate(plan, spec.options(plan, seed), goal=goal, regions=regions)
    m = res.metrics.to_dict()
    row: dict[str, Any] = {"scene": scene_name, "planner": planner, "trial": seed}
    row.update({k: m[k] for k in TRIAL_FIELDS})
    opts = spec.options(plan, seed)
    row["push_impulse"] = opts.pushes[0].impulse if opts.pushes else 0.0
    return row


def _mean(vals: list[float]) -> float:
    v = [x for x in vals if x is not None and math.isfinite(x)]
    return float(np.mean(v)) if v else math.nan


def summarise(
    rows: list[dict[str, Any]], plans: dict[tuple[str, str], FootstepPlan]
) -> list[dict[str, Any]]:
    """Aggregate trial rows per (scene, planner) into the table of section 5.5."""
    table = []
    for (scene, planner), plan in plans.items():
        sel = [r for r in rows if r["scene"] == scene and r["planner"] == planner]
        table.append(
            {
                "scene": scene,
                "planner": planner,
                "plan_status": plan.status.value,
                "plan_steps": plan.n_steps,
                "planning_time": plan.solve_time,
                "trials": len(sel),
                "zmp_mean": _mean([r["zmp_offset_mean"] for r in sel]),
                "zmp_max": max(
                    (r["zmp_offset_max"] for r in sel if r["zmp_offset_max"] is not None),
                    default=math.nan,
                ),
                "zmp_max_mean": _mean([r["zmp_offset_max"] for r in sel]),
                "success_rate": _mean([float(r["success"]) for r in sel]),
                "fall_rate": _mean([float(r["fell"]) for r in sel]),
                "stop_rate": _mean([float(r["stopped"]) for r in sel]),
                "goal_error": _mean([r["goal_error"] for r in sel]),
                "message": plan.message,
            }
        )
    return table


def claim_note(table: list[dict[str, Any]]) -> list[str]:
    """Whether the full-horizon planner has the smallest mean single-support ZMP offset, per scene."""
    lines = []
    for scene in dict.fromkeys(r["scene"] for r in table):
        rows = {r["planner"]: r for r in table if r["scene"] == scene and r["trials"] > 0}
        if "miqcqp" not in rows or len(rows) < 2:
            lines.append(f"- {scene}: cannot be judged (no MIQCQP plan or no baseline ran).")
            continue
        ours = rows["miqcqp"]["zmp_mean"]
        others = {p: r["zmp_mean"] for p, r in rows.items() if p != "miqcqp"}
        holds = all(ours < v for v in others.values())
        txt = ", ".join(f"{p} {1000 * v:.2f} mm" for p, v in others.items())
        verdict = "holds" if holds else "does NOT hold"
        lines.append(
            f"- {scene}: the claim {verdict}: mean single-support ZMP offset miqcqp "
            f"{1000 * ours:.2f} mm vs {txt}."
        )
    return lines


def write_outputs(
    out: Path, rows: list[dict[str, Any]], table: list[dict[str, Any]], header: str
) -> list[Path]:
    """Write compare.csv, compare.md and the box plots; return the paths."""
    out.mkdir(parents=True, exist_ok=True)
    csv_path = out / "compare.csv"
    fields = ["scene", "planner", "trial", "push_impulse", *TRIAL_FIELDS]
    with atomic_open(csv_path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for r in sorted(rows, key=lambda r: (r["scene"], r["planner"], r["trial"])):
            w.writerow(r)
    md = [
        "# Planner comparison (document 000, section 5.5)",
        "",
        header,
        "",
        "| scene | planner | plan | steps | planning time [s] | trials | mean ZMP offset [mm] "
        "| mean of max [mm] | max ZMP offset [mm] | success | falls | stopped | goal error [m] |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in table:
        md.append(
            f"| {r['scene']} | {r['planner']} | {r['plan_status']} | {r['plan_steps']} "
            f"| {r['planning_time']:.2f} | {r['trials']} | {1000 * r['zmp_mean']:.2f} "
            f"| {1000 * r['zmp_max_mean']:.2f} | {1000 * r['zmp_max']:.2f} "
            f"| {100 * r['success_rate']:.0f}% | {100 * r['fall_rate']:.0f}% "
            f"| {100 * r['stop_rate']:.0f}% | {r['goal_error']:.3f} |"
        )
    md += ["", "## Document 000's claim", "", *claim_note(table), ""]
    notes = [r for r in table if r["trials"] == 0 or r["message"]]
    if notes:
        md += ["## Plans", ""]
        md += [f"- {r['scene']} / {r['planner']}: {r['message']}" for r in notes]
        md.append("")
    md_path = out / "compare.md"
    write_text(md_path, "\n".join(md))
    from footfall.viz.compare_plots import plot_compare

    figs = plot_compare(rows, out)
    return [csv_path, md_path, *figs]


def run_compare(
    scenes: dict[str, Scene],
    planners: list[str],
    trials: int,
    out: Path,
    spec: TrialSpec,
    workers: int = 1,
    n_steps: int | dict[str, int] | None = None,
    options: PlannerOptions | None = None,
    progress: Callable[[str, int, int], None] | None = None,
) -> tuple[list[dict[str, Any]], list[dict[str, Any]], dict[tuple[str, str], FootstepPlan]]:
    """Plan (cached in ``out/plans``), then run ``trials`` seeded trials per (scene, planner) over
    ``workers`` processes.

    ``n_steps``: footsteps of the horizon planners, for all scenes or per scene name (missing
    scenes: the smallest N with a plan, see :func:`comparison_plan`). ``options``: the planner
    options of every plan.

    Returns:
        ``(rows, table, plans)``.
    """
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor, as_completed

    options = options or PlannerOptions()
    cache = PlanCache(out / "plans")
    plans: dict[tuple[str, str], FootstepPlan] = {}
    for s_name, scene in scenes.items():
        for planner in planners:
            if progress:
                progress(f"planning {s_name} / {planner}", 0, 0)
            n: int | None = n_steps.get(s_name) if isinstance(n_steps, dict) else n_steps
            plans[(s_name, planner)] = comparison_plan(scene, planner, n, options, cache)
    jobs = [
        (s, p, plan, seed)
        for (s, p), plan in plans.items()
        if plan.has_solution and plan.states.shape[0] == plan.n_steps
        for seed in range(trials)
    ]
    rows: list[dict[str, Any]] = []
    if workers <= 1:
        for i, (s, p, plan, seed) in enumerate(jobs):
            sc = scenes[s]
            rows.append(run_trial(s, p, plan, spec, seed, sc.goal.position, sc.terrain.regions))
            if progress:
                progress("trials", i + 1, len(jobs))
    elif jobs:
        # The first trial runs here: it compiles (or loads) the simulation kernel once and leaves it
        # in numba's disk cache, so the workers load it instead of each compiling it at once.
        s0, p0, plan0, seed0 = jobs[0]
        sc0 = scenes[s0]
        rows.append(run_trial(s0, p0, plan0, spec, seed0, sc0.goal.position, sc0.terrain.regions))
        if progress:
            progress("trials", 1, len(jobs))
        # spawn: children import numpy afresh (single-threaded BLAS from the environment)
        with ProcessPoolExecutor(workers, mp_context=mp.get_context("spawn")) as pool:
            futs = [
                pool.submit(run_trial, s, p, plan, spec, seed, scenes[s].goal.position)
                for s, p, plan, seed in jobs[1:]
            ]
            for i, f in enumerate(as_completed(futs)):
                rows.append(f.result())
                if progress:
                    progress("trials", i + 2, len(jobs))
    table = summarise(rows, plans)
    return rows, table, plans


def describe(
    spec: TrialSpec, trials: int, time_limit: float, plans: dict[tuple[str, str], FootstepPlan]
) -> str:
    """One paragraph saying how the trials were disturbed and what each plan was (the header of
    compare.md)."""
    planned = "; ".join(
        f"{s}/{p}: {pl.status.value}, N={pl.n_steps}, {pl.solve_time:.1f} s"
        for (s, p), pl in plans.items()
    )
    return (
        f"{trials} trials per scene and planner; pushes uniform in [0, {spec.push_max:g}] N s "
        f"({spec.push_duration:g} s pulse, random direction, at 10-80 % of the walk), estimate "
        f"noise {spec.noise_pos:g} m / {spec.noise_vel:g} m/s, placement error "
        f"{spec.placement_error:g} m, mismatch {spec.mismatch:g}, control rate "
        f"{spec.control_rate:g} Hz; planner time limit {time_limit:g} s. Plans: {planned}."
    )


def summary_lines(table: list[dict[str, Any]]) -> list[str]:
    """One console line per (scene, planner) of the summary table."""
    return [
        f"{r['scene']:>18} {r['planner']:>9}: mean ZMP {1000 * r['zmp_mean']:.2f} mm, "
        f"max {1000 * r['zmp_max']:.2f} mm, success {100 * r['success_rate']:.0f}% "
        f"({r['trials']} trials)"
        for r in table
    ]
