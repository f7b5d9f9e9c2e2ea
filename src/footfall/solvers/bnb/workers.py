"""Forked worker processes that solve node relaxations for one search.

With ``threads >= 2`` the search hands node solves (and the dive) to :class:`_Workers`; the queue,
incumbent and pruning stay in the calling process. A worker that dies or raises stops the search
with :class:`WorkerError`; every worker is reaped however the search ends.
"""

from __future__ import annotations

import math
import os
import time
from typing import Any

from footfall._process import die_with_parent
from footfall._typing import FloatArray
from footfall.errors import SolverError
from footfall.solvers.bnb.branching import _dive
from footfall.solvers.bnb.relaxation import HullRelaxation, _Relaxation

_WORKER: HullRelaxation | None = None


#: in a worker: a shared flag the search sets when it ends (see :class:`_Workers`)
_STOP: Any = None


class WorkerError(SolverError, RuntimeError):
    """A worker process of the search died or failed; the message says which and how."""


def _work(task: tuple[tuple[tuple[int, ...], ...], bool]) -> _Relaxation:
    """Solve one node relaxation in a worker process (forked with the relaxation built)."""
    assert _WORKER is not None
    allowed, full = task
    res = _WORKER.solve(allowed, full=full)
    if res.status == "failed" and not full:
        res = _WORKER.solve(allowed, full=True)
    return res


def _work_dive(
    task: tuple[FloatArray, tuple[tuple[int, ...], ...], float, float],
) -> tuple[tuple[tuple[int, ...], ...] | None, _Relaxation | None]:
    """Dive in a worker process (see :func:`_dive`); returns the assignment it ends at and the
    condensed relaxation with every group fixed to it."""
    assert _WORKER is not None
    chosen = _dive(_WORKER, *task, stop=_STOP)
    return chosen, None if chosen is None else _WORKER.solve(chosen)


def _serve(conn: Any, relax: HullRelaxation, stop: Any, parent: int, theirs: list[Any]) -> None:
    """Body of a worker process: answer ``(id, kind, task)`` messages with ``(id, ok, result)``
    until ``None`` or the end of the pipe. A task's exception is sent back as text (it may not
    pickle); SIGINT is left to the search, which shuts the workers down.

    The worker dies with the search process ``parent`` (:func:`die_with_parent`), and closes
    the search's ends of the pipes it inherited (``theirs``), so that its own pipe reads an end
    of file once the search is gone."""
    import signal
    import traceback

    global _WORKER, _STOP
    die_with_parent(parent)
    for end in theirs:
        end.close()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _WORKER, _STOP = relax, stop
    while True:
        try:
            msg = conn.recv()
        except (EOFError, OSError):
            return  # the search process is gone
        if msg is None:
            return
        tid, kind, task = msg
        out: tuple[int, bool, Any]
        try:
            out = (tid, True, _work_dive(task) if kind == "dive" else _work(task))
        except Exception:
            out = (tid, False, traceback.format_exc())
        try:
            conn.send(out)
        except (BrokenPipeError, OSError):
            return


