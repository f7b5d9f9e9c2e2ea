"""JSON form of a :class:`FootstepPlan` (the ``plan.json`` written by ``footfall plan``)."""

from __future__ import annotations

import math
from typing import Any

from footfall.planning.plan import FootstepPlan


def _num(v: float) -> float | None:
    """JSON has no NaN/inf: unknown numbers become null."""
    return float(v) if math.isfinite(v) else None


def plan_to_dict(plan: FootstepPlan, scene_name: str = "") -> dict[str, Any]:
    """Plain-JSON dict of a plan, SI units (m, rad, s, N m, kg m^2/s).

    Keys: ``status``, ``planner``, ``scene``, ``message``, ``objective``, ``bound``, ``gap``,
    ``solve_time_s``, ``solver``, ``region_margin`` [m], ``reach_both_frames``, ``swing_max`` [m]
    (null: no swing bound), ``stats``, ``footsteps`` (``index``, ``side``, ``position``,
    ``heading``, ``region``; index 0 is the initial stance foot) and ``alip`` (``states`` per step:
    K states of 4; ``torques`` per step: K - 1 torques of 2; ``final_state``; the state layout).
    """
    stats = {k: (_num(v) if isinstance(v, float) else v) for k, v in plan.stats.items()}
    return {
        "status": plan.status.value,
        "planner": plan.planner,
        "scene": scene_name,
        "message": plan.message,
        "objective": _num(plan.objective),
        "bound": _num(plan.bound),
        "gap": _num(plan.gap),
        "solve_time_s": plan.solve_time,
        "solver": plan.solver,
        "region_margin": plan.region_margin,
        "reach_both_frames": plan.reach_both_frames,
        "swing_max": plan.swing_max,
        "heading_segments": plan.heading_segments,
        "stats": stats,
        "robot": {
            "mass": plan.robot.mass,
            "com_height": plan.robot.com_height,
            "t_ss": plan.robot.t_ss,
            "t_ds": plan.robot.t_ds,
            "n_nodes": plan.robot.n_nodes,
            "u_max": plan.robot.u_max,
        },
        "footsteps": [
            {
                "index": i,
                "side": plan.sides[i].value,
                "position": plan.footsteps[i].tolist(),
                "heading": float(plan.headings[i]),
                "region": plan.regions[i],
            }
            for i in range(plan.footsteps.shape[0])
        ],
        "alip": {
            "state_layout": ["x_c [m]", "y_c [m]", "L_x [kg m^2/s]", "L_y [kg m^2/s]"],
            "states": plan.states.tolist(),
            "torques": plan.torques.tolist(),
            "final_state": [_num(v) for v in plan.final_state],
        },
    }
