"""A primal heuristic for the MIQCQP: every heading pinned but those of a window of footsteps.

Beyond the document (its section 5.3 solves the model with a commercial solver). Some terrains
can only be crossed with the robot turned: a gap longer than the forward reach of eq. (5.12f) is
crossed by a step along the reach trapezoid's far corner, with the stance heading 15-25 degrees off
the path (the G1 on stairs_slope_gap: forward reach 0.23 m, the gap with the sole's half length
on either side 0.294 m). The branch and bound then finds no feasible point: its relaxation mixes
heading segments at every footstep (the union of their reaches), and each dive leaves several
footsteps on the wrong segments at once, so no incumbent is found before the time limit.

This heuristic restricts the model and solves the restrictions with the same backend:

* outside a window of footsteps ``|i - k| <= width`` every heading ``theta_i`` is pinned to the
  band between the start and goal headings, widened by a quarter of a heading segment, so that
  both segments that meet at a breakpoint there stay available (the optimum of eq. 5.11 holds
  the heading on a breakpoint to get both segments' reach); the segment binaries outside the band
  are fixed to 0;
* inside the window the headings keep the model's bounds (a full turn).

A restriction only tightens variable bounds, so each of its solutions satisfies every row of the
model: it is a feasible plan of the model (and the independent checker checks it as any other).
A restriction proven infeasible proves nothing about the model.

Windows are tried in the order of where a turn is likely needed: the centre ``k`` whose footstep,
spaced evenly on the straight line from the start to the goal, lies nearest to a hole in the
terrain (a point of that line inside no region); on a line without holes, from the middle
outward. When no window of that width has a plan, the width doubles (fewer, wider windows; the
G1's N = 21 plan of stairs_slope_gap turns gradually over footsteps 7-20, which no five-footstep
window holds), as long as a window leaves some free footstep pinned. Each window is solved to
the model's gap; the search keeps the best plan, tries no wider windows once it has one, and
stops when the windows are tried or its time is up.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Protocol, TypeVar

import numpy as np

from footfall._typing import FloatArray, IntArray
from footfall.planning.plan import PlannerOptions
from footfall.solvers import SolveStatus, solve
from footfall.solvers.base import SolveProgress, relative_gap
from footfall.solvers.problem import MIQCQP
from footfall.terrain.scene import Scene


class HeadingModel(Protocol):
    """What the search reads of a :class:`~footfall.planning.miqcqp.FootstepProblem` (a
    structural type: the planner's module calls this one, so this one does not import it)."""

    @property
    def problem(self) -> MIQCQP: ...
    @property
    def n_steps(self) -> int: ...
    @property
    def theta(self) -> IntArray: ...
    @property
    def segments(self) -> IntArray: ...
    @property
    def breakpoints(self) -> FloatArray: ...


M = TypeVar("M", bound=HeadingModel)

#: points per metre of the straight start-to-goal line tested for holes
HOLE_SAMPLES_PER_M = 200


@dataclass(frozen=True)
class WindowResult:
    """The best plan the heading-window search found.

    Attributes:
        x: the model's variable vector (n,).
        objective: its objective (eq. 5.11).
        centre: the window's centre footstep k.
        width: its half-width: footsteps k - width .. k + width were free.
        tried: windows solved (or stopped by the clock).
        feasible: windows with a plan.
        seconds: wall time of the search [s].
    """

    x: FloatArray
    objective: float
    centre: int
    width: int
    tried: int
    feasible: int
    seconds: float


def window_order(scene: Scene, n_steps: int, width: int) -> list[int]:
    """Window centres ``k`` in the order the search tries them (module docstring): the free
    footsteps are 1..N-2 (the last two stand at the goal), so the centres are ``1 + width``
    .. ``N - 2 - width`` (at least one centre)."""
    first, last = 1 + width, max(1 + width, n_steps - 2 - width)
    centres = list(range(first, last + 1))
    start = 0.5 * (scene.start.left[:2] + scene.start.right[:2])
    goal = np.asarray(scene.goal.position[:2], dtype=float)
    length = float(np.linalg.norm(goal - start))
    fractions = np.linspace(0.0, 1.0, max(2, int(length * HOLE_SAMPLES_PER_M) + 1))
    points = start + fractions[:, None] * (goal - start)
    covered = np.zeros(len(points), dtype=bool)
    for region in scene.terrain:
        a, b = region.halfspaces()
        covered |= np.all(points @ a.T <= b + 1e-9, axis=1)
    holes = fractions[~covered]

    # distances rounded so that ties (equally far either side) go to the lower k on any machine
    def where(k: int) -> float:  # fraction of the line of footstep k, spaced evenly
        return k / max(1, n_steps - 1)

    if len(holes) == 0:
        return sorted(centres, key=lambda k: (round(abs(where(k) - 0.5), 9), k))
    return sorted(centres, key=lambda k: (round(float(np.min(np.abs(holes - where(k)))), 9), k))


def window_schedule(scene: Scene, n_steps: int, width: int) -> list[tuple[int, int]]:
    """``(width, centre)`` pairs in the order the search tries them: every centre of
    :func:`window_order` at ``width``, then at twice the width, and so on while a window leaves
    some free footstep (1..N-2) pinned (a window over all of them is the unrestricted model,
    which the solve before the search has had)."""
    out: list[tuple[int, int]] = []
    free = n_steps - 2
    w = width
    while w >= 1 and (2 * w + 1 < free or not out):
        out.extend((w, k) for k in window_order(scene, n_steps, w))
        w *= 2
    return out


def pin_headings(fp: M, centre: int, width: int) -> M:
    """``fp`` with every heading outside the window ``|i - centre| <= width`` pinned to the
    start-goal heading band (module docstring) and the segment binaries outside its bounds fixed
    to 0."""
    problem = fp.problem
    theta, segments, breaks = fp.theta, fp.segments, fp.breakpoints
    lb, ub = problem.lb.copy(), problem.ub.copy()
    seg_width = float(breaks[1] - breaks[0])
    # footstep 0's heading is the start's, footstep N's the goal's (both fixed by their bounds)
    theta0, theta_goal = float(lb[int(theta[0])]), float(lb[int(theta[-1])])
    lo = min(theta0, theta_goal) - 0.25 * seg_width
    hi = max(theta0, theta_goal) + 0.25 * seg_width
    for i in range(1, len(theta)):
        t = int(theta[i])
        if abs(i - centre) > width:
            lb[t], ub[t] = max(lb[t], lo), min(ub[t], hi)
        for ell, z in enumerate(segments[i]):
            if z >= 0 and (breaks[ell + 1] < lb[t] - 1e-12 or breaks[ell] > ub[t] + 1e-12):
                ub[int(z)] = 0.0
    return replace(fp, problem=replace(problem, lb=lb, ub=ub))  # type: ignore[type-var]


def heading_window_search(
    fp: HeadingModel,
    scene: Scene,
    options: PlannerOptions,
    seconds: float,
    progress: Callable[[SolveProgress], None] | None = None,
    after: SolveProgress | None = None,
) -> WindowResult | None:
    """The best plan of the restrictions (module docstring) found within ``seconds`` [s], or
    None when none has one. ``fp``: the model, with any members already fixed out.

    ``progress`` hears of the search about once a second, as one solve that goes on from
    ``after`` (where the unrestricted solve ended: its nodes and seconds are counted on, and its
    bound, which holds for the whole model, stays the bound; a restriction's own bound does not).
    The incumbent is the best plan found so far."""
    t0 = time.perf_counter()
    deadline = t0 + seconds
    best: tuple[float, FloatArray, int, int] | None = None  # objective, x, centre, width
    tried = feasible = nodes_done = 0
    start = after or SolveProgress(0, 0.0, None, math.nan, math.inf)

    def report(p: SolveProgress) -> None:  # a window solve's progress, as the search's
        if progress is None:
            return
        found = [v for v in (p.incumbent, best[0] if best else None) if v is not None]
        incumbent = min(found) if found else None
        progress(
            SolveProgress(
                nodes=start.nodes + nodes_done + p.nodes,
                seconds=start.seconds + time.perf_counter() - t0,
                incumbent=incumbent,
                bound=start.bound,
                gap=math.inf if incumbent is None else relative_gap(incumbent, start.bound),
            )
        )

    for w, centre in window_schedule(scene, fp.n_steps, options.heading_windows):
        if best is not None and w > best[3]:
            break  # a plan at this width: no wider windows (slower, and not needed)
        left = deadline - time.perf_counter()
        if left <= 0.0:
            break
        restricted = pin_headings(fp, centre, w)
        if restricted.problem.bounds_conflict():
            continue
        tried += 1
        opts = replace(options.solver_options(), time_limit=left, progress=report)
        result = solve(restricted.problem, options.solver, opts)
        nodes_done += int(result.stats.get("nodes", 0))
        if result.x is None or result.status not in (
            SolveStatus.OPTIMAL,
            SolveStatus.FEASIBLE,
            SolveStatus.TIME_LIMIT,
        ):
            continue
        feasible += 1
        if best is None or result.objective < best[0]:
            best = (float(result.objective), np.asarray(result.x, dtype=float), centre, w)
    if best is None:
        return None
    return WindowResult(
        x=best[1],
        objective=best[0],
        centre=best[2],
        width=best[3],
        tried=tried,
        feasible=feasible,
        seconds=time.perf_counter() - t0,
    )


__all__ = [
    "HeadingModel",
    "WindowResult",
    "heading_window_search",
    "pin_headings",
    "window_order",
    "window_schedule",
]
