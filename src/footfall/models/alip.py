"""ALIP model with two-axis ankle torque (document 000, section 5.2, eq. 5.1-5.10).

State ``x = [x_c, y_c, L_x, L_y]`` (eq. 5.1): CoM horizontal position relative to the stance contact
point [m] and the horizontal angular momentum about that point [kg m^2/s]. Input
``u = [tau_x, tau_y]`` (eq. 5.3): ankle torque that the ground applies to the robot about the
stance point [N m].

Sign convention. A centre of pressure (ZMP) offset ``d = (d_x, d_y)`` from the stance point, carrying
the weight ``m g``, exerts the torque ``d x (0, 0, m g) = (m g d_y, -m g d_x)``; hence

    tau_x =  m g d_y,   tau_y = -m g d_x,   ZMP = stance + (-tau_y, tau_x) / (m g).

Reset map (eq. 5.8-5.10) and its correction. During double support of length ``T_ds`` the contact
point is assumed to move linearly from the old foot ``p-`` to the new foot ``p+``. Measured from the
fixed old foot this is the single-support dynamics driven by the torque ``E (s/T_ds) (p+ - p-)`` with
``E = [[0,0,0],[0,0,0],[0,mg,0],[-mg,0,0]]`` (the 4x3 matrix of eq. 5.10). At the end the state is
re-expressed relative to the new foot, which subtracts the horizontal displacement from the CoM
position. Therefore

    B_r = (1/T_ds A^-2 (A_r - I) - A^-1) E  -  [[I_2, 0], [0, 0]],

i.e. eq. (5.10) with the identity block negated (``-I``, not ``+I``). The first term equals the
document's ``A_r A^-1 (1/T_ds A^-1 (I - A_r^-1) - A_r^-1) E``. The change of the angular momentum
about a pivot of different height (``dz x m v``) is bilinear and neglected, as in the document: the
third (z) column of ``B_r`` is zero. ``tests/models/test_alip.py`` shows both facts against a
``solve_ivp`` integration.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from footfall._typing import FloatArray
from footfall._validate import finite_array, finite_vector, positive
from footfall.models._linear import LinearModel, check_horizon, finite_matrices
from footfall.models.lip import GRAVITY

#: index slices into the ALIP state
POS = slice(0, 2)
MOMENTUM = slice(2, 4)


@dataclass(frozen=True)
class ALIP(LinearModel):
    """Angular-momentum linear inverted pendulum with ankle torque.

    Attributes:
        mass: total mass m [kg].
        com_height: CoM height z_H above the stance contact point [m].
        g: gravity [m/s^2].
    """

    mass: float
    com_height: float
    g: float = GRAVITY
    nx = 4
    nu = 2

    def __post_init__(self) -> None:
        object.__setattr__(self, "mass", positive("mass", self.mass))
        object.__setattr__(self, "com_height", positive("com_height", self.com_height))
        object.__setattr__(self, "g", positive("g", self.g))

    @property
    def A(self) -> FloatArray:
        """Continuous state matrix of eq. (5.2), shape (4, 4)."""
        m, zh, g = self.mass, self.com_height, self.g
        return np.array(
            [
                [0.0, 0.0, 0.0, 1.0 / (m * zh)],
                [0.0, 0.0, -1.0 / (m * zh), 0.0],
                [0.0, -m * g, 0.0, 0.0],
                [m * g, 0.0, 0.0, 0.0],
            ]
        )

    @property
    def B(self) -> FloatArray:
        """Input matrix of eq. (5.4), ``[0_2x2; I_2x2]``, shape (4, 2)."""
        return np.vstack([np.zeros((2, 2)), np.eye(2)])

    @property
    def E(self) -> FloatArray:
        """Map from a contact-point displacement (3,) [m] to the equivalent torque (eq. 5.10), (4, 3)."""
        mg = self.mass * self.g
        e = np.zeros((4, 3))
        e[2, 1] = mg
        e[3, 0] = -mg
        return e

    @property
    def omega(self) -> float:
        """Natural frequency ``sqrt(g / z_H)`` [1/s] of the unstable/stable modes."""
        return float(np.sqrt(self.g / self.com_height))

    def reset_map(self, t_ds: float) -> tuple[FloatArray, FloatArray]:
        """Double-support reset map ``x+ = A_r x- + B_r (p+ - p-)`` (eq. 5.8-5.10, corrected).

        Computed with one augmented matrix exponential: the contact displacement ``d`` is a ramp,
        ``d' = w``, ``w = (p+ - p-) / T_ds``, so ``expm`` of ``[[A, E, 0], [0, 0, I], [0, 0, 0]] T_ds``
        holds ``A_r`` and the ramp response without any inverse of ``A``.

        Args:
            t_ds: double-support duration T_ds [s], > 0.

        Returns:
            ``(A_r, B_r)`` of shapes (4, 4) and (4, 3); ``B_r`` acts on the 3-D displacement
            ``p+ - p-`` [m] and its z column is zero.
        """
        t_ds = positive("t_ds", t_ds)
        check_horizon("t_ds", self.omega, t_ds)
        m = np.zeros((10, 10))
        m[:4, :4] = self.A
        m[:4, 4:7] = self.E
        m[4:7, 7:10] = np.eye(3)
        from scipy.linalg import expm  # here: scipy.linalg takes 0.3 s to import

        e = expm(m * t_ds)
        finite_matrices("t_ds", t_ds, e)
        a_r = e[:4, :4].copy()
        b_r = e[:4, 7:10] / t_ds
        # Re-express the CoM position relative to the new stance foot: the -I block (see module doc).
        b_r[0:2, 0:2] -= np.eye(2)
        return a_r, b_r

    def velocity(self, x: ArrayLike) -> NDArray[np.float64]:
        """CoM horizontal velocity ``(L_y, -L_x) / (m z_H)`` [m/s] of states ``x`` (..., 4)."""
        xx = finite_array("x", x)
        mzh = self.mass * self.com_height
        return np.stack([xx[..., 3] / mzh, -xx[..., 2] / mzh], axis=-1)

    def state_from_velocity(self, pos: ArrayLike, vel: ArrayLike) -> NDArray[np.float64]:
        """ALIP state from CoM position (2,) [m] and velocity (2,) [m/s] relative to the stance point.

        Uses ``L = m z_H (-v_y, v_x)``, exact for the ALIP (no CoM angular momentum, constant height).
        """
        p = finite_vector("pos", pos, 2)
        v = finite_vector("vel", vel, 2)
        mzh = self.mass * self.com_height
        return np.array([p[0], p[1], -mzh * v[1], mzh * v[0]])

    def zmp(self, stance: ArrayLike, u: ArrayLike) -> NDArray[np.float64]:
        """Zero-moment point ``stance + (-tau_y, tau_x) / (m g)`` [m] for torques ``u`` (..., 2)."""
        s = finite_array("stance", stance)[..., :2]
        uu = finite_array("u", u)
        mg = self.mass * self.g
        return s + np.stack([-uu[..., 1], uu[..., 0]], axis=-1) / mg

    def torque_for_zmp(self, offset: ArrayLike) -> NDArray[np.float64]:
        """Ankle torque ``(m g d_y, -m g d_x)`` [N m] that puts the ZMP at ``offset`` (..., 2) [m]."""
        d = finite_array("offset", offset)
        mg = self.mass * self.g
        return np.stack([mg * d[..., 1], -mg * d[..., 0]], axis=-1)
