"""Region-aware MPC tick (issue 23): the MPC of eq. (5.19) with region rows, timed per tick.

Run: ``OPENBLAS_NUM_THREADS=1 PYTHONPATH=src python benchmarks/bench_region_mpc.py``

Instance: the flat scene's reactive plan (8 steps) with every footstep on a stone of its own
(0.26 x 0.16 m: 3 cm of room around the 0.2 x 0.1 m sole), walked by the reduced-order closed
loop at 500 Hz with ``region_aware="nearby"`` under one push per run (0, 2, 4, 6, 8 N s, four
directions). Every MPC input is recorded, then replayed tick by tick in the same order (warm
starts as in the loop) through three fresh solvers, each timed with ``perf_counter``:

- ``free``: document 000's MPC (:meth:`MPC.solve_theta`), today's tick;
- ``planned``: :meth:`RegionMPC.solve` with the planned stone only;
- ``nearby``: the same with every stone within reach as a candidate (one QP each, pruned by the
  bound-free relaxation); its worst tick is the per-candidate variant's worst case.

Reported: median, p99 and max [us] and how each region solve was found. All three run in the
same process, so a loaded machine slows them alike.
"""

from __future__ import annotations

import os
import time
from collections import Counter
from dataclasses import replace

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np

import footfall.sim.reduced.regions as reduced_regions
from footfall.control import MPC
from footfall.control.adjusters import SWITCH_MARGIN
from footfall.control.region_mpc import RegionMPC, region_rows, regions_in_reach
from footfall.planning.reactive import plan_reactive
from footfall.sim import Push, SimOptions, simulate
from footfall.sim.reduced.closed_loop import _mpc_model
from footfall.terrain import builtin_scene
from footfall.terrain.region import Region

STONE_HALF = np.array([0.13, 0.08])
PUSHES = (0.0, 2.0, 4.0, 6.0, 8.0)
DIRECTIONS = (0.0, 0.5 * np.pi, np.pi, 1.5 * np.pi)


def stones_plan(n: int = 8):  # type: ignore[no-untyped-def]
    plan = plan_reactive(builtin_scene("flat"))
    box = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * STONE_HALF
    regions = tuple(
        Region.from_height(f"stone{j}", 0.0, f[:2] + box) for j, f in enumerate(plan.footsteps)
    )
    return replace(plan, regions=tuple(r.name for r in regions)), regions


def record(plan, regions) -> tuple[list[tuple], int, int]:  # type: ignore[no-untyped-def]
    calls: list[tuple] = []
    orig = reduced_regions.RegionFeet.solve

    def rec(self, i, k, theta, stance, p_ref):  # type: ignore[no-untyped-def]
        calls.append((i, k, theta.copy(), np.array(stance), np.array(p_ref)))
        return orig(self, i, k, theta, stance, p_ref)

    reduced_regions.RegionFeet.solve = rec  # type: ignore[method-assign]
    falls = runs = 0
    try:
        for imp in PUSHES:
            for ang in DIRECTIONS if imp > 0 else (0.0,):
                push = (Push.horizontal(1.2, imp, ang, 0.1),) if imp > 0 else ()
                opts = SimOptions(pushes=push, region_aware="nearby")
                res = simulate(plan, opts, regions=regions)
                falls += res.metrics.fell
                runs += 1
    finally:
        reduced_regions.RegionFeet.solve = orig  # type: ignore[method-assign]
    return calls, falls, runs


def replay(plan, regions, calls, variant: str) -> tuple[np.ndarray, Counter]:  # type: ignore[no-untyped-def]
    mdl = _mpc_model(plan.robot, SimOptions())
    robot = plan.robot
    by_name = {r.name: r for r in regions}
    mpc = MPC(mdl)
    rmpc = RegionMPC(mpc)
    times = np.zeros(len(calls))
    methods: Counter = Counter()
    nearby: dict[tuple[int, tuple[float, ...]], tuple[str, ...]] = {}
    rows: dict[tuple[int, tuple[float, ...], str], object] = {}
    for j, (i, k, theta, stance, p_ref) in enumerate(calls):
        t0 = time.perf_counter()
        if variant == "free":
            mpc.solve_theta(k, theta, stance, p_ref)
        else:
            names = [plan.regions[i + 1]]
            key = (i, tuple(np.round(stance, 4)))  # once per phase, as the loop does
            if variant == "nearby":
                if key not in nearby:
                    nearby[key] = regions_in_reach(
                        regions, stance, float(plan.headings[i]), plan.sides[i], robot
                    )
                names += [n for n in nearby[key] if n != names[0]]
            heading = float(plan.headings[i + 1])
            for n in names:
                if (*key, n) not in rows:
                    rows[(*key, n)] = region_rows(by_name[n], stance, heading, robot)
            cands = [rows[(*key, n)] for n in names]
            rs = rmpc.solve(k, theta, stance, p_ref, cands, SWITCH_MARGIN)
            methods[rs.method] += 1
        times[j] = time.perf_counter() - t0
    return times, methods


def main() -> None:
    plan, regions = stones_plan()
    calls, falls, runs = record(plan, regions)
    print(f"{len(calls)} recorded ticks from {runs} runs ({falls} falls)")
    print("| variant | median [us] | p99 [us] | max [us] | region solves by method |")
    print("|---|---|---|---|---|")
    for variant in ("free", "planned", "nearby"):
        times, methods = replay(plan, regions, calls, variant)
        us = times * 1e6
        how = ", ".join(f"{m} {c}" for m, c in methods.most_common()) or "-"
        print(
            f"| {variant} | {np.median(us):.0f} | {np.percentile(us, 99):.0f} | "
            f"{us.max():.0f} | {how} |"
        )


if __name__ == "__main__":
    main()
