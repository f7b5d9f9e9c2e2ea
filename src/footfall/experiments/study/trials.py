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

from footfall.experiments.study.design import Disturbance, StudyDesign
from footfall.planning.plan import FootstepPlan
from footfall.sim.pushes import Push
from footfall.terrain.scene import Scene

#: the columns of ``trials.parquet`` in order, with their Arrow types (see ``store.py``)
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
    ("success", "bool"),
    ("fell", "bool"),
    ("zmp_offset_mean", "float64"),
    ("zmp_offset_max", "float64"),
    ("footstep_error_mean", "float64"),
    ("goal_error", "float64"),
    ("steps_landed", "int64"),
    ("wall_time", "float64"),
    ("error", "string"),
)
#: columns a table written before they existed may lack (read as None)
OPTIONAL_COLUMNS = ("plan",)
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
        impulse: push impulse [N s] (0: no push).
        disturbance: the seed's disturbance.
        design: the study (simulator, controller, noise, durations).
    """

    key: str
    scene: Scene
    planner: str
    plan: FootstepPlan
    smallest_n: bool
    equal_n: bool
    impulse: float
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


def _pushes(trial: Trial, walk_start: float) -> tuple[tuple[Push, ...], int, float]:
    """The initial perturbation and the trial's push; the pushed step and the push time [s].

    ``walk_start``: when the first single support starts [s]; the initial perturbation ends
    before it (reduced: it starts at 0 and the first support starts then too)."""
    d, design, robot = trial.disturbance, trial.design, trial.plan.robot
    step = d.push_step(trial.plan.n_steps)
    t_push = walk_start + step * (robot.t_ss + robot.t_ds) + d.phase * robot.t_ss
    pushes = []
    if design.initial_impulse > 0:
        t0 = max(0.0, walk_start - 1.5 * design.push_duration)
        pushes.append(
            Push.horizontal(t0, design.initial_impulse, d.initial_direction, design.push_duration)
        )
    if trial.impulse > 0:
        pushes.append(Push.horizontal(t_push, trial.impulse, d.direction, design.push_duration))
    return tuple(pushes), step, t_push


def _reduced(trial: Trial) -> dict[str, Any]:
    from footfall.sim.reduced.closed_loop import SimOptions, simulate

    pushes, step, t_push = _pushes(trial, 0.0)
    design = trial.design
    opts = SimOptions(
        noise_pos=design.noise_pos,
        noise_vel=design.noise_vel,
        placement_error=design.placement_error,
        pushes=pushes,
        seed=trial.disturbance.seed,
        region_aware=design.region_aware,
    )
    # the regions only when the MPC needs them (the off rows stay those of earlier studies)
    regions = trial.scene.terrain.regions if design.region_aware != "off" else None
    m = simulate(trial.plan, opts, goal=trial.scene.goal.position, regions=regions).metrics
    return {
        "push_step": step,
        "push_time": t_push,
        "success": bool(m.success),
        "fell": bool(m.fell),
        "zmp_offset_mean": m.zmp_offset_mean,
        "zmp_offset_max": m.zmp_offset_max,
        "footstep_error_mean": m.footstep_dev_mean,
        "goal_error": m.goal_error,
        "steps_landed": int(m.steps_taken),
    }


def _mujoco(trial: Trial) -> dict[str, Any]:
    from footfall.sim.biped.options import WalkOptions
    from footfall.sim.biped.walk import walk

    base = WalkOptions(controller=str(trial.design.controller))
    start = base.settle_time + base.shift_time
    pushes, step, t_push = _pushes(trial, start)
    opts = WalkOptions(
        controller=base.controller, pushes=pushes, region_aware=trial.design.region_aware
    )
    res = walk(trial.scene, trial.plan, opts)
    m = res.metrics
    return {
        "push_step": step,
        "push_time": t_push,
        "success": bool(m.reached_goal and not m.fell),
        "fell": bool(m.fell),
        "zmp_offset_mean": m.zmp.mean,
        "zmp_offset_max": m.zmp.max,
        "footstep_error_mean": m.footstep_error_m.mean,
        "goal_error": m.goal_error_m,
        "steps_landed": int(m.steps_landed),
    }


def run_trial(trial: Trial) -> dict[str, Any]:
    """Walk ``trial`` and return its row (``COLUMNS``); an exception becomes the row's ``error``."""
    t0 = time.perf_counter()
    row: dict[str, Any] = {
        "key": trial.key,
        "scene": trial.scene.name,
        "planner": trial.planner,
        "n_steps": int(trial.plan.n_steps),
        "plan": plan_digest(trial.plan),
        "smallest_n": trial.smallest_n,
        "equal_n": trial.equal_n,
        "push_impulse": float(trial.impulse),
        "seed": int(trial.disturbance.seed),
        "simulator": trial.design.simulator,
        "controller": trial.design.controller,
        "push_direction": trial.disturbance.direction if trial.impulse > 0 else math.nan,
        "error": None,
    }
    try:
        out = _mujoco(trial) if trial.design.simulator == "mujoco" else _reduced(trial)
        row.update(out)
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
