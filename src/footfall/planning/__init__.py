"""Footstep and walking-pattern planners.

- :func:`lip_walk` — Kajita's LIP walking pattern (document 004).
- :func:`plan_footsteps` — the full-horizon MIQCQP of document 000 (section 5.3);
  :func:`build_footstep_problem` returns its inspectable model. Where its solve finds no plan,
  :func:`~footfall.planning.windows.heading_window_search` looks for one with the headings
  pinned outside a window of footsteps (``PlannerOptions.heading_windows``).
- :func:`plan_kinematic`, :func:`plan_reactive` — the two baselines; :func:`make_plan` dispatches
  by name and :func:`plan_min_steps` searches the smallest N (from the lower bound of
  :func:`reachable_steps_bound`, reporting to a :class:`SearchMonitor`).
- :class:`HorizonPlanner` — the short-horizon MIQP for the control loop (H = 3 footsteps from the
  measured ALIP state, exact, warm-started); :func:`horizon_input` makes a tick's input from a plan.
- :func:`check_plan` — an independent constraint checker; :func:`load_plan` reads a saved
  ``plan.json`` back.
"""

from typing import TYPE_CHECKING, Any

# imported now: the function shares its module's name, and a module imported later would take
# the package's attribute (the module is light: numpy and the LIP)
from footfall.planning.lip_walk import LipWalk, LipWalkParams, lip_walk, optimal_foothold

if TYPE_CHECKING:
    from footfall.planning.bounds import StepsBound, reachable_steps_bound
    from footfall.planning.check import CheckReport, Violation, check_plan
    from footfall.planning.horizon import (
        HorizonInput,
        HorizonOptions,
        HorizonPlanner,
        HorizonSolution,
        horizon_input,
    )
    from footfall.planning.horizon_model import horizon_problem
    from footfall.planning.kinematic import plan_kinematic
    from footfall.planning.lip_examples import example as lip_example
    from footfall.planning.miqcqp import FootstepProblem, build_footstep_problem, plan_footsteps
    from footfall.planning.plan import PLANNERS, FootstepPlan, PlannerOptions, PlannerWeights
    from footfall.planning.plan_file import load_plan
    from footfall.planning.reactive import plan_reactive
    from footfall.planning.run import SearchMonitor, make_plan, plan_min_steps

#: each public name and the module (and name there) that defines it: imported when first used,
#: so that reading a plan does not import the solvers and scipy's integrators
_WHERE = {
    "StepsBound": ("footfall.planning.bounds", "StepsBound"),
    "reachable_steps_bound": ("footfall.planning.bounds", "reachable_steps_bound"),
    "CheckReport": ("footfall.planning.check", "CheckReport"),
    "Violation": ("footfall.planning.check", "Violation"),
    "check_plan": ("footfall.planning.check", "check_plan"),
    "HorizonInput": ("footfall.planning.horizon", "HorizonInput"),
    "HorizonOptions": ("footfall.planning.horizon", "HorizonOptions"),
    "HorizonPlanner": ("footfall.planning.horizon", "HorizonPlanner"),
    "HorizonSolution": ("footfall.planning.horizon", "HorizonSolution"),
    "horizon_input": ("footfall.planning.horizon", "horizon_input"),
    "horizon_problem": ("footfall.planning.horizon_model", "horizon_problem"),
    "plan_kinematic": ("footfall.planning.kinematic", "plan_kinematic"),
    "lip_example": ("footfall.planning.lip_examples", "example"),
    "FootstepProblem": ("footfall.planning.miqcqp", "FootstepProblem"),
    "build_footstep_problem": ("footfall.planning.miqcqp", "build_footstep_problem"),
    "plan_footsteps": ("footfall.planning.miqcqp", "plan_footsteps"),
    "PLANNERS": ("footfall.planning.plan", "PLANNERS"),
    "FootstepPlan": ("footfall.planning.plan", "FootstepPlan"),
    "PlannerOptions": ("footfall.planning.plan", "PlannerOptions"),
    "PlannerWeights": ("footfall.planning.plan", "PlannerWeights"),
    "load_plan": ("footfall.planning.plan_file", "load_plan"),
    "plan_reactive": ("footfall.planning.reactive", "plan_reactive"),
    "SearchMonitor": ("footfall.planning.run", "SearchMonitor"),
    "make_plan": ("footfall.planning.run", "make_plan"),
    "plan_min_steps": ("footfall.planning.run", "plan_min_steps"),
}

__all__ = [
    "PLANNERS",
    "CheckReport",
    "FootstepPlan",
    "FootstepProblem",
    "HorizonInput",
    "HorizonOptions",
    "HorizonPlanner",
    "HorizonSolution",
    "LipWalk",
    "LipWalkParams",
    "PlannerOptions",
    "PlannerWeights",
    "SearchMonitor",
    "StepsBound",
    "Violation",
    "build_footstep_problem",
    "check_plan",
    "horizon_input",
    "horizon_problem",
    "lip_example",
    "lip_walk",
    "load_plan",
    "make_plan",
    "optimal_foothold",
    "plan_footsteps",
    "plan_kinematic",
    "plan_min_steps",
    "plan_reactive",
    "reachable_steps_bound",
]


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        import importlib

        module, attr = _WHERE[name]
        value = getattr(importlib.import_module(module), attr)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
