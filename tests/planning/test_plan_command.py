"""``footfall plan``: plan.json contents, figure, exit codes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from tests.planning.scenes import SHORT_FLAT, TWO_STONES


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=600
    )


def test_plan_yaml_file_writes_json_and_png(tmp_path: Path) -> None:
    scene_file = tmp_path / "stones.yaml"
    scene_file.write_text(TWO_STONES)
    out = tmp_path / "out"
    res = run("plan", str(scene_file), "--steps", "5", "--time-limit", "60", "--out", str(out))
    assert res.returncode == 0, res.stderr
    data = json.loads((out / "plan.json").read_text())
    assert data["status"] == "optimal"
    assert data["check"]["ok"] is True
    steps = data["footsteps"]
    assert [s["index"] for s in steps] == list(range(6))
    assert steps[0]["side"] == "right" and steps[1]["side"] == "left"
    assert steps[0]["position"] == [0.0, -0.1, 0.0]
    assert steps[1]["region"] == "stone_a"
    assert len(data["alip"]["states"]) == 5 and len(data["alip"]["states"][0]) == 4
    assert len(data["alip"]["torques"][0]) == 3 and len(data["alip"]["torques"][0][0]) == 2
    assert data["objective"] > 0 and data["gap"] <= 1e-4 and data["solver"] == "bnb"
    assert (out / "plan.png").stat().st_size > 20_000


def test_smallest_n_search(tmp_path: Path) -> None:
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    res = run("plan", str(scene_file), "--min-steps", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    data = json.loads((tmp_path / "plan.json").read_text())
    assert len(data["footsteps"]) - 1 == 3
    # N = 2 (the distance bound) is ruled out by the reachable sets, without a solve ...
    assert data["stats"]["tried"] == []
    assert data["stats"]["skipped"]["from"] == 2 and data["stats"]["skipped"]["to"] == 2
    assert "N = 2 ruled out without a solve" in data["message"]
    # ... and rightly so: the solver proves it infeasible
    from footfall.planning import make_plan
    from footfall.terrain import load_scene

    assert make_plan(load_scene(scene_file), "miqcqp", 2).status.value == "infeasible"


def test_swing_bound_is_planned_checked_and_recorded(tmp_path: Path) -> None:
    # 0.6 m ahead with swings of at most 0.35 m: each foot swings twice, so N = 4 (3 without)
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    res = run("plan", str(scene_file), "--swing-max", "0.35", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    data = json.loads((tmp_path / "plan.json").read_text())
    assert data["swing_max"] == 0.35 and data["check"]["ok"] is True
    assert len(data["footsteps"]) - 1 == 4


def test_reactive_on_builtin_scene(tmp_path: Path) -> None:
    res = run("plan", "--scene", "flat", "--planner", "reactive", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    data = json.loads((tmp_path / "plan.json").read_text())
    assert data["planner"] == "reactive" and data["check"]["ok"]


def test_infeasible_exits_1_with_diagnosis(tmp_path: Path) -> None:
    scene_file = tmp_path / "stones.yaml"
    scene_file.write_text(TWO_STONES)
    res = run("plan", str(scene_file), "--steps", "2", "--out", str(tmp_path))
    assert res.returncode == 1
    data = json.loads((tmp_path / "plan.json").read_text())
    assert data["status"] == "infeasible" and "at least" in data["message"]
    assert "Traceback" not in res.stderr


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--scene", "moon"], "moon"),
        (["--scene", "flat", "--planner", "astar"], "miqcqp, kinematic, reactive"),
        (["--scene", "flat", "--steps", "0"], "steps"),
        (["--scene", "flat", "--time-limit", "-3", "--steps", "4"], "time_limit"),
        (["--scene", "flat", "--solver", "cplex", "--steps", "4"], "scip, gurobi"),
        (["--scene", "flat", "--swing-max", "-0.2", "--steps", "4"], "swing_max"),
        (["--scene", "flat", "--swing-max", "nan", "--steps", "4"], "swing_max"),
        ([], "SCENE.yaml"),
    ],
)
def test_bad_input_exits_2(tmp_path: Path, args: list[str], needle: str) -> None:
    res = run("plan", *args, "--out", str(tmp_path))
    assert res.returncode == 2, res.stderr
    assert needle in res.stderr
    assert "Traceback" not in res.stderr


def test_invalid_yaml_names_the_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text(TWO_STONES.replace("height: 0.08", "height: high"))
    res = run("plan", str(bad), "--steps", "5", "--out", str(tmp_path))
    assert res.returncode == 2
    assert "line" in res.stderr and "height" in res.stderr


def test_a_plan_the_checker_rejects_exits_1(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An optimal plan that the independent checker rejects is a failed run, not a success."""
    from typer.testing import CliRunner

    import footfall.planning as planning
    from footfall.cli import app
    from footfall.planning.check import CheckReport, Violation

    rejected = CheckReport((Violation("region", 2, 0.0917, "9.17e-02 m off the plane"),), 0.0)
    monkeypatch.setattr(planning, "check_plan", lambda plan, scene: rejected)
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    res = CliRunner().invoke(app, ["plan", str(scene_file), "--steps", "3", "--out", str(tmp_path)])
    assert res.exit_code == 1, res.output
    data = json.loads((tmp_path / "plan.json").read_text())
    assert data["status"] == "optimal" and data["check"]["ok"] is False
