"""Folders that footfall's commands wrote, made once per test session: a short pushed walk of the
biped and one gait cycle of the quadruped (both through the command line, as a user makes them)."""

from __future__ import annotations

import json
import math
import os
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("mujoco")
pytest.importorskip("mink")

from typer.testing import CliRunner

from footfall.cli import app
from footfall.terrain import Goal, builtin_scene
from footfall.terrain.scene import scene_to_yaml

#: CI installs the view extra and Chromium and sets this: the browser tests must run, not skip
REQUIRE_BROWSER = os.environ.get("FOOTFALL_REQUIRE_BROWSER") == "1"


@pytest.fixture(scope="session")
def walk_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``footfall walk`` of four kinematic footsteps over 0.6 m of flat ground with a 4 N s push
    (40 N for 0.1 s; the servo controller: the fast one)."""
    root = tmp_path_factory.mktemp("walk")
    scene = replace(builtin_scene("flat"), goal=Goal(np.array([0.6, 0.0, 0.0]), 0.0), name="short")
    path = root / "short.yaml"
    path.write_text(scene_to_yaml(scene))
    out = root / "out"
    args = ["walk", str(path), "--planner", "kinematic", "--steps", "4", "--no-video"]
    res = CliRunner().invoke(
        app, [*args, "--controller", "servo", "--push", "4", "--out", str(out), "--quiet"]
    )
    assert res.exit_code == 0, res.output
    return out


@pytest.fixture(scope="session")
def quadruped_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``footfall quadruped`` for one gait cycle up the document's 15 degree slope."""
    out = tmp_path_factory.mktemp("quadruped")
    res = CliRunner().invoke(app, ["quadruped", "--cycles", "1", "--no-video", "--out", str(out)])
    assert res.exit_code == 0, res.output
    return out


@pytest.fixture
def study_dir(walk_dir: Path, tmp_path: Path) -> Path:
    """A study folder as ``footfall study`` leaves it: two trials of ``flat`` in trials.parquet
    (written by the study's own store), the first one's plan in the plans/ cache."""
    pytest.importorskip("pyarrow")
    from footfall.experiments.study.store import write_rows
    from footfall.experiments.study.trials import COLUMNS
    from footfall.planning import load_plan
    from footfall.planning.cache import PlanCache

    PlanCache(tmp_path / "plans").save("a" * 64, load_plan(walk_dir / "plan.json"), "flat")
    rows = []
    for planner, n in (("kinematic", 4), ("miqcqp", 9)):
        row: dict[str, object] = {name: None for name, _ in COLUMNS}
        row.update(key=f"flat|{planner}|N={n}|J=10|seed=0", scene="flat", planner=planner,
                   n_steps=n, push_impulse=10.0, push_time=2.0, push_direction=math.pi / 2,
                   seed=0, success=True, fell=False, goal_error=0.01)  # fmt: skip
        rows.append(row)
    write_rows(tmp_path / "trials.parquet", rows)
    return tmp_path


def browser_or_skip() -> None:
    """Skip a browser test where no Chromium or Playwright is installed, unless CI requires it."""
    from footfall.errors import InputError
    from footfall.viz.view.browser import chromium_path

    try:
        import playwright.sync_api  # noqa: F401

        chromium_path()
    except (ImportError, InputError) as e:
        if REQUIRE_BROWSER:
            raise
        pytest.skip(f"no browser for the page tests ({e}); CI installs one")


@pytest.fixture(scope="session")
def mujoco_study_dir(walk_dir: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A MuJoCo study folder as ``footfall study`` leaves it, of one trial walked by the study's
    own runner: the 4-step plan of ``walk_dir`` on ``flat`` with seed 3's 2 N s push (servo
    controller), its ``study.json``, its row in trials.parquet and its plan in the cache."""
    pytest.importorskip("pyarrow")
    from footfall.experiments.study.design import StudyDesign
    from footfall.experiments.study.store import write_rows
    from footfall.experiments.study.trials import Trial, run_trial, trial_key
    from footfall.planning import load_plan
    from footfall.planning.cache import PlanCache
    from footfall.sim.disturbance import Disturbance

    folder = tmp_path_factory.mktemp("mujoco_study")
    design = StudyDesign(
        name="again", simulator="mujoco", controller="servo", scenes=("flat",),
        planners=("kinematic",), steps=("smallest",), seeds=1, push_levels=(), level_seeds=0,
        default_push=2.0,
    )  # fmt: skip
    plan = load_plan(walk_dir / "plan.json")
    trial = Trial(
        key=trial_key("flat", "kinematic", plan.n_steps, 2.0, 3),
        scene=builtin_scene("flat"),
        planner="kinematic",
        plan=plan,
        smallest_n=True,
        equal_n=False,
        disturbance=Disturbance.of_seed(
            3, impulse=2.0, duration=design.push_duration, initial_impulse=design.initial_impulse
        ),
        design=design,
    )
    row = run_trial(trial)
    assert row["error"] is None, row["error"]
    (folder / "study.json").write_text(
        json.dumps({"fingerprint": design.fingerprint(), "design": design.to_dict()})
    )
    write_rows(folder / "trials.parquet", [row])
    PlanCache(folder / "plans").save("b" * 64, plan, "flat")
    return folder
