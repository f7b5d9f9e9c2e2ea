"""SIGTERM and SIGINT end a command and every worker process it started, within a few seconds."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.skipif(not Path("/proc").is_dir(), reason="reads /proc for child pids")


def _children(pid: int) -> list[int]:
    """Pids whose parent is ``pid`` (from /proc)."""
    found = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        # the command name may hold spaces: the parent pid is the 2nd field after ')'
        if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
            found.append(int(entry.name))
    return found


def _alive(pid: int) -> bool:
    try:
        stat = (Path("/proc") / str(pid) / "stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def _signal_once_workers_run(args: list[str], sig: int, tmp_path: Path) -> tuple[int, list[int]]:
    proc = subprocess.Popen(
        [sys.executable, "-m", "footfall", *args, "--out", str(tmp_path)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=os.environ | {"OPENBLAS_NUM_THREADS": "1"},
    )
    workers: list[int] = []
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        workers = _children(proc.pid)
        if len(workers) >= 2:
            break
        time.sleep(0.2)
    assert proc.poll() is None, f"the command ended before starting workers: {proc.stderr.read()}"  # type: ignore[union-attr]
    assert len(workers) >= 2, "no worker processes appeared"
    time.sleep(1.0)  # let the workers get busy
    proc.send_signal(sig)
    try:
        code = proc.wait(timeout=15)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("the command did not stop within 15 s of the signal")
    return code, workers


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_compare_ends_its_trial_pool(sig: int, tmp_path: Path) -> None:
    args = ["compare", "--scenes", "flat", "--planners", "reactive", "--trials", "400",
            "--workers", "2"]  # fmt: skip
    code, workers = _signal_once_workers_run(args, sig, tmp_path)
    assert code == 128 + sig
    time.sleep(1.0)
    assert not [w for w in workers if _alive(w)], "worker processes outlived the command"


def test_plan_ends_its_solver_workers(tmp_path: Path) -> None:
    # a long solve on two workers: stepping stones with many footsteps
    args = ["plan", "--scene", "stairs_slope_gap", "--steps", "20", "--threads", "2",
            "--time-limit", "300"]  # fmt: skip
    code, workers = _signal_once_workers_run(args, signal.SIGTERM, tmp_path)
    assert code == 128 + signal.SIGTERM
    time.sleep(1.0)
    assert not [w for w in workers if _alive(w)], "solver workers outlived the command"
