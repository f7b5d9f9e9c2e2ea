"""Worker processes that die with the process that started them.

A worker blocked in a solve does not notice that its parent was killed (``kill -9``, the
out-of-memory killer, a crash): it would run on, reparented to PID 1, until its task ends. On
Linux the kernel can send it a signal when its parent dies (``prctl(PR_SET_PDEATHSIG)``);
elsewhere workers rely on their pipes (an end-of-file when the parent is gone) and on the
parent's own clean-up.
"""

from __future__ import annotations

import ctypes
import os
import signal
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

#: ``PR_SET_PDEATHSIG`` of <sys/prctl.h>
_PR_SET_PDEATHSIG = 1


def spawn_pool(workers: int) -> Any:
    """A ``ProcessPoolExecutor`` of ``workers`` spawned processes (each imports numpy afresh, so
    it reads single-threaded BLAS from the environment), each dying with this process even when
    it is killed (:func:`die_with_parent`)."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    return ProcessPoolExecutor(
        workers,
        mp_context=mp.get_context("spawn"),
        initializer=die_with_parent,
        initargs=(os.getpid(),),
    )


def die_with_parent(parent_pid: int) -> bool:
    """In a child process: have the kernel kill this process (SIGKILL) as soon as its parent
    ``parent_pid`` dies; exit at once if it has died already. Returns whether the kernel will
    (False off Linux, or where ``prctl`` is not available: a no-op there).

    The signal follows the parent *thread* that started the child; footfall starts its workers
    from the thread that then waits for them."""
    armed = False
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            armed = libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
        except (OSError, AttributeError):
            armed = False
    if os.getppid() != parent_pid:  # the parent died before the request: nobody would ask
        os._exit(1)
    return armed


def unreachable(address: str, timeout: float = 5.0) -> str | None:
    """Why nothing accepts a TCP connection at ``address`` (``host:port``, with an optional
    scheme such as ``ray://``) within ``timeout`` seconds; None when something does. A client
    library may retry an unreachable address for minutes, deaf to signals, before it says so."""
    import socket

    hostport = address.split("://", 1)[-1].rstrip("/")
    host, sep, port = hostport.rpartition(":")
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        return "not host:port"
    try:
        with socket.create_connection((host.strip("[]"), int(port)), timeout=timeout):
            return None
    except OSError as e:
        return e.strerror or type(e).__name__


class DeferredSignals:
    """Within the block, SIGINT and SIGTERM are recorded instead of handled: :meth:`check`,
    called between two calls into an extension, hands a recorded signal to the handler that was
    installed before the block (which may raise), and so does the end of the block.

    Ray's core worker calls back into Python while it waits: a handler's exception raised in
    such a callback comes out as a ``SystemError`` (or a crash), and ``ray.init`` replaces the
    SIGTERM handler with its own; :meth:`arm` records again after such a call. In a thread
    other than the main one (where handlers cannot be set) the block changes nothing."""

    SIGNALS = (signal.SIGINT, signal.SIGTERM)

    def __init__(self) -> None:
        self.previous: dict[int, Any] = {}
        self.pending: list[int] = []

    def __enter__(self) -> DeferredSignals:
        if threading.current_thread() is threading.main_thread():
            self.previous = {s: signal.getsignal(s) for s in self.SIGNALS}
            self.arm()
        return self

    def _record(self, signum: int, frame: object) -> None:
        self.pending.append(signum)

    def arm(self) -> None:
        """Record the signals (again: a call may have installed its own handlers)."""
        for signum in self.previous:
            signal.signal(signum, self._record)

    @contextmanager
    def blocked(self) -> Iterator[None]:
        """Block the signals in this thread (and in the threads started meanwhile, which
        inherit the mask) for a call that installs handlers of its own, C-level ones included
        (``ray.init``: its fatal-signal handler aborts the process on SIGTERM); then record
        them again and let the ones that arrived meanwhile through, to :meth:`check`."""
        if not self.previous or not hasattr(signal, "pthread_sigmask"):
            yield
            return
        old = signal.pthread_sigmask(signal.SIG_BLOCK, set(self.SIGNALS))
        try:
            yield
        finally:
            self.arm()
            signal.pthread_sigmask(signal.SIG_SETMASK, old)

    def restore(self) -> None:
        """Put the handlers of before the block back."""
        for signum, handler in self.previous.items():
            signal.signal(signum, handler)

    def check(self) -> None:
        """Hand the first recorded signal, if any, to its previous handler (the handlers of
        before the block are back then)."""
        if not self.pending:
            return
        signum = self.pending[0]
        self.pending.clear()
        self.restore()
        self.previous = {}  # the block is over as far as signals go
        handler = signal.getsignal(signum)
        if callable(handler):
            handler(signum, None)
        elif handler == signal.SIG_DFL:
            signal.raise_signal(signum)

    def __exit__(self, kind: object, exc: object, tb: object) -> None:
        self.restore()
        if kind is None:
            self.check()
