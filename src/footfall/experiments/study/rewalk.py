"""Walk a study's trial again: a study records a row per walk, not its motion, and its simulators
are deterministic, so walking the trial's plan with the trial's disturbance (its seed and push
impulse, the study's push duration and initial perturbation) on the study's plant repeats the
walk its row describes, this time recording what ``footfall walk`` writes (``walk.json``,
``plan.json``, ``replay.npz``), for ``footfall view`` to show.

Only a MuJoCo study has a robot to record; a reduced-order study is refused with the reason.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

from footfall._io import write_json
from footfall.errors import InputError
from footfall.experiments.study.design import study_from_dict
from footfall.experiments.study.store import META
from footfall.experiments.study.trials import study_plant
from footfall.planning.plan import FootstepPlan
from footfall.planning.plan_file import read_json_file
from footfall.results.outcome import Outcome
from footfall.results.walk import walk_report
from footfall.sim.disturbance import Disturbance
from footfall.terrain.scene import Scene, scene_to_yaml

#: the largest study.json read [bytes]
MAX_STUDY_JSON = 1_000_000


def walk_trial_again(
    folder: Path,
    scene: Scene,
    planner: str,
    plan: FootstepPlan,
    seed: int,
    impulse: float,
    out: Path,
) -> Outcome:
    """Walk again the trial (``scene``, ``planner``, ``plan``, ``seed``, push ``impulse`` [N s])
    of the study in ``folder`` on the study's plant (its ``study.json`` design), writing the
    walk's folder into ``out``; its outcome is the trial row's (the same walk)."""
    from footfall.sim.biped.trial import MujocoBipedPlant
    from footfall.sim.replay import REPLAY_FILE, ReplayRecorder, biped_traces
    from footfall.sim.trial import run_trial, trial_pushes

    path = folder / META
    if not path.is_file():
        raise InputError("study folder", str(folder), f"a {META} (the study's design)")
    data = read_json_file(path, "study file", MAX_STUDY_JSON)
    design = study_from_dict(data.get("design") if isinstance(data, dict) else None, str(path))
    if design.simulator != "mujoco":
        raise InputError(
            "trial", plan.planner, "a trial of a MuJoCo study (a reduced-order walk has no robot)"
        )
    base = study_plant(design)
    if not isinstance(base, MujocoBipedPlant):  # the design said mujoco: the biped's plant
        raise InputError("simulator", base.name, "the MuJoCo biped's plant")
    recorder = ReplayRecorder("biped")
    plant = replace(base, replay=recorder)
    disturbance = Disturbance.of_seed(
        seed, impulse=impulse, duration=design.push_duration, initial_impulse=design.initial_impulse
    )
    pushes = trial_pushes(plant, plan, disturbance)
    outcome = run_trial(plant, scene, plan, disturbance)
    result = outcome.detail
    recorder.write(
        out / REPLAY_FILE, biped_traces(result.trace, recorder.times), scene_to_yaml(scene)
    )
    write_json(out / "plan.json", plan.to_dict(scene.name))
    report = walk_report(scene.name, planner, design.robot, plan, disturbance, pushes, result)
    write_json(out / "walk.json", report)
    return outcome


def trial_walker(folder: Path, trial: Any, scene: Scene, out: Path) -> Outcome:
    """:func:`walk_trial_again` for a trial of ``footfall view``'s study page (a
    :class:`~footfall.viz.view.load.StudyTrial`: its planner, plan, seed and impulse)."""
    if trial.plan is None or trial.seed is None:
        raise InputError("trial", trial.key, "a trial whose plan and seed the study holds")
    return walk_trial_again(
        folder, scene, trial.planner, trial.plan, trial.seed, trial.impulse, out
    )
