"""The study's table on disk: ``DIR/trials.parquet``, one row per trial, written as trials finish.

Each finished row is written at once as a small Parquet part file (``DIR/trials.parts/part-*.parquet``,
written to a temporary name, flushed to disk and renamed, so a crash leaves either a whole part or
none) before the walk is reported done; every ``COMPACT_PARTS`` parts, and when the store is closed,
the rows are merged into ``trials.parquet`` sorted by key and the parts removed. A rerun reads both,
so Ctrl-C, a crash, ``kill -9`` or a lost worker loses only the walks that had not finished. The folder also
holds ``study.json`` (the design's fingerprint): a folder is reused only by a study whose trials
compute the same numbers.
"""

from __future__ import annotations

import json
import os
import time
from pathlib import Path
from typing import Any

from footfall._io import atomic_path, write_text
from footfall.errors import InputError
from footfall.experiments.study.design import StudyDesign
from footfall.experiments.study.trials import COLUMNS, OPTIONAL_COLUMNS

TABLE = "trials.parquet"
PARTS = "trials.parts"
META = "study.json"
#: part files after which the rows are merged into the table and the parts removed (a part per
#: finished walk keeps every walk on disk; the merge keeps their number small)
COMPACT_PARTS = 100


def _arrow() -> Any:
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        raise InputError(
            "pyarrow", "not installed", "pip install 'footfall[study]' (the study table is Parquet)"
        ) from None
    return pyarrow


def schema() -> Any:
    """The Arrow schema of the table (``trials.COLUMNS``)."""
    pa = _arrow()
    kinds = {
        "string": pa.string(),
        "int64": pa.int64(),
        "float64": pa.float64(),
        "bool": pa.bool_(),
    }
    return pa.schema([(name, kinds[kind]) for name, kind in COLUMNS])


def read_rows(path: Path) -> list[dict[str, Any]]:
    """The rows of one Parquet file of this schema (a damaged file is an error naming it)."""
    pa = _arrow()
    try:
        table = pa.parquet.read_table(path)
    except (OSError, pa.ArrowException) as e:
        raise InputError("trials file", str(path), f"a readable Parquet table ({e})") from None
    missing = [n for n, _ in COLUMNS if n not in table.column_names]
    if [n for n in missing if n not in OPTIONAL_COLUMNS]:
        raise InputError("trials file", str(path), f"the study columns (missing {missing})")
    rows = table.select([n for n, _ in COLUMNS if n not in missing]).to_pylist()
    return [{n: r.get(n) for n, _ in COLUMNS} for r in rows]


def write_rows(path: Path, rows: list[dict[str, Any]]) -> Path:
    """Write ``rows`` as one Parquet file, atomically (temporary name, then rename)."""
    pa = _arrow()
    table = pa.Table.from_pylist(rows, schema=schema())
    with atomic_path(path) as tmp:  # flushed to disk, then renamed
        pa.parquet.write_table(table, tmp)
    return path


class TrialStore:
    """The finished rows of a study folder, and the writer of new ones.

    Args:
        folder: the study's output folder (created).
        design: the study; a folder holding trials of a study with another fingerprint
            (:meth:`StudyDesign.fingerprint`) is refused.
    """

    def __init__(self, folder: Path, design: StudyDesign) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        _arrow()
        meta = self.folder / META
        fp = design.fingerprint()
        if meta.exists():
            try:
                old = json.loads(meta.read_text())["fingerprint"]
            except (OSError, ValueError, KeyError, TypeError):
                old = None
            if not isinstance(old, dict):  # unreadable, damaged or edited
                raise InputError(
                    "study folder", str(meta), "a study.json written by footfall study"
                ) from None
            if old != fp:
                diff = sorted(k for k in set(old) | set(fp) if old.get(k) != fp.get(k))
                raise InputError(
                    "--out",
                    str(self.folder),
                    f"a folder of this study or a new one: its trials were run with other "
                    f"{', '.join(diff)} ({', '.join(f'{k}={old.get(k)!r}' for k in diff)})",
                )
        write_text(meta, json.dumps({"fingerprint": fp, "design": design.to_dict()}, indent=1))
        self.parts = self.folder / PARTS
        self.rows: dict[str, dict[str, Any]] = {}
        table = self.folder / TABLE
        if table.exists():
            for r in read_rows(table):
                self.rows[r["key"]] = r
        if self.parts.is_dir():
            for p in sorted(self.parts.glob("part-*.parquet")):
                for r in read_rows(p):
                    self.rows[r["key"]] = r
        self.pending: list[dict[str, Any]] = []
        self.n_parts = 0

    def done(self, key: str, plan: str | None = None) -> bool:
        """Whether the trial ``key`` has a row (errors included: rerun them with a new folder or
        by deleting their rows; a trial that raises is expected to raise again) and, with
        ``plan`` (:func:`~footfall.experiments.study.trials.plan_digest`), whether that row
        walked this plan: a row of another plan, or of an unknown one (a table written before
        rows named their plan), is walked again and replaced."""
        row = self.rows.get(key)
        return row is not None and (plan is None or row["plan"] == plan)

    def add(self, row: dict[str, Any]) -> None:
        """Keep a finished row, on disk when this returns (its own part file): a walk reported
        done is never lost. Every ``COMPACT_PARTS`` parts the table is merged (:meth:`compact`)."""
        self.rows[row["key"]] = row
        self.pending.append(row)
        self.flush()
        if self.n_parts >= COMPACT_PARTS:
            self.compact()

    def flush(self) -> None:
        """Write the pending rows as one part file."""
        if self.pending:
            self.parts.mkdir(exist_ok=True)
            name = f"part-{time.time_ns():020d}-{os.getpid()}-{self.n_parts:05d}.parquet"
            write_rows(self.parts / name, self.pending)
            self.n_parts += 1
            self.pending = []

    def compact(self) -> Path:
        """Merge every row into ``trials.parquet`` (sorted by key) and remove the parts: the
        table is written whole first, so a crash between the two leaves rows twice (read once),
        never none."""
        self.flush()
        path = write_rows(self.folder / TABLE, [self.rows[k] for k in sorted(self.rows)])
        if self.parts.is_dir():
            # the parts and any temporary file a crash left mid-write (.part-*.tmp*)
            for p in [*self.parts.glob("part-*.parquet"), *self.parts.glob(".part-*.tmp*")]:
                p.unlink()
            self.parts.rmdir()
        self.n_parts = 0
        return path

    def close(self) -> Path:
        """Merge everything into ``trials.parquet`` (sorted by key) and remove the parts."""
        return self.compact()
