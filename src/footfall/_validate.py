"""Small validation helpers shared by the frozen parameter dataclasses."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np
from numpy.typing import NDArray

from footfall.errors import InputError


def positive(field: str, value: object) -> float:
    """Return ``value`` as a float after checking it is a finite number > 0."""
    v = finite(field, value)
    if v <= 0.0:
        raise InputError(field, value, "a finite number > 0")
    return v


def non_negative(field: str, value: object) -> float:
    """Return ``value`` as a float after checking it is a finite number >= 0."""
    v = finite(field, value)
    if v < 0.0:
        raise InputError(field, value, "a finite number >= 0")
    return v


def in_range(field: str, value: object, lo: float, hi: float, unit: str) -> float:
    """Return ``value`` as a float after checking it is a finite number in ``[lo, hi]``: the
    physical range of a parameter, outside which the models overflow or underflow."""
    v = finite(field, value)
    if not lo <= v <= hi:
        raise InputError(field, value, f"a number in [{lo:g}, {hi:g}] {unit}".rstrip())
    return v


def finite(field: str, value: object) -> float:
    """Return ``value`` as a float after checking it is a finite real number (not bool)."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        raise InputError(field, value, "a finite real number")
    v = float(value)
    if not math.isfinite(v):
        raise InputError(field, value, "a finite real number")
    return v


def finite_vector(field: str, value: object, length: int | None = None) -> NDArray[np.float64]:
    """Return ``value`` as a 1-D float array after checking every entry is finite.

    Args:
        field: parameter name used in the error message.
        value: a sequence of numbers.
        length: required length, or None for any non-empty length.
    """
    if isinstance(value, str | bytes) or not isinstance(value, Sequence | np.ndarray):
        raise InputError(field, value, "a sequence of finite numbers")
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(field, value, "a sequence of finite numbers") from None
    if arr.ndim != 1:
        raise InputError(field, value, "a flat (1-D) sequence of numbers")
    if length is not None and arr.shape[0] != length:
        raise InputError(field, value, f"exactly {length} numbers")
    if arr.shape[0] == 0:
        raise InputError(field, value, "at least one number")
    if not np.all(np.isfinite(arr)):
        raise InputError(field, value, "finite numbers (no NaN or inf)")
    return arr


def finite_array(field: str, value: object) -> NDArray[np.float64]:
    """Return ``value`` as a float array (any shape) after checking every entry is a finite
    number: a NaN or inf given to a model would come back as NaN results, not as an error."""
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise InputError(field, value, "finite numbers") from None
    if not np.all(np.isfinite(arr)):
        raise InputError(field, value, "finite numbers (no NaN or inf)")
    return arr


def names_in(field: str, names: Sequence[str], valid: Sequence[str]) -> list[str]:
    """``names`` stripped of blanks, each checked to be one of ``valid`` (at least one name)."""
    out = [n.strip() for n in names if n.strip()]
    if not out:
        raise InputError(field, ",".join(names), f"one or more of {', '.join(valid)}")
    for n in out:
        if n not in valid:
            raise InputError(field, n, f"one of {', '.join(valid)}")
    return out


def instance_of(field: str, value: object, types: type | tuple[type, ...], expected: str) -> None:
    """Raise :class:`InputError` naming ``field`` unless ``value`` is one of ``types``: a public
    function given the wrong type says which argument, instead of an AttributeError deep inside."""
    if not isinstance(value, types):
        raise InputError(field, type(value).__name__, expected)


def check_fields(
    obj: object, check: Callable[[str, object], object], names: Sequence[str], prefix: str = ""
) -> None:
    """Replace each named field of the frozen dataclass ``obj`` by ``check(prefix + name, value)``
    (e.g. :func:`positive`), which raises :class:`InputError` naming the field."""
    for name in names:
        object.__setattr__(obj, name, check(prefix + name, getattr(obj, name)))
