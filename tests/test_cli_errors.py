"""The command line's error contract: one plain line (no markup interpretation), exit 2 for bad input."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest


def _run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=120
    )


def test_markup_in_a_scene_name_is_printed_as_typed() -> None:
    r = _run("plan", "--scene", "[/x][bold]oops")
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "[/x][bold]oops" in r.stderr


def test_help_shows_units_in_brackets() -> None:
    r = _run("plan", "--help")
    assert r.returncode == 0
    assert "[s]" in r.stdout


def test_a_long_error_stays_on_one_line() -> None:
    r = _run("plan", "--scene", "no_such_scene_" + "x" * 100)
    assert r.returncode == 2
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1, r.stderr


def test_steps_with_min_steps_is_refused() -> None:
    r = _run("plan", "--scene", "flat", "--steps", "8", "--min-steps")
    assert r.returncode == 2
    assert "min-steps" in r.stderr


def test_an_output_path_that_is_a_file_is_refused_before_planning(tmp_path) -> None:  # type: ignore[no-untyped-def]
    f = tmp_path / "taken"
    f.write_text("x")
    r = _run("plan", "--scene", "flat", "--steps", "8", "--out", str(f))
    assert r.returncode == 2
    assert "out:" in r.stderr and "Traceback" not in r.stderr
    assert "planning" not in r.stdout


def test_threads_beyond_the_cores_are_refused() -> None:
    r = _run("plan", "--scene", "flat", "--steps", "8", "--threads", "4096")
    assert r.returncode == 2
    assert "threads" in r.stderr


def test_a_failed_reactive_plan_exits_1_and_leaves_no_stale_figure(tmp_path) -> None:  # type: ignore[no-untyped-def]
    ok = _run("plan", "--scene", "flat", "--planner", "reactive", "--out", str(tmp_path))
    assert ok.returncode == 0, ok.stderr
    assert (tmp_path / "plan.png").exists()
    # two footsteps cannot reach the goal of `flat` (1 m away)
    short = _run(
        "plan", "--scene", "flat", "--planner", "reactive", "--steps", "2", "--out", str(tmp_path)
    )
    assert short.returncode == 1, short.stdout + short.stderr
    assert '"status": "incomplete"' in (tmp_path / "plan.json").read_text()


@pytest.mark.parametrize(
    ("package", "args"),
    [
        ("mujoco", ["quadruped", "--cycles", "1", "--no-video"]),
        ("shapely", ["terrain", "from-heightmap", "MAP", "--resolution", "0.02"]),
    ],
)
def test_a_missing_optional_package_exits_2_naming_the_extra(
    tmp_path: Path, package: str, args: list[str]
) -> None:
    """Nothing ran and the message says what to install: like bad input, exit 2 (not 1, a run
    that failed)."""
    import os

    import numpy as np

    blocked = tmp_path / "blocked" / package
    blocked.mkdir(parents=True)
    (blocked / "__init__.py").write_text(f"raise ImportError('{package} blocked for this test')\n")
    np.save(tmp_path / "map.npy", np.random.default_rng(0).normal(0.0, 1e-3, (20, 20)))
    args = [str(tmp_path / "map.npy") if a == "MAP" else a for a in args]
    # the blocked package first, then whatever path the tests run with (a worktree's src)
    path = os.pathsep.join(p for p in (str(blocked.parent), os.environ.get("PYTHONPATH")) if p)
    env = os.environ | {"PYTHONPATH": path}
    r = subprocess.run(
        [sys.executable, "-m", "footfall", *args, "--out", str(tmp_path / "out.yaml")],
        capture_output=True, text=True, timeout=120, env=env,
    )  # fmt: skip
    assert r.returncode == 2, r.stdout + r.stderr
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    assert "pip install" in lines[0] and "footfall[" in lines[0], lines[0]


@pytest.mark.parametrize("command", ["plan", "walk"])
@pytest.mark.parametrize("value", ["-1", "x"])
def test_a_bad_heading_window_count_is_refused(command: str, value: str, tmp_path: Path) -> None:
    r = _run(command, "--scene", "flat", "--heading-windows", value, "--out", str(tmp_path / "o"))
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "heading" in r.stderr and "integer" in r.stderr  # the option and what it takes
    assert not (tmp_path / "o").exists()  # the output folder it made is not left behind


def test_a_failed_command_removes_only_the_empty_folders_it_created(tmp_path: Path) -> None:
    from footfall.cli._common import _CREATED, output_folder, remove_unused_folders

    _CREATED.clear()
    kept = tmp_path / "existing"
    kept.mkdir()
    output_folder(kept)  # existed before: never removed
    output_folder(tmp_path / "a" / "b" / "c")  # three new folders
    output_folder(tmp_path / "used")
    (tmp_path / "used" / "result.json").write_text("{}")  # written into: kept
    remove_unused_folders()
    assert kept.is_dir() and (tmp_path / "used" / "result.json").is_file()
    assert not (tmp_path / "a").exists()
    assert not _CREATED
