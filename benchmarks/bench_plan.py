"""Benchmark of the MIQCQP footstep planner: direct SCIP model vs the fast planner (issue 5).

Usage (from the repository root):

    PYTHONPATH=src python benchmarks/bench_plan.py --steps 6,10,15 --nodes 5,10 --seeds 0,1,2

Prints the markdown table of :func:`footfall.experiments.bench.format_table` and, with ``--json``, writes every
run. Same as ``footfall bench plan``.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from footfall.experiments.bench import bench_plan, format_table, rows_to_dict


def _ints(text: str) -> list[int]:
    return [int(v) for v in text.split(",") if v.strip()]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", default="6,10,15", help="numbers of footsteps N")
    ap.add_argument("--nodes", default="5,10", help="numbers of ALIP nodes K")
    ap.add_argument("--seeds", default="0,1,2", help="random stepping-stone seeds")
    ap.add_argument("--regions", type=int, default=8, help="regions per random scene")
    ap.add_argument("--scenes", default="", help="built-in scenes to add, comma separated")
    ap.add_argument("--time-limit-direct", type=float, default=60.0)
    ap.add_argument("--time-limit-fast", type=float, default=60.0)
    ap.add_argument("--gap", type=float, default=1e-3)
    ap.add_argument("--fast-only", action="store_true", help="skip the direct model")
    ap.add_argument("--fast-threads", type=int, default=2, help="fast planner worker processes")
    ap.add_argument("--json", type=Path, default=None, help="write every run here")
    args = ap.parse_args(argv)

    def progress(run: object) -> None:
        print(run, file=sys.stderr, flush=True)

    rows = bench_plan(
        n_steps=_ints(args.steps),
        n_nodes=_ints(args.nodes),
        seeds=_ints(args.seeds),
        n_regions=args.regions,
        scenes=[s for s in args.scenes.split(",") if s],
        time_limit_direct=args.time_limit_direct,
        time_limit_fast=args.time_limit_fast,
        gap=args.gap,
        direct=not args.fast_only,
        fast_threads=args.fast_threads,
        progress=progress,
    )
    print(format_table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps(rows_to_dict(rows), indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
