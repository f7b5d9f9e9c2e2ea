"""Latency of the short-horizon footstep MIQP (:mod:`footfall.planning.horizon`) along a walk.

For every scene, a reference plan (the reactive baseline's: it has ALIP states and needs no long
solve) is followed tick by tick: at ``ticks`` times per single support the measured state is the
plan's, pushed at the start of the step by a velocity change of up to ``push`` [m/s] in a random
direction (seeded) and carried by the ALIP with the plan's torques. Each tick is solved twice in
the same process, warm-started from the previous tick's regions as in the loop, and cold; the
first tick of every step is also solved by SCIP on :func:`~footfall.planning.horizon_model.horizon_problem`
(the same problem written independently) as the same-run baseline and certificate.

Times are wall times of :meth:`HorizonPlanner.solve` (``time.perf_counter``) in this process, one
core; they are for a benchmark table, never for a test.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from footfall._typing import FloatArray
from footfall.errors import InputError
from footfall.planning.horizon import (
    HorizonOptions,
    HorizonPlanner,
    HorizonSolution,
    horizon_input,
)
from footfall.planning.horizon_model import horizon_problem
from footfall.planning.plan import FootstepPlan

#: scenes of the default horizon benchmark: every built-in scene with more than one region
DEFAULT_SCENES = (
    "discrete_steps",
    "stairs_slope_gap",
    "narrow_stones_gap",
    "roll_ramps",
    "corridor_corner",
)


@dataclass(frozen=True)
class HorizonTick:
    """One tick: where, and what the warm, cold and (first tick of a step) SCIP solves gave."""

    scene: str
    seed: int
    step: int
    time_left: float
    warm_ms: float
    cold_ms: float
    status: str
    cold_status: str
    objective: float
    cold_objective: float
    nodes: int
    cold_nodes: int
    warm_used: bool
    regions: tuple[str, ...]
    scip_ms: float = math.nan
    scip_status: str = ""
    scip_objective: float = math.nan
    scip_bound: float = math.nan


@dataclass(frozen=True)
class HorizonBench:
    """All ticks of a run and the settings that made them."""

    horizon: int
    ticks_per_step: int
    push: float
    gap: float
    ticks: tuple[HorizonTick, ...] = field(default_factory=tuple)


def _pushed_state(plan: FootstepPlan, step: int, t: float, dv: FloatArray) -> FloatArray:
    """The plan's state ``t`` [s] into single support ``step``, after a velocity change ``dv``
    (2,) [m/s] at its start, carried by the ALIP with the plan's torque blocks."""
    robot = plan.robot
    alip = robot.alip()
    mzh = robot.mass * robot.com_height
    x = plan.states[step, 0].copy()
    x[2] += -mzh * dv[1]  # v = (L_y, -L_x) / (m z_H)
    x[3] += mzh * dv[0]
    ad, bd = alip.discretize(robot.node_dt)
    full = min(int(t // robot.node_dt), robot.n_nodes - 1)
    for blk in range(full):
        x = ad @ x + bd @ plan.torques[step, blk]
    rest = t - full * robot.node_dt
    if rest > 1e-12 and full < robot.n_nodes - 1:
        ad_r, bd_r = alip.discretize(rest)
        x = ad_r @ x + bd_r @ plan.torques[step, full]
    return np.asarray(x)


def _agrees(tick: HorizonTick, gap: float) -> bool:
    """Our optimum within the gap of SCIP's (or below SCIP's proven bound when it stopped)."""
    ours, theirs = tick.objective, tick.scip_objective
    if not (math.isfinite(ours) and math.isfinite(theirs)):
        return tick.status == "infeasible" and tick.scip_status == "infeasible"
    tol = gap * max(abs(ours), abs(theirs)) + 1e-9
    if tick.scip_status == "optimal":
        return abs(ours - theirs) <= tol + 1e-6 * max(abs(theirs), 1.0)
    return ours <= theirs + tol


def check_bench_args(
    scenes: Sequence[str], horizon: int, ticks: int, push: float, gap: float
) -> HorizonOptions:
    """Raise :class:`InputError` for arguments :func:`bench_horizon` cannot run; its options."""
    from footfall.terrain import builtin_scene_names

    known = builtin_scene_names()
    for name in scenes:
        if name not in known:
            raise InputError("scenes", name, f"built-in scene names ({', '.join(known)})")
    if isinstance(ticks, bool) or not isinstance(ticks, int) or ticks < 1:
        raise InputError("ticks", ticks, "an integer number of solves per step >= 1")
    if not (isinstance(push, int | float) and math.isfinite(push) and push >= 0.0):
        raise InputError("push", push, "a velocity change >= 0 [m/s]")
    return HorizonOptions(horizon=horizon, gap=gap)


def bench_horizon(
    scenes: Sequence[str] = DEFAULT_SCENES,
    seeds: Sequence[int] = (0,),
    horizon: int = 3,
    ticks: int = 20,
    push: float = 0.3,
    gap: float = 1e-4,
    scip: bool = True,
    scip_time_limit: float = 60.0,
    progress: Callable[[HorizonTick], None] | None = None,
) -> HorizonBench:
    """Run the benchmark of the module docstring.

    Args:
        scenes: built-in scene names.
        seeds: seeds of the pushes (one walk per scene and seed).
        horizon: H, footsteps per solve.
        ticks: solves per single support (evenly spaced in time).
        push: largest velocity change [m/s] at the start of a step (uniform in [0, push]).
        gap: relative optimality gap.
        scip: also solve the first tick of every step with SCIP.
        scip_time_limit: SCIP's time limit per solve [s].
        progress: called with every tick.
    """
    from footfall.planning.reactive import plan_reactive
    from footfall.solvers import SolverOptions, SolveStatus, solve
    from footfall.terrain import builtin_scene

    options = check_bench_args(scenes, horizon, ticks, push, gap)
    out: list[HorizonTick] = []
    for name in scenes:
        scene = builtin_scene(name)
        plan = plan_reactive(scene)
        if not plan.reaches_goal:
            raise InputError("scenes", name, "a scene whose reference plan reaches the goal")
        planner = HorizonPlanner(scene, plan.robot, options)
        cold_planner = HorizonPlanner(scene, plan.robot, options)
        t_ss = plan.robot.t_ss
        for seed in seeds:
            rng = np.random.default_rng([seed, 7])
            prev: HorizonSolution | None = None
            for step in range(plan.n_steps - horizon + 1):
                angle = rng.uniform(0.0, 2.0 * math.pi)
                dv = rng.uniform(0.0, push) * np.array([math.cos(angle), math.sin(angle)])
                for m in range(ticks):
                    t = t_ss * m / ticks
                    x = _pushed_state(plan, step, t, dv)
                    inp = horizon_input(plan, step, t_ss - t, x, horizon)
                    warm = None if prev is None else prev.next_regions(stepped=m == 0)
                    sol = planner.solve(inp, warm=warm)
                    cold = cold_planner.solve(inp)
                    extra: dict[str, Any] = {}
                    if scip and m == 0:
                        res = solve(
                            horizon_problem(planner, inp),
                            "scip",
                            SolverOptions(time_limit=scip_time_limit, gap=gap, threads=1),
                        )
                        extra = {
                            "scip_ms": res.solve_time * 1e3,
                            "scip_status": {
                                SolveStatus.OPTIMAL: "optimal",
                                SolveStatus.INFEASIBLE: "infeasible",
                            }.get(res.status, res.status.value),
                            "scip_objective": res.objective,
                            "scip_bound": res.bound,
                        }
                    tick = HorizonTick(
                        scene=name,
                        seed=int(seed),
                        step=step,
                        time_left=t_ss - t,
                        warm_ms=sol.solve_time * 1e3,
                        cold_ms=cold.solve_time * 1e3,
                        status=sol.status,
                        cold_status=cold.status,
                        objective=sol.objective,
                        cold_objective=cold.objective,
                        nodes=sol.nodes,
                        cold_nodes=cold.nodes,
                        warm_used=sol.warm_used,
                        regions=sol.regions,
                        **extra,
                    )
                    out.append(tick)
                    if progress is not None:
                        progress(tick)
                    prev = sol
    return HorizonBench(horizon, ticks, float(push), gap, tuple(out))


def _dist(values: Sequence[float]) -> str:
    v = np.asarray(values, dtype=float)
    return (
        f"{np.median(v):.2f} | {np.percentile(v, 90):.2f} | {np.percentile(v, 99):.2f} | "
        f"{np.max(v):.2f}"
    )


def summary_rows(bench: HorizonBench) -> list[dict[str, Any]]:
    """One row per scene and one for all: tick count, latency quantiles [ms], nodes, statuses,
    the SCIP comparison."""
    groups: dict[str, list[HorizonTick]] = {}
    for t in bench.ticks:
        groups.setdefault(t.scene, []).append(t)
    groups["all"] = list(bench.ticks)
    rows = []
    for name, ts in groups.items():
        warm = [t.warm_ms for t in ts]
        cold = [t.cold_ms for t in ts]
        scip = [t for t in ts if t.scip_status]
        rows.append(
            {
                "scene": name,
                "ticks": len(ts),
                "optimal": sum(t.status == "optimal" for t in ts),
                "cold_optimal": sum(t.cold_status == "optimal" for t in ts),
                "warm_ms": {
                    "median": float(np.median(warm)),
                    "p90": float(np.percentile(warm, 90)),
                    "p99": float(np.percentile(warm, 99)),
                    "max": float(np.max(warm)),
                },
                "cold_ms": {
                    "median": float(np.median(cold)),
                    "p99": float(np.percentile(cold, 99)),
                    "max": float(np.max(cold)),
                },
                "nodes_median": float(np.median([t.nodes for t in ts])),
                "nodes_max": int(max(t.nodes for t in ts)),
                "cold_nodes_median": float(np.median([t.cold_nodes for t in ts])),
                "warm_used": sum(t.warm_used for t in ts),
                "objectives_equal": sum(
                    _same(t.objective, t.cold_objective, bench.gap) for t in ts
                ),
                "scip_ticks": len(scip),
                "scip_agree": sum(_agrees(t, bench.gap) for t in scip),
                "scip_optimal": sum(t.scip_status == "optimal" for t in scip),
                "scip_ms_median": float(np.median([t.scip_ms for t in scip])) if scip else math.nan,
                "scip_over_warm": (
                    float(np.median([t.scip_ms / t.warm_ms for t in scip])) if scip else math.nan
                ),
            }
        )
    return rows


def _same(a: float, b: float, gap: float) -> bool:
    if not (math.isfinite(a) and math.isfinite(b)):
        return not math.isfinite(a) and not math.isfinite(b)
    return abs(a - b) <= 2.0 * gap * max(abs(a), abs(b)) + 1e-9


def format_horizon_table(bench: HorizonBench) -> str:
    """The markdown table of :func:`summary_rows`."""
    head = (
        f"Short-horizon MIQP, H = {bench.horizon}, {bench.ticks_per_step} ticks per step, pushes "
        f"up to {bench.push:g} m/s, gap {bench.gap:g}; times in ms on one core\n\n"
        "| scene | ticks | optimal (warm / cold) | warm median / p90 / p99 / max | "
        "cold median / p99 / max | nodes median / max (cold median) | warm start used | "
        "SCIP agrees (optimal) | SCIP median | SCIP / warm |\n"
        "|---|---|---|---|---|---|---|---|---|---|"
    )
    lines = [head]
    for r in summary_rows(bench):
        w, c = r["warm_ms"], r["cold_ms"]
        lines.append(
            f"| {r['scene']} | {r['ticks']} | {r['optimal']} / {r['cold_optimal']} | "
            f"{w['median']:.2f} / {w['p90']:.2f} / {w['p99']:.2f} / {w['max']:.2f} | "
            f"{c['median']:.2f} / {c['p99']:.2f} / {c['max']:.2f} | "
            f"{r['nodes_median']:g} / {r['nodes_max']} ({r['cold_nodes_median']:g}) | "
            f"{r['warm_used']} | {r['scip_agree']} of {r['scip_ticks']} ({r['scip_optimal']}) | "
            f"{r['scip_ms_median']:.1f} | {r['scip_over_warm']:.0f}x |"
        )
    return "\n".join(lines)


def bench_to_dict(bench: HorizonBench) -> dict[str, Any]:
    """JSON form: settings, the summary rows and every tick."""
    return {
        "horizon": bench.horizon,
        "ticks_per_step": bench.ticks_per_step,
        "push_m_per_s": bench.push,
        "gap": bench.gap,
        "summary": summary_rows(bench),
        "ticks": [asdict(t) for t in bench.ticks],
    }
