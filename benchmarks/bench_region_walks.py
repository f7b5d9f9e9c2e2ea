"""Built-in scenes walked by the MuJoCo biped with the miqcqp plan, region-aware or not (issue 23).

Run (one core; a miqcqp plan is solved once per scene and kept in --cache)::

    OPENBLAS_NUM_THREADS=1 MUJOCO_GL=egl PYTHONPATH=src python benchmarks/bench_region_walks.py \\
        --scenes stepping_stones,discrete_steps --seeds none,0,1,2 --region-aware planned \\
        --cache out/plans --out out/region_walks.jsonl

Each walk is exactly ``footfall walk --scene S --planner miqcqp --no-video`` (the same
``plan_for_walk``, whole-body controller and seeded push), with ``--push 20 --seed K`` for a seed
K (20 N for 0.1 s: 2 N s) and no push for ``none``. One JSON line per walk is appended to --out:
fell, fall time, goal reached, footsteps landed off every region, correction sizes and region
changes (:class:`~footfall.sim.biped.metrics.WalkMetrics`).
"""

from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.plans import plan_for_walk, random_push, robot_model
from footfall.sim.biped.walk import walk
from footfall.terrain import builtin_scene

#: the push of a seeded walk [N] over PUSH_DURATION = 0.1 s: 2 N s
PUSH_N = 20.0
KEYS = ("fell", "fall_time_s", "reached_goal", "footsteps_off_regions", "correction_m")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--scenes", required=True)
    ap.add_argument("--seeds", default="none")
    ap.add_argument("--region-aware", default="planned")
    ap.add_argument("--cache", type=Path, default=Path("out/plans"))
    ap.add_argument("--out", type=Path, default=Path("out/region_walks.jsonl"))
    args = ap.parse_args()
    model = robot_model("biped")
    for name in args.scenes.split(","):
        scene = builtin_scene(name)
        plan = plan_for_walk(scene, "miqcqp", None, 300.0, args.cache, model=model)
        for seed in args.seeds.split(","):
            base = WalkOptions(controller="wbc", region_aware=args.region_aware)
            pushes = () if seed == "none" else (random_push(int(seed), PUSH_N, plan, base),)
            opts = WalkOptions(controller="wbc", region_aware=args.region_aware, pushes=pushes)
            t0 = time.perf_counter()
            m = walk(scene, plan, opts, model_params=model).metrics.to_dict()
            row = {"scene": name, "seed": seed, "region_aware": args.region_aware}
            row |= {k: m[k] for k in KEYS}
            row["region_changes"] = len(m["region_changes"])
            row["wall_s"] = round(time.perf_counter() - t0, 1)
            with args.out.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
