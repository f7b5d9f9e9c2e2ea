"""The ``footfall`` command line.

Every command that computes something writes JSON and a figure into ``--out``. The commands live
by subject in :mod:`.planning`, :mod:`.simulation`, :mod:`.bench`, :mod:`.terrain` and :mod:`.view`;
:func:`main` turns errors into one line and an exit code (:func:`main` lists them) and ends worker
processes on SIGINT / SIGTERM.
"""

from __future__ import annotations

import os
import signal
import sys
import time

from footfall.cli._common import _say_error, app, remove_unused_folders
from footfall.errors import (
    FootfallError,
    InputError,
    MissingExtraError,
    SolverUnavailableError,
    Stopped,
)


def _end_children() -> None:
    """Terminate this process's worker processes (solver workers, trial pools), then kill what
    is still alive a second later: no worker outlives an interrupted command."""
    import multiprocessing as mp

    children = mp.active_children()
    for child in children:
        child.terminate()
    deadline = time.monotonic() + 1.0
    for child in children:
        child.join(max(0.0, deadline - time.monotonic()))
        if child.is_alive():
            child.kill()


#: pid of the process that installed the handlers (forked workers inherit them)
_MAIN_PID = 0


def _on_signal(signum: int, frame: object) -> None:
    if os.getpid() != _MAIN_PID:  # a forked worker: leave at once, quietly
        os._exit(128 + signum)
    signal.signal(signum, signal.SIG_IGN)  # a second signal must not interrupt the clean-up
    _end_children()
    raise Stopped(signum)


def main() -> None:
    """Entry point of the ``footfall`` console script.

    Exit codes: 0 success, 1 a run that failed (no plan, a solver error, a fall reported as a
    failure), 2 bad input (:class:`footfall.errors.InputError`) or a missing optional package
    (:class:`~footfall.errors.MissingExtraError`, :class:`~footfall.errors.SolverUnavailableError`:
    nothing ran, the message says what to install), 128 + the signal number when
    stopped by SIGINT (130) or SIGTERM (143), after ending every worker process. Errors footfall
    raises are printed as one line, never as a traceback; an output folder the command created
    and left empty is removed.
    """
    global _MAIN_PID
    _MAIN_PID = os.getpid()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, _on_signal)
    try:
        app()
    except (InputError, MissingExtraError, SolverUnavailableError) as exc:
        remove_unused_folders()
        _say_error("error", str(exc))
        sys.exit(2)
    except FootfallError as exc:
        remove_unused_folders()
        _say_error("failed", str(exc))
        sys.exit(1)
    except Stopped as exc:
        remove_unused_folders()
        _say_error("stopped", f"by {signal.Signals(exc.signum).name}")
        sys.exit(128 + exc.signum)


# the command modules register their commands on ``app`` when imported
from footfall.cli import bench, planning, robot, simulation, study, terrain, view  # noqa: E402

__all__ = ["app", "bench", "main", "planning", "robot", "simulation", "study", "terrain", "view"]
