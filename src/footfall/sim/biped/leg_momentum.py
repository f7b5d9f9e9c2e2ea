"""The legs' centroidal angular momentum in the walker's ALIP prediction (document 000, eq. 5.5).

The walker measures the ALIP state with ``L = m z_H (-v_y, v_x)`` from the CoM velocity: the
point mass's momentum, the quantity the plan's states hold. The whole robot's momentum about the
stance point is ``L_c = L_G + m (c - p) x v``, and ``dL_c/dt = m g (x, y) + u`` holds for it
(eq. 5.3), so the point-mass part obeys

    dL/dt = m g (x, y) + u - dL_G/dt,

the ALIP with the rate of change of the legs' (and torso's) momentum about the CoM as one more
torque. A swinging leg changes ``L_G`` over the step and then gives it back: the prediction of the
end of the step, which eq. (5.19) uses, misses that disturbance (benchmarks/RESULTS.md, "Pushes
per robot": the sagittal end-of-step CoM is predicted 32-142 mm short on four robots).

:class:`LegMomentumForecast` forecasts the sagittal ``L_G`` over the rest of the single support
by the profile measured over the previous one (a walk repeats itself step after step) and folds
a share of the disturbance into the measured state: :func:`forecast_shift` gives the ``d`` with
``A^n (x + d) = A^n x + sum_j A^(n-1-j) B w_j``, so every end-of-step prediction from ``x + d``
carries the forecast disturbance ``w_j = -(L_G[k+j+1] - L_G[k+j]) / dt`` of tick ``k + j``,
whatever torques the MPC then adds. The lateral ``L_G`` is left out: there the point-mass
estimate already predicts the end of the step within 2-14 mm.
"""

from __future__ import annotations

import math

import numpy as np

from footfall._typing import FloatArray


def forecast_shift(
    profile: FloatArray, k: int, dt: float, inv_powers: FloatArray, heading: float
) -> FloatArray:
    """The state shift (4,) that carries the forecast sagittal ``L_G`` change of the ticks
    ``k .. M - 1`` of a single support.

    Args:
        profile: the forecast sagittal ``L_G`` at each tick of the support, shape (M,)
            [kg m^2/s] (about the heading's lateral axis: ``-sin(h) L_x + cos(h) L_y``).
        k: the current tick, ``0 <= k < M``.
        dt: the tick [s].
        inv_powers: ``A^-(j+1) B`` for ``j = 0 .. M - 2``, shape (M - 1, 4, 2), with ``A``, ``B``
            the ALIP's ZOH matrices of one tick (eq. 5.5).
        heading: the stance heading [rad].

    Returns:
        ``d`` (4,) in the world frame: position [m] and momentum [kg m^2/s] parts.
    """
    m = profile.shape[0]
    if not 0 <= k < m:
        raise ValueError(f"tick {k} outside the support's 0..{m - 1}")
    w = -np.diff(profile[k:]) / dt  # (M - 1 - k,) torques [N m] about the lateral axis
    if w.size == 0:
        return np.zeros(4)
    axis = np.array([-math.sin(heading), math.cos(heading)])
    return np.asarray(np.einsum("jab,b,j->a", inv_powers[: w.size], axis, w))


def inverse_powers(ad: FloatArray, bd: FloatArray, m: int) -> FloatArray:
    """``A^-(j+1) B`` for ``j = 0 .. m - 2``, shape (m - 1, 4, 2) (see :func:`forecast_shift`)."""
    ainv = np.linalg.inv(ad)
    out = np.empty((max(m - 1, 0), ad.shape[0], bd.shape[1]))
    p = ainv @ bd
    for j in range(m - 1):
        out[j] = p
        p = ainv @ p
    return out


class LegMomentumForecast:
    """The walker's forecast of the legs' sagittal momentum (see the module).

    Each single-support tick, :meth:`shift` records the measured ``L_G`` and returns the share
    ``gain`` of :func:`forecast_shift` over the previous support's profile (zero in the first
    support, or when the previous one was not walked whole).
    """

    def __init__(self, ad: FloatArray, bd: FloatArray, dt: float, t_ss: float, gain: float):
        self.dt = dt
        self.gain = gain
        self.m = max(round(t_ss / dt), 1)
        self.inv_powers = inverse_powers(ad, bd, self.m)
        self._phase = -1
        self._current = np.full(self.m, np.nan)
        self._previous: FloatArray | None = None

    def shift(self, phase: int, tp: float, l_g: FloatArray, heading: float) -> FloatArray:
        """The state shift (4,) for tick time ``tp`` [s] of single support ``phase``, given the
        measured momentum about the CoM ``l_g`` (3,) [kg m^2/s] and the stance heading [rad]."""
        if phase != self._phase:
            whole = phase == self._phase + 1 and not np.isnan(self._current).any()
            self._previous = self._current if whole else None
            self._current = np.full(self.m, np.nan)
            self._phase = phase
        k = min(max(round(tp / self.dt), 0), self.m - 1)
        self._current[k] = -math.sin(heading) * float(l_g[0]) + math.cos(heading) * float(l_g[1])
        if self._previous is None or self.gain == 0.0:
            return np.zeros(4)
        return self.gain * forecast_shift(self._previous, k, self.dt, self.inv_powers, heading)
