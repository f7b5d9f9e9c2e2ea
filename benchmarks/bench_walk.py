"""Speed of the MuJoCo biped walk (issue 7): simulated seconds per wall second, and time shares.

Run: ``PYTHONPATH=src python benchmarks/bench_walk.py [scene] [planner]`` (default: flat reactive).
No video. Planning is timed separately (its share of the whole pipeline is reported too); for
miqcqp, pass a cache folder as the third argument so the plan is solved once.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from footfall.sim.biped.plans import plan_for_walk
from footfall.sim.biped.walk import walk
from footfall.terrain import builtin_scene


def main() -> None:
    """Plan, walk, print the speed table."""
    scene_name = sys.argv[1] if len(sys.argv) > 1 else "flat"
    planner = sys.argv[2] if len(sys.argv) > 2 else "reactive"
    cache = Path(sys.argv[3]) if len(sys.argv) > 3 else None
    scene = builtin_scene(scene_name)
    t0 = time.perf_counter()
    plan = plan_for_walk(scene, planner, cache_dir=cache)
    t_plan = time.perf_counter() - t0
    res = walk(scene, plan)
    tm = res.timing
    loop = tm["control"] + tm["ik"] + tm["physics"]
    total = t_plan + loop
    print(f"scene {scene_name}, planner {planner}: {plan.n_steps} steps, fell={res.fell}")
    print(f"simulated {res.sim_time:.2f} s in {loop:.2f} s wall (no video)")
    print(f"real-time factor (simulated s per wall s): {res.sim_time / loop:.2f}")
    for name, value in (
        ("planning", t_plan),
        ("control (measure, adjuster, references)", tm["control"]),
        ("whole-body IK (mink QP, daqp)", tm["ik"]),
        ("MuJoCo physics", tm["physics"]),
    ):
        print(f"  {name:42s} {value:7.3f} s  {100 * value / total:5.1f} %")


if __name__ == "__main__":
    main()
