"""The ``footfall`` command line: outputs and clear input errors with exit code 2."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=300
    )


def test_lip_writes_json_and_png(tmp_path: Path) -> None:
    res = run(
        "lip", "--zc", "0.8", "--t-sup", "0.8", "--sx", "0,0.3,0.3,0.3,0",
        "--sy", "0.2,0.2,0.2,0.2,0.2", "--theta-deg", "0,20,40,60,60",
        "--a", "10", "--b", "1", "--out", str(tmp_path),
    )  # fmt: skip
    assert res.returncode == 0, res.stderr
    data = json.loads((tmp_path / "lip_walk.json").read_text())
    assert (tmp_path / "lip_walk.png").stat().st_size > 10_000
    assert [f["step"] for f in data["footsteps"]] == list(range(6))
    assert data["footsteps"][1]["ideal"] == pytest.approx([0.0, 0.2])
    com = data["com"]
    assert len(com["t"]) == len(com["x"]) == len(com["vy"])
    final = data["final_state"]
    assert [final["x"], final["y"]] == pytest.approx([com["x"][-1], com["y"][-1]])
    assert np.hypot(final["vx"], final["vy"]) < 0.01
    assert data["params"]["theta"][2] == pytest.approx(np.deg2rad(40.0))


@pytest.mark.parametrize("name", ["straight", "diagonal", "turn", "circle"])
def test_lip_examples(tmp_path: Path, name: str) -> None:
    res = run("lip", "--example", name, "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    assert json.loads((tmp_path / "lip_walk.json").read_text())["footsteps"]


def test_lip_example_options_change_the_example(tmp_path: Path) -> None:
    base, low = tmp_path / "base", tmp_path / "low"
    assert run("lip", "--example", "straight", "--out", str(base)).returncode == 0
    res = run("lip", "--example", "straight", "--zc", "0.6", "--out", str(low))
    assert res.returncode == 0, res.stderr
    p0 = json.loads((base / "lip_walk.json").read_text())["params"]
    p1 = json.loads((low / "lip_walk.json").read_text())["params"]
    assert p1["z_c"] == pytest.approx(0.6) and p0["z_c"] != pytest.approx(0.6)
    # everything not given stays the example's
    assert {k: v for k, v in p1.items() if k != "z_c"} == {
        k: v for k, v in p0.items() if k != "z_c"
    }


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--sy", "0.2,0.3,0.2,0.2"], "sy"),
        (["--zc", "0"], "z_c"),
        (["--t-sup", "-1"], "t_sup"),
        (["--sx", "0,nan,0.3,0.3,0"], "sx"),
        (["--sx", "0,abc"], "sx"),
        (["--theta-deg", "0,20"], "theta"),
        (["--example", "zigzag"], "straight, diagonal, turn, circle"),
        # options given with an example change it, so they are checked like any other
        (["--example", "straight", "--zc", "nan"], "z_c"),
        (["--example", "turn", "--sx", "0,0.3"], "sx"),
    ],
)
def test_lip_bad_input_exits_2_with_clear_message(
    tmp_path: Path, args: list[str], needle: str
) -> None:
    res = run("lip", *args, "--out", str(tmp_path))
    assert res.returncode == 2
    assert needle in res.stderr
    assert "Traceback" not in res.stderr


def test_demo_writes_summary(tmp_path: Path) -> None:
    res = run("demo", "--out", str(tmp_path))
    assert res.returncode == 0, res.stderr
    summary = json.loads((tmp_path / "demo.json").read_text())
    assert summary["lip"]["turn"]["final_speed_mps"] < 0.01
    assert summary["plans"]["miqcqp"]["status"] == "optimal"
    assert all(p["check_ok"] for p in summary["plans"].values())
    assert summary["quadruped"]["fell"] is False
    assert (tmp_path / "lip" / "circle" / "lip_walk.png").exists()