class _Workers:
    """``n`` forked worker processes solving the node relaxations of one search.

    Forked, so every worker inherits the built relaxation (:class:`HullRelaxation`, with its
    templates and condensed KKT factor) instead of receiving it pickled; a task is only a node's
    allowed members (tuples of ints) and a result one :class:`_Relaxation`.

    Not :class:`multiprocessing.pool.Pool`: a Pool silently replaces a worker that dies (a crash
    in the node solver, the out-of-memory killer) and the task it held never returns, so the search
    would wait for it until its time limit (and the replacement, forked later, would not hold the
    relaxation). Here each worker has its own pipe and :meth:`wait` watches the pipes and the
    processes' sentinels together, so a dead worker raises :class:`WorkerError` at once. There are
    no helper threads, and :meth:`close` always reaps every process.
    """

    def __init__(self, relax: HullRelaxation, n: int) -> None:
        import multiprocessing as mp

        ctx = mp.get_context("fork")
        self.settings = relax.settings
        #: shared flag: 1 ends dives early (set by :meth:`close`)
        self.stop = ctx.Value("b", 0, lock=False)
        self.conns: list[Any] = []
        self.procs: list[Any] = []
        #: per worker, the ids of the tasks sent and not answered yet
        self.pending: list[list[int]] = []
        self.closed = False
        parent = os.getpid()
        try:
            for _ in range(n):
                here, there = ctx.Pipe(duplex=True)
                theirs = [*self.conns, here]  # the search's ends, copied into the fork
                proc = ctx.Process(
                    target=_serve, args=(there, relax, self.stop, parent, theirs), daemon=True
                )
                proc.start()
                there.close()
                self.conns.append(here)
                self.procs.append(proc)
                self.pending.append([])
        except BaseException:
            self.close()
            raise

    @staticmethod
    def available() -> bool:
        """Forked workers need the fork start method (Linux, and macOS where it is not the
        default); elsewhere the search runs in one process."""
        import multiprocessing as mp

        return "fork" in mp.get_all_start_methods()

    @property
    def idle(self) -> bool:
        """Some worker has no task."""
        return any(not p for p in self.pending)

    @property
    def busy(self) -> int:
        """Tasks sent and not answered yet."""
        return sum(map(len, self.pending))

    def submit(self, tid: int, kind: str, task: Any) -> None:
        """Send task ``tid`` (``kind`` "node": :func:`_work`, "dive": :func:`_work_dive`) to the
        worker with the fewest unanswered tasks."""
        i = min(range(len(self.conns)), key=lambda k: len(self.pending[k]))
        try:
            self.conns[i].send((tid, kind, task))
        except (BrokenPipeError, OSError) as exc:
            raise self._died(i) from exc
        self.pending[i].append(tid)

    def _died(self, i: int) -> WorkerError:
        proc = self.procs[i]
        proc.join(timeout=1.0)
        return WorkerError(
            f"bnb worker process {proc.pid} died (exit code {proc.exitcode}) with "
            f"{len(self.pending[i])} node solve(s) unanswered; the search is stopped"
        )

    def wait(self, timeout: float) -> list[tuple[int, Any]]:
        """The ``(id, result)`` of the tasks answered within ``timeout`` seconds ([] if none).

        Raises :class:`WorkerError` when a worker died or a task raised in a worker.
        """
        from multiprocessing.connection import wait

        sentinels = {p.sentinel: i for i, p in enumerate(self.procs)}
        ready = wait([*self.conns, *sentinels], timeout=max(timeout, 0.0))
        out: list[tuple[int, Any]] = []
        for i, conn in enumerate(self.conns):
            try:
                while conn.poll():
                    tid, ok, res = conn.recv()
                    self.pending[i].remove(tid)
                    if not ok:
                        raise WorkerError(f"a bnb worker failed solving a node:\n{res}")
                    out.append((tid, res))
            except (EOFError, OSError) as exc:
                raise self._died(i) from exc
        for obj in ready:
            if obj in sentinels:
                raise self._died(sentinels[obj])
        return out

    def map(self, kind: str, tasks: list[Any], deadline: float = math.inf) -> list[Any]:
        """Results of ``tasks`` in their order, solved in the workers (a synchronous batch:
        probing, the local search); None for the tasks not sent before ``deadline``
        (``time.perf_counter`` seconds).

        At most ``settings.map_depth`` tasks per worker are in flight: a worker blocks sending its result
        while its pipe is full, so sending it every task at once could deadlock both ends."""
        base = 1 << 40  # ids apart from the asynchronous tasks
        got: dict[int, Any] = {}
        sent = 0
        limit = len(tasks)
        while len(got) < sent or sent < limit:
            if time.perf_counter() > deadline:
                limit = sent  # send no more; wait for those in flight
            while sent < limit and self.busy < self.settings.map_depth * len(self.conns):
                self.submit(base + sent, kind, tasks[sent])
                sent += 1
            if len(got) < sent:
                got.update(self.wait(60.0))
        return [got.get(base + k) for k in range(len(tasks))]

    def drain(self) -> None:
        """Wait for every task in flight and drop its result (the workers are then idle)."""
        while self.busy:
            self.wait(60.0)

    def close(self, grace: float | None = None) -> None:
        """Stop every worker and reap it: dives end early (shared flag), each worker finishes its
        current solve and exits on ``None``; one still alive after ``grace`` seconds (default
        ``settings.drain_timeout``) is terminated, then killed. Unanswered results are dropped.
        Safe to call twice."""
        if self.closed:
            return
        grace = self.settings.drain_timeout if grace is None else grace
        self.closed = True
        self.stop.value = 1
        for conn in self.conns:
            try:
                conn.send(None)
            except (BrokenPipeError, OSError):
                pass
        end = time.perf_counter() + grace
        from multiprocessing.connection import wait

        # read what the workers still send, so none blocks on a full pipe while exiting; a worker
        # whose sentinel is ready has exited (is_alive() may lag until it is reaped, so join it:
        # waiting on an empty list instead would sleep out the whole grace)
        while time.perf_counter() < end:
            alive = [i for i, p in enumerate(self.procs) if p.is_alive()]
            if not alive:
                break
            conns = {self.conns[i]: i for i in alive}
            sentinels = {self.procs[i].sentinel: i for i in alive}
            for obj in wait([*conns, *sentinels], timeout=max(end - time.perf_counter(), 0.0)):
                if obj in sentinels:
                    self.procs[sentinels[obj]].join()
                else:
                    try:
                        self.conns[conns[obj]].recv()
                    except (EOFError, OSError):
                        pass
        for proc in self.procs:
            if proc.is_alive():
                proc.terminate()
                proc.join(timeout=1.0)
            if proc.is_alive():  # pragma: no cover - SIGTERM is not ignored by the workers
                proc.kill()
            proc.join()
        for conn in self.conns:
            conn.close()
