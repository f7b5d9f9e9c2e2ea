"""Exact zero-order-hold discretisation shared by the LIP and ALIP models."""

from __future__ import annotations

import numpy as np

from footfall._typing import FloatArray
from footfall._validate import positive
from footfall.errors import InputError

#: largest ``|lambda| dt`` of a discretisation: ``exp`` overflows a float beyond ~709
MAX_EXPONENT = 700.0


def check_horizon(field: str, rate: float, dt: float) -> None:
    """Refuse a period ``dt`` [s] over which a mode of growth ``rate`` [1/s] (the largest
    eigenvalue magnitude) overflows a float (``exp(rate dt)``, cosh, sinh), instead of
    returning inf or NaN matrices."""
    if rate * abs(dt) > MAX_EXPONENT:
        limit = f"at most {MAX_EXPONENT / rate:.4g} s (longer overflows exp(|eigenvalue| dt))"
        raise InputError(field, dt, limit)


def finite_matrices(field: str, dt: float, *mats: FloatArray) -> None:
    """Refuse ``dt`` when a matrix computed for it is not finite (an overflow)."""
    if not all(np.all(np.isfinite(m)) for m in mats):
        raise InputError(field, dt, "a shorter period (the matrices overflow)")


def zoh(a: FloatArray, b: FloatArray, dt: float) -> tuple[FloatArray, FloatArray]:
    """Exact ZOH discretisation of ``xdot = A x + B u`` over ``dt``.

    Uses the augmented-matrix exponential ``expm([[A, B], [0, 0]] dt) = [[Ad, Bd], [0, I]]``, which
    equals ``Ad = exp(A dt)`` and ``Bd = A^-1 (Ad - I) B`` (document 000 eq. 5.7a-b) without
    inverting ``A`` (so it also holds for singular ``A``).

    Args:
        a: state matrix, shape (n, n).
        b: input matrix, shape (n, m).
        dt: sample period [s], > 0.

    Returns:
        ``(Ad, Bd)`` of shapes (n, n) and (n, m).
    """
    from scipy.linalg import expm  # here: importing scipy.linalg takes 0.3 s, most users of
    # the models (reading a plan or a scene) never discretise

    dt = positive("dt", dt)
    check_horizon("dt", float(np.max(np.abs(np.linalg.eigvals(a)))), dt)
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = a
    aug[:n, n:] = b
    e = expm(aug * dt)
    finite_matrices("dt", dt, e)
    return e[:n, :n].copy(), e[:n, n:].copy()


class LinearModel:
    """Common shape of the reduced-order models: continuous ``A``, ``B`` and exact discretisation."""

    #: number of states
    nx: int
    #: number of inputs
    nu: int

    @property
    def A(self) -> FloatArray:
        """Continuous state matrix, shape (nx, nx)."""
        raise NotImplementedError

    @property
    def B(self) -> FloatArray:
        """Continuous input matrix, shape (nx, nu)."""
        raise NotImplementedError

    def discretize(self, dt: float) -> tuple[FloatArray, FloatArray]:
        """Exact ZOH matrices ``(Ad, Bd)`` for the period ``dt`` [s] (document 000 eq. 5.6-5.7)."""
        return zoh(self.A, self.B, dt)
