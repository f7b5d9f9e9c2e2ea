"""Kinematic baseline: the navigation-goal planner without dynamics (Deits & Tedrake 2014 style).

Same regions, reachability, heading-rate, heading-smoothness, step and goal terms as the MIQCQP of
document 000, but no ALIP states or ankle torques. To compare it with the full-horizon planner, the
ALIP trajectory these footsteps need is computed afterwards with the footsteps fixed: the
least-torque states and torques (same torque and terminal terms) under the torque bound; when the
bound cannot hold for these footsteps, the bound is lifted and the plan says so (the checker then
reports the torque violation).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from footfall.models.biped import BipedParams
from footfall.planning.miqcqp import build_footstep_problem, extract_plan
from footfall.planning.plan import FootstepPlan, PlannerOptions, result_meta
from footfall.solvers import SolveStatus, solve
from footfall.solvers.base import SolveProgress
from footfall.solvers.problem import fix_variables
from footfall.terrain.scene import Scene


def plan_kinematic(
    scene: Scene,
    robot: BipedParams | None = None,
    n_steps: int = 8,
    options: PlannerOptions | None = None,
    solve_progress: Callable[[SolveProgress], None] | None = None,
) -> FootstepPlan:
    """Plan footsteps without dynamics, then attach the least-torque ALIP trajectory
    (``solve_progress``: see :func:`footfall.planning.miqcqp.plan_footsteps`)."""
    from dataclasses import replace

    from footfall.planning.diagnose import diagnose_infeasible, geometric_infeasibility

    options = options or PlannerOptions()
    solver_opts = dataclasses.replace(options.solver_options(), progress=solve_progress)
    kin = build_footstep_problem(scene, robot, n_steps, options, dynamics=False)
    early = geometric_infeasibility(
        scene, kin.robot, n_steps, options.region_margin, options.swing_max
    )
    if early is not None:
        return FootstepPlan.empty(
            "kinematic", SolveStatus.INFEASIBLE, kin.robot, early, solver=options.solver
        )
    res = solve(kin.problem, options.solver, solver_opts)
    meta = result_meta(res)
    if res.x is None:
        msg = (
            diagnose_infeasible(
                scene,
                kin.robot,
                n_steps,
                options.region_margin,
                options.swing_max,
                heading_segments=options.heading_segments,
                torque_bound=False,
            )
            if res.status is SolveStatus.INFEASIBLE
            else f"kinematic planner found no plan ({res.stats.get('raw_status')})"
        )
        return FootstepPlan.empty("kinematic", robot=kin.robot, message=msg, **meta)

    # Dynamics for the chosen footsteps: the full model with every discrete choice and footstep fixed.
    full = build_footstep_problem(scene, robot, n_steps, options, dynamics=True)
    fixed_idx = [full.p.ravel(), full.theta, full.s, full.c]
    fixed_val = [res.x[kin.p].ravel(), res.x[kin.theta], res.x[kin.s], res.x[kin.c]]
    for a_full, a_kin in ((full.regions, kin.regions), (full.segments, kin.segments)):
        mask = a_full >= 0
        fixed_idx.append(a_full[mask])
        fixed_val.append(np.round(res.x[a_kin[mask]]))
    dyn_problem = fix_variables(full.problem, np.concatenate(fixed_idx), np.concatenate(fixed_val))
    dyn = solve(dyn_problem, options.solver, solver_opts)
    note = "kinematic plan; ALIP trajectory of least torque for its footsteps"
    if dyn.x is None:
        relaxed = replace(full.robot, u_max=1e6)
        full = build_footstep_problem(scene, relaxed, n_steps, options, dynamics=True)
        dyn_problem = fix_variables(
            full.problem, np.concatenate(fixed_idx), np.concatenate(fixed_val)
        )
        if dyn.status is SolveStatus.INFEASIBLE:
            why = "no ALIP trajectory for these footsteps keeps"
        else:  # time limit or error: nothing proven about the bound
            why = f"no ALIP trajectory was found ({dyn.status.value}) that keeps"
        dyn = solve(dyn_problem, options.solver, solver_opts)
        note += (
            f"; {why} the ankle torque within U_max = {kin.robot.u_max:g} N m, which the "
            "kinematic planner does not enforce: the trajectory shown is the least-torque one "
            "without that bound"
        )
    meta["stats"]["dynamics_status"] = dyn.status.value
    meta["stats"]["dynamics_objective"] = dyn.objective
    meta["solve_time"] = res.solve_time + dyn.solve_time
    if dyn.x is None:
        return FootstepPlan.empty(
            "kinematic", robot=kin.robot, message=note + ": dynamics failed", **meta
        )
    plan = extract_plan(full, dyn.x, message=note, **meta)
    return replace(plan, planner="kinematic", robot=kin.robot)
