"""One entry point for every footstep planner, and the smallest-N search (``--min-steps``)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import replace
from functools import partial
from typing import Protocol

from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning.bounds import (
    BackwardSets,
    ForwardSets,
    LiveMembers,
    StepsBound,
    live_members,
    reachable_steps_bound,
)
from footfall.planning.diagnose import min_steps_lower_bound
from footfall.planning.plan import (
    FootstepPlan,
    PlannerOptions,
    check_n_steps,
    check_planner_name,
    check_planning_arguments,
    result_meta,
)
from footfall.solvers.base import SolveProgress
from footfall.terrain.scene import Scene

#: how many footsteps beyond the lower bound ``--min-steps`` tries by default
MIN_STEPS_SPAN = 10
#: how far beyond the distance bound the reachable-set bound looks when no ``n_max`` is given
BOUND_HORIZON = 40
#: relative gap of the kinematic feasibility solves (:func:`_kinematic_proof`): stop at any plan
FEASIBILITY_GAP = 1.0
#: most seconds a kinematic feasibility solve may take (it only pays when it proves quickly)
KINEMATIC_CHECK_LIMIT = 30.0
#: share of each N's time limit the live members may take before the solve goes on without them
MEMBERS_SHARE = 0.5


def make_plan(
    scene: Scene,
    planner: str = "miqcqp",
    n_steps: int | None = None,
    options: PlannerOptions | None = None,
    robot: BipedParams | None = None,
    solve_progress: Callable[[SolveProgress], None] | None = None,
    monitor: SearchMonitor | None = None,
    members: LiveMembers | None = None,
) -> FootstepPlan:
    """Plan with the named planner (``miqcqp``, ``kinematic`` or ``reactive``).

    Args:
        scene: terrain, start and goal.
        planner: planner name.
        n_steps: footsteps N for the optimising planners; the reactive planner walks until the
            goal and uses ``n_steps`` (default 40) only as its limit. None for the optimising
            planners means the smallest feasible N (:func:`plan_min_steps`).
        options: planner options.
        robot: robot parameters (default ``scene.robot``).
        solve_progress: called about once a second during a ``bnb`` solve of a given N
            (``SolverOptions.progress``); the smallest-N search reports through
            :func:`plan_min_steps`'s ``monitor`` instead.
        monitor: the smallest-N search's reporter (``n_steps`` None), see
            :func:`plan_min_steps`.
        members: for ``miqcqp`` with a given N, the members each footstep can use
            (:func:`~footfall.planning.bounds.live_members`); the others are fixed out.
    """
    check_planning_arguments(scene, robot, options)
    check_planner_name(planner)
    if n_steps is not None:
        check_n_steps(n_steps)
    options = options or PlannerOptions()
    if members is not None and (planner != "miqcqp" or n_steps is None):
        raise InputError("members", "given", "only with the miqcqp planner and a given N")
    if planner == "reactive":
        from footfall.planning.reactive import plan_reactive

        if options.reach_both_frames:
            raise InputError(
                "reach_both_frames", True, "False for the reactive planner (miqcqp or kinematic)"
            )
        if options.swing_max is not None:
            raise InputError(
                "swing_max",
                options.swing_max,
                "None for the reactive planner (miqcqp or kinematic)",
            )

        return plan_reactive(
            scene, robot, max_steps=n_steps or 40, region_margin=options.region_margin
        )
    if n_steps is None:
        return plan_min_steps(scene, planner, options, robot, monitor=monitor)
    if planner == "kinematic":
        from footfall.planning.kinematic import plan_kinematic

        return plan_kinematic(scene, robot, n_steps, options, solve_progress)
    from footfall.planning.miqcqp import plan_footsteps

    return plan_footsteps(scene, robot, n_steps, options, solve_progress, members)


class SearchMonitor(Protocol):
    """What a smallest-N search reports while it runs (:func:`plan_min_steps`'s ``monitor``)."""

    def skipped(self, first: int, last: int, reason: str) -> None:
        """N = ``first``..``last`` are ruled out by the reachable-set bound, without a solve."""

    def solving(self, n_steps: int, progress: SolveProgress, model: str = "") -> None:
        """The solve of N = ``n_steps`` is at ``progress`` (about once a second); ``model`` names
        what is solved (``kinematic relaxation`` before the planner's own model)."""

    def tried(self, n_steps: int, plan: FootstepPlan, seconds: float, proof: str) -> None:
        """N = ``n_steps`` ended with ``plan`` after ``seconds`` [s]; ``proof`` says which model
        decided it (``solver`` or ``kinematic relaxation``)."""


def _skipped_note(skipped: dict[str, object] | None) -> str:
    if not skipped:
        return ""
    first, last = skipped["from"], skipped["to"]
    which = f"N = {first}" if first == last else f"N = {first}..{last}"
    return f"; {which} ruled out without a solve ({skipped['reason']})"


def _search_note(
    found: int,
    start: int,
    tried: list[dict[str, object]],
    skipped: dict[str, object] | None = None,
) -> str:
    """What a smallest-N search proved: the N below ``found`` that the reachable-set bound ruled
    out without a solve, those the solver proved infeasible, and the N that were not decided (time
    limit, error), in which case ``found`` may not be the smallest."""
    proven = [
        f"{t['n_steps']}" + (f" ({t['proof']})" if t.get("proof", "solver") != "solver" else "")
        for t in tried
        if t["status"] == "infeasible"
    ]
    open_ = [f"{t['n_steps']} ({t['status']})" for t in tried if t["status"] != "infeasible"]
    note = f"first N with a plan: {found} (searched from the lower bound {start}"
    note += _skipped_note(skipped)
    if proven:
        # proven for the planner's model (conservative linear reach): see the plans' messages
        note += f"; proven infeasible: N = {', '.join(proven)} for the planner's model"
    if open_:
        return (
            note + f"; not decided: N = {', '.join(open_)}, so a plan with fewer steps may exist)"
        )
    return note + f"; so {found} is the smallest N with a plan in the planner's model)"


def plan_min_steps(
    scene: Scene,
    planner: str = "miqcqp",
    options: PlannerOptions | None = None,
    robot: BipedParams | None = None,
    n_max: int | None = None,
    progress: Callable[[int, FootstepPlan], None] | None = None,
    monitor: SearchMonitor | None = None,
) -> FootstepPlan:
    """The plan with the smallest number of footsteps N that has a solution.

    Tries N upward from a lower bound: the larger of the distance and heading bound
    (:func:`~footfall.planning.diagnose.min_steps_lower_bound`) and the reachable-set bound of
    :func:`~footfall.planning.bounds.reachable_steps_bound`, which rules N out from the model's own
    reach, heading-rate, step-height, region and swing rows without a solve (a valid lower bound:
    no N it skips has a plan in the planner's model). The N it skips are recorded in the returned
    plan's ``stats["skipped"]`` (``from``, ``to``, ``reason``); each try that ends without a plan in
    ``stats["tried"]`` with its status. Up to ``n_max`` (default: the bound + ``MIN_STEPS_SPAN``).
    For the ``miqcqp`` planner each N is first put to its rows without the ALIP dynamics
    (:func:`_kinematic_proof`), until that check first fails to prove an N infeasible.
    ``progress(n, plan)`` is called after each N tried; ``monitor`` (a :class:`SearchMonitor`)
    also hears of the skipped N and of the solves while they run.
    """
    if planner == "reactive":
        raise InputError("planner", planner, "miqcqp or kinematic (reactive has no N to search)")
    robot = robot or scene.robot
    options = options or PlannerOptions()
    distance = min_steps_lower_bound(scene, robot, options.swing_max)
    if n_max is not None and n_max < distance:
        raise InputError("n_max", n_max, f"at least the lower bound {distance}")
    horizon = n_max if n_max is not None else distance + BOUND_HORIZON
    # the reachable sets serve the bound and every N's live members (computed as far as needed)
    forward = ForwardSets(scene, robot, options, horizon + MIN_STEPS_SPAN + 1)
    backward = BackwardSets(scene, robot, options)
    try:  # within the time limit of one N: a bound that takes longer than a solve does not pay
        deadline = time.perf_counter() + options.time_limit
        bound = reachable_steps_bound(scene, robot, options, horizon, forward, deadline)
    except TimeoutError:
        bound = StepsBound(distance, horizon, "distance and heading")
    start = max(distance, bound.n_steps)
    skipped = _skipped(distance, start, bound)
    n_max = n_max if n_max is not None else start + MIN_STEPS_SPAN
    if monitor is not None and skipped is not None:
        monitor.skipped(distance, min(start - 1, n_max), bound.reason)
    if start > n_max:
        return _ruled_out(planner, robot, options, distance, n_max, skipped)
    tried: list[dict[str, object]] = []
    plan: FootstepPlan | None = None
    # the kinematic check runs until it first fails to prove an N infeasible: larger N have
    # more room, so it would keep failing (a cost, never a wrong answer: the solver decides)
    precheck = planner == "miqcqp"
    for n in range(start, n_max + 1):
        t0 = time.perf_counter()
        # options.time_limit bounds each N as a whole: its live members, its kinematic check and
        # its solve share it (a small limit was overrun 10-25 times by the work before the solve)
        deadline = t0 + options.time_limit
        proof = "solver"
        plan = None
        members = None
        if planner == "miqcqp":
            # at most a share of the N's time: the solve keeps the rest (the sets computed are
            # kept for the next N, so a search on a large terrain still gets its members)
            sets_deadline = t0 + MEMBERS_SHARE * options.time_limit
            try:
                members = live_members(scene, robot, options, n, forward, sets_deadline, backward)
            except TimeoutError:  # an optimisation only: the solve goes on without it
                members = None
            else:
                plan = _members_proof(planner, robot, options, n, members)
                if plan is not None:
                    proof = "reachable sets"
        if plan is None and precheck and time.perf_counter() < deadline:
            hook = _hook(monitor, n, "kinematic relaxation")
            plan = _kinematic_proof(scene, robot, n, options, hook, members, deadline)
            precheck = plan is not None
            if plan is not None:
                proof = "kinematic relaxation"
        if plan is None:
            plan = _solve_within(scene, planner, n, options, robot, monitor, members, deadline)
        if progress is not None:
            progress(n, plan)
        if monitor is not None:
            monitor.tried(n, plan, time.perf_counter() - t0, proof)
        if plan.has_solution:
            stats = dict(plan.stats)
            stats["tried"] = tried
            stats["skipped"] = skipped
            note = _search_note(n, start, tried, skipped)
            return replace(plan, stats=stats, message=plan.message + "; " + note)
        seconds = round(time.perf_counter() - t0, 3)
        tried.append(
            {"n_steps": n, "status": plan.status.value, "proof": proof, "seconds": seconds}
        )
    assert plan is not None
    return replace(
        plan,
        message=plan.message + f"; no plan for N = {start}..{n_max}" + _skipped_note(skipped),
        stats={"tried": tried, "skipped": skipped},
    )


def _solve_within(
    scene: Scene,
    planner: str,
    n_steps: int,
    options: PlannerOptions,
    robot: BipedParams,
    monitor: SearchMonitor | None,
    members: LiveMembers | None,
    deadline: float,
) -> FootstepPlan:
    """The planner's solve of N = ``n_steps`` with what is left of this N's time limit (an
    undecided N, status ``time_limit``, when nothing is left)."""
    left = deadline - time.perf_counter()
    if left <= 0.0:
        from footfall.solvers import SolveStatus

        message = (
            f"no solve of N = {n_steps}: its time limit of {options.time_limit:g} s ran out in "
            "the checks before it"
        )
        return FootstepPlan.empty(
            planner, SolveStatus.TIME_LIMIT, robot, message, solver=options.solver
        )
    hook = _hook(monitor, n_steps, planner)
    within = replace(options, time_limit=left)
    plan = make_plan(scene, planner, n_steps, within, robot, hook, members=members)
    # the plan was made with the options asked for; only its clock was shorter
    return plan


def _hook(
    monitor: SearchMonitor | None, n_steps: int, model: str
) -> Callable[[SolveProgress], None] | None:
    """The solver progress hook that reports to ``monitor`` as the solve of ``model`` at N."""
    return None if monitor is None else partial(monitor.solving, n_steps, model=model)


def _kinematic_proof(
    scene: Scene,
    robot: BipedParams,
    n_steps: int,
    options: PlannerOptions,
    solve_progress: Callable[[SolveProgress], None] | None = None,
    members: LiveMembers | None = None,
    deadline: float = math.inf,
) -> FootstepPlan | None:
    """An infeasible plan if the MIQCQP's rows *without* the ALIP dynamics, torque bound and
    their objective terms (the kinematic planner's model, ``dynamics=False``) are proven to have
    no solution with ``n_steps`` footsteps; None otherwise (a plan, a time limit, an error).

    Every row of that model is a row of the full model (eq. 5.12e-k, 5.14-5.18, the goal and the
    options beyond the document), so a proof that it is infeasible proves the full model
    infeasible. A mixed-integer *linear* feasibility question, it is decided in a fraction of
    the time the branch and bound needs with the dynamics. ``members``: the live members of
    this N (:func:`~footfall.planning.bounds.live_members`), the others fixed out.
    """
    from footfall.planning.miqcqp import _model_infeasible, build_footstep_problem, restrict_members
    from footfall.solvers import SolveStatus, solve

    kin = build_footstep_problem(scene, robot, n_steps, options, dynamics=False)
    if members is not None:
        kin, _ = restrict_members(kin, members)
    if kin.problem.bounds_conflict():
        result_status, meta = SolveStatus.INFEASIBLE, {"solver": options.solver}
    else:
        # a feasibility question: any incumbent answers it (a gap of 1 stops at the first one,
        # the objective being a sum of squares, >= 0)
        left = min(options.time_limit, KINEMATIC_CHECK_LIMIT, deadline - time.perf_counter())
        if left <= 0.0:
            return None
        feasibility = replace(
            options.solver_options(),
            gap=FEASIBILITY_GAP,
            time_limit=left,
            progress=solve_progress,
        )
        result = solve(kin.problem, options.solver, feasibility)
        result_status, meta = result.status, result_meta(result)
        meta.pop("status")
    if result_status is not SolveStatus.INFEASIBLE:
        return None
    message = (
        _model_infeasible(scene, kin.robot, n_steps, options)
        + " (proven on its rows without the ALIP dynamics: the kinematic planner's model)"
    )
    return FootstepPlan.empty("miqcqp", SolveStatus.INFEASIBLE, kin.robot, message, **meta)


def _members_proof(
    planner: str, robot: BipedParams, options: PlannerOptions, n_steps: int, members: LiveMembers
) -> FootstepPlan | None:
    """An infeasible plan when some free footstep has no live heading segment or region (no
    position of it is both reachable from the start and able to reach the goal); else None."""
    from footfall.solvers import SolveStatus

    free = range(1, n_steps - 1)
    stuck = [i for i in free if not members.segments[i].any() or not members.regions[i].any()]
    if not stuck:
        return None
    message = (
        f"infeasible in the planner's model for N = {n_steps}: footstep {stuck[0]} has no "
        "position both reachable from the start and able to reach the goal feet in the "
        f"remaining {n_steps - 1 - stuck[0]} steps (reachable sets of the reach, heading-rate, "
        "step-height and region rows)"
    )
    return FootstepPlan.empty(
        planner, SolveStatus.INFEASIBLE, robot, message, solver=options.solver
    )


def _skipped(distance: int, start: int, bound: StepsBound) -> dict[str, object] | None:
    """The N the reachable-set bound rules out above the distance bound, with its reason."""
    if start <= distance:
        return None
    return {"from": distance, "to": start - 1, "reason": bound.reason}


def _ruled_out(
    planner: str,
    robot: BipedParams,
    options: PlannerOptions,
    distance: int,
    n_max: int,
    skipped: dict[str, object] | None,
) -> FootstepPlan:
    """The result of a search whose every N the bounds rule out: infeasible without a solve."""
    from footfall.solvers import SolveStatus

    skipped = skipped or {"from": distance, "to": n_max, "reason": "distance and heading"}
    skipped = {**skipped, "to": n_max}
    message = (
        f"infeasible in the planner's model for N = {distance}..{n_max} (and, by distance and "
        f"heading, below): {skipped['reason']}"
    )
    plan = FootstepPlan.empty(
        planner, SolveStatus.INFEASIBLE, robot, message, solver=options.solver
    )
    return replace(plan, stats={"tried": [], "skipped": skipped})
