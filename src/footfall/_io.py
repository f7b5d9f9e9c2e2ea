"""File output shared by the CLI and the demo."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np


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
