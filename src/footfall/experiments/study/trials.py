"""One trial of a study: a plan walked once with its seed's disturbance, as one row of the table.

:class:`Trial` carries everything a worker needs (scene, plan, impulse, disturbance, simulator
settings) and :func:`run_trial` is a top-level function, so both executors (a process pool, Ray)
can ship it. A trial that raises becomes a row with its ``error`` (and no numbers), never a lost
trial.
"""

from __future__ import annotations

import hashlib
import math
import time
import traceback
from dataclasses import dataclass
from typing import Any

import numpy as np

from footfall.experiments.study.design import StudyDesign
from footfall.planning.plan import FootstepPlan
from footfall.results.outcome import OUTCOME_COLUMNS
from footfall.sim.disturbance import Disturbance
from footfall.sim.trial import Plant, make_plant, shared_plant
from footfall.sim.trial import run_trial as run_plant
from footfall.terrain.scene import Scene

#: the columns of ``trials.parquet`` in order, with their Arrow types (see ``store.py``): the
#: trial's identity and push, the plant's :class:`~footfall.results.outcome.Outcome`, the error
COLUMNS: tuple[tuple[str, str], ...] = (
    ("key", "string"),
    ("scene", "string"),
    ("planner", "string"),
    ("n_steps", "int64"),
    ("plan", "string"),
    ("smallest_n", "bool"),
    ("equal_n", "bool"),
    ("push_impulse", "float64"),
    ("seed", "int64"),
    ("simulator", "string"),
    ("controller", "string"),
    ("push_step", "int64"),
    ("push_time", "float64"),
    ("push_direction", "float64"),
    *OUTCOME_COLUMNS,
    ("error", "string"),
)
#: columns a table written before they existed may lack (read as None)
OPTIONAL_COLUMNS = (
    "plan",
    "fall_time",
    "cop_error_mean",
    "cop_error_max",
    "footsteps_off_terrain",
    "sim_time",
)
#: the columns that vary between runs of the same trial (left out when runs are compared)
RUN_DEPENDENT = ("wall_time",)


@dataclass(frozen=True)
class Trial:
    """One walk of a study.

    Attributes:
        key: its identity in the table (scene, planner, N, impulse, seed).
        scene: the scene walked.
        planner: planner name.
        plan: the plan walked (its ``n_steps`` is N).
        smallest_n: the plan is the planner's smallest-N plan.
        equal_n: the plan has the reactive walk's N.
        disturbance: the seed's disturbance with this trial's push impulse [N s] (0: no
            push) and the study's push duration and initial perturbation.
        design: the study (simulator, controller, noise, durations).
    """

    key: str
    scene: Scene
    planner: str
    plan: FootstepPlan
    smallest_n: bool
    equal_n: bool
    disturbance: Disturbance
    design: StudyDesign


def plan_digest(plan: FootstepPlan) -> str:
    """16 hex digits that change whenever the walked plan does: its planner, footsteps,
    headings, sides, regions, ALIP states, torques and final state (rounded to 1e-9). A row
    records the digest of the plan it walked, so a study rerun after a planner changed walks
    that planner's trials again instead of keeping rows of a plan it no longer makes."""
    h = hashlib.sha256()
    h.update(f"{plan.planner}|{plan.sides}|{plan.regions}".encode())
    for arr in (plan.footsteps, plan.headings, plan.states, plan.torques, plan.final_state):
        h.update((np.round(np.asarray(arr, dtype=float), 9) + 0.0).tobytes())  # -0.0 -> 0.0
    return h.hexdigest()[:16]


def trial_key(scene: str, planner: str, n_steps: int, impulse: float, seed: int) -> str:
    """The identity of a walk: two trials with the same key compute the same row."""
    return f"{scene}|{planner}|N={n_steps}|J={impulse:g}|seed={seed}"


def study_plant(design: StudyDesign) -> Plant:
    """The plant of the study's simulator (:data:`footfall.sim.trial.PLANTS`) with its settings."""
    if design.simulator == "mujoco":
        from footfall.sim.biped.options import WalkOptions
        from footfall.sim.biped.plans import robot_model

        options = WalkOptions(controller=str(design.controller), region_aware=design.region_aware)
        robot = None if design.robot == "biped" else robot_model(design.robot)
        return make_plant("mujoco", options=options, robot=robot)
    from footfall.sim.reduced.closed_loop import SimOptions

    sim = SimOptions(
        noise_pos=design.noise_pos,
        noise_vel=design.noise_vel,
        placement_error=design.placement_error,
        region_aware=design.region_aware,
    )
    return make_plant("reduced", options=sim)


def run_trial(trial: Trial) -> dict[str, Any]:
    """Walk ``trial`` and return its row (``COLUMNS``); an exception becomes the row's ``error``."""
    t0 = time.perf_counter()
    d = trial.disturbance
    row: dict[str, Any] = {
        "key": trial.key,
        "scene": trial.scene.name,
        "planner": trial.planner,
        "n_steps": int(trial.plan.n_steps),
        "plan": plan_digest(trial.plan),
        "smallest_n": trial.smallest_n,
        "equal_n": trial.equal_n,
        "push_impulse": float(d.impulse),
        "seed": d.seed,
        "simulator": trial.design.simulator,
        "controller": trial.design.controller,
        "push_direction": d.direction if d.impulse > 0 else math.nan,
        "error": None,
    }
    try:
        plant = shared_plant(study_plant(trial.design))
        row["push_step"] = d.push_step(trial.plan.n_steps)
        row["push_time"] = d.push_time(plant.timeline(trial.plan))
        row.update(run_plant(plant, trial.scene, trial.plan, d).row())
    except Exception as exc:  # recorded, not dropped: the table says which trial failed and why
        last = traceback.extract_tb(exc.__traceback__)[-1:]
        where = f" at {last[0].filename.rsplit('/', 1)[-1]}:{last[0].lineno}" if last else ""
        row["error"] = f"{type(exc).__name__}: {exc}{where}"
        row["wall_time"] = time.perf_counter() - t0
    return normalise_row(row)


def normalise_row(row: dict[str, Any]) -> dict[str, Any]:
    """``row`` with every column of ``COLUMNS`` (missing: None) and non-finite floats as NaN."""
    out: dict[str, Any] = {}
    for name, kind in COLUMNS:
        v = row.get(name)
        if kind == "float64":
            v = math.nan if v is None else float(v)
        elif kind == "int64" and v is not None:
            v = int(v)
        elif kind == "bool" and v is not None:
            v = bool(v)
        out[name] = v
    return out
