"""Speed of the MuJoCo biped walk: simulated seconds per wall second, and time shares, per controller.

Run (one core)::

    OPENBLAS_NUM_THREADS=1 PYTHONPATH=src taskset -c 0 python benchmarks/bench_walk.py \\
        --scene flat_long --steps 20 --robot biped --controllers servo,wbc --repeats 3 --cache out/plans

The controllers walk the same plan alternately (servo, wbc, servo, wbc, ...) so that both see the
same machine load; the table gives each one's median real-time factor over the repeats and the
ratio wbc / servo measured in this run, and the time shares of the last repeat: control
(measurement, adjuster, references), the whole body (``servo``: mink IK; ``wbc``: MuJoCo's model
terms and the tasks, then the QP) and the physics. No video; planning is not timed (pass a cache
folder so that a miqcqp plan is solved once).
"""

from __future__ import annotations

import argparse
import os
import statistics
from pathlib import Path

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.plans import plan_for_walk, robot_model
from footfall.sim.biped.walk import walk
from footfall.terrain import builtin_scene


def main() -> None:
    """Plan (or load), walk each controller ``--repeats`` times, print the table."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", default="flat_long")
    ap.add_argument("--steps", type=int, default=20)
    ap.add_argument("--planner", default="miqcqp")
    ap.add_argument("--robot", default="biped")
    ap.add_argument("--controllers", default="servo,wbc")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cache", type=Path, default=None)
    a = ap.parse_args()
    model = robot_model(a.robot)
    scene = builtin_scene(a.scene)
    plan = plan_for_walk(scene, a.planner, a.steps, cache_dir=a.cache, model=model)
    controllers = a.controllers.split(",")
    rtf: dict[str, list[float]] = {c: [] for c in controllers}
    last = {}
    for _ in range(a.repeats):
        for c in controllers:
            res = walk(scene, plan, WalkOptions(controller=c), model_params=model)
            tm = res.trace.timing
            loop = tm["total"] - tm["render"]
            rtf[c].append(res.trace.sim_time / loop)
            last[c] = (res, loop)
    print(f"{a.robot} on {a.scene}, {a.planner} N = {plan.n_steps}, {a.repeats} repeats")
    print("| controller | real-time factor (median, min-max) | fell | shares of the loop |")
    print("|---|---|---|---|")
    for c in controllers:
        res, loop = last[c]
        shares = ", ".join(
            f"{k} {100 * v / loop:.0f} %"
            for k, v in res.trace.timing.items()
            if k not in ("total", "render")
        )
        med = statistics.median(rtf[c])
        print(
            f"| {c} | {med:.1f}x ({min(rtf[c]):.1f}-{max(rtf[c]):.1f}) | {res.trace.fell} | {shares} |"
        )
    if "servo" in rtf and "wbc" in rtf:
        ratio = statistics.median(w / s for w, s in zip(rtf["wbc"], rtf["servo"], strict=True))
        print(f"\nwbc / servo real-time factor, same run: {ratio:.2f}")


if __name__ == "__main__":
    main()
