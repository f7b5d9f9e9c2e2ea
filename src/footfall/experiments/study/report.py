"""The report of a study: ``summary.md`` (tables and the verdict), ``summary.json``, ``cells.csv``
and the figures, all computed from the rows of ``trials.parquet``."""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from footfall._io import atomic_open, write_json, write_text
from footfall.experiments.study import stats, terrain_stats
from footfall.experiments.study.design import StudyDesign
from footfall.experiments.study.runner import PlanEntry, design_families, terrain_family


@dataclass(frozen=True)
class Summary:
    """The statistics of a study (:mod:`.stats`): cells, paired comparisons at the default push,
    fragility points, the verdict lines and the error count."""

    cells: list[stats.Cell]
    pairs: list[stats.Paired]
    fragility: list[stats.FragilityPoint]
    verdict: list[str]
    errors: int
    terrain_pairs: list[terrain_stats.TerrainPaired] = field(default_factory=list)
    family_verdict: list[str] = field(default_factory=list)
    family_cells: list[terrain_stats.FamilyCell] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        """Plain data (``summary.json``)."""
        return {
            "cells": [asdict(c) | {"success_rate": c.success_rate} for c in self.cells],
            "pairs": [asdict(p) | {"zmp_significant": p.zmp_significant} for p in self.pairs],
            "fragility": [asdict(f) for f in self.fragility],
            "verdict": self.verdict,
            "terrain_pairs": [
                asdict(p)
                | {"significant": p.significant, "proven_significant": p.proven_significant}
                for p in self.terrain_pairs
            ],
            "family_verdict": self.family_verdict,
            "family_cells": [asdict(c) for c in self.family_cells],
            "errors": self.errors,
        }


def plan_infos(plans: list[PlanEntry]) -> dict[tuple[str, str, str], terrain_stats.PlanInfo]:
    """Status and N of each plan by (scene, planner, mode)."""
    return {
        (p.scene, p.planner, p.mode): terrain_stats.plan_info(
            p.planner, p.plan.status.value, p.plan.has_solution, p.plan.n_steps
        )
        for p in plans
    }


def summarise(
    design: StudyDesign, rows: list[dict[str, Any]], plans: list[PlanEntry] | None = None
) -> Summary:
    """The statistics of ``rows`` (the study's table): per named scene, and with the terrain as
    the unit per terrain family (:mod:`.terrain_stats`; needs ``plans`` to mark time-limited
    plans)."""
    modes = list(design.steps)
    generated = terrain_family(design)
    cells = stats.cells(rows, modes)
    named_cells = [c for c in cells if c.scene not in generated]
    n_steps = {(c.scene, c.planner, c.mode): c.n_steps for c in named_cells}
    pairs = stats.distinct(
        stats.comparisons(rows, design.scenes, modes, design.default_push, design.planners),
        n_steps,
    )
    errors = sum(r["error"] is not None for r in rows)
    families = design_families(design)
    terrain_pairs = terrain_stats.family_comparisons(
        rows, families, plan_infos(plans or []), modes, design.default_push, design.planners
    )
    return Summary(
        cells,
        pairs,
        stats.fragility(named_cells),
        stats.verdict(pairs, n_steps),
        errors,
        terrain_pairs,
        terrain_stats.family_verdict(terrain_pairs, {f: len(t) for f, t in families.items()}),
        terrain_stats.family_cells(rows, families, modes, design.default_push, design.planners),
    )


def _mm(x: float) -> str:
    return "-" if x != x else f"{1000 * x:.2f}"


def _pct(k: int, n: int, lo: float, hi: float) -> str:
    if n == 0:
        return "-"
    return f"{100 * k / n:.0f} % ({100 * lo:.0f}-{100 * hi:.0f})"


