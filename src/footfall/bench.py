"""``footfall bench plan``: the direct SCIP model against the fast planner, same instances, one run.

Both solve the same MIQCQP (:func:`footfall.planning.miqcqp.build_footstep_problem`, document 000
eq. 5.11-5.18); only the backend differs (``scip`` vs ``bnb``, see :mod:`footfall.planning.fast`).
Instances are seeded random stepping-stone scenes (:func:`random_stepping_stones`) and optionally
built-in scenes, for every requested number of steps N and ALIP nodes K. The machine may be shared,
so the table reports the speed-up as a ratio of times measured in the same run; when the direct
model hits its time limit the ratio is a lower bound (printed ``>=``).
"""

from __future__ import annotations

import dataclasses
import math
import statistics
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

from footfall.models.biped import BipedParams
from footfall.planning.check import check_plan
from footfall.planning.miqcqp import plan_footsteps
from footfall.planning.plan import FootstepPlan, PlannerOptions
from footfall.solvers.base import SolveStatus
from footfall.terrain.scene import Scene, builtin_scene, random_stepping_stones

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
