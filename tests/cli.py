"""Running the ``footfall`` command in a subprocess, and its one-line error contract."""

from __future__ import annotations

import subprocess
import sys


def footfall(*args: str, timeout: float = 300) -> subprocess.CompletedProcess[str]:
    """``python -m footfall ARGS`` with its output captured (``timeout``: a hang guard [s])."""
    return subprocess.run(
        [sys.executable, "-m", "footfall", *args], capture_output=True, text=True, timeout=timeout
    )


def error_line(r: subprocess.CompletedProcess[str], field: str) -> str:
    """The one stderr line of a refused command (exit 2, no traceback), which names ``field``."""
    assert r.returncode == 2, r.stdout + r.stderr[-2000:]
    lines = [line for line in r.stderr.splitlines() if line.strip()]
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr[-2000:]
    assert field in lines[0], lines[0]
    return lines[0]
