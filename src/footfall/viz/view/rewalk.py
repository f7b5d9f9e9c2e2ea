"""Walk a study's trial again, for the page: a study records a row per walk, not its motion, and
its simulators are deterministic, so walking the trial's plan with the trial's disturbance (its
seed and push impulse, the study's push duration and initial perturbation) on the study's plant
repeats the walk its row describes, this time recording the replay.

Only a MuJoCo study has a robot to show; a reduced-order study is refused with the reason.
"""

from __future__ import annotations

import tempfile
from dataclasses import replace
from pathlib import Path

from footfall._io import write_json
from footfall.errors import InputError
from footfall.planning.plan_file import read_json_file
from footfall.results.outcome import Outcome
from footfall.terrain.scene import Scene, scene_to_yaml
from footfall.viz.view.load import STUDY_FILE, StudyTrial, ViewData, load_view

#: the largest study.json read [bytes]
MAX_STUDY_JSON = 1_000_000


def rewalk_trial(folder: Path, trial: StudyTrial, scene: Scene | None) -> tuple[ViewData, Outcome]:
    """The walk of ``trial`` of the study in ``folder``, walked again on the study's plant with a
    replay recorded (what a ``footfall walk`` folder holds), and its outcome (the numbers of
    the trial's row: the same walk)."""
    from footfall.experiments.study.design import study_from_dict
    from footfall.experiments.study.trials import study_plant
    from footfall.results.walk import walk_report
    from footfall.sim.biped.trial import MujocoBipedPlant
    from footfall.sim.disturbance import Disturbance
    from footfall.sim.replay import REPLAY_FILE, ReplayRecorder, biped_traces
    from footfall.sim.trial import run_trial, trial_pushes

    path = folder / STUDY_FILE
    if not path.is_file():
        raise InputError("study folder", str(folder), f"a {STUDY_FILE} (the study's design)")
    data = read_json_file(path, "study file", MAX_STUDY_JSON)
    design = study_from_dict(data.get("design") if isinstance(data, dict) else None, str(path))
    if design.simulator != "mujoco":
        raise InputError(
            "trial", trial.key, "a trial of a MuJoCo study (a reduced-order walk has no robot)"
        )
    if trial.plan is None or scene is None or trial.seed is None:
        missing = "plan" if trial.plan is None else "scene" if scene is None else "seed"
        raise InputError("trial", trial.key, f"a trial whose {missing} the folder holds")
    base = study_plant(design)
    if not isinstance(base, MujocoBipedPlant):  # the design said mujoco: the biped's plant
        raise InputError("simulator", base.name, "the MuJoCo biped's plant")
    recorder = ReplayRecorder("biped")
    plant = replace(base, replay=recorder)
    disturbance = Disturbance.of_seed(
        trial.seed,
        impulse=trial.impulse,
        duration=design.push_duration,
        initial_impulse=design.initial_impulse,
    )
    pushes = trial_pushes(plant, trial.plan, disturbance)
    outcome = run_trial(plant, scene, trial.plan, disturbance)
    result = outcome.detail
    with tempfile.TemporaryDirectory(prefix="footfall-trial-") as tmp:
        out = Path(tmp)
        recorder.write(
            out / REPLAY_FILE, biped_traces(result.trace, recorder.times), scene_to_yaml(scene)
        )
        write_json(out / "plan.json", trial.plan.to_dict(scene.name))
        report = walk_report(
            scene.name, trial.planner, design.robot, trial.plan, disturbance, pushes, result
        )
        write_json(out / "walk.json", report)
        walked = load_view(out)  # the scene: the one replay.npz holds
    assert walked.walk is not None
    summary = (
        f"walked again: success {outcome.success}, fell {outcome.fell}, goal error "
        f"{outcome.goal_error:.4g} m, ZMP offset mean {outcome.zmp_offset_mean:.4g} m"
    )
    shown = replace(walked.walk, summary=summary)
    return replace(walked, title=f"{trial.key}, walked again", walk=shown, notes=()), outcome