def markdown(
    design: StudyDesign,
    summary: Summary,
    plans: list[PlanEntry],
    rows: int,
    header: list[str],
) -> str:
    """``summary.md``: the study, its plans, the default-push table, the verdict, fragility."""
    md = [f"# Study {design.name} (document 000, section 5.5)", "", *header, ""]
    generated = terrain_family(design)
    if design.families:
        md += family_markdown(design, summary, plans)
    if not design.scenes:
        md += [f"{rows} walks in the table; {summary.errors} raised an error (left out above).", ""]
        return "\n".join(md)
    plans = [p for p in plans if p.scene not in generated]
    md += [
        "## Plans",
        "",
        "A plan stopped by the time limit is the best found, not a proven optimum: its gap "
        "(relative, incumbent vs bound) says how far from optimal it may be.",
        "",
        "| scene | planner | N mode | status | N | objective | gap | solve time [s] |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for p in plans:
        ok = p.plan.has_solution
        n = p.plan.n_steps if ok else "-"
        obj = f"{p.plan.objective:.4g}" if ok and p.plan.objective == p.plan.objective else "-"
        gap = f"{p.plan.gap:.2%}" if ok and p.plan.gap < float("inf") else "-"
        md.append(
            f"| {p.scene} | {p.planner} | {p.mode} | {p.plan.status.value} | {n} | {obj} | {gap} "
            f"| {p.plan.solve_time:.1f} |"
        )
    md += [
        "",
        f"## At the default push ({design.default_push:g} N s)",
        "",
        "Success with its Wilson 95 % interval; the ZMP offset (mean single-support CoP offset from "
        "the sole centre, document 000's metric) over the successful walks, with its bootstrap 95 % CI.",
        "",
        "| scene | N mode | planner | N | walks | success | mean ZMP offset [mm] (95 % CI) | mean of max [mm] | footstep error [mm] |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for c in summary.cells:
        if c.impulse != design.default_push or c.scene in generated:
            continue
        md.append(
            f"| {c.scene} | {c.mode} | {c.planner} | {c.n_steps} | {c.walks} "
            f"| {_pct(c.successes, c.walks, c.success_lo, c.success_hi)} "
            f"| {_mm(c.zmp_mean)} ({_mm(c.zmp_lo)}-{_mm(c.zmp_hi)}) | {_mm(c.zmp_max_mean)} "
            f"| {_mm(c.footstep_error)} |"
        )
    md += ["", "## Verdict on document 000's claim", ""]
    md += summary.verdict or ["- cannot be judged: the study has no miqcqp walks or no baseline."]
    md += [
        "",
        "Paired over seeds (same push, same initial perturbation); differences are "
        f"{stats.CLAIMANT} minus the baseline, negative = {stats.CLAIMANT} lower; significant = "
        f"Wilcoxon p < {stats.ALPHA} and the CI excludes 0.",
        "",
        "## Fragility (success against push impulse)",
        "",
        "| scene | planner | N mode | "
        + " | ".join(f"{x:g} N s" for x in sorted(design.impulses()))
        + " |",
        "|---|---|---|" + "---|" * len(design.impulses()),
    ]
    groups = dict.fromkeys((f.scene, f.planner, f.mode) for f in summary.fragility)
    for g in groups:
        by = {f.impulse: f for f in summary.fragility if (f.scene, f.planner, f.mode) == g}
        cols = [
            _pct(by[x].successes, by[x].walks, by[x].lo, by[x].hi) + f" n={by[x].walks}"
            if x in by
            else "-"
            for x in sorted(design.impulses())
        ]
        md.append(f"| {g[0]} | {g[1]} | {g[2]} | " + " | ".join(cols) + " |")
    md += ["", f"{rows} walks in the table; {summary.errors} raised an error (left out above).", ""]
    failed = [p for p in plans if not p.plan.has_solution]
    if failed:
        md += ["## Plans without a solution (no walks)", ""]
        md += [f"- {p.scene} / {p.planner} ({p.mode}): {p.plan.message}" for p in failed]
        md.append("")
    return "\n".join(md)


def _ci_mm(x: float, lo: float, hi: float) -> str:
    """``x (lo to hi)`` in mm; the interval left out where it is undefined (fewer than 2)."""
    return _mm(x) if lo != lo else f"{_mm(x)} ({_mm(lo)} to {_mm(hi)})"


def family_markdown(design: StudyDesign, summary: Summary, plans: list[PlanEntry]) -> list[str]:
    """The family sections of ``summary.md``: ranges, plan outcomes, cells and the paired
    comparisons with the terrain as the unit, and their verdict."""
    from footfall.terrain.families import ranges_dict

    families = design_families(design)
    seeds = design.seeds_at(design.default_push)
    md = [
        "## Across terrain: the terrain is the unit",
        "",
        f"{design.terrains} terrains per family (family seeds {design.terrain_start}-"
        f"{design.terrain_start + design.terrains - 1}; scene files in `terrains/`), "
        f"{len(seeds)} pushed seeds per terrain at {design.default_push:g} N s. Every mean, "
        "CI and test below treats the terrain as the sample: per-terrain means, a cluster "
        "bootstrap over terrains (BCa, 4000 resamples) and a Wilcoxon signed-rank test over "
        "terrains. Ranges drawn uniformly (footfall.terrain.families):",
        "",
    ]
    for f in design.families:
        rng = ", ".join(f"{k} {v}" for k, v in ranges_dict(f).items())
        md.append(f"- {f}: {rng} [m, deg].")
    md += [
        "",
        "### Plans",
        "",
        "Proven: the optimum within the gap (the reactive planner claims no optimality and "
        "counts as proven when it reached the goal; one that stopped short is no plan). "
        "Time-limited: a plan the planner stopped before it proved it optimal (its time limit), "
        "with its gap; such a terrain is marked in every comparison.",
        "",
        "| family | planner | N mode | terrains | proven | time-limited | no plan | median N "
        "| median solve time [s] | median gap of the time-limited |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for fp in terrain_stats.family_plans(plans, families):
        gap = "-" if fp.gap_median != fp.gap_median else f"{fp.gap_median:.1%}"
        n = "-" if fp.n_median != fp.n_median else f"{fp.n_median:g}"
        md.append(
            f"| {fp.family} | {fp.planner} | {fp.mode} | {fp.terrains} | {fp.optimal} "
            f"| {fp.time_limited} | {fp.no_plan} | {n} | {fp.time_median:.1f} | {gap} |"
        )
    md += [
        "",
        f"### Walks at the default push ({design.default_push:g} N s)",
        "",
        "Means over terrains of each terrain's success rate and of its mean ZMP offset "
        "(successful walks), with cluster-bootstrap 95 % CIs.",
        "",
        "| family | N mode | planner | terrains | walks | success [%] (95 % CI) "
        "| mean ZMP offset [mm] (95 % CI) |",
        "|---|---|---|---|---|---|---|",
    ]
    for c in summary.family_cells:
        succ = "-" if c.success != c.success else f"{100 * c.success:.0f}"
        if c.success_lo == c.success_lo:
            succ += f" ({100 * c.success_lo:.0f}-{100 * c.success_hi:.0f})"
        md.append(
            f"| {c.family} | {c.mode} | {c.planner} | {c.terrains} | {c.walks} | {succ} "
            f"| {_ci_mm(c.zmp, c.zmp_lo, c.zmp_hi)} |"
        )
    md += [
        "",
        "### Paired comparisons",
        "",
        f"{stats.CLAIMANT} minus the baseline on the same terrain and seed, averaged per "
        "terrain, then over terrains; negative = "
        f"{stats.CLAIMANT} lower. Proven: the same on the terrains where both plans are "
        "proven. Success: terrains where the planner's success rate is higher / lower (sign "
        "test). SD between / within: the random-effects split of the seed differences into "
        "terrain and seed.",
        "",
        "| family | N mode | vs | terrains (pairs) | difference [mm] (95 % CI) | p "
        "| time-limited terrains | proven: terrains, difference [mm] (95 % CI) | N differs "
        "| success higher / lower (p) | SD between / within [mm], terrain share |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for p in summary.terrain_pairs:
        icc = "-" if p.icc != p.icc else f"{p.icc:.0%}"
        md.append(
            f"| {p.family} | {p.mode} | {p.baseline} | {p.terrains} ({p.pairs}) "
            f"| {_ci_mm(p.diff, p.lo, p.hi)} | {p.p:.2g} | {p.time_limited} "
            f"| {p.proven_terrains}, {_ci_mm(p.proven_diff, p.proven_lo, p.proven_hi)} "
            f"| {p.unequal_n} | {p.terrains_better} / {p.terrains_worse} ({p.success_p:.2g}) "
            f"| {_mm(p.sd_between)} / {_mm(p.sd_within)}, {icc} |"
        )
    md += ["", "### Verdict across terrain", ""]
    md += summary.family_verdict or ["- cannot be judged: the study has no miqcqp walks."]
    md += [
        "",
        "Significant = Wilcoxon p < 0.05 over terrains and the CI excludes 0; not "
        "significant is a result too. Each line is one population of terrains and one pair "
        "of plans per terrain; the two N modes are two questions (a terrain where both modes "
        "have the same plans is in both).",
        "",
    ]
    return md


def report_names(design: StudyDesign) -> list[str]:
    """The files :func:`write_report` may write into the study folder."""
    zmp = [f"zmp_{mode}_n.png" for mode in design.steps]
    return [
        "summary.md",
        "summary.json",
        "cells.csv",
        "fragility.png",
        *zmp,
        "paired.png",
        "terrain_paired.png",
    ]


def write_report(
    out: Path,
    design: StudyDesign,
    rows: list[dict[str, Any]],
    plans: list[PlanEntry],
    header: list[str],
) -> tuple[Summary, list[Path]]:
    """Write summary.md, summary.json, cells.csv and the figures into ``out``."""
    from footfall.viz.study_plots import (
        plot_fragility,
        plot_paired,
        plot_terrain_paired,
        plot_zmp_distributions,
    )

    summary = summarise(design, rows, plans)
    out = Path(out)
    paths = [out / "summary.md"]
    write_text(paths[0], markdown(design, summary, plans, len(rows), header))
    paths.append(
        write_json(
            out / "summary.json",
            {
                "design": design.to_dict(),
                "plans": [p.to_dict() for p in plans],
                **summary.to_dict(),
            },
        )
    )
    cells_csv = out / "cells.csv"
    with atomic_open(cells_csv, "w", newline="") as fh:
        fields = [*stats.Cell.__dataclass_fields__, "success_rate"]
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for c in summary.cells:
            w.writerow(asdict(c) | {"success_rate": c.success_rate})
    paths.append(cells_csv)
    if summary.terrain_pairs:
        paths.append(
            plot_terrain_paired(
                [asdict(p) for p in summary.terrain_pairs], out / "terrain_paired.png"
            )
        )
    if not design.scenes:  # a study of terrain families only: the per-scene figures would
        return summary, paths  # hold a panel per terrain
    generated = terrain_family(design)
    named = [r for r in rows if r["scene"] not in generated]
    paths.append(plot_fragility([asdict(f) for f in summary.fragility], out / "fragility.png"))
    for mode in design.steps:
        paths.append(
            plot_zmp_distributions(named, design.default_push, mode, out / f"zmp_{mode}_n.png")
        )
    if summary.pairs:
        paths.append(plot_paired([asdict(p) for p in summary.pairs], out / "paired.png"))
    return summary, paths
