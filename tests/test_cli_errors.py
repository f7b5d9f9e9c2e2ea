"""The command line's error contract: one plain line (no markup interpretation), exit 2 for bad input."""

from __future__ import annotations

import subprocess
import sys


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
