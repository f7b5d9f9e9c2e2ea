"""Throughput of ``footfall study``: walks per minute with 1 and 2 local workers and with Ray on 2
workers, the same walks each time, in one run (so the ratios share the machine's state).

    OPENBLAS_NUM_THREADS=1 python benchmarks/bench_study.py --simulator mujoco --seeds 12 \
        --plans out/study55/plans

Each executor walks the same study into its own fresh folder (the plans are copied from
``--plans`` so no executor pays for planning), and the rows are checked equal across executors
(except the wall time). Prints one line per executor and the scaling ratios.
"""

from __future__ import annotations

import argparse
import math
import shutil
import tempfile
import time
from pathlib import Path

from footfall.experiments.study import run_study
from footfall.experiments.study.design import StudyDesign
from footfall.experiments.study.trials import RUN_DEPENDENT


def _comparable(rows: list[dict]) -> list[dict]:
    """Rows without the run-dependent columns, NaN replaced by a marker: NaN != NaN, so a row
    with an unset number (a walk that did not fall has no fall time) never equalled itself."""
    return [
        {
            k: "nan" if isinstance(v, float) and math.isnan(v) else v
            for k, v in r.items()
            if k not in RUN_DEPENDENT
        }
        for r in rows
    ]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--simulator", default="mujoco", choices=("mujoco", "reduced"))
    ap.add_argument("--scene", default="discrete_steps")
    ap.add_argument("--planner", default="miqcqp")
    ap.add_argument("--seeds", type=int, default=12)
    ap.add_argument("--plans", type=Path, default=None, help="folder of cached plans to reuse")
    args = ap.parse_args()
    design = StudyDesign(
        name="throughput",
        simulator=args.simulator,
        controller="wbc" if args.simulator == "mujoco" else None,
        scenes=(args.scene,),
        planners=(args.planner,),
        steps=("smallest",),
        default_push=3.0,
        seeds=args.seeds,
        push_levels=(),
        level_seeds=0,
        time_limit=300.0,  # footfall walk's and section55's: their cached plans serve
    )
    runs = [("local", 1), ("local", 2), ("ray", 2)]
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        for executor, workers in runs:
            out = Path(tmp) / f"{executor}{workers}"
            if args.plans is not None:
                shutil.copytree(args.plans, out / "plans")
            t0 = time.perf_counter()
            run = run_study(design, out, executor, workers)
            total = time.perf_counter() - t0
            rate = 60.0 * run.ran / run.wall_time
            results[(executor, workers)] = (rate, run.rows)
            print(
                f"{executor:>5} x{workers}: {run.ran} walks in {run.wall_time:6.1f} s "
                f"({rate:5.1f} walks/min; {total:.1f} s with start-up and planning)"
            )
    base_rate, base_rows = results[("local", 1)]
    for key, (rate, rows) in results.items():
        same = _comparable(rows) == _comparable(base_rows)
        print(
            f"{key[0]} x{key[1]}: {rate / base_rate:.2f}x local x1; rows equal to local x1: {same}"
        )


if __name__ == "__main__":
    main()
