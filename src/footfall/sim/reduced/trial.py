"""The reduced-order plant of the trial pipeline (:mod:`footfall.sim.trial`): the closed loop of
:func:`~footfall.sim.reduced.closed_loop.simulate` (document 000, sections 5.4-5.5)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

from footfall.control.mpc import CondensedMPC
from footfall.planning.plan import FootstepPlan
from footfall.results.outcome import Outcome
from footfall.sim.disturbance import Push, SupportTimeline
from footfall.sim.reduced.closed_loop import SimOptions, mpc_key, mpc_model, simulate
from footfall.sim.trial import check_settings
from footfall.terrain.scene import Scene


@dataclass(frozen=True)
class ReducedPlant:
    """The ALIP closed loop with a rectangular sole.

    Attributes:
        options: the loop's options (noise, model mismatch, rate, engine, region handling);
            their ``pushes`` must be empty: pushes come from the trial's disturbance.
    """

    options: SimOptions = field(default_factory=SimOptions)
    _mpcs: dict[str, CondensedMPC] = field(
        default_factory=dict, init=False, repr=False, compare=False, hash=False
    )

    name = "reduced"

    def __post_init__(self) -> None:
        check_settings(self.options, SimOptions, "a SimOptions")

    def timeline(self, plan: FootstepPlan) -> SupportTimeline:
        """The walk starts at once: single support i starts at ``i (T_ss + T_ds)``,
        standing on footstep i."""
        return SupportTimeline.periodic(
            0.0, plan.n_steps, plan.robot.t_ss, plan.robot.t_ds, plan.headings, plan.sides
        )

    def mass(self, plan: FootstepPlan) -> float:
        """The plan robot's mass [kg] (the model's, before any mismatch)."""
        return float(plan.robot.mass)

    def run(self, scene: Scene, plan: FootstepPlan, pushes: tuple[Push, ...], seed: int) -> Outcome:
        """Simulate with ``seed`` for the estimate noise and placement errors; the condensed MPC
        of the plan's robot is built once per plant."""
        key = mpc_key(plan.robot, self.options)
        if key not in self._mpcs:
            self._mpcs[key] = mpc_model(plan.robot, self.options)
        res = simulate(
            plan,
            replace(self.options, pushes=pushes, seed=seed),
            goal=scene.goal.position,
            regions=scene.terrain.regions,
            mpc=self._mpcs[key],
        )
        m = res.metrics
        return Outcome(
            plant=self.name,
            success=bool(m.success),
            fell=bool(m.fell),
            fall_time=m.fall_time,
            zmp_offset_mean=m.zmp_offset_mean,
            zmp_offset_max=m.zmp_offset_max,
            footstep_error_mean=m.footstep_dev_mean,
            goal_error=m.goal_error,
            steps_landed=int(m.steps_taken),
            footsteps_off_terrain=m.footsteps_off_regions,
            sim_time=m.sim_time,
            detail=res,
        )

    def __getstate__(self) -> dict[str, Any]:
        # the MPC cache stays in its process: a copy sent to a worker builds its own
        return {"options": self.options}

    def __setstate__(self, state: dict[str, Any]) -> None:
        object.__setattr__(self, "options", state["options"])
        object.__setattr__(self, "_mpcs", {})
