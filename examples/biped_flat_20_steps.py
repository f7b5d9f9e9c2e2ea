"""Issue 7 must-show: the MuJoCo biped walks 20 steps of 0.2 m on flat ground.

The plan comes from the reactive ALIP planner with its nominal speed set to 0.4 m/s, i.e. 0.2 m
per step at T_ss + T_ds = 0.5 s, on a long flat region with the goal 4.0 m ahead.
Run: ``PYTHONPATH=src python examples/biped_flat_20_steps.py [out_dir]``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

import footfall.planning.reactive as reactive
from footfall.planning import make_plan
from footfall.sim.biped_model import planner_params
from footfall.sim.biped_plot import plot_walk
from footfall.sim.biped_walk import walk
from footfall.terrain import Goal, Region, Scene, Start, Terrain

#: step length [m] and the walking speed that gives it at 0.5 s per step
STEP = 0.2
SPEED = 0.4
N_STEPS = 20


def main() -> None:
    """Plan, walk, write walk_flat20.json and .png."""
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("out/biped_flat20")
    ground = Region.from_height("ground", 0.0, [[-1.0, -1.5], [6.0, -1.5], [6.0, 1.5], [-1.0, 1.5]])
    robot = planner_params()
    scene = Scene(
        name="flat_long",
        description="flat ground, goal 4 m ahead",
        robot=robot,
        terrain=Terrain((ground,)),
        start=Start(np.array([0.0, 0.1, 0.0]), np.array([0.0, -0.1, 0.0]), 0.0, "right"),
        goal=Goal(np.array([STEP * N_STEPS, 0.0, 0.0]), 0.0),
    )
    reactive.NOMINAL_SPEED = SPEED  # the reactive planner's only speed knob is this constant
    plan = make_plan(scene, "reactive", 60, robot=robot)
    steps = np.diff(plan.footsteps[:, 0])
    res = walk(scene, plan)
    m = res.metrics
    out.mkdir(parents=True, exist_ok=True)
    summary = {
        "n_steps": plan.n_steps,
        "mean_step_m": float(np.mean(steps)),
        "fell": m["fell"],
        "fall_time_s": m["fall_time_s"],
        "steps_landed": m["steps_landed"],
        "reached_goal": m["reached_goal"],
        "footstep_error_m": m["footstep_error_m"],
        "footstep_error_vs_target_m": m["footstep_error_vs_target_m"],
        "zmp": m["zmp"],
    }
    (out / "walk_flat20.json").write_text(json.dumps(summary, indent=2, default=float))
    plot_walk(res, scene, out / "walk_flat20.png", title="flat, 0.2 m steps")
    print(json.dumps(summary, indent=1, default=float))


if __name__ == "__main__":
    main()
