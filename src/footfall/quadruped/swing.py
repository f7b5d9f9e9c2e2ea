"""Zero-impact swing-foot trajectory on a slope, document 001 sec. 3 (eq. 10-13).

The trajectory is planned in the foot ground frame ``{G}`` (x along the slope in the walking
direction, z normal to the slope, origin at the centre of the step) and rotated into the leg frame
by the body-to-slope angle ``beta_Delta = beta_S - beta_B`` (eq. 13). Both coordinates start and
end with zero velocity and zero acceleration, so the foot leaves and meets the ground without an
impact.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from footfall._typing import FloatArray
from footfall._validate import non_negative, positive
from footfall.quadruped.kinematics import rot_y

TWO_PI = 2.0 * np.pi
FOUR_PI = 4.0 * np.pi


@dataclass(frozen=True)
class SwingProfile:
    """Parameters of eq. (10)-(12).

    Attributes:
        step: step length S along the slope [m].
        height: swing height H normal to the slope [m] (the apex of z(t)).
        period: swing period T_w [s].
    """

    step: float
    height: float
    period: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "step", non_negative("step", self.step))
        object.__setattr__(self, "height", non_negative("height", self.height))
        object.__setattr__(self, "period", positive("swing_period", self.period))

    def _phase(self, t: ArrayLike) -> FloatArray:
        return np.clip(np.asarray(t, dtype=float), 0.0, self.period) / self.period

    def f_e(self, t: ArrayLike) -> FloatArray:
        """``f_E(t) = t/T_w - sin(4 pi t/T_w) / (4 pi)``, eq. (11)."""
        u = self._phase(t)
        return u - np.sin(FOUR_PI * u) / FOUR_PI

    def position(self, t: ArrayLike) -> FloatArray:
        """Foot position (x, z) in ``{G}`` at times ``t`` in [0, T_w], eq. (10)-(12).

        Implements eq. (10) ``x = S [t/T_w - sin(2 pi t/T_w)/(2 pi)] - S/2`` and
        ``z = H [sgn(T_w/2 - t) (2 f_E(t) - 1) + 1]`` with sgn from eq. (12) (+1 on [0, T_w/2),
        -1 on [T_w/2, T_w]).

        Args:
            t: time since lift-off [s], scalar or shape (N,); clipped to [0, T_w].

        Returns:
            Shape (2,) or (N, 2) [m].
        """
        u = self._phase(t)
        x = self.step * (u - np.sin(TWO_PI * u) / TWO_PI) - 0.5 * self.step
        sgn = np.where(u < 0.5, 1.0, -1.0)
        z = self.height * (sgn * (2.0 * self.f_e(t) - 1.0) + 1.0)
        return np.stack([x, z], axis=-1)

    def velocity(self, t: ArrayLike) -> FloatArray:
        """Time derivative of :meth:`position` (closed form), shape like position [m/s]."""
        u = self._phase(t)
        tw = self.period
        xd = self.step / tw * (1.0 - np.cos(TWO_PI * u))
        sgn = np.where(u < 0.5, 1.0, -1.0)
        zd = self.height * sgn * 2.0 / tw * (1.0 - np.cos(FOUR_PI * u))
        return np.stack([xd, zd], axis=-1)

    def acceleration(self, t: ArrayLike) -> FloatArray:
        """Second time derivative of :meth:`position` (closed form) [m/s^2]."""
        u = self._phase(t)
        tw = self.period
        xdd = self.step * TWO_PI / tw**2 * np.sin(TWO_PI * u)
        sgn = np.where(u < 0.5, 1.0, -1.0)
        zdd = self.height * sgn * 2.0 * FOUR_PI / tw**2 * np.sin(FOUR_PI * u)
        return np.stack([xdd, zdd], axis=-1)


def slope_to_leg_rotation(beta_delta: float) -> FloatArray:
    """Rotation ``{G} -> {leg}`` for a slope steeper than the body by ``beta_delta`` [rad], (3, 3).

    Eq. (13) writes this rotation as ``[[c, 0, s], [0, 1, 0], [-s, 0, c]]`` with the document's
    angle convention of fig. 8. footfall's leg frame has z up and x forward, and a slope steeper
    than the body tilts ``{G}``'s x axis *upwards* in it, which is ``R_y(-beta_Delta)``; the matrix
    is the document's with the sign of beta_Delta flipped.
    """
    return rot_y(-beta_delta)


def swing_in_leg_frame(
    profile: SwingProfile, t: ArrayLike, beta_delta: float, origin: ArrayLike
) -> FloatArray:
    """Swing-foot trajectory in the leg frame, eq. (13).

    Implements eq. (13) of document 001: ``p_leg = R(beta_Delta) [x(t), 0, z(t)]^T + P_G`` where
    ``P_G`` is the origin of ``{G}`` (centre of the step, foot-centre plane) in the leg frame.

    Args:
        profile: S, H, T_w of eq. (10).
        t: times since lift-off [s], scalar or shape (N,).
        beta_delta: body-to-slope angle beta_Delta = beta_S - beta_B [rad].
        origin: ``{G}`` origin in the leg frame, shape (3,) [m].

    Returns:
        Foot positions in the leg frame, shape (3,) or (N, 3) [m].
    """
    xz = profile.position(t)
    g = np.stack([xz[..., 0], np.zeros_like(xz[..., 0]), xz[..., 1]], axis=-1)
    return g @ slope_to_leg_rotation(beta_delta).T + np.asarray(origin, dtype=float)
