"""`footfall simulate` and `footfall compare`: outputs and input errors (exit code 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=300
    )


def test_simulate_writes_metrics_and_figures(tmp_path: Path) -> None:
    r = run(
        "simulate",
        "--scene",
        "flat",
        "--planner",
        "reactive",
        "--push",
        "5",
        "--engine",
        "python",
        "--out",
        str(tmp_path),
    )
    assert r.returncode == 0, r.stderr
    data = json.loads((tmp_path / "sim.json").read_text())
    m = data["metrics"]
    assert m["fell"] is False and m["zmp_offset_max"] >= m["zmp_offset_mean"] > 0
    assert data["options"]["engine"] == m["engine"] == "python"
    for name in ("sim_top.png", "sim_zmp.png", "sim_torque.png"):
        assert (tmp_path / name).stat().st_size > 0


def test_compare_is_a_study_of_its_options(tmp_path: Path) -> None:
    pytest.importorskip("pyarrow")
    from footfall.experiments.study.store import read_rows

    r = run(
        "compare",
        "--scenes",
        "flat",
        "--planners",
        "reactive",
        "--trials",
        "2",
        "--push",
        "4",
        "--workers",
        "1",
        "--out",
        str(tmp_path),
    )
    assert r.returncode == 0, r.stderr
    rows = read_rows(tmp_path / "trials.parquet")
    assert [(x["seed"], x["push_impulse"], x["simulator"]) for x in rows] == [
        (0, 4.0, "reduced"),
        (1, 4.0, "reduced"),
    ]
    design = json.loads((tmp_path / "study.json").read_text())["design"]
    assert design["name"] == "compare" and design["push_levels"] == []
    assert design["initial_impulse"] == 0.0
    assert "| flat |" in (tmp_path / "summary.md").read_text()
    assert list((tmp_path / "plans").glob("plan-*.json"))
    assert not list((tmp_path / "plans").glob("*.pkl"))
    # a second run finds every walk done
    again = run("compare", "--scenes", "flat", "--planners", "reactive", "--trials", "2",
                "--push", "4", "--workers", "1", "--out", str(tmp_path))  # fmt: skip
    assert again.returncode == 0 and "2 walks" not in again.stderr + again.stdout


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (("simulate", "--scene", "moon"), "discrete_steps"),
        (("simulate", "--planner", "astar"), "miqcqp, kinematic, reactive"),
        (("simulate", "--rate", "-500"), "control_rate"),
        (("simulate", "--push", "-3"), "push impulse [N s]"),
        (("simulate", "--push-dv", "nan"), "push velocity change [m/s]"),
        (("simulate", "--push-phase", "2"), "push phase"),
        (("simulate", "--seed", "-1"), "seed"),
        (("compare", "--planners", "reactive,dijkstra"), "miqcqp, kinematic, reactive"),
        (("compare", "--trials", "0"), "seeds"),
        (("compare", "--scenes", "flat", "--workers", "0"), "workers"),
        (("compare", "--scenes", "flat", "--steps", "fewest"), "smallest, equal"),
        (("compare", "--scenes", "moon.yaml"), "scene file"),
        (("compare", "--sim", "mujoco", "--scenes", "flat", "--push", "nan"), "default_push"),
        (("compare", "--scenes", "flat", "--push", "-1"), "default_push"),
    ],
)
def test_bad_input_exits_2_with_the_valid_choices(
    tmp_path: Path, args: tuple[str, ...], needle: str
) -> None:
    r = run(*args, "--out", str(tmp_path))
    assert r.returncode == 2
    assert needle in " ".join((r.stderr + r.stdout).split())


def test_bench_sim_reports_both_engines_and_their_ratio(tmp_path: Path) -> None:
    r = run("bench", "sim", "--runs", "1", "--nodes", "plan", "--out", str(tmp_path))
    assert r.returncode == 0, r.stderr
    rows = json.loads((tmp_path / "bench_sim.json").read_text())["rows"]
    assert [row["engine"] for row in rows] == ["python", "compiled"]
    for row in rows:
        assert row["realtime"] == pytest.approx(row["sim_time"] / row["wall_median"])
        assert row["mpc_solves"] > 0 and row["mpc_fallbacks"] == 0 and not row["fell"]
        assert 0 < row["mpc_median"] <= row["mpc_p99"]
    assert rows[1]["max_com_diff"] <= 1e-9  # the same walk
    table = (tmp_path / "bench_sim.md").read_text()
    assert "x real time" in table and "speed ratio" in table and "| compiled |" in table
    for args, name in ((("--nodes", "1"), "nodes"), (("--runs", "0"), "runs")):
        bad = run("bench", "sim", *args, "--out", str(tmp_path))
        assert bad.returncode == 2 and name in bad.stderr + bad.stdout


def test_simulate_rejects_an_unknown_engine(tmp_path: Path) -> None:
    bad = run("simulate", "--planner", "reactive", "--engine", "gpu", "--out", str(tmp_path))
    assert bad.returncode == 2 and "engine" in bad.stderr + bad.stdout
