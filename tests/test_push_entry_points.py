"""One push for one seed: `footfall study`, `compare`, `simulate` and `walk` give the walk of seed
s with impulse J the same push (impulse [N s], direction, step and phase of its single support),
each on its own plant's clock."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from footfall.cli import app
from footfall.sim.disturbance import Disturbance
from footfall.terrain import builtin_scene
from footfall.terrain.scene import Goal, scene_to_yaml

SEED, IMPULSE = 5, 3.0


def _scene(tmp_path: Path) -> Path:
    scene = replace(builtin_scene("flat"), goal=Goal(np.array([1.0, 0.0, 0.0]), 0.0))
    path = tmp_path / "short.yaml"
    path.write_text(scene_to_yaml(scene))
    return path


def _invoke(*args: str) -> None:
    res = CliRunner().invoke(app, list(args))
    assert res.exit_code == 0, res.output


def _row(folder: Path) -> dict[str, object]:
    from footfall.experiments.study.store import read_rows

    rows = [r for r in read_rows(folder / "trials.parquet") if r["seed"] == SEED]
    assert len(rows) == 1
    return rows[0]


def _phase(start: float, step: int, walk_start: float, t_ss: float, t_ds: float) -> float:
    return (start - walk_start - step * (t_ss + t_ds)) / t_ss


def test_every_entry_point_gives_seed_s_the_same_push(tmp_path: Path) -> None:
    pytest.importorskip("pyarrow")
    scene = _scene(tmp_path)
    d = Disturbance.of_seed(SEED)
    push = ("--push", str(IMPULSE))
    # the study, reduced plant
    study = tmp_path / "study.yaml"
    study.write_text(
        "name: pushes\nsimulator: reduced\nscenes: [short.yaml]\nplanners: [reactive]\n"
        f"default_push: {IMPULSE}\nseeds: {SEED + 1}\npush_levels: []\nlevel_seeds: 0\n"
        "initial_impulse: 0.0\n"
    )
    _invoke("study", str(study), "--out", str(tmp_path / "s"), "--workers", "1", "--quiet")
    # compare, a preset of the study
    _invoke(
        "compare", "--scenes", str(scene), "--planners", "reactive", "--trials", str(SEED + 1),
        *push, "--workers", "1", "--out", str(tmp_path / "c"), "--quiet",
    )  # fmt: skip
    rows = [_row(tmp_path / "s"), _row(tmp_path / "c")]
    # simulate (reduced) and walk (MuJoCo) write the pushes they applied
    _invoke(
        "simulate", "--scene", str(scene), "--planner", "reactive", *push, "--seed", str(SEED),
        "--out", str(tmp_path / "sim"),
    )  # fmt: skip
    sim = json.loads((tmp_path / "sim" / "sim.json").read_text())
    (sim_push,) = sim["options"]["pushes"]
    n_reduced = sim["plan"]["steps"]
    pytest.importorskip("mujoco")
    _invoke(
        "walk", str(scene), "--planner", "reactive", *push, "--seed", str(SEED), "--no-video",
        "--out", str(tmp_path / "w"),
    )  # fmt: skip
    walked = json.loads((tmp_path / "w" / "walk.json").read_text())
    (walk_push,) = walked["push"]
    n_walk = walked["plan"]["n_steps"]

    from footfall.models.biped import BipedParams
    from footfall.sim.biped.options import WalkOptions

    t_ss, t_ds = BipedParams().t_ss, BipedParams().t_ds
    walk_start = WalkOptions().settle_time + WalkOptions().shift_time
    for r in rows:
        assert r["push_impulse"] == IMPULSE and r["n_steps"] == n_reduced
        assert r["push_step"] == d.push_step(n_reduced)
        assert r["push_direction"] == pytest.approx(d.direction, abs=1e-12)
        step = int(r["push_step"])  # type: ignore[call-overload]
        assert _phase(float(r["push_time"]), step, 0.0, t_ss, t_ds) == pytest.approx(d.phase)  # type: ignore[arg-type]
    assert sim_push["start_s"] == pytest.approx(rows[0]["push_time"], abs=1e-12)
    for p, start, n in ((sim_push, 0.0, n_reduced), (walk_push, walk_start, n_walk)):
        assert p["impulse_Ns"] == pytest.approx(IMPULSE)
        assert math.remainder(p["direction_rad"] - d.direction, 2 * math.pi) == pytest.approx(
            0.0, abs=1e-12
        )
        step = d.push_step(n)
        assert _phase(p["start_s"], step, start, t_ss, t_ds) == pytest.approx(d.phase)
    assert walked["disturbance"]["seed"] == SEED
