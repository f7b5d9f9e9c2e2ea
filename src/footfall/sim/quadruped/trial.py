"""The MuJoCo quadruped of the trial pipeline (:mod:`footfall.sim.trial`): the document-001 walk
gait (:func:`~footfall.sim.quadruped.sim.simulate`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from footfall.errors import InputError
from footfall.quadruped.gait import GaitPlan, PhaseKind
from footfall.results.outcome import Outcome
from footfall.sim.disturbance import Push, SupportTimeline
from footfall.sim.quadruped.mjcf import SimSettings
from footfall.sim.quadruped.sim import CONTROLLERS, simulate
from footfall.sim.quadruped.slip import SlipGuard

#: a walk succeeds when it does not fall and ends within this share of its planned distance
#: from the planned final body position (a walk that slides back down the slope fails)
DRIFT_SHARE = 0.25


@dataclass(frozen=True)
class QuadrupedPlant:
    """The quadruped in MuJoCo. Its single supports are the gait's swings (three feet down).

    Attributes:
        controller: ``servo`` (the document's joint servos) or ``wbc`` (whole-body QP).
        settings: physics settings (None: defaults; a quadruped scene's friction goes here).
        slip_guard: stop the gait when a foot slips (None: off).
        video_path: write an MP4 here (None: no video).
    """

    controller: str = "servo"
    settings: SimSettings | None = None
    slip_guard: SlipGuard | None = None
    video_path: Path | None = None

    name = "quadruped"

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLERS:
            raise InputError("controller", self.controller, f"one of {', '.join(CONTROLLERS)}")

    def timeline(self, plan: GaitPlan) -> SupportTimeline:
        """The swings, on the gait's clock (0 when the gait starts, after the settling)."""
        swings = [p for p in plan.phases if p.kind is PhaseKind.SWING]
        return SupportTimeline(
            swings[0].t0 if swings else 0.0,
            tuple(p.t0 for p in swings),
            tuple(p.duration for p in swings),
        )

    def mass(self, plan: GaitPlan) -> float:
        """The robot's total mass [kg]."""
        return float(plan.robot.total_mass)

    def run(self, scene: Any, plan: GaitPlan, pushes: tuple[Push, ...], seed: int) -> Outcome:
        """Simulate the gait; ``scene`` and ``seed`` are unused (the plan carries its ground,
        the simulation is deterministic)."""
        res = simulate(
            plan,
            self.settings,
            video_path=self.video_path,
            controller=self.controller,
            pushes=pushes,
            slip_guard=self.slip_guard,
        )
        m = res.metrics
        planned = abs(m.planned_distance_up_slope_m)
        return Outcome(
            plant=self.name,
            success=bool(not m.fell and m.trunk_drift_from_plan_m <= DRIFT_SHARE * planned),
            fell=bool(m.fell),
            fall_time=m.fall_time_s if m.fall_time_s is not None else math.nan,
            cop_error_mean=_nan(m.zmp_error_mean_m),
            cop_error_max=_nan(m.zmp_error_max_m),
            goal_error=m.trunk_drift_from_plan_m,
            sim_time=m.sim_time_s,
            detail=res,
        )


def _nan(x: float | None) -> float:
    return math.nan if x is None else x
