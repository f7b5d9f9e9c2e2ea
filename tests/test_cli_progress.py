"""Progress of ``footfall plan`` without a terminal: plain lines, ``--quiet``, ``--log-json``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from footfall.cli import _progress
from footfall.cli._progress import ProgressLog
from footfall.planning import make_plan
from footfall.solvers.base import SolveProgress
from footfall.terrain import load_scene
from tests.planning.scenes import SHORT_FLAT, TWO_STONES


def _plan(tmp_path: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    scene_file = tmp_path / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    # stdout and stderr are pipes: no terminal
    return subprocess.run(
        [
            *(sys.executable, "-m", "footfall", "plan", str(scene_file), "--min-steps"),
            "--out",
            str(tmp_path / "out"),
            *extra,
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )


def test_a_search_in_a_pipe_logs_one_line_per_n_and_json_lines(tmp_path: Path) -> None:
    log = tmp_path / "progress.jsonl"
    res = _plan(tmp_path, "--log-json", str(log))
    assert res.returncode == 0, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.startswith("[")]
    # N = 2 is ruled out by the reachable sets, N = 3 is solved
    assert any("N = 2: ruled out without a solve (" in line for line in lines), res.stderr
    assert any("N = 3: optimal in " in line and "objective" in line for line in lines)
    records = [json.loads(line) for line in log.read_text().splitlines()]
    events = [r["event"] for r in records]
    assert events[0] == "start" and events[-1] == "done"
    assert {"event": "skipped", "from": 2, "to": 2}.items() <= records[1].items()
    tried = [r for r in records if r["event"] == "tried"]
    assert [(t["n_steps"], t["status"]) for t in tried] == [(3, "optimal")]
    plan = json.loads((tmp_path / "out" / "plan.json").read_text())
    assert records[-1]["objective"] == pytest.approx(plan["objective"])
    assert all(r["elapsed"] >= 0.0 for r in records)


def test_quiet_silences_the_lines_but_not_the_json_log(tmp_path: Path) -> None:
    log = tmp_path / "progress.jsonl"
    res = _plan(tmp_path, "--quiet", "--log-json", str(log))
    assert res.returncode == 0, res.stderr
    assert not [line for line in res.stderr.splitlines() if line.startswith("[")]
    assert "short_flat: miqcqp -> optimal, 3 steps" in res.stderr  # the result is still printed
    assert [json.loads(line)["event"] for line in log.read_text().splitlines()][-1] == "done"


def test_log_json_into_a_folder_is_bad_input(tmp_path: Path) -> None:
    res = _plan(tmp_path, "--log-json", str(tmp_path))
    assert res.returncode == 2
    assert "log_json" in res.stderr and "Traceback" not in res.stderr


def test_solve_lines_are_held_back_for_the_log_period(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    clock = [100.0]
    monkeypatch.setattr(_progress.time, "perf_counter", lambda: clock[0])
    at = SolveProgress(nodes=10, seconds=1.0, incumbent=None, bound=0.5, gap=float("inf"))
    with ProgressLog("test", json_path=tmp_path / "p.jsonl", terminal=False) as log:
        log.solving(7, at)
        clock[0] += _progress.LOG_PERIOD / 2
        log.solving(7, at)  # too soon: not logged
        clock[0] += _progress.LOG_PERIOD / 2
        log.solving(7, at, model="kinematic relaxation")
    err = capsys.readouterr().err
    solving = [line for line in err.splitlines() if "solving" in line]
    assert len(solving) == 2, err
    assert "N = 7: solving, 10 nodes, incumbent none, bound 0.5, gap none" in solving[0]
    assert "N = 7, kinematic relaxation: solving" in solving[1]
    records = [json.loads(x) for x in (tmp_path / "p.jsonl").read_text().splitlines()]
    assert [r["event"] for r in records] == ["start", "solving", "solving"]
    assert records[1]["incumbent"] is None and records[1]["gap"] is None
    assert records[2]["model"] == "kinematic relaxation"


def test_a_solve_reports_its_progress_to_the_hook(monkeypatch: pytest.MonkeyPatch) -> None:
    from footfall.solvers.bnb import search

    monkeypatch.setattr(search, "PROGRESS_PERIOD", 0.0)  # report at every node
    seen: list[SolveProgress] = []
    plan = make_plan(load_scene(TWO_STONES), "miqcqp", 5, solve_progress=seen.append)
    assert plan.has_solution and seen
    nodes = [p.nodes for p in seen]
    assert nodes == sorted(nodes) and nodes[-1] <= plan.stats["nodes"]
    for p in seen:  # the bound never passes the optimum; an incumbent is never below it
        assert p.bound <= plan.objective * (1 + 1e-6)
        assert p.incumbent is None or p.incumbent >= plan.objective * (1 - 1e-6)


def test_walk_logs_its_smallest_n_search_and_records_its_controller(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    log = tmp_path / "progress.jsonl"
    out = tmp_path / "out"
    res = subprocess.run(
        [
            *(sys.executable, "-m", "footfall", "walk", "--scene", "flat", "--no-video"),
            *("--out", str(out), "--log-json", str(log)),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stderr
    # a line per N tried, on stderr (a pipe, no terminal), and the JSON lines of the same search
    assert any(" optimal in " in line for line in res.stderr.splitlines() if line.startswith("["))
    records = [json.loads(line) for line in log.read_text().splitlines()]
    assert records[0]["event"] == "start" and records[-1]["event"] == "done"
    walked = json.loads((out / "walk.json").read_text())
    assert records[-1]["n_steps"] == walked["plan"]["n_steps"]
    assert walked["controller"]["name"] == "wbc"  # the biped's default controller
    assert walked["walker"] == {
        "region_aware": "horizon",  # the walker's default region mode
        "leg_momentum": 0.5,  # the wbc walker's default share
        "capture_stop": True,
        "walk_on": 4,
        "torque_weight_mass": 30.1,
        "step_timing": True,  # the walker's default
    }


def test_study_logs_its_smallest_n_searches(tmp_path: Path) -> None:
    """``footfall study`` in a pipe: a line per plan and the search's own lines per N."""
    study = tmp_path / "tiny.yaml"
    study.write_text(
        "name: tiny\nsimulator: reduced\nscenes: [flat]\nplanners: [miqcqp]\n"
        "steps: [smallest]\ndefault_push: 0.0\nseeds: 1\npush_levels: []\nlevel_seeds: 0\n"
        "time_limit: 60\n"
    )
    res = subprocess.run(
        [sys.executable, "-m", "footfall", "study", str(study), "--out", str(tmp_path / "o")],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stderr
    assert "planning flat / miqcqp (smallest N)" in res.stderr
    assert any(" optimal in " in line for line in res.stderr.splitlines() if line.startswith("["))


def test_compare_in_mujoco_logs_its_smallest_n_search(tmp_path: Path) -> None:
    pytest.importorskip("mujoco")
    res = subprocess.run(
        [
            *(sys.executable, "-m", "footfall", "compare", "--sim", "mujoco", "--scenes", "flat"),
            *("--planners", "miqcqp", "--trials", "1", "--push", "0", "--workers", "1"),
            *("--out", str(tmp_path / "o")),
        ],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert res.returncode == 0, res.stderr
    lines = [line for line in res.stderr.splitlines() if line.startswith("[")]
    assert any("flat / miqcqp" in line for line in lines), res.stderr
    assert any(" optimal in " in line for line in lines), res.stderr
