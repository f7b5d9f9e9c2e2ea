"""The ``footfall demo`` pipeline: each capability on its built-in default, into one folder.

1. The four LIP walks of document 004.
2. The full-horizon MIQCQP footstep plan of document 000 on the built-in ``discrete_steps`` scene
   (document fig. 5.5; smallest feasible N, fast exact solver), with the kinematic (same N) and
   reactive baselines, each checked by the independent checker.
3. The MIQCQP plan walked in closed loop by the MPC (eq. 5.19) on the reduced-order plant with a
   10 N s sideways push.
4. The document-001 quadruped walking up a 15 degree slope in MuJoCo (when the ``[sim]`` extra is
   installed).
"""

from __future__ import annotations

import importlib.util
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

from footfall._io import write_json
from footfall.planning.lip_examples import EXAMPLES
from footfall.planning.lip_io import lip_walk_to_dict
from footfall.planning.lip_walk import lip_walk

#: the demo scene (document 000 fig. 5.5)
DEMO_SCENE = "discrete_steps"


def _lip(out: Path, lines: list[str]) -> dict[str, Any]:
    from footfall.viz.lip_plot import plot_lip_walk

    summary: dict[str, Any] = {}
    for name, make in EXAMPLES.items():
        walk = lip_walk(make())
        folder = out / "lip" / name
        write_json(folder / "lip_walk.json", lip_walk_to_dict(walk))
        plot_lip_walk(walk, folder / "lip_walk.png", title=f"LIP walk: {name} (document 004)")
        speed = math.hypot(*walk.final_vel)
        summary[name] = {"steps": int(walk.footholds.shape[0]), "final_speed_mps": speed}
        lines.append(
            f"LIP {name:9s}: {walk.footholds.shape[0]:2d} steps, final speed {speed:.4f} m/s"
        )
    return summary


def _plans(out: Path, lines: list[str]) -> dict[str, Any]:
    from footfall.planning import PlannerOptions, check_plan, make_plan
    from footfall.terrain import builtin_scene
    from footfall.viz.plan_plot import plot_plan

    scene = builtin_scene(DEMO_SCENE)
    summary: dict[str, Any] = {}
    options = PlannerOptions(time_limit=120.0, threads=2)
    steps: int | None = None  # miqcqp: the smallest N with a plan
    for planner in ("miqcqp", "kinematic", "reactive"):
        plan = make_plan(scene, planner, None if planner == "reactive" else steps, options)
        if planner == "miqcqp":
            steps = plan.n_steps or None  # the kinematic baseline plans the same N
            summary["_miqcqp_plan"] = plan
        folder = out / "plan" / planner
        payload = plan.to_dict(scene.name)
        report = check_plan(plan, scene) if plan.has_solution else None
        payload["check"] = {"ok": bool(report and report.ok)}
        write_json(folder / "plan.json", payload)
        if plan.has_solution:
            plot_plan(plan, scene, folder / "plan.png")
        effort = float((plan.torques**2).sum()) if plan.has_solution else math.nan
        peak = float(abs(plan.torques).max()) if plan.torques.size else 0.0
        summary[planner] = {
            "status": plan.status.value,
            "steps": plan.n_steps,
            "solve_time_s": plan.solve_time,
            "torque_effort_Nm2": effort,
            "peak_torque_Nm": peak,
            "check_ok": payload["check"]["ok"],
        }
        lines.append(
            f"plan {planner:9s} on {scene.name}: {plan.status.value}, {plan.n_steps} steps, "
            f"peak ankle torque {peak:5.1f} N m, {plan.solve_time:5.1f} s, "
            f"checker {'ok' if payload['check']['ok'] else 'FAILED'}"
        )
    return summary


def _closed_loop(out: Path, lines: list[str], plan: Any) -> dict[str, Any]:
    from footfall.sim import Push, SimOptions, simulate
    from footfall.terrain import builtin_scene
    from footfall.viz.sim_plots import save_sim_figures

    scene = builtin_scene(DEMO_SCENE)
    push = Push.horizontal(2.0, 10.0, math.pi / 2)
    res = simulate(plan, SimOptions(pushes=(push,)), goal=scene.goal.position)
    save_sim_figures(res, out / "closed_loop", scene.terrain)
    m = res.metrics.to_dict()
    write_json(out / "closed_loop" / "sim.json", m)
    lines.append(
        f"closed loop (MPC, 10 N s push): fell {m['fell']}, single-support ZMP offset mean "
        f"{1000 * m['zmp_offset_mean']:.1f} mm, max {1000 * m['zmp_offset_max']:.1f} mm"
    )
    return m


def _quadruped(out: Path, lines: list[str]) -> dict[str, Any]:
    if importlib.util.find_spec("mujoco") is None:
        lines.append('quadruped: skipped (MuJoCo missing: pip install "footfall[sim]")')
        return {"skipped": "mujoco not installed"}
    from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
    from footfall.sim.quadruped.sim import simulate
    from footfall.viz import quadruped_plots as qp

    params = GaitParams(slope=math.radians(15.0), body_pitch=math.radians(10.0), cycles=2)
    plan = plan_gait(QuadrupedRobot(), params)
    res = simulate(plan)
    folder = out / "quadruped"
    folder.mkdir(parents=True, exist_ok=True)
    qp.plot_stability(plan, res.trace, folder / "stability.png")
    qp.plot_foot_path(plan, res.trace, folder / "fig10_lf_foot_path.png")
    write_json(folder / "quadruped.json", res.metrics.to_dict())
    m = res.metrics
    lines.append(
        f"quadruped 15 deg slope, 2 cycles: fell {m.fell}, "
        f"min stability margin {m.stability_margin_min_m:.3f} m, "
        f"{m.distance_up_slope_m:.2f} m up the slope"
    )
    return m.to_dict()


def run_demo(out: Path, progress: Callable[[str], None] | None = None) -> dict[str, Any]:
    """Run the demo and write ``out/demo.json`` plus one sub-folder of outputs per part.

    Returns:
        The summary written to ``demo.json``; ``lines`` holds a human-readable digest.
    """
    lines: list[str] = []
    summary: dict[str, Any] = {}
    for key, part in (("lip", _lip), ("plans", _plans), ("quadruped", _quadruped)):
        if progress is not None:
            progress(key)
        summary[key] = part(out, lines)
        if key == "plans":
            plan = summary["plans"].pop("_miqcqp_plan")
            if progress is not None:
                progress("closed_loop")
            summary["closed_loop"] = _closed_loop(out, lines, plan) if plan.has_solution else {}
    summary["lines"] = lines
    write_json(out / "demo.json", summary)
    return summary
