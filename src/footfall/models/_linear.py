"""Exact zero-order-hold discretisation shared by the LIP and ALIP models."""

from __future__ import annotations

import numpy as np
from scipy.linalg import expm

from footfall._typing import FloatArray
from footfall._validate import positive


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
    dt = positive("dt", dt)
    n, m = b.shape
    aug = np.zeros((n + m, n + m))
    aug[:n, :n] = a
    aug[:n, n:] = b
    e = expm(aug * dt)
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
