"""Issue 7 must-show: the MuJoCo biped walks 20 steps of 0.2 m on flat ground.

The built-in ``flat_long`` scene puts the goal 4 m ahead; with N = 20 the MIQCQP planner
(document 000) spaces the footsteps 0.2 m apart, and the walker follows them with the MPC of
eq. (5.19) in the loop. The same as ``footfall walk --scene flat_long --steps 20 --out DIR``.
Run: ``PYTHONPATH=src python examples/biped_flat_20_steps.py [out_dir]``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from footfall.planning import make_plan
from footfall.sim.biped.model import planner_params
from footfall.sim.biped.walk import walk
from footfall.terrain import builtin_scene
from footfall.viz.walk_plot import plot_walk

N_STEPS = 20


def main() -> None:
    """Plan, walk, write walk_flat20.json and .png."""
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/biped_flat20")
    scene = builtin_scene("flat_long")
    plan = make_plan(scene, "miqcqp", N_STEPS, robot=planner_params(base=scene.robot))
    steps = np.diff(plan.footsteps[:, 0])
    res = walk(scene, plan)
    m = res.metrics
    out.mkdir(parents=True, exist_ok=True)
    summary = {
        "n_steps": plan.n_steps,
        "mean_step_m": float(np.mean(steps)),
        "fell": m.fell,
        "fall_time_s": m.fall_time_s,
        "steps_landed": m.steps_landed,
        "reached_goal": m.reached_goal,
        "footstep_error_m": m.footstep_error_m.to_dict(),
        "footstep_error_vs_target_m": m.footstep_error_vs_target_m.to_dict(),
        "zmp": m.zmp.to_dict(),
    }
    (out / "walk_flat20.json").write_text(json.dumps(summary, indent=2, default=float))
    plot_walk(res, scene, out / "walk_flat20.png", title="flat, 20 x 0.2 m, MIQCQP + MPC")
    print(json.dumps(summary, indent=1, default=float))


if __name__ == "__main__":
    main()
