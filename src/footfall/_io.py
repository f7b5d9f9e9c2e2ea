"""File input and output shared by the CLI, the demo and the viewer."""

from __future__ import annotations

import json
import math
import stat
from pathlib import Path
from typing import Any

import numpy as np

from footfall.errors import InputError


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


def write_json(path: Path, payload: dict[str, Any]) -> Path:
    """Write ``payload`` (made :func:`json_ready`) as indented JSON to ``path``, creating parent
    folders; return the path. The file is strict JSON: no ``NaN`` or ``Infinity`` tokens."""
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(json_ready(payload), indent=2, allow_nan=False) + "\n")
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
