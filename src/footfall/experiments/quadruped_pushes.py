"""Lateral pushes on a quadruped walking document 001's gait up a slope: the largest velocity
change it survives, per robot, with paired seeds (beyond document 001).

A trial pushes the trunk once, sideways (world +y or -y, across the slope), for ``duration``
seconds with the impulse ``M dv`` [N s] (``M`` the robot's mass): the trunk's velocity changes by
about ``dv`` [m/s]. Seed ``s`` draws the push's start uniformly over the middle half of the walk
and its side (left or right) from ``numpy.random.default_rng(s)``; the same seed gives the same
start and side at every level, so levels are paired. A trial succeeds when the robot does not fall
and its trunk ends within 25 % of the planned distance of where the plan ends. A level is
survived when every seed succeeds; the summary gives each level's successes with a 95 % Wilson
interval and the largest level survived.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Callable
from dataclasses import asdict, dataclass

import numpy as np

from footfall.errors import InputError
from footfall.experiments.study.stats import wilson
from footfall.quadruped import GaitParams, plan_gait
from footfall.quadruped.gait import BODY_RATIO, GaitPlan
from footfall.quadruped.scaling import scale_gait
from footfall.robots.quadruped import resolve_quadruped
from footfall.sim.disturbance import Push
from footfall.sim.quadruped.mjcf import robot_settings
from footfall.sim.quadruped.sim import simulate

#: a walk succeeds when its trunk ends within this share of the planned distance of the plan's end
DRIFT_SHARE = 0.25
#: pushes start within this span of the walk (shares of its duration)
PUSH_SPAN = (0.25, 0.75)


@dataclass(frozen=True)
class QuadrupedPushRow:
    """One pushed walk: the robot, the push (velocity change, impulse, start, side) and the
    measured outcome."""

    robot: str
    slope_deg: float
    dv_m_s: float
    seed: int
    impulse_n_s: float
    start_s: float
    side: str
    fell: bool
    drift_m: float
    planned_distance_m: float
    success: bool


def push_of_seed(seed: int, duration_s: float) -> tuple[float, float]:
    """(start share of the walk in ``PUSH_SPAN``, side +1 left / -1 right) of seed ``seed``."""
    rng = np.random.default_rng(seed)
    share = float(rng.uniform(*PUSH_SPAN))
    side = 1.0 if rng.random() < 0.5 else -1.0
    return share, side


def check_push_inputs(dvs: tuple[float, ...], seeds: tuple[int, ...], duration: float) -> None:
    """The levels, seeds and push length, each checked (an error names the first bad one)."""
    if not dvs or any(not (math.isfinite(v) and v >= 0.0) for v in dvs):
        raise InputError("dv", dvs, "velocity changes >= 0 [m/s]")
    if not seeds:
        raise InputError("seeds", seeds, "at least one seed")
    if not (math.isfinite(duration) and duration > 0.0):
        raise InputError("duration", duration, "a push length > 0 [s]")


def push_walk_plan(robot_name: str, slope_deg: float, cycles: int) -> GaitPlan:
    """The walk every push of :func:`run_quadruped_pushes` is applied to: document 001's gait up
    ``slope_deg`` (the body at ``BODY_RATIO`` of it), scaled to the robot."""
    robot = resolve_quadruped(robot_name)
    if not math.isfinite(slope_deg):
        raise InputError("slope_deg", slope_deg, "a finite slope [deg]")
    slope = math.radians(slope_deg)
    params = scale_gait(
        robot, GaitParams(slope=slope, body_pitch=BODY_RATIO * slope, cycles=cycles)
    )
    return plan_gait(robot, params)


def run_quadruped_pushes(
    robot_name: str,
    slope_deg: float,
    dvs: tuple[float, ...],
    seeds: tuple[int, ...],
    duration: float = 0.05,
    cycles: int = 4,
    progress: Callable[[QuadrupedPushRow], None] | None = None,
    plan: GaitPlan | None = None,
) -> list[QuadrupedPushRow]:
    """Walk ``robot_name`` up ``slope_deg`` once per (level, seed) with that seed's lateral push
    (module docstring); rows in level-major order. ``plan``: the walk of
    :func:`push_walk_plan` when the caller has planned it already."""
    check_push_inputs(dvs, seeds, duration)
    robot = resolve_quadruped(robot_name)
    if plan is None:
        plan = push_walk_plan(robot_name, slope_deg, cycles)
    settings = robot_settings(robot)
    rows = []
    for dv in dvs:
        for seed in seeds:
            share, side = push_of_seed(seed, duration)
            start = share * plan.duration
            impulse = robot.total_mass * dv
            pushes = (
                (Push.horizontal(start, impulse, side * math.pi / 2, duration),) if dv > 0 else ()
            )
            m = simulate(plan, settings, controller="wbc", pushes=pushes).metrics
            planned = abs(m.planned_distance_up_slope_m)
            row = QuadrupedPushRow(
                robot=robot.name,
                slope_deg=slope_deg,
                dv_m_s=dv,
                seed=seed,
                impulse_n_s=impulse,
                start_s=start,
                side="left" if side > 0 else "right",
                fell=m.fell,
                drift_m=m.trunk_drift_from_plan_m,
                planned_distance_m=planned,
                success=(not m.fell) and m.trunk_drift_from_plan_m <= DRIFT_SHARE * planned,
            )
            rows.append(row)
            if progress is not None:
                progress(row)
    return rows


def summary_lines(rows: list[QuadrupedPushRow]) -> list[str]:
    """A Markdown table: per level the successes of n, the 95 % Wilson interval, and the largest
    level every seed survived."""
    levels = sorted({r.dv_m_s for r in rows})
    robot = rows[0].robot if rows else "?"
    out = [
        f"{robot}, lateral pushes of 0.05 s on {rows[0].slope_deg:g} deg (paired seeds):"
        if rows
        else "no rows",
        "",
        "| dv [m/s] | impulse [N s] | success | 95 % Wilson |",
        "|---|---|---|---|",
    ]
    survived = []
    for dv in levels:
        sel = [r for r in rows if r.dv_m_s == dv]
        k, n = sum(r.success for r in sel), len(sel)
        lo, hi = wilson(k, n)
        out.append(
            f"| {dv:g} | {sel[0].impulse_n_s:.2f} | {k}/{n} | {100 * lo:.0f}-{100 * hi:.0f} % |"
        )
        survived.append(k == n)
    out.append("")
    out.append(_largest_survived(levels, survived))
    return out


def _largest_survived(levels: list[float], survived: list[bool]) -> str:
    """The summary line: the largest level every seed survived, said with what qualifies it
    (no level of the grid failed: the limit is at or above it; a lower level failed)."""
    best = max((dv for dv, ok in zip(levels, survived, strict=True) if ok), default=None)
    if best is None:
        return "no level every seed survived"
    if all(survived):
        return f"largest level every seed survived: >= {best:g} m/s (no level of the grid failed)"
    below = [dv for dv, ok in zip(levels, survived, strict=True) if not ok and dv < best]
    note = f" (but not {', '.join(f'{v:g}' for v in below)} m/s)" if below else ""
    return f"largest level every seed survived: {best:g} m/s{note}"


def rows_csv(rows: list[QuadrupedPushRow]) -> str:
    """The rows as CSV text (a header line, one line per walk)."""
    buf = io.StringIO()
    fields = list(QuadrupedPushRow.__dataclass_fields__)
    w = csv.DictWriter(buf, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    for r in rows:
        w.writerow(asdict(r))
    return buf.getvalue()
