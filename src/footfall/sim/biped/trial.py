"""The MuJoCo biped of the trial pipeline (:mod:`footfall.sim.trial`): a humanoid walking a
footstep plan with the MPC of eq. (5.19) and a whole-body controller
(:func:`~footfall.sim.biped.walk.walk`, document 000, section 5.5)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from footfall.planning.plan import FootstepPlan
from footfall.results.outcome import Outcome
from footfall.sim.biped.model import BipedSimSettings, WalkerModel
from footfall.sim.biped.options import WalkOptions
from footfall.sim.biped.walk import walk
from footfall.sim.disturbance import Push, SupportTimeline
from footfall.sim.replay import ReplayRecorder
from footfall.sim.trial import check_settings
from footfall.terrain.scene import Scene


@dataclass(frozen=True)
class MujocoBipedPlant:
    """A humanoid in MuJoCo.

    Attributes:
        options: the walking controller's options; their ``pushes`` must be empty (pushes come
            from the trial's disturbance).
        robot: the walker model (None: footfall's 30 kg biped).
        settings: physics settings (None: the model's defaults).
        video_path: write an MP4 of the walk here (None: no video).
        replay: record the joint positions for ``footfall view`` into this recorder (None:
            none; a command's plant of one walk).
    """

    options: WalkOptions = field(default_factory=WalkOptions)
    robot: WalkerModel | None = None
    settings: BipedSimSettings | None = None
    video_path: Path | None = None
    replay: ReplayRecorder | None = None

    name = "mujoco"

    def __post_init__(self) -> None:
        check_settings(self.options, WalkOptions, "a WalkOptions")

    def timeline(self, plan: FootstepPlan) -> SupportTimeline:
        """The robot stands for ``settle_time``, shifts its CoM over the first stance foot for
        ``shift_time``, then single support i starts every ``T_ss + T_ds``,
        standing on footstep i."""
        start = self.options.settle_time + self.options.shift_time
        return SupportTimeline.periodic(
            start, plan.n_steps, plan.robot.t_ss, plan.robot.t_ds, plan.headings, plan.sides
        )

    def mass(self, plan: FootstepPlan) -> float:
        """The plan robot's mass [kg] (measured from the walker model when planned for it)."""
        return float(plan.robot.mass)

    def run(self, scene: Scene, plan: FootstepPlan, pushes: tuple[Push, ...], seed: int) -> Outcome:
        """Walk in MuJoCo (:func:`~footfall.sim.biped.walk.walk`); ``seed`` is unused (the
        simulation is deterministic)."""
        res = walk(
            scene,
            plan,
            replace(self.options, pushes=pushes),
            model_params=self.robot,
            settings=self.settings,
            video_path=self.video_path,
            replay=self.replay,
        )
        m = res.metrics
        return Outcome(
            plant=self.name,
            success=bool(m.reached_goal and not m.fell),
            fell=bool(m.fell),
            fall_time=m.fall_time_s if m.fall_time_s is not None else math.nan,
            zmp_offset_mean=m.zmp.mean,
            zmp_offset_max=m.zmp.max,
            footstep_error_mean=m.footstep_error_m.mean,
            goal_error=m.goal_error_m,
            steps_landed=int(m.steps_landed),
            footsteps_off_terrain=m.footsteps_off_regions,
            sim_time=m.sim_time_s,
            detail=res,
        )
