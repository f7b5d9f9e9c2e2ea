"""Progress of a planning run that a person or a log can read (``--quiet``, ``--log-json``).

In a terminal: one live status line (N being tried, nodes, incumbent, bound, gap, elapsed).
Without one (CI, a cluster job, a pipe): plain lines on stderr, one per N tried or skipped and, while
a solve runs, at most one every ``LOG_PERIOD``. ``--quiet`` silences both; ``--log-json FILE``
writes every line as a JSON object (JSON lines), whatever the terminal or ``--quiet``.
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from types import TracebackType
from typing import IO, TYPE_CHECKING, Any

from footfall.cli._common import console
from footfall.errors import InputError

if TYPE_CHECKING:  # annotations only: importing the planner costs every command a second
    from footfall.planning.plan import FootstepPlan
    from footfall.solvers.base import SolveProgress

#: least time [s] between two progress lines of a running solve (plain and JSON lines)
LOG_PERIOD = 5.0


def _num(value: float | None) -> float | None:
    """A JSON-safe number: None for a missing or non-finite value."""
    return None if value is None or not math.isfinite(value) else float(value)


def _fmt(value: float | None) -> str:
    return "none" if value is None or not math.isfinite(value) else f"{value:.6g}"


class ProgressLog:
    """The progress reporter of ``footfall plan`` (a :class:`~footfall.planning.run.SearchMonitor`).

    Args:
        title: what is being planned, e.g. ``discrete_steps with miqcqp``.
        quiet: no status line and no plain lines.
        json_path: file for the JSON lines (created or overwritten), or None.
        terminal: whether stderr is a terminal (default: ask the console).
    """

    def __init__(
        self,
        title: str,
        quiet: bool = False,
        json_path: Path | None = None,
        terminal: bool | None = None,
    ) -> None:
        self.title = title
        self.quiet = quiet
        self.terminal = console.is_terminal if terminal is None else terminal
        self.start = time.perf_counter()
        self.logged_at = -math.inf
        self.json: IO[str] | None = None
        self.json_path = str(json_path)
        if json_path is not None:
            try:
                self.json = json_path.open("w", encoding="utf-8")
            except OSError as e:
                raise InputError(
                    "log_json", str(json_path), f"a file that can be written ({e.strerror})"
                ) from None
        self.status: Any = None

    def __enter__(self) -> ProgressLog:
        # the first JSON line is written before any work: a file that cannot take it (a full
        # disk, /dev/full) is bad input, refused before the planning starts
        try:
            self._write({"event": "start", "what": self.title})
        except OSError as e:
            self._close()
            raise InputError(
                "log_json", self.json_path, f"a file that can be written ({e.strerror})"
            ) from None
        if self.terminal and not self.quiet:
            self.status = console.status(f"planning {self.title} ...")
            self.status.__enter__()
        # without a terminal the log says what it is about (a command may plan several times)
        self._emit(None, f"planning {self.title}", False)
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        if self.status is not None:
            self.status.__exit__(kind, exc, tb)
        self._close()

    def _close(self) -> None:
        if self.json is not None:
            try:
                self.json.close()
            except OSError:  # what could not be flushed was reported when it was written
                pass
            self.json = None

    # --- the SearchMonitor interface ------------------------------------------------------------
    def skipped(self, first: int, last: int, reason: str) -> None:
        """N = ``first``..``last`` ruled out without a solve."""
        which = f"N = {first}" if first == last else f"N = {first}..{last}"
        record = {"event": "skipped", "from": first, "to": last, "reason": reason}
        self._emit(record, f"{which}: ruled out without a solve ({reason})")

    def solving(self, n_steps: int | None, progress: SolveProgress, model: str = "") -> None:
        """A solve (of ``model``, if named) is at ``progress``: the status line follows it, the
        log every LOG_PERIOD."""
        where = "" if n_steps is None else f"N = {n_steps}"
        where += f"{', ' if where else ''}{model}" if model else ""
        where += ": " if where else ""
        text = (
            f"{where}solving, {progress.nodes} nodes, incumbent {_fmt(progress.incumbent)}, "
            f"bound {_fmt(progress.bound)}, gap {_fmt(progress.gap)}, "
            f"{progress.seconds:.1f} s"
        )
        if self.status is not None:
            self.status.update(f"planning {self.title}: {text}")
        now = time.perf_counter()
        if now < self.logged_at + LOG_PERIOD:
            return
        self.logged_at = now
        record = {
            "event": "solving",
            "n_steps": n_steps,
            "model": model or None,
            "nodes": progress.nodes,
            "incumbent": _num(progress.incumbent),
            "bound": _num(progress.bound),
            "gap": _num(progress.gap),
            "solve_seconds": round(progress.seconds, 3),
        }
        self._emit(record, text, permanent=False)

    def tried(self, n_steps: int, plan: FootstepPlan, seconds: float, proof: str) -> None:
        """N = ``n_steps`` ended with ``plan``."""
        by = f" ({proof})" if proof != "solver" and plan.status.value == "infeasible" else ""
        text = f"N = {n_steps}: {plan.status.value}{by} in {seconds:.1f} s"
        if plan.has_solution:
            text += f", objective {_fmt(plan.objective)}, gap {_fmt(plan.gap)}"
        record = {
            "event": "tried",
            "n_steps": n_steps,
            "status": plan.status.value,
            "proof": proof,
            "seconds": round(seconds, 3),
            "objective": _num(plan.objective),
            "gap": _num(plan.gap),
        }
        self.logged_at = -math.inf  # the next solve's first progress line is not held back
        self._emit(record, text)

    def done(self, plan: FootstepPlan) -> None:
        """The run's result (JSON only: the command prints its own summary)."""
        record = {
            "event": "done",
            "status": plan.status.value,
            "n_steps": plan.n_steps if plan.has_solution else None,
            "objective": _num(plan.objective),
            "gap": _num(plan.gap),
        }
        self._emit(record, None)

    # --- output -----------------------------------------------------------------------------------
    def _write(self, record: dict[str, Any]) -> None:
        """One JSON line, flushed (a reader following the file sees each line as it happens)."""
        if self.json is not None:
            elapsed = time.perf_counter() - self.start
            self.json.write(json.dumps({"elapsed": round(elapsed, 3), **record}) + "\n")
            self.json.flush()

    def _emit(
        self, record: dict[str, Any] | None, text: str | None, permanent: bool = True
    ) -> None:
        """Write ``record`` to the JSON lines and ``text`` as a plain line (``permanent``: also
        above the status line in a terminal; otherwise only without one). A JSON line that
        cannot be written (the disk filled up) ends the JSON log with one warning; the planning
        goes on."""
        if record is not None:
            try:
                self._write(record)
            except OSError as e:
                self._close()
                console.print(f"warning: --log-json {self.json_path}: {e.strerror}; log stopped")
        if text is None or self.quiet or (self.status is not None and not permanent):
            return
        console.print(f"[{time.perf_counter() - self.start:7.1f} s] {text}")
