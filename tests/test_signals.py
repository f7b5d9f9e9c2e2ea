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
    code, workers, _ = _signal_once_workers_run_err(args, sig, tmp_path)
    return code, workers


def _signal_once_workers_run_err(
    args: list[str], sig: int, tmp_path: Path
) -> tuple[int, list[int], str]:
    """Start ``footfall ARGS --out TMP``, send ``sig`` once it has two child processes (and a
    second later); its exit code, the children and what it printed on stderr."""
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
        code = proc.wait(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        pytest.fail("the command did not stop within 60 s of the signal")
    return code, workers, proc.stderr.read()  # type: ignore[union-attr]


def _gone_within(pids: list[int], seconds: float) -> list[int]:
    """The pids still alive after up to ``seconds`` (polled)."""
    deadline = time.monotonic() + seconds
    alive = [p for p in pids if _alive(p)]
    while alive and time.monotonic() < deadline:
        time.sleep(0.2)
        alive = [p for p in alive if _alive(p)]
    return alive


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT])
def test_compare_ends_its_trial_pool(sig: int, tmp_path: Path) -> None:
    args = ["compare", "--scenes", "flat", "--planners", "reactive", "--trials", "400",
            "--workers", "2"]  # fmt: skip
    code, workers = _signal_once_workers_run(args, sig, tmp_path)
    assert code == 128 + sig
    assert not _gone_within(workers, 30.0), "worker processes outlived the command"


def test_plan_ends_its_solver_workers(tmp_path: Path) -> None:
    # a long solve on two workers: stepping stones with many footsteps
    args = ["plan", "--scene", "stairs_slope_gap", "--steps", "20", "--threads", "2",
            "--time-limit", "300"]  # fmt: skip
    code, workers = _signal_once_workers_run(args, signal.SIGTERM, tmp_path)
    assert code == 128 + signal.SIGTERM
    assert not _gone_within(workers, 30.0), "solver workers outlived the command"


def test_plan_solver_workers_die_with_a_killed_parent(tmp_path: Path) -> None:
    """kill -9 leaves no clean-up to the command: the kernel ends its workers (they ran on for
    20-40 s, reparented to PID 1)."""
    args = ["plan", "--scene", "stairs_slope_gap", "--steps", "20", "--threads", "2",
            "--time-limit", "300"]  # fmt: skip
    code, workers = _signal_once_workers_run(args, signal.SIGKILL, tmp_path)
    assert code == -signal.SIGKILL
    assert not _gone_within(workers, 30.0), "solver workers outlived their killed parent"


def test_study_pool_workers_die_with_a_killed_parent(tmp_path: Path) -> None:
    args = ["study", str(_long_reduced_study(tmp_path)), "--workers", "2", "--quiet"]
    code, workers = _signal_once_workers_run(args, signal.SIGKILL, tmp_path)
    assert code == -signal.SIGKILL
    assert not _gone_within(workers, 30.0), "pool workers outlived their killed parent"


def _long_reduced_study(tmp_path: Path) -> Path:
    study = tmp_path / "s.yaml"
    study.write_text(
        "name: killed\nsimulator: reduced\nscenes: [flat_long]\nplanners: [reactive]\n"
        "steps: [smallest]\ndefault_push: 4.0\nseeds: 2000\npush_levels: []\n"
    )
    return study


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_study_on_ray_stops_cleanly(sig: int, tmp_path: Path) -> None:
    """Ctrl-C on Ray exited 1 with a SystemError traceback (a handler's exception raised inside
    Ray's core worker) in 2 of 3 tries, or crashed; SIGTERM while Ray started aborted."""
    pytest.importorskip("ray")
    args = ["study", str(_long_reduced_study(tmp_path)), "--executor", "ray", "--workers", "2",
            "--quiet"]  # fmt: skip
    code, _, err = _signal_once_workers_run_err(args, sig, tmp_path / "out")
    assert code == 128 + sig, err[-3000:]
    assert "Traceback" not in err and "SystemError" not in err, err[-3000:]
    assert f"stopped: by {signal.Signals(sig).name}" in err


def test_study_on_an_unreachable_ray_cluster_is_refused_at_once(tmp_path: Path) -> None:
    """Ray retried an unreachable --address for minutes, deaf to SIGTERM."""
    import socket

    pytest.importorskip("ray")
    with socket.socket() as s:  # a port nobody listens on once closed
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    r = subprocess.run(
        [sys.executable, "-m", "footfall", "study", str(_long_reduced_study(tmp_path)),
         "--executor", "ray", "--address", f"127.0.0.1:{port}", "--out", str(tmp_path / "o")],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert r.returncode == 2, r.stderr[-2000:]
    assert "--address:" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "o" / "plans").exists()  # refused before any planning
