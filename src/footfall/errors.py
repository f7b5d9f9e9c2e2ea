"""Exception hierarchy of footfall.

Every error footfall raises on purpose derives from :class:`FootfallError`, so a caller can catch
one type. Input errors name the offending field, the value given and what was expected.
"""

from __future__ import annotations


class FootfallError(Exception):
    """Root of every error footfall raises on purpose."""


class InputError(FootfallError, ValueError):
    """A user-supplied parameter is invalid.

    Attributes:
        field: name of the offending parameter (e.g. ``"sx"`` or ``"robot.mass"``).
        value: the value that was given.
        expected: what would have been accepted.
    """

    def __init__(self, field: str, value: object, expected: str) -> None:
        self.field = field
        self.value = value
        self.expected = expected
        super().__init__(f"{field}: got {value!r}, expected {expected}")


class SceneError(InputError):
    """A terrain scene (file or object) is invalid."""


class InfeasibleError(FootfallError):
    """An optimisation problem has no solution; the message says what is known about why."""


class SolverUnavailableError(FootfallError):
    """A requested solver backend is not installed; the message says what to install."""
