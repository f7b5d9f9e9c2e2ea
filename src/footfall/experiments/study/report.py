"""The report of a study: ``summary.md`` (tables and the verdict), ``summary.json``, ``cells.csv``
and the figures, all computed from the rows of ``trials.parquet``."""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from footfall._io import atomic_open, write_json, write_text
from footfall.experiments.study import stats
from footfall.experiments.study.design import StudyDesign
from footfall.experiments.study.runner import PlanEntry


@dataclass(frozen=True)
class Summary:
    """The statistics of a study (:mod:`.stats`): cells, paired comparisons at the default push,
    fragility points, the verdict lines and the error count."""

    cells: list[stats.Cell]
    pairs: list[stats.Paired]
    fragility: list[stats.FragilityPoint]
    verdict: list[str]
    errors: int

    def to_dict(self) -> dict[str, Any]:
        """Plain data (``summary.json``)."""
        return {
            "cells": [asdict(c) | {"success_rate": c.success_rate} for c in self.cells],
            "pairs": [asdict(p) | {"zmp_significant": p.zmp_significant} for p in self.pairs],
            "fragility": [asdict(f) for f in self.fragility],
            "verdict": self.verdict,
            "errors": self.errors,
        }


def summarise(design: StudyDesign, rows: list[dict[str, Any]]) -> Summary:
    """The statistics of ``rows`` (the study's table)."""
    modes = list(design.steps)
    cells = stats.cells(rows, modes)
    n_steps = {(c.scene, c.planner, c.mode): c.n_steps for c in cells}
    pairs = stats.distinct(
        stats.comparisons(rows, design.scenes, modes, design.default_push, design.planners),
        n_steps,
    )
    errors = sum(r["error"] is not None for r in rows)
    return Summary(cells, pairs, stats.fragility(cells), stats.verdict(pairs, n_steps), errors)


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
        if c.impulse != design.default_push:
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


def report_names(design: StudyDesign) -> list[str]:
    """The files :func:`write_report` may write into the study folder."""
    zmp = [f"zmp_{mode}_n.png" for mode in design.steps]
    return ["summary.md", "summary.json", "cells.csv", "fragility.png", *zmp, "paired.png"]


def write_report(
    out: Path,
    design: StudyDesign,
    rows: list[dict[str, Any]],
    plans: list[PlanEntry],
    header: list[str],
) -> tuple[Summary, list[Path]]:
    """Write summary.md, summary.json, cells.csv and the figures into ``out``."""
    from footfall.viz.study_plots import plot_fragility, plot_paired, plot_zmp_distributions

    summary = summarise(design, rows)
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
    paths.append(plot_fragility([asdict(f) for f in summary.fragility], out / "fragility.png"))
    for mode in design.steps:
        paths.append(
            plot_zmp_distributions(rows, design.default_push, mode, out / f"zmp_{mode}_n.png")
        )
    if summary.pairs:
        paths.append(plot_paired([asdict(p) for p in summary.pairs], out / "paired.png"))
    return summary, paths
