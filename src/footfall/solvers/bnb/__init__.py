"""Branch and bound on convex-hull relaxations, with Clarabel as the node solver.

This backend solves the :class:`~footfall.solvers.problem.MIQCQP` exactly as built (same variables,
rows, cones, bounds and objective), for problems of the shape the footstep planner builds (document
000, eq. 5.11-5.18):

* every integer variable is a binary and belongs to exactly one *choice group*: an equality row
  ``sum_{z in G} z = 1`` (one region per footstep, eq. 5.12j; one heading segment, eq. 5.12k);
* every inequality row holds no binary, only binaries (a valid inequality), or one binary ``z`` as
  a big-M row ``a^T x + M z <= b`` (``M > 0``) whose ``z = 0`` form is implied by the variable
  bounds (rows of :meth:`ProblemBuilder.add_le_big_m`): "z = 1 implies a^T x <= b - M";
* binaries appear in no objective row, cone or other equality row.

Anything else raises :class:`UnsupportedProblem` in :func:`analyse`, and :func:`solve` hands the
problem to SCIP (``stats["fallback"]``).

Relaxation of a node (each group ``G`` may use the members ``Z`` still allowed):

* Hull (Balas' extended formulation). The member rows of ``G`` are written over *forms* ``f = B
  x_V`` (an orthonormal basis of their row space; for a heading segment: heading and the two step
  components). Each member ``z`` gets a copy ``f^z`` and ``B x_V = sum_z f^z``, ``a_f^T f^z <= beta
  z`` (its rows scaled by ``z``), ``z >= 0``; the group row gives ``sum z = 1``. This is the convex
  hull of the union of the member sets, where big-M only gives a box. A group with one allowed
  member gets its rows on ``x`` directly; excluded members are fixed to 0. Variables private to a
  group's rows (the piecewise-linear sin/cos of eq. 5.12g-h) are removed by Fourier-Motzkin
  elimination (the exact projection) and recovered from the chosen member.
* Perspective. Objective rows that lie in one group's forms (the horizontal step-length terms of
  eq. 5.11 in the heading-segment group) are charged ``sum_z w (C f^z - t z)^2 / z`` (rotated
  second-order cones): equal at integral points, tighter in between.
* Condensed dynamics. Variables that appear only in equality rows, the objective, their bounds and
  cones (the ALIP states and torques) are eliminated: their optimal cost is a convex quadratic of
  the rest, from one KKT solve. Dropping their bounds and cones keeps a lower bound; when a node's
  recovered point violates one (``BnbSettings.escalate``: e.g. the torque limit, eq. 5.12d), the
  node is re-solved with the full model, and so are its descendants. A condensed point that breaks
  nothing is feasible for the full relaxation with the same cost, so the bound is the full one
  either way; where it breaks something, the full model's bound is higher and can prove the node
  infeasible (the condensed model alone cannot see an instance that only the torque limit makes
  infeasible, and has to enumerate it).

* Compact node problems (``BnbSettings.compact``). The same relaxation with a smaller KKT system (a
  node solve costs about linearly in its size): excluded binaries are left out instead of fixed to
  0, as are columns that only their own bounds constrain (the private sin/cos) and the rows ``z >=
  0`` that a perspective cone implies; a form that every member bounds only by its own interval (a
  segment's heading) loses its copies, ``sum_z lo_z z <= B_j x_V <= sum_z hi_z z`` being their
  exact projection (:func:`~footfall.solvers.bnb.templates._separable_forms`).

* Links (``BnbSettings.links``, off: tighter but dearer per node, see ``benchmarks/RESULTS.md``).
  Two groups coupled by a plain row (the heading rate, eq. 5.12e, between the segment groups of
  consecutive steps) keep only the member pairs that row allows on the members' boxes; the group
  weights must be the marginals of weights on those pairs, written as prefix rows when the pairs
  form a staircase (:func:`~footfall.solvers.bnb.links._staircase`), and children drop the members
  left without a partner.

Every bound is ``min(primal, dual)`` of a Clarabel solve of a convex problem, so it is valid.

Search: best-first on the bound. A relaxation point that satisfies the rows of one member of every
group is a feasible point of the MIQCQP (the binaries are then set to those members), so the node
is solved exactly even when the interior-point weights are spread. Otherwise the group whose
nearest member is violated most is split where the cumulative weight of its members (in index
order, the angle order for segments) crosses 1/2 (SOS1 branching). Incumbents come from such nodes
and a dive from the root.

Probing (``BnbSettings.probe_rounds``). A search still open after ``probe_after`` nodes per
undecided root member solves the root once with each member fixed and kills the members whose bound
reaches the incumbent (or that are infeasible): no better point uses them, so every open node drops
them (a node that loses any is solved again before it is branched), and the node problems shrink.
One round ranks the members; two primal heuristics then look for a better incumbent (a search of at
most ``heur_nodes`` nodes over each group's ``heur_top`` members of the lowest probe bound, and a
one-group-at-a-time local search), and further rounds probe with it until a round kills nothing.

With ``threads >= 2`` forked worker processes (:class:`~footfall.solvers.bnb.workers._Workers`)
solve the nodes asynchronously: whenever one is free, the best open node is branched and its
children submitted; the dive runs in a worker meanwhile. The queue, incumbent and pruning stay in
the calling process, so the search is the serial one with the node solves moved out (node order may
differ, the optimum within the gap does not). A worker that dies or raises stops the search with
:class:`WorkerError`; every worker is reaped however the search ends. The search stops when
``(incumbent - bound) / min(|incumbent|, |bound|) <= gap`` (SCIP's definition) or at the time
limit, returning the best point and an honest gap; a node whose solve fails numerically makes the
result ``feasible`` at best, never ``optimal``.

Modules: :mod:`~footfall.solvers.settings` (:class:`BnbSettings`),
:mod:`~footfall.solvers.bnb.structure` (:func:`analyse`), :mod:`~footfall.solvers.bnb.links`,
:mod:`~footfall.solvers.bnb.templates` and :mod:`~footfall.solvers.bnb.relaxation` (the node
relaxation), :mod:`~footfall.solvers.bnb.branching`, :mod:`~footfall.solvers.bnb.workers`,
:mod:`~footfall.solvers.bnb.probing` and :mod:`~footfall.solvers.bnb.search` (:func:`solve`).
"""

from __future__ import annotations

from footfall.solvers.bnb.relaxation import HullRelaxation
from footfall.solvers.bnb.search import NAME, solve
from footfall.solvers.bnb.structure import UnsupportedProblem, analyse
from footfall.solvers.bnb.workers import WorkerError
from footfall.solvers.settings import BnbSettings

__all__ = [
    "NAME",
    "BnbSettings",
    "HullRelaxation",
    "UnsupportedProblem",
    "WorkerError",
    "analyse",
    "solve",
]
