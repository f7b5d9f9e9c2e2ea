"""``footfall study``: the section 5.5 study of document 000 as a declared, resumable experiment."""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import typer

from footfall._io import write_text
from footfall.cli._common import app, console, output_folder, refuse_inputs_as_outputs
from footfall.errors import FootfallError, InputError

if TYPE_CHECKING:
    from footfall.experiments.study.design import StudyDesign

#: least time between two progress lines without a terminal [s]
LOG_PERIOD = 5.0


@app.command("study")
def study_command(
    study_file: Path | None = typer.Argument(
        None,
        help="Study YAML file (see footfall/experiments/study/section55.yaml).",
        metavar="[STUDY]",
    ),
    builtin: str | None = typer.Option(
        None,
        help="A built-in study instead of a file: section55 (the final MuJoCo study), "
        "section55_reduced (the same grid in the reduced-order loop), section55_terrain "
        "(100 generated terrains per family, the terrain as the unit) or quick.",
    ),
    quick: bool = typer.Option(False, "--quick", help="The tiny built-in study (about a minute)."),
    out: Path = typer.Option(Path("out/study"), help="Output folder (reruns resume it)."),
    executor: str = typer.Option("local", help="local (process pool) or ray."),
    workers: int | None = typer.Option(
        None, help="Parallel walks (default: the cores this process may use)."
    ),
    address: str | None = typer.Option(
        None, help="--executor ray: address of an existing Ray cluster (default: start one here)."
    ),
    limit: int | None = typer.Option(
        None, help="Run at most this many new walks, then write the report of what is done."
    ),
    quiet: bool = typer.Option(False, "--quiet", help="No progress lines."),
) -> None:
    """Walk a study's grid of scenes x planners x N x push levels x seeds; write trials.parquet
    (one row per walk, resumable), summary.md (CIs, paired tests, verdict) and figures.

    Exit 1 when a walk raised an error (its row says which and why) or a plan is missing."""
    from footfall.experiments.study import builtin_study, load_study

    chosen = [x for x in (study_file is not None, builtin is not None, quick) if x]
    if len(chosen) != 1:
        raise InputError(
            "study", "none" if not chosen else "several", "one of STUDY, --builtin NAME, --quick"
        )
    design = (
        load_study(study_file)
        if study_file is not None
        else builtin_study("quick" if quick else str(builtin))
    )
    run_design(design, out, executor, workers, address, limit, quiet, inputs=[study_file])


def run_design(
    design: StudyDesign,
    out: Path,
    executor: str,
    workers: int | None,
    address: str | None,
    limit: int | None,
    quiet: bool,
    inputs: Sequence[Path | None] = (),
) -> None:
    """Run ``design`` into ``out`` with progress lines, write the report and say the verdict
    (``footfall study`` and its presets, such as ``footfall compare``). ``inputs``: the files
    the command read besides the design's scene and robot files (the study file); none of them
    may be an output."""
    from footfall.experiments.study import run_study, write_report
    from footfall.planning.plan import available_cores

    if workers is None:
        workers = available_cores()
    if limit is not None and limit < 0:
        raise InputError("--limit", limit, "an integer >= 0")
    from footfall.experiments.study.report import report_names
    from footfall.experiments.study.store import META, TABLE

    names = [TABLE, META, "run.json", *report_names(design)]
    read = [*inputs, *design.scenes, design.robot]
    refuse_inputs_as_outputs(read, {"out": [out / name for name in names]})
    output_folder(out)
    # small matrices run fastest single-threaded; spawned workers and Ray workers read this
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    terminal = console.is_terminal and not quiet
    say = None if quiet else (lambda line: console.print(line))
    logged = [-math.inf]
    t0 = time.perf_counter()

    def progress(done: int, total: int, row: dict[str, Any]) -> None:
        now = time.perf_counter()
        if quiet or (not terminal and now - logged[0] < LOG_PERIOD and done < total):
            return
        logged[0] = now
        ok = "error" if row["error"] else ("ok" if row["success"] else "failed")
        line = f"{done}/{total} walks, {now - t0:.0f} s: last {row['key']} {ok}"
        if terminal:
            console.print(line, end="\r")
        else:
            console.print(line)

    started = time.perf_counter()
    from footfall.cli._progress import ProgressLog

    run = run_study(
        design,
        out,
        executor,
        workers,
        address,
        say,
        progress,
        limit,
        monitor_for=lambda title: ProgressLog(title, quiet),
        # a study of terrain families has many scenes: plan them in parallel too
        plan_workers=workers if design.families else 1,
    )
    if terminal:
        console.print()
    header = [
        f"Simulator {design.simulator}"
        + (f" ({design.controller} controller)" if design.controller else "")
        + f"; {len(design.scenes)} scenes"
        + "".join(
            f" + {design.terrains} {f} terrains (family seeds {design.terrain_start}-"
            f"{design.terrain_start + design.terrains - 1})"
            for f in design.families
        )
        + f" x {len(design.planners)} planners; step modes "
        f"{', '.join(design.steps)}; default push {design.default_push:g} N s "
        f"({design.push_duration:g} s pulse) on seeds {design.seed_start}-"
        f"{design.seed_start + design.seeds - 1}; "
        + (
            f"push levels {', '.join(f'{x:g}' for x in design.push_levels)} N s on "
            f"{design.level_seeds} seeds ({', '.join(design.level_steps or ())} N); "
            if design.push_levels
            else "no other push levels; "
        )
        + f"initial perturbation "
        f"{design.initial_impulse:g} N s.",
        "",
        f"Command: `footfall {' '.join(sys.argv[1:])}`. This run: {run.ran} new walks in "
        f"{run.wall_time:.0f} s ({executor}, {workers} worker{'s' if workers != 1 else ''}"
        + (
            f", {60 * run.ran / run.wall_time:.1f} walks/min"
            if run.ran and run.wall_time > 0
            else ""
        )
        + f"); the table holds {len(run.rows)} of the study's {run.trials} walks.",
    ]
    summary, paths = write_report(out, design, run.rows, run.plans, header)
    for line in summary.verdict:
        console.print(line)
    write_text(
        out / "run.json",
        json.dumps(
            {
                "executor": executor,
                "workers": workers,
                "ran": run.ran,
                "wall_time": run.wall_time,
                "total_time": time.perf_counter() - started,
                "walks": run.trials,
                "rows": len(run.rows),
            },
            indent=1,
        ),
    )
    console.print(f"wrote {out / 'trials.parquet'}, " + ", ".join(str(p) for p in paths))
    # a generated terrain a planner finds no plan for is a result of the study (its report
    # counts it per family and planner), a named scene's missing plan is a failed run
    from footfall.experiments.study.runner import terrain_family

    generated = terrain_family(design)
    missing = [p for p in run.plans if not p.plan.has_solution and p.scene not in generated]
    if summary.errors or missing:
        raise FootfallError(
            f"{summary.errors} walk(s) raised an error and {len(missing)} plan(s) failed "
            f"(see {out / 'summary.md'})"
        )
    if len(run.rows) < run.trials:
        console.print(
            f"{run.trials - len(run.rows)} walks still to run: rerun the same command to resume"
        )
