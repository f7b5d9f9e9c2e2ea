"""Kajita's linear inverted pendulum (LIP) in closed form (document 004).

The CoM moves on the plane ``z = z_c`` above a point foot at ``p``; in each horizontal axis

    xddot = (x - p) / Tc^2,        Tc = sqrt(z_c / g)

whose solution over one support phase is (document 004, code lines 33-40; Kajita eq. 4.54-4.55)

    x(t)    = (x0 - p) cosh(t/Tc) + Tc v0 sinh(t/Tc) + p
    xdot(t) = (x0 - p) / Tc sinh(t/Tc) + v0 cosh(t/Tc).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from footfall._typing import FloatArray
from footfall._validate import finite_array, positive
from footfall.models._linear import LinearModel, check_horizon

#: standard gravity [m/s^2]
GRAVITY = 9.81


@dataclass(frozen=True)
class LIP(LinearModel):
    """Linear inverted pendulum with state ``[x, y, xdot, ydot]`` and input foot ``p = [p_x, p_y]``.

    Attributes:
        z_c: CoM height above the foot plane [m].
        g: gravity [m/s^2].
    """

    z_c: float
    g: float = GRAVITY
    nx = 4
    nu = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "z_c", positive("z_c", self.z_c))
        object.__setattr__(self, "g", positive("g", self.g))

    @property
    def Tc(self) -> float:
        """Time constant ``Tc = sqrt(z_c / g)`` [s]."""
        return float(np.sqrt(self.z_c / self.g))

    @property
    def A(self) -> FloatArray:
        w2 = 1.0 / self.Tc**2
        a = np.zeros((4, 4))
        a[0, 2] = a[1, 3] = 1.0
        a[2, 0] = a[3, 1] = w2
        return a

    @property
    def B(self) -> FloatArray:
        w2 = 1.0 / self.Tc**2
        b = np.zeros((4, 2))
        b[2, 0] = b[3, 1] = -w2
        return b

    def state_at(
        self, pos0: ArrayLike, vel0: ArrayLike, foot: ArrayLike, t: ArrayLike
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Closed-form CoM position and velocity at times ``t`` (Kajita eq. 4.54-4.55).

        Args:
            pos0: initial CoM position, shape (d,) [m] (d = 1 or 2 axes).
            vel0: initial CoM velocity, shape (d,) [m/s].
            foot: support point, shape (d,) [m].
            t: times since the start of the support phase, shape (T,) or scalar [s].

        Returns:
            ``(pos, vel)`` each of shape (T, d) (or (d,) for scalar ``t``).
        """
        x0 = finite_array("pos0", pos0)
        v0 = finite_array("vel0", vel0)
        p = finite_array("foot", foot)
        tt = finite_array("t", t)
        tc = self.Tc
        if tt.size:
            check_horizon("t", 1.0 / tc, float(np.max(np.abs(tt))))
        c = np.cosh(tt / tc)[..., None]
        s = np.sinh(tt / tc)[..., None]
        pos = (x0 - p) * c + tc * v0 * s + p
        vel = (x0 - p) / tc * s + v0 * c
        return pos, vel

    def orbital_energy(
        self, pos: ArrayLike, vel: ArrayLike, foot: ArrayLike
    ) -> NDArray[np.float64]:
        """Orbital energy per axis ``E = v^2 / 2 - g / (2 z_c) (x - p)^2`` [m^2/s^2].

        It is conserved along every LIP trajectory (Kajita eq. 4.21).
        """
        x = finite_array("pos", pos)
        v = finite_array("vel", vel)
        p = finite_array("foot", foot)
        return np.asarray(0.5 * v**2 - self.g / (2.0 * self.z_c) * (x - p) ** 2)

    def sample_step(
        self, pos0: ArrayLike, vel0: ArrayLike, foot: ArrayLike, t_sup: float, dt: float
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
        """Sample one support phase of length ``t_sup`` every ``dt``, both ends included.

        Returns:
            ``(t, pos, vel)`` with shapes (T,), (T, d), (T, d).
        """
        t_sup = positive("t_sup", t_sup)
        dt = positive("dt", dt)
        n = max(1, int(np.ceil(t_sup / dt - 1e-9)))
        t = np.linspace(0.0, t_sup, n + 1)
        pos, vel = self.state_at(pos0, vel0, foot, t)
        return t, pos, vel
