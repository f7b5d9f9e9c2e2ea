"""The fast MIQCQP footstep planner: the same problem as :func:`plan_footsteps`, another solver.

``plan_footsteps_fast`` builds exactly the model of :mod:`footfall.planning.miqcqp` (document 000,
eq. 5.11-5.18: same variables, rows, cones, objective and bounds) and solves it with the ``bnb``
backend (:mod:`footfall.solvers.bnb`) instead of SCIP. Equivalently, pass
``PlannerOptions(solver="bnb")`` to :func:`footfall.planning.miqcqp.plan_footsteps`; the default
(``solver="scip"``) is unchanged.

Why it is faster (measured in ``benchmarks/bench_plan.py``; see the note there):

* Relaxation. Each footstep's region choice (eq. 5.12i-j) and heading-segment choice (eq. 5.12g-h,
  5.12k, with the segment's reach rows 5.12f) is a disjunction; ``bnb`` relaxes each by its convex
  hull (Balas' extended formulation) instead of the big-M box, and charges the horizontal
  step-length terms of eq. (5.11) in perspective form over the heading segments. With the regions
  fixed, the root gap on the seeded N = 10 benchmark fell from 19 % (hull only) to 6 %.
* Condensed dynamics. The ALIP states and torques (eq. 5.12a-d) appear only in equality rows, the
  objective, bounds and cones: ``V(p) = min_{x,u}`` of the torque and terminal terms is a convex
  quadratic of the footsteps, computed once from the KKT system. Node relaxations therefore have
  no ALIP variables (their size does not grow with K); when a node's solution would violate a
  dropped state bound or torque cone, that node is re-solved with the full model.
* Search. Best-first branch and bound on the relaxation bound with SOS-style splits of the most
  violated group, integrality detected geometrically (a relaxation point that satisfies one
  member's rows in every group is a feasible plan even if the weights are spread), a dive from the
  root for an early incumbent, Clarabel interior-point node solves.
"""

from __future__ import annotations

import dataclasses

from footfall.models.biped import BipedParams
from footfall.planning.miqcqp import plan_footsteps
from footfall.planning.plan import FootstepPlan, PlannerOptions
from footfall.terrain.scene import Scene

#: the backend of the fast planner
FAST_SOLVER = "bnb"


def plan_footsteps_fast(
    scene: Scene,
    robot: BipedParams | None = None,
    n_steps: int = 8,
    options: PlannerOptions | None = None,
) -> FootstepPlan:
    """Plan ``n_steps`` footsteps with the MIQCQP of document 000 (eq. 5.11-5.18), solved by ``bnb``.

    Same arguments and result as :func:`footfall.planning.miqcqp.plan_footsteps`; ``options.solver``
    is overridden. A time-limited run returns its best plan with an honest gap; an infeasible
    problem returns the diagnosis of :mod:`footfall.planning.diagnose`.
    """
    options = dataclasses.replace(options or PlannerOptions(), solver=FAST_SOLVER)
    return plan_footsteps(scene, robot, n_steps, options)
