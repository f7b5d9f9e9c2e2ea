"""Exception hierarchy of footfall.

Every error footfall raises on purpose derives from :class:`FootfallError`, so a caller can catch
one type. Input errors name the offending field, the value given and what was expected. A stop
signal is :class:`Stopped`, which (like ``KeyboardInterrupt``) is not an error: code that records
a failed trial with ``except Exception`` and goes on must not swallow it.
"""

from __future__ import annotations

import reprlib

#: how much of an offending value an error message shows: a value read from a file may be huge
#: (a YAML alias bomb expands to gigabytes), so its repr is bounded in length and depth
_VALUE_REPR = reprlib.Repr()
for _name, _limit in (("maxlevel", 3), ("maxlist", 8), ("maxtuple", 8), ("maxdict", 8),
                      ("maxset", 8), ("maxstring", 120), ("maxother", 120), ("maxlong", 40)):  # fmt: skip
    setattr(_VALUE_REPR, _name, _limit)


def value_repr(value: object) -> str:
    """``repr(value)`` bounded in length and nesting depth (at most a few hundred characters)."""
    return _VALUE_REPR.repr(value)


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
        super().__init__(f"{field}: got {value_repr(value)}, expected {expected}")


class UnknownNameError(InputError, KeyError):
    """A name (region, joint, body) that the container does not hold; also a :class:`KeyError`,
    so mapping-style lookups keep their protocol."""

    def __str__(self) -> str:  # KeyError would print the repr of the message
        return str(self.args[0]) if self.args else ""


class SceneError(InputError):
    """A terrain scene (file or object) is invalid."""


class InfeasibleError(FootfallError):
    """An optimisation problem has no solution; the message says what is known about why."""


class SolverError(FootfallError):
    """A solver backend cannot take a problem or failed while solving it."""


class SolverUnavailableError(FootfallError):
    """A requested solver backend is not installed; the message says what to install."""


class MissingExtraError(FootfallError, ImportError):
    """An optional dependency group (a pip extra) is not installed; the message names it and the
    command that installs it."""


class Stopped(BaseException):
    """SIGINT or SIGTERM arrived (the command line raises it from its signal handler): it unwinds
    the command like Ctrl-C. A :class:`BaseException`, not a :class:`FootfallError`: a study that
    records a trial's exception as a row and goes on must stop instead.

    Attributes:
        signum: the signal's number.
    """

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum
