"""Footstep and walking-pattern planners.

- :func:`lip_walk` — Kajita's LIP walking pattern (document 004).
- :func:`plan_footsteps` — the full-horizon MIQCQP of document 000 (section 5.3);
  :func:`build_footstep_problem` returns its inspectable model.
- :func:`plan_kinematic`, :func:`plan_reactive` — the two baselines; :func:`make_plan` dispatches
  by name and :func:`plan_min_steps` searches the smallest N (from the lower bound of
  :func:`reachable_steps_bound`, reporting to a :class:`SearchMonitor`).
- :func:`check_plan` — an independent constraint checker; :func:`load_plan` reads a saved
  ``plan.json`` back.
"""

from footfall.planning.bounds import StepsBound, reachable_steps_bound
from footfall.planning.check import CheckReport, Violation, check_plan
from footfall.planning.kinematic import plan_kinematic
from footfall.planning.lip_examples import example as lip_example
from footfall.planning.lip_walk import LipWalk, LipWalkParams, lip_walk, optimal_foothold
from footfall.planning.miqcqp import FootstepProblem, build_footstep_problem, plan_footsteps
from footfall.planning.plan import PLANNERS, FootstepPlan, PlannerOptions, PlannerWeights
from footfall.planning.plan_file import load_plan
from footfall.planning.reactive import plan_reactive
from footfall.planning.run import SearchMonitor, make_plan, plan_min_steps

__all__ = [
    "PLANNERS",
    "CheckReport",
    "FootstepPlan",
    "FootstepProblem",
    "LipWalk",
    "LipWalkParams",
    "PlannerOptions",
    "PlannerWeights",
    "SearchMonitor",
    "StepsBound",
    "Violation",
    "build_footstep_problem",
    "check_plan",
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
