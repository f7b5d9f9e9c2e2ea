"""Built-in scenes walked by the MuJoCo biped with the miqcqp plan, region-aware or not.

Run (one core; a miqcqp plan is solved once per scene and kept in --cache)::

    OPENBLAS_NUM_THREADS=1 MUJOCO_GL=egl PYTHONPATH=src python benchmarks/bench_region_walks.py \\
        --scenes stepping_stones,discrete_steps --seeds none,0,1,2 --region-aware planned \\
        --cache out/plans --out out/region_walks.jsonl

Each walk is exactly ``footfall walk --scene S --planner miqcqp --no-video`` (the same
``plan_for_walk``, whole-body controller and seeded push), with ``--push 2 --seed K`` (2 N s) for
a seed K and no push for ``none``. One JSON line per walk is appended to --out:
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
from footfall.sim.biped.plans import plan_for_walk, robot_model
from footfall.sim.biped.trial import MujocoBipedPlant
from footfall.sim.disturbance import Disturbance
from footfall.sim.trial import run_trial
from footfall.terrain import builtin_scene

#: the impulse of a seeded walk's push [N s]
PUSH_IMPULSE = 2.0
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
            opts = WalkOptions(controller="wbc", region_aware=args.region_aware)
            plant = MujocoBipedPlant(opts, robot=model)
            push = None if seed == "none" else Disturbance.of_seed(int(seed), impulse=PUSH_IMPULSE)
            t0 = time.perf_counter()
            m = run_trial(plant, scene, plan, push).detail.metrics.to_dict()
            row = {"scene": name, "seed": seed, "region_aware": args.region_aware}
            row |= {k: m[k] for k in KEYS}
            row["region_changes"] = len(m["region_changes"])
            row["wall_s"] = round(time.perf_counter() - t0, 1)
            with args.out.open("a") as f:
                f.write(json.dumps(row) + "\n")
            print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
