"""The walking examples of document 004 (Kajita p. 130-143), as ready-made :class:`LipWalkParams`.

All use the document's z_c = 0.8 m, T_sup = 0.8 s, a = 10, b = 1 and its gravity g = 9.8 m/s^2.
Where the document's own command is malformed (its turning example gives ``sy`` one entry short)
or not printed (diagonal, circle), the values below complete it; each is stated in its docstring.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from footfall.errors import InputError
from footfall.planning.lip_walk import LipWalkParams

#: gravity used by the document's MATLAB code [m/s^2]
DOCUMENT_G = 9.8
_COMMON: dict[str, Any] = {"z_c": 0.8, "t_sup": 0.8, "a": 10.0, "b": 1.0, "g": DOCUMENT_G}


def straight() -> LipWalkParams:
    """Straight walk, document 004 section 2.4.1 (sy completed to 5 entries with 0.2 m)."""
    return LipWalkParams(sx=(0.0, 0.3, 0.3, 0.3, 0.0), sy=(0.2,) * 5, **_COMMON)


def diagonal() -> LipWalkParams:
    """Diagonal (side) walk, section 2.4.2: alternating 0.3 m / 0.1 m feet distance drifts left."""
    return LipWalkParams(sx=(0.0, 0.2, 0.2, 0.2, 0.0), sy=(0.2, 0.3, 0.1, 0.3, 0.1), **_COMMON)


def turn() -> LipWalkParams:
    """Turning 20 degrees per step, section 3.4.1 (the book's p. 143 data; sy completed with 0.2 m)."""
    return LipWalkParams(
        sx=(0.0, 0.25, 0.25, 0.25, 0.0),
        sy=(0.2, 0.3, 0.2, 0.2, 0.2),
        theta=tuple(np.deg2rad([0.0, 20.0, 40.0, 60.0, 60.0])),
        **_COMMON,
    )


def circle(steps: int = 18, step_deg: float = 20.0, sx: float = 0.25) -> LipWalkParams:
    """Walking a full circle, section 3.4.2: ``steps`` steps of ``step_deg`` degrees (18 x 20 = 360)."""
    headings = [0.0, *[step_deg * k for k in range(1, steps + 1)], step_deg * steps]
    return LipWalkParams(
        sx=(0.0, *([sx] * steps), 0.0),
        sy=(0.2,) * (steps + 2),
        theta=tuple(np.deg2rad(headings)),
        **_COMMON,
    )


EXAMPLES = {"straight": straight, "diagonal": diagonal, "turn": turn, "circle": circle}


def example(name: str) -> LipWalkParams:
    """The named document example: one of ``straight``, ``diagonal``, ``turn``, ``circle``."""
    try:
        return EXAMPLES[name]()
    except KeyError:
        raise InputError("example", name, f"one of {', '.join(EXAMPLES)}") from None


#: the walk of ``footfall lip`` without ``--example``: four 0.3 m steps on 0.2 m wide feet, with
#: standard gravity (the document's examples use its 9.8 m/s^2)
DEFAULT_WALK: dict[str, Any] = {
    "z_c": 0.8,
    "t_sup": 0.8,
    "sx": (0.0, 0.3, 0.3, 0.3, 0.0),
    "sy": (0.2, 0.2, 0.2, 0.2, 0.2),
    "a": 10.0,
    "b": 1.0,
    "a_stop": 1.0,
    "b_stop": 1.0,
    "g": 9.81,
}


def lip_params(name: str | None = None, **given: Any) -> LipWalkParams:
    """The named document example (or :data:`DEFAULT_WALK` when ``name`` is None), with the
    fields in ``given`` replaced; :class:`LipWalkParams` validates the result."""
    from dataclasses import replace

    if name is None:
        return LipWalkParams(**(DEFAULT_WALK | given))
    try:
        return replace(example(name), **given)
    except TypeError as exc:  # an unknown field name
        raise InputError(
            "lip parameters", sorted(given), f"fields of LipWalkParams ({exc})"
        ) from None
