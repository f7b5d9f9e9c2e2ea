"""``footfall bench plan``: the direct SCIP model against the fast planner, same instances, one run;
``footfall bench sim``: the reduced-order simulation's python and compiled engines, same walk, one run.

Both solve the same MIQCQP (:func:`footfall.planning.miqcqp.build_footstep_problem`, document 000
eq. 5.11-5.18); only the backend differs (``scip`` vs ``bnb``, see :mod:`footfall.solvers.bnb`).
Instances are seeded random stepping-stone scenes (:func:`random_stepping_stones`) and optionally
built-in scenes, for every requested number of steps N and ALIP nodes K. The machine may be shared,
so the table reports the speed-up as a ratio of times measured in the same run; when the direct
model hits its time limit the ratio is a lower bound (printed ``>=``).

``footfall bench quadruped``: the document-001 slope walk's closed loop against bare ``mj_step``,
and the gait plan's time (:func:`benchmark_quadruped`).
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from footfall.models.biped import BipedParams
from footfall.planning.check import check_plan
from footfall.planning.miqcqp import plan_footsteps
from footfall.planning.plan import FootstepPlan, PlannerOptions
from footfall.solvers.base import SolveStatus
from footfall.terrain.scene import Scene, builtin_scene, random_stepping_stones

if TYPE_CHECKING:
    from footfall.sim.reduced.closed_loop import SimOptions

#: relative objective difference above which two optimal runs disagree (beyond both gaps)
AGREE_SLACK = 1e-6


@dataclass(frozen=True)
class BenchRun:
    """One solve of one instance.

    Attributes:
        instance: scene name.
        n_steps: N.
        n_nodes: K.
        regions: number of regions of the scene.
        solver: ``scip`` (direct) or ``bnb`` (fast).
        status: solve status.
        time: wall time of the planner call [s].
        objective: objective (nan without a plan).
        bound: proven lower bound (nan if none).
        gap: relative gap (inf if unknown).
        nodes: branch-and-bound nodes.
        check_ok: the independent checker accepts the plan (None without a plan).
    """

    instance: str
    n_steps: int
    n_nodes: int
    regions: int
    solver: str
    status: str
    time: float
    objective: float
    bound: float
    gap: float
    nodes: int
    check_ok: bool | None


@dataclass(frozen=True)
class BenchRow:
    """One line of the table: every instance of one (N, K), both planners.

    Attributes:
        n_steps, n_nodes: N and K.
        regions: region counts of the instances, as "min-max".
        instances: number of instances.
        direct, fast: the runs.
    """

    n_steps: int
    n_nodes: int
    regions: str
    instances: int
    direct: tuple[BenchRun, ...] = field(default=())
    fast: tuple[BenchRun, ...] = field(default=())

    @staticmethod
    def _times(runs: tuple[BenchRun, ...]) -> tuple[float, float]:
        ts = [r.time for r in runs]
        return (statistics.median(ts), max(ts)) if ts else (math.nan, math.nan)

    def speedup(self) -> tuple[float, bool]:
        """Median direct time over median fast time, and whether it is only a lower bound (some
        direct run stopped at its time limit or without proof)."""
        d_med, _ = self._times(self.direct)
        f_med, _ = self._times(self.fast)
        unproven = (
            SolveStatus.TIME_LIMIT.value,
            SolveStatus.FEASIBLE.value,
            SolveStatus.ERROR.value,
        )
        lower = any(r.status in unproven for r in self.direct)
        return (d_med / f_med if f_med > 0 else math.inf), lower

    def disagreements(self) -> list[str]:
        """Instances where the two runs contradict each other beyond the gaps: both optimal with
        different objectives, a fast optimum outside a time-limited direct run's [bound,
        incumbent], or one infeasible where the other found a plan."""
        out: list[str] = []
        if not self.direct:  # --fast-only: nothing to compare against
            return out
        for d, f in zip(self.direct, self.fast, strict=True):
            if d.status == f.status == SolveStatus.OPTIMAL.value:
                tol = max(d.gap, f.gap, 0.0) + AGREE_SLACK
                if abs(d.objective - f.objective) > tol * max(abs(d.objective), 1e-12) + 1e-9:
                    out.append(d.instance)
            elif f.status == SolveStatus.OPTIMAL.value and math.isfinite(d.objective):
                # a time-limited direct run brackets the optimum: bound <= optimum <= incumbent
                tol = max(f.gap, 0.0) + AGREE_SLACK
                scale = max(abs(f.objective), 1e-12)
                if f.objective > d.objective + tol * scale or (
                    math.isfinite(d.bound) and f.objective < d.bound - tol * scale
                ):
                    out.append(d.instance)
            elif d.status == SolveStatus.INFEASIBLE.value or f.status == "infeasible":
                if d.status != f.status and d.status != SolveStatus.TIME_LIMIT.value:
                    out.append(d.instance)
        return out


def bench_instances(
    seeds: Sequence[int], n_regions: int, robot: BipedParams, scenes: Sequence[str] = ()
) -> list[Scene]:
    """Seeded random stepping stones (``n_regions`` regions each) and the named built-in scenes,
    all with ``robot``."""
    out = [random_stepping_stones(int(s), n_regions, robot=robot) for s in seeds]
    for name in scenes:
        out.append(dataclasses.replace(builtin_scene(name), robot=robot))
    return out


def _run(
    scene: Scene, n: int, k: int, solver: str, options: PlannerOptions
) -> tuple[BenchRun, FootstepPlan]:
    t0 = time.perf_counter()
    plan = plan_footsteps(scene, None, n, dataclasses.replace(options, solver=solver))
    elapsed = time.perf_counter() - t0
    ok = check_plan(plan, scene).ok if plan.has_solution else None
    run = BenchRun(
        instance=scene.name,
        n_steps=n,
        n_nodes=k,
        regions=len(scene.terrain),
        solver=solver,
        status=plan.status.value,
        time=elapsed,
        objective=float(plan.objective),
        bound=float(plan.bound),
        gap=float(plan.gap),
        nodes=int(plan.stats.get("nodes", 0)),
        check_ok=ok,
    )
    return run, plan


def bench_plan(
    n_steps: Sequence[int] = (6, 10, 15),
    n_nodes: Sequence[int] = (5, 10),
    seeds: Sequence[int] = (0, 1, 2),
    n_regions: int = 8,
    scenes: Sequence[str] = (),
    time_limit_direct: float = 60.0,
    time_limit_fast: float = 60.0,
    gap: float = 1e-3,
    direct: bool = True,
    fast_threads: int = 2,
    progress: Callable[[BenchRun], Any] | None = None,
) -> list[BenchRow]:
    """Run the direct model (SCIP) and the fast planner on the same instances.

    Args:
        n_steps: numbers of footsteps N.
        n_nodes: numbers of ALIP nodes K per single support.
        seeds: seeds of the random stepping-stone scenes.
        n_regions: regions per random scene (start pad, stones, goal pad).
        scenes: names of built-in scenes to add.
        time_limit_direct, time_limit_fast: wall-time limits [s].
        gap: relative optimality gap of both.
        direct: also run the direct model (False: fast planner only).
        fast_threads: worker processes of the fast planner (the direct model uses SCIP's single
            thread, as in the issue's measurements).
        progress: called with every finished run.

    Returns:
        One :class:`BenchRow` per (N, K).
    """
    rows = []
    for k in n_nodes:
        robot = BipedParams(n_nodes=int(k))
        instances = bench_instances(seeds, n_regions, robot, scenes)
        for n in n_steps:
            d_runs: list[BenchRun] = []
            f_runs: list[BenchRun] = []
            for scene in instances:
                pairs = [("bnb", time_limit_fast, fast_threads, f_runs)]
                if direct:
                    pairs.insert(0, ("scip", time_limit_direct, 1, d_runs))
                for solver, limit, threads, sink in pairs:
                    opts = PlannerOptions(time_limit=limit, gap=gap, threads=threads)
                    run, _ = _run(scene, int(n), int(k), solver, opts)
                    sink.append(run)
                    if progress is not None:
                        progress(run)
            counts = [len(s.terrain) for s in instances]
            rows.append(
                BenchRow(
                    n_steps=int(n),
                    n_nodes=int(k),
                    regions=f"{min(counts)}-{max(counts)}"
                    if min(counts) != max(counts)
                    else str(counts[0]),
                    instances=len(instances),
                    direct=tuple(d_runs),
                    fast=tuple(f_runs),
                )
            )
    return rows


def _fmt_obj(runs: tuple[BenchRun, ...]) -> str:
    objs = [r.objective for r in runs if math.isfinite(r.objective)]
    return f"{statistics.median(objs):.4f}" if objs else "-"


def _fmt_gap(runs: tuple[BenchRun, ...]) -> str:
    """Worst gap over the runs that returned a plan (infeasible ones have none)."""
    gaps = [r.gap for r in runs if math.isfinite(r.objective)]
    if not gaps:
        return "-"
    worst = max(gaps)
    return "inf" if math.isinf(worst) else f"{worst:.1e}"


def _status(runs: tuple[BenchRun, ...]) -> str:
    n_opt = sum(r.status == SolveStatus.OPTIMAL.value for r in runs)
    n_inf = sum(r.status == SolveStatus.INFEASIBLE.value for r in runs)
    s = f"{n_opt}/{len(runs)} opt"
    return s + (f", {n_inf} inf" if n_inf else "")


def format_table(rows: Sequence[BenchRow]) -> str:
    """Markdown table: per (N, K), median/max time, worst gap, median objective, statuses of both,
    and the speed-up (``>=`` when a direct run stopped at its time limit)."""
    head = (
        "| N | K | regions | inst | direct med/max [s] | direct gap | direct status | "
        "fast med/max [s] | fast gap | fast status | objective direct / fast | speed-up |"
    )
    lines = [head, "|" + "---|" * 12]
    for row in rows:
        f_med, f_max = BenchRow._times(row.fast)
        if row.direct:
            d_med, d_max = BenchRow._times(row.direct)
            ratio, lower = row.speedup()
            d_cells = f"{d_med:.2f} / {d_max:.2f} | {_fmt_gap(row.direct)} | {_status(row.direct)}"
            sp = f"{'>=' if lower else ''}{ratio:.1f}x"
            obj = f"{_fmt_obj(row.direct)} / {_fmt_obj(row.fast)}"
        else:
            d_cells, sp, obj = "- | - | -", "-", f"- / {_fmt_obj(row.fast)}"
        lines.append(
            f"| {row.n_steps} | {row.n_nodes} | {row.regions} | {row.instances} | {d_cells} | "
            f"{f_med:.2f} / {f_max:.2f} | {_fmt_gap(row.fast)} | {_status(row.fast)} | {obj} | "
            f"{sp} |"
        )
    bad = [(r.n_steps, r.n_nodes, i) for r in rows for i in r.disagreements()]
    unchecked = [
        (r.n_steps, r.n_nodes, run.instance)
        for r in rows
        for run in (*r.direct, *r.fast)
        if run.check_ok is False
    ]
    lines.append("")
    lines.append(
        "times: median / max over the instances; gap: worst over the runs with a plan; objective:"
        " median over the runs with a plan (a time-limited direct run reports its incumbent)"
    )
    lines.append(
        "objective agreement (both optimal: equal within the gap; direct time-limited: the fast"
        " optimum lies between the direct bound and incumbent): "
        + ("all agree" if not bad else f"DISAGREE on {bad}")
    )
    lines.append(
        "independent plan check: " + ("all plans pass" if not unchecked else f"FAIL {unchecked}")
    )
    return "\n".join(lines)


def rows_to_dict(rows: Sequence[BenchRow]) -> list[dict[str, Any]]:
    """JSON-ready form of the runs."""
    return [dataclasses.asdict(run) for row in rows for run in (*row.direct, *row.fast)]


def rows_from_dict(runs: Sequence[dict[str, Any]]) -> list[BenchRow]:
    """Rebuild the table rows from :func:`rows_to_dict` output (to re-print a saved run)."""
    keyed: dict[tuple[int, int], list[BenchRun]] = {}
    for d in runs:
        run = BenchRun(**d)
        keyed.setdefault((run.n_steps, run.n_nodes), []).append(run)
    out = []
    for (n, k), group in keyed.items():
        direct = tuple(r for r in group if r.solver != "bnb")
        fast = tuple(r for r in group if r.solver == "bnb")
        counts = [r.regions for r in fast]
        lo, hi = min(counts), max(counts)
        out.append(BenchRow(n, k, str(lo) if lo == hi else f"{lo}-{hi}", len(fast), direct, fast))
    return out


# --- reduced-order simulation speed ---

#: engines of the reduced-order simulation, in the order they are run and reported
SIM_ENGINES = ("python", "compiled")


@dataclass(frozen=True)
class SimSpeed:
    """Speed of one engine of :func:`footfall.sim.simulate` on one walk, over repeated runs.

    Attributes:
        engine: ``python`` (reference) or ``compiled``.
        n_nodes: MPC nodes K (K - 1 torque blocks).
        control_rate: control rate [Hz].
        runs: timed runs.
        sim_time: simulated time of one run [s].
        wall_median: median wall time of a run [s].
        wall_best: best wall time of a run [s].
        mpc_median: median over the runs of the per-run median MPC solve time [s].
        mpc_p99: median over the runs of the per-run 99th percentile MPC solve time [s].
        mpc_solves: MPC solves per run.
        mpc_fallbacks: failed MPC solves per run.
        fell: the walk fell.
        max_com_diff: largest CoM difference from the python engine's run [m] (0 for it).
    """

    engine: str
    n_nodes: int
    control_rate: float
    runs: int
    sim_time: float
    wall_median: float
    wall_best: float
    mpc_median: float
    mpc_p99: float
    mpc_solves: int
    mpc_fallbacks: int
    fell: bool
    max_com_diff: float

    @property
    def realtime(self) -> float:
        """Simulated time over the median wall time ("x real time")."""
        return self.sim_time / self.wall_median

    @property
    def realtime_best(self) -> float:
        """Simulated time over the best wall time."""
        return self.sim_time / self.wall_best


def bench_sim_options(control_rate: float = 500.0) -> SimOptions:
    """The disturbed walk of the benchmark: estimate noise (2 mm, 0.02 m/s) and two pushes, 10 N s
    sideways at 1 s and 12 N s at 3 s (so the torque discs bind on about a tenth of the ticks)."""
    from footfall.sim import Push, SimOptions

    return SimOptions(
        control_rate=control_rate,
        noise_pos=0.002,
        noise_vel=0.02,
        pushes=(Push.horizontal(1.0, 10.0, math.pi / 2), Push.horizontal(3.0, 12.0, 0.3)),
    )


def bench_sim(
    plan: FootstepPlan,
    n_nodes: Sequence[int | None] = (None, 10),
    runs: int = 5,
    options: SimOptions | None = None,
) -> list[SimSpeed]:
    """Time both engines of the reduced-order closed loop on ``plan`` in the same run.

    For every K the engines run alternately (python, compiled, python, ...) so that the load of a
    shared machine hits both alike; one untimed run per engine first builds the MPC and loads the
    compiled kernel. Speed is simulated time over wall time (MPC, plant and metrics included).

    Args:
        plan: a footstep plan with states.
        n_nodes: MPC nodes K to run (None: the plan robot's K).
        runs: timed runs per engine and K, >= 1.
        options: simulation options (default :func:`bench_sim_options`); ``engine`` and
            ``mpc_nodes`` are set by the benchmark.

    Returns:
        One :class:`SimSpeed` per (K, engine), engines in :data:`SIM_ENGINES` order.
    """

    from footfall.errors import InputError
    from footfall.sim import simulate

    if isinstance(runs, bool) or not isinstance(runs, int) or runs < 1:
        raise InputError("runs", runs, "an integer >= 1")
    opts0 = bench_sim_options() if options is None else options
    out: list[SimSpeed] = []
    for k in n_nodes:
        base = dataclasses.replace(opts0, mpc_nodes=k)
        opts = {e: dataclasses.replace(base, engine=e) for e in SIM_ENGINES}
        first = {e: simulate(plan, o) for e, o in opts.items()}  # warm-up, and the trajectories
        timed: dict[str, list[Any]] = {e: [] for e in SIM_ENGINES}
        for _ in range(runs):
            for e, o in opts.items():
                timed[e].append(simulate(plan, o).metrics)
        ref = first[SIM_ENGINES[0]].com
        for e in SIM_ENGINES:
            ms = timed[e]
            com = first[e].com
            diff = float(np.abs(com - ref).max()) if com.shape == ref.shape else math.inf
            walls = [m.wall_time for m in ms]
            out.append(
                SimSpeed(
                    engine=e,
                    n_nodes=plan.robot.n_nodes if k is None else int(k),
                    control_rate=opts0.control_rate,
                    runs=runs,
                    sim_time=ms[0].sim_time,
                    wall_median=statistics.median(walls),
                    wall_best=min(walls),
                    mpc_median=statistics.median(m.mpc_time_median for m in ms),
                    mpc_p99=statistics.median(m.mpc_time_p99 for m in ms),
                    mpc_solves=ms[0].mpc_solves,
                    mpc_fallbacks=ms[0].mpc_fallbacks,
                    fell=ms[0].fell,
                    max_com_diff=diff,
                )
            )
    return out


def format_sim_table(rows: Sequence[SimSpeed]) -> str:
    """Markdown table: per K and engine, x real time (median and best run), MPC solve median / p99,
    failed solves, CoM agreement with the python engine, and the compiled / python speed ratio."""
    lines = [
        "| K | engine | simulated [s] | wall median [s] | x real time (median / best) | "
        "MPC median / p99 [us] | failed solves | max CoM diff [m] | speed ratio |",
        "|" + "---|" * 9,
    ]
    base: dict[int, float] = {}
    for r in rows:
        if r.engine == SIM_ENGINES[0]:
            base[r.n_nodes] = r.realtime
        ratio = r.realtime / base[r.n_nodes] if r.n_nodes in base else math.nan
        lines.append(
            f"| {r.n_nodes} | {r.engine} | {r.sim_time:.2f} | {r.wall_median:.4f} | "
            f"{r.realtime:.0f}x / {r.realtime_best:.0f}x | "
            f"{1e6 * r.mpc_median:.1f} / {1e6 * r.mpc_p99:.1f} | {r.mpc_fallbacks}/{r.mpc_solves} | "
            f"{r.max_com_diff:.1e} | {ratio:.1f}x |"
        )
    rate = rows[0].control_rate if rows else math.nan
    lines.append("")
    lines.append(
        f"control rate {rate:g} Hz; x real time = simulated time / wall time of a whole run (MPC, "
        "plant, metrics); speed ratio = x real time over the python engine's, same run; MPC times "
        "are per control tick (python: the MPC.solve_theta call; compiled: the compiled solve, "
        "timed inside the kernel)"
    )
    return "\n".join(lines)


def sim_speed_to_dict(rows: Sequence[SimSpeed]) -> list[dict[str, Any]]:
    """JSON-ready form of the rows (with the derived x real time)."""
    return [
        {**dataclasses.asdict(r), "realtime": r.realtime, "realtime_best": r.realtime_best}
        for r in rows
    ]


def benchmark_quadruped(
    slope_deg: float = 15.0,
    body_deg: float = 10.0,
    sim_cycles: int = 6,
    plan_cycles: int = 10,
    plan_repeats: int = 20,
) -> dict[str, Any]:
    """Speed of the slope walk (issue goals: >= 5x real time; 10-cycle plan < 50 ms).

    Measures, in one run on the current core:

    * the closed-loop simulation (control, contact forces, CoP, margins, slip; no video) as
      simulated seconds per wall second, against a baseline of bare ``mj_step`` calls on the same
      model for the same simulated time (so ``overhead_ratio`` is what footfall's loop costs on
      top of the physics);
    * the gait plan of ``plan_cycles`` cycles (``plan_gait``) and its dense sampling at 100 Hz
      with joint angles and eq.-(5) ZMP (``GaitPlan.sample``), median of ``plan_repeats``.

    Returns:
        A JSON-ready dict of timings and ratios.
    """
    import mujoco

    from footfall.quadruped import GaitParams, QuadrupedRobot, plan_gait
    from footfall.sim.quadruped.sim import QuadrupedSim, simulate

    robot = QuadrupedRobot()
    slope, pitch = math.radians(slope_deg), math.radians(body_deg)
    plan = plan_gait(robot, GaitParams(slope, pitch, cycles=sim_cycles))
    done = simulate(plan)
    res = done.trace
    loop_rtf = res.sim_time / res.wall_time

    base = QuadrupedSim(robot, slope)
    ref = plan.sample(0.01, with_zmp=False)
    base.set_pose(ref.body_pos[0], float(ref.body_pitch[0]), ref.joints[0])
    steps = round(res.sim_time / base.model.opt.timestep)
    t0 = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(base.model, base.data)
    base_wall = time.perf_counter() - t0
    base_rtf = res.sim_time / base_wall

    params = GaitParams(slope, pitch, cycles=plan_cycles)
    plan_gait(robot, params).sample(0.01)  # warm-up (imports, caches)
    plan_times, sample_times = [], []
    for _ in range(plan_repeats):
        t0 = time.perf_counter()
        p = plan_gait(robot, params)
        t1 = time.perf_counter()
        p.sample(0.01)
        plan_times.append(t1 - t0)
        sample_times.append(time.perf_counter() - t1)
    plan_ms = 1e3 * float(np.median(plan_times))
    sample_ms = 1e3 * float(np.median(sample_times))
    return {
        "slope_deg": slope_deg,
        "body_deg": body_deg,
        "sim_cycles": sim_cycles,
        "simulated_s": res.sim_time,
        "loop_wall_s": res.wall_time,
        "loop_realtime_factor": loop_rtf,
        "baseline_mj_step_realtime_factor": base_rtf,
        "overhead_ratio": base_rtf / loop_rtf,
        "realtime_goal": 5.0,
        "realtime_vs_goal": loop_rtf / 5.0,
        "fell": done.metrics.fell,
        "plan_cycles": plan_cycles,
        "plan_ms_median": plan_ms,
        "sample_100hz_ms_median": sample_ms,
        "plan_plus_sample_ms_median": plan_ms + sample_ms,
        "plan_goal_ms": 50.0,
        "plan_goal_over_plan_ms": 50.0 / plan_ms,
        "plan_goal_over_plan_plus_sample_ms": 50.0 / (plan_ms + sample_ms),
    }
