"""``load_plan`` and ``footfall check``: a saved plan read back, checked, and bad files refused."""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from footfall._io import write_json
from footfall.errors import InputError
from footfall.models.biped import BipedParams
from footfall.planning import check_plan, load_plan, make_plan
from footfall.planning.plan_file import MAX_PLAN_BYTES
from footfall.terrain.scene import robot_to_dict
from tests.planning.scenes import SHORT_FLAT, scene

#: how far a tampered footstep is moved [m]: far off the 3 m x 2 m ground
TAMPER = 5.0


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=300
    )


@pytest.fixture(scope="module")
def saved(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path, dict[str, Any]]:
    """A valid 3-step plan of SHORT_FLAT saved as plan.json, the scene file, and the JSON data."""
    folder = tmp_path_factory.mktemp("saved")
    sc = scene(SHORT_FLAT)
    result = make_plan(sc, "miqcqp", 3)
    assert check_plan(result, sc).ok
    data = result.to_dict(sc.name)
    scene_file = folder / "flat.yaml"
    scene_file.write_text(SHORT_FLAT)
    return write_json(folder / "plan.json", data), scene_file, data


def test_load_plan_round_trips_the_saved_plan(saved: tuple[Path, Path, dict[str, Any]]) -> None:
    path, _, data = saved
    sc = scene(SHORT_FLAT)
    loaded = load_plan(path, sc)
    assert loaded.n_steps == 3 and robot_to_dict(loaded.robot) == robot_to_dict(sc.robot)
    np.testing.assert_array_equal(
        loaded.footsteps, np.array([s["position"] for s in data["footsteps"]])
    )
    assert check_plan(loaded, sc).ok


def test_alip_blocks_name_their_stance_footstep(saved: tuple[Path, Path, dict[str, Any]]) -> None:
    _, _, data = saved
    alip = data["alip"]
    assert alip["stance_footstep"] == [0, 1, 2] == list(range(len(alip["states"])))
    assert "footstep i" in alip["layout"]
    # the pairing is the one the checker re-simulates: block i starts on footstep i
    sc = scene(SHORT_FLAT)
    np.testing.assert_allclose(alip["states"][0][0], sc.start.alip_state, atol=1e-9)


def test_a_file_pairing_states_otherwise_is_refused(
    saved: tuple[Path, Path, dict[str, Any]], tmp_path: Path
) -> None:
    _, _, data = saved
    bad = json.loads(json.dumps(data))
    bad["alip"]["stance_footstep"] = [1, 2, 3]
    path = write_json(tmp_path / "plan.json", bad)
    with pytest.raises(InputError, match="stance_footstep"):
        load_plan(path)


def test_the_file_robot_is_used_not_the_scene_one(tmp_path: Path) -> None:
    # a plan made for another robot (as for a MuJoCo walker) is checked for that robot
    sc = scene(SHORT_FLAT)
    walker = dataclasses.replace(sc.robot, mass=45.0, com_height=0.7, stance_width=0.22)
    result = make_plan(sc, "kinematic", 3, robot=walker)
    path = write_json(tmp_path / "plan.json", result.to_dict(sc.name))
    loaded = load_plan(path, sc)
    assert robot_to_dict(loaded.robot) == robot_to_dict(walker) != robot_to_dict(sc.robot)
    assert check_plan(loaded, sc).summary() == check_plan(result, sc).summary()


def test_an_old_file_with_a_partial_robot_takes_the_rest_from_the_argument(
    saved: tuple[Path, Path, dict[str, Any]], tmp_path: Path
) -> None:
    _, _, data = saved
    old = json.loads(json.dumps(data))
    old["robot"] = {k: old["robot"][k] for k in ("mass", "com_height", "t_ss", "t_ds", "n_nodes")}
    del old["alip"]["stance_footstep"], old["alip"]["layout"]
    base = BipedParams(n_nodes=4, stance_width=0.2, u_max=25.0)
    loaded = load_plan(write_json(tmp_path / "plan.json", old), base)
    assert loaded.robot.u_max == 25.0 and loaded.robot.n_nodes == 4


@pytest.mark.parametrize(
    ("content", "expected"),
    [
        ('{"status": "optimal", "footsteps": [', "valid JSON"),
        ("\x00\xff garbage", "valid JSON"),
        ("[1, 2, 3]", "a JSON object"),
        ('{"status": "optimal", "footsteps": [], "robot": {"mass": -1}}', "robot.mass"),
        ('{"status": "optimal", "footsteps": [], "robot": {"legs": 3}}', "robot.legs"),
    ],
)
def test_bad_plan_files_raise_input_error_naming_the_file(
    tmp_path: Path, content: str, expected: str
) -> None:
    path = tmp_path / "plan.json"
    path.write_text(content)
    with pytest.raises(InputError, match=expected) as info:
        load_plan(path)
    assert "plan.json" in str(info.value)


def test_non_regular_and_oversized_files_are_refused(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="regular file"):
        load_plan(tmp_path)
    big = tmp_path / "big.json"
    with big.open("wb") as fh:
        fh.truncate(MAX_PLAN_BYTES + 1)
    with pytest.raises(InputError, match="at most"):
        load_plan(big)


def test_cli_check_valid_plan_exits_0(saved: tuple[Path, Path, dict[str, Any]]) -> None:
    path, scene_file, _ = saved
    res = run("check", str(path), str(scene_file))
    assert res.returncode == 0, res.stderr
    assert "valid" in res.stderr


def test_cli_check_moved_footstep_exits_1_and_names_it(
    saved: tuple[Path, Path, dict[str, Any]], tmp_path: Path
) -> None:
    _, scene_file, data = saved
    bad = json.loads(json.dumps(data))
    bad["footsteps"][2]["position"][1] += TAMPER
    path = write_json(tmp_path / "plan.json", bad)
    res = run("check", str(path), str(scene_file), "--out", str(tmp_path / "out"))
    assert res.returncode == 1, res.stderr
    assert "region at footstep 2" in res.stderr
    assert "Traceback" not in res.stderr
    report = json.loads((tmp_path / "out" / "check.json").read_text())
    assert report["ok"] is False
    assert any(line.startswith("region at footstep 2") for line in report["violations"])


def test_cli_check_garbage_exits_2_on_one_line(
    saved: tuple[Path, Path, dict[str, Any]], tmp_path: Path
) -> None:
    path, scene_file, _ = saved
    truncated = tmp_path / "plan.json"
    truncated.write_text(path.read_text()[:200])
    res = run("check", str(truncated), str(scene_file))
    assert res.returncode == 2
    lines = [line for line in res.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in res.stderr, res.stderr
    assert "plan.json" in lines[0] and "valid JSON" in lines[0]
