"""The document-001 slope walk as the CLI runs it: one plan per ZMP strategy, then a table of the
strategies' body sway, margin and speed measured in MuJoCo (document 001, sec. 4)."""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING, Any

from footfall.errors import InputError
from footfall.quadruped.gait import GaitParams, GaitPlan, ZmpStrategy, plan_gait
from footfall.quadruped.robot import QuadrupedRobot

if TYPE_CHECKING:
    from footfall.results.quadruped import QuadrupedMetrics, QuadrupedResult


def plan_strategies(
    robot: QuadrupedRobot, params: GaitParams, compare: bool
) -> tuple[dict[ZmpStrategy, GaitPlan], dict[str, str]]:
    """Plan ``params`` and, with ``compare``, the same gait under every other ZMP strategy.

    Every plan is built (and validated) before any simulation starts: an InputError of
    ``params`` propagates, one of another strategy is collected instead.

    Returns:
        ``(plans by strategy, the first one being params.strategy; errors by strategy value)``.
    """
    plans = {params.strategy: plan_gait(robot, params)}
    errors: dict[str, str] = {}
    if compare:
        for other in ZmpStrategy:
            if other is not params.strategy:
                try:
                    plans[other] = plan_gait(robot, replace(params, strategy=other))
                except InputError as exc:
                    errors[other.value] = str(exc)
    return plans, errors


def _row(m: QuadrupedMetrics) -> dict[str, Any]:
    """One strategy's line of the comparison table."""
    return {
        "shifts_per_cycle": m.body_sway_planned.shifts_per_cycle,
        "planned_path_per_cycle_m": m.body_sway_planned.path_per_cycle_m,
        "measured_path_per_cycle_m": m.body_sway_measured.path_per_cycle_m,
        "measured_lateral_path_per_cycle_m": m.body_sway_measured.lateral_path_per_cycle_m,
        "measured_excess_path_per_cycle_m": m.body_sway_measured.excess_path_per_cycle_m,
        "stability_margin_min_m": m.stability_margin_min_m,
        "mean_speed_m_s": m.mean_speed_m_s,
        "fell": m.fell,
    }


def compare_strategies(
    plans: dict[ZmpStrategy, GaitPlan], done: QuadrupedResult
) -> dict[str, dict[str, Any]]:
    """Table of body sway, margin and speed by strategy value, simulating every plan but the first
    (whose simulation is ``done``), with ``done``'s controller."""
    from footfall.sim.quadruped.sim import simulate

    first = next(iter(plans))
    return {
        s.value: _row((done if s is first else simulate(p, controller=done.controller)).metrics)
        for s, p in plans.items()
    }
