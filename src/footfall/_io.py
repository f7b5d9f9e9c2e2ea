"""File input and output shared by the CLI, the demo and the viewer.

Every output file is written whole or not at all: it is written under a temporary name beside
its destination, flushed to disk and renamed over it (:func:`atomic_path`), so a signal, a crash
or a full disk leaves the previous file in place, never a truncated one.
"""

from __future__ import annotations

import itertools
import json
import math
import os
import stat
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import numpy as np

from footfall.errors import InputError

#: distinguishes the temporary files of one process
_TMP_IDS = itertools.count()


def json_ready(value: Any) -> Any:
    """``value`` as plain JSON data: numpy arrays and scalars become lists and Python numbers,
    tuples become lists, dict keys become strings, and non-finite floats (which JSON cannot
    represent) become ``null``."""
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


class PendingFile:
    """A file written under a temporary name beside ``path`` (with its suffix, so writers that
    choose the format from it, matplotlib, imageio, pyarrow, write the destination's format:
    ``.walk.1234-0.tmp.png``) and put in place whole by :meth:`commit`, or removed by
    :meth:`abort`. Parent folders are created. For a writer open for a long time (a video);
    :func:`atomic_path` is the same for one block."""

    def __init__(self, path: Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        name = f".{self.path.stem}.{os.getpid()}-{next(_TMP_IDS)}.tmp{self.path.suffix}"
        self.tmp = self.path.with_name(name)

    def commit(self) -> Path:
        """Flush the temporary file to disk and rename it over ``path`` (``os.replace``: atomic
        on one file system); returns ``path``."""
        try:
            fd = os.open(self.tmp, os.O_RDONLY)
            try:
                os.fsync(fd)  # the data is on disk before the name points at it
            finally:
                os.close(fd)
            os.replace(self.tmp, self.path)
        finally:
            self.abort()
        return self.path

    def abort(self) -> None:
        """Remove the temporary file (``path`` is left as it was)."""
        self.tmp.unlink(missing_ok=True)

    def finish(self, complete: bool) -> None:
        """:meth:`commit` a complete file, :meth:`abort` an interrupted one."""
        if complete:
            self.commit()
        else:
            self.abort()


@contextmanager
def atomic_path(path: Path) -> Iterator[Path]:
    """A temporary path beside ``path`` for a writer to fill (:class:`PendingFile`): when the
    block ends normally the file is flushed to disk and renamed over ``path``, otherwise it is
    removed and ``path`` is left as it was."""
    pending = PendingFile(path)
    try:
        yield pending.tmp
    except BaseException:
        pending.abort()
        raise
    pending.commit()


@contextmanager
def atomic_open(path: Path, mode: str = "w", **kwargs: Any) -> Iterator[IO[Any]]:
    """``open(path, mode)`` through :func:`atomic_path`: the file appears whole when the block
    ends, or not at all (``mode`` "w" or "wb"; ``kwargs`` go to :func:`open`)."""
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh


def write_text(path: Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (:func:`atomic_path`); return the path."""
    with atomic_open(path, "w", encoding="utf-8") as fh:
        fh.write(text)
    return path


def write_json(path: Path, payload: dict[str, Any]) -> Path:
    """Write ``payload`` (made :func:`json_ready`) as indented JSON to ``path``, creating parent
    folders; return the path. The file is strict JSON: no ``NaN`` or ``Infinity`` tokens, and it
    is written atomically (:func:`atomic_path`)."""
    return write_text(path, json.dumps(json_ready(payload), indent=2, allow_nan=False) + "\n")


def save_figure(fig: Any, path: Path, **savefig: Any) -> Path:
    """Save the matplotlib figure ``fig`` to ``path`` atomically (:func:`atomic_path`; the
    format from the suffix), close it and return the path. ``savefig`` goes to
    :meth:`matplotlib.figure.Figure.savefig` (``dpi``, ``bbox_inches``)."""
    import matplotlib.pyplot as plt

    try:
        with atomic_path(path) as tmp:
            fig.savefig(tmp, **savefig)
    finally:
        plt.close(fig)
    return path


def regular_file(
    path: Path,
    what: str,
    max_bytes: int,
    kind: str = "file",
    error: type[InputError] = InputError,
) -> int:
    """The size of ``path`` [bytes] after checking that it is a regular file (not a folder,
    device or pipe) of at most ``max_bytes``; anything else raises ``error`` naming ``what``,
    the file and what was expected (``kind``, e.g. "YAML file")."""
    try:
        info = Path(path).stat()
    except OSError as e:
        raise error(what, str(path), f"a readable {kind} ({e.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise error(what, str(path), "a regular file (not a folder, device or pipe)")
    if info.st_size > max_bytes:
        raise error(what, f"{path} ({info.st_size} bytes)", f"at most {max_bytes} bytes")
    return int(info.st_size)


def read_bounded(
    path: Path, what: str, max_bytes: int, kind: str, error: type[InputError] = InputError
) -> str:
    """The UTF-8 text of ``path``: a :func:`regular_file` of at most ``max_bytes`` bytes, read
    no further than that even if it grows meanwhile."""
    path = Path(path)
    regular_file(path, what, max_bytes, kind, error)
    try:
        with path.open("rb") as fh:
            raw = fh.read(max_bytes + 1)
    except OSError as e:
        raise error(what, str(path), f"a readable {kind} ({e.strerror})") from None
    if len(raw) > max_bytes:
        raise error(what, f"{path} (over {max_bytes} bytes)", f"at most {max_bytes} bytes")
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise error(what, str(path), f"UTF-8 text ({e.reason} at byte {e.start})") from None


def remove_outputs(folder: Path, *names: str) -> None:
    """Remove the files ``names`` of ``folder`` that an earlier run wrote, before a run writes
    its own: a run stopped between two of its files then leaves some files missing, never a new
    file beside an old one of another run."""
    for name in names:
        (Path(folder) / name).unlink(missing_ok=True)
