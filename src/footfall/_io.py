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


def regular_file(path: Path, what: str, max_bytes: int) -> int:
    """The size of ``path`` [bytes] after checking that it is a regular file (not a folder,
    device or pipe) of at most ``max_bytes``; anything else is an :class:`InputError` naming
    ``what`` and the file."""
    try:
        info = path.stat()
    except OSError as e:
        raise InputError(what, str(path), f"a readable file ({e.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(what, str(path), "a regular file (not a folder, device or pipe)")
    if info.st_size > max_bytes:
        raise InputError(what, f"{path} ({info.st_size} bytes)", f"at most {max_bytes} bytes")
    return int(info.st_size)
