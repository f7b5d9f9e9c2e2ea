"""Kajita's LIP walking pattern generator with foot placement modification (document 004).

Per step ``n`` (document 004 section 1 and the turning code):

1. the CoM follows the LIP from the step's initial state over ``T_sup`` around the actual foot;
2. the ideal next foothold is the previous ideal one plus the walk parameters rotated by the new
   heading, ``p0_n = p0_{n-1} + Rot(theta_n) [s_x,n; -(-1)^n s_y,n]`` (Kajita eq. 4.60-4.61);
3. the ideal end-of-step CoM state relative to that foothold is
   ``xbar = Rot(theta_{n+1}) [s_x,n+1 / 2; (-1)^n s_y,n+1 / 2]`` with velocities
   ``vxbar = (C + 1) / (Tc S) xbar``, ``vybar = (C - 1) / (Tc S) ybar`` (Kajita eq. 4.57). The
   velocity is **not** rotated: document 004 points out that the book's eq. (4.62) is wrong there.
4. the actual foothold minimises ``a (x_d - x_f)^2 + b (v_d - v_f)^2`` (Kajita eq. 4.58), whose
   minimiser is (eq. 4.59)

       p* = -a (C - 1) / D (x_d - C x_i - Tc S v_i) - b S / (Tc D) (v_d - S / Tc x_i - C v_i),
       D = a (C - 1)^2 + b (S / Tc)^2.

Start (document 004 section 2.2.1): the foothold of step 0 is also chosen by the optimal placement,
which offsets foot and CoM so the robot starts moving from rest. Stop (section 2.2.2): one extra
zero step is appended and its foothold uses the weights ``a_stop``, ``b_stop`` (default 1, 1), so
the CoM comes to rest over the last foot.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from footfall._geometry import rot2
from footfall._typing import FloatArray
from footfall._validate import finite_vector, instance_of, non_negative, positive
from footfall.errors import InputError
from footfall.models.lip import GRAVITY, LIP

#: longest support phase, in time constants T_c: cosh(20) = 2.4e8 still leaves the foot placement
#: (differences of such terms) about 8 significant digits in double precision
MAX_SUPPORT_TIME_CONSTANTS = 20
#: most CoM samples of :meth:`LipWalk.com_trajectory` (a JSON of ~100 MB; 1 ms over 16 min)
MAX_SAMPLES = 1_000_000


@dataclass(frozen=True)
class LipWalkParams:
    """Walk parameters of document 004 (arguments of its ``LIP`` MATLAB function).

    Attributes:
        z_c: CoM height z_c [m], > 0.
        t_sup: duration of every support phase T_sup [s], > 0.
        sx: forward walk parameter per step, shape (n,) [m] (step 0 is the start step).
        sy: lateral walk parameter per step, shape (n,) [m] (distance between the feet).
        theta: heading of each step in the world frame, shape (n,) [rad]; zeros for straight walking.
        a: weight of the position error in the placement cost (Kajita eq. 4.58).
        b: weight of the velocity error in the placement cost.
        com0: initial CoM position (x_i, y_i), shape (2,) [m].
        vel0: initial CoM velocity, shape (2,) [m/s].
        foot0: initial (ideal) foot placement (p_x, p_y), shape (2,) [m].
        a_stop: weight ``a`` used for the appended stop step (document 004 section 2.2.2).
        b_stop: weight ``b`` used for the appended stop step.
        g: gravity [m/s^2].
    """

    z_c: float
    t_sup: float
    sx: tuple[float, ...]
    sy: tuple[float, ...]
    theta: tuple[float, ...] | None = None
    a: float = 10.0
    b: float = 1.0
    com0: tuple[float, float] = (0.0, 0.0)
    vel0: tuple[float, float] = (0.0, 0.0)
    foot0: tuple[float, float] = (0.0, 0.0)
    a_stop: float = 1.0
    b_stop: float = 1.0
    g: float = GRAVITY
    _theta: tuple[float, ...] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "z_c", positive("z_c", self.z_c))
        set_(self, "t_sup", positive("t_sup", self.t_sup))
        set_(self, "g", positive("g", self.g))
        t_c = math.sqrt(self.z_c / self.g)
        if self.t_sup > MAX_SUPPORT_TIME_CONSTANTS * t_c:
            raise InputError(
                "t_sup",
                self.t_sup,
                f"at most {MAX_SUPPORT_TIME_CONSTANTS} T_c = {MAX_SUPPORT_TIME_CONSTANTS * t_c:.3g} s "
                f"(T_c = sqrt(z_c / g) = {t_c:.3g} s): the pendulum grows like exp(T_sup / T_c), so a "
                "longer support loses the foot placement to rounding",
            )
        sx = finite_vector("sx", self.sx)
        sy = finite_vector("sy", self.sy)
        if sy.shape != sx.shape:
            raise InputError(
                "sy",
                list(self.sy),
                f"{sx.shape[0]} values, one per step like sx (got {sy.shape[0]})",
            )
        theta = np.zeros_like(sx) if self.theta is None else finite_vector("theta", self.theta)
        if theta.shape != sx.shape:
            raise InputError(
                "theta",
                list(self.theta or ()),
                f"{sx.shape[0]} values, one per step like sx (got {theta.shape[0]})",
            )
        set_(self, "sx", tuple(float(v) for v in sx))
        set_(self, "sy", tuple(float(v) for v in sy))
        set_(self, "_theta", tuple(float(v) for v in theta))
        for name in ("a", "b", "a_stop", "b_stop"):
            set_(self, name, non_negative(name, getattr(self, name)))
        for pair in (("a", "b"), ("a_stop", "b_stop")):
            if getattr(self, pair[0]) + getattr(self, pair[1]) == 0.0:
                raise InputError(f"{pair[0]}, {pair[1]}", (0.0, 0.0), "weights not both zero")
        for name in ("com0", "vel0", "foot0"):
            set_(self, name, tuple(float(v) for v in finite_vector(name, getattr(self, name), 2)))

    @property
    def headings(self) -> tuple[float, ...]:
        """Heading per step [rad] (zeros when ``theta`` was not given)."""
        return self._theta

    @property
    def n_steps(self) -> int:
        """Number of support phases walked: the given steps plus the appended stop step."""
        return len(self.sx) + 1


@dataclass(frozen=True)
class LipWalk:
    """Result of :func:`lip_walk`.

    Attributes:
        params: the parameters it was computed from.
        footholds: actual (modified) footholds per support phase, shape (n + 1, 2) [m].
        ideal_footholds: ideal footholds from the walk parameters, shape (n + 1, 2) [m].
        com_start: CoM position at the start of each support phase, shape (n + 1, 2) [m].
        vel_start: CoM velocity at the start of each support phase, shape (n + 1, 2) [m/s].
        final_com: CoM position at the end of the last support phase, shape (2,) [m].
        final_vel: CoM velocity at the end of the last support phase, shape (2,) [m/s].
    """

    params: LipWalkParams
    footholds: FloatArray
    ideal_footholds: FloatArray
    com_start: FloatArray
    vel_start: FloatArray
    final_com: FloatArray
    final_vel: FloatArray

    @property
    def lip(self) -> LIP:
        """The pendulum the walk was computed with."""
        return LIP(self.params.z_c, self.params.g)

    @property
    def duration(self) -> float:
        """Total walking time [s]."""
        return self.params.t_sup * self.footholds.shape[0]

    def com_trajectory(self, dt: float = 0.01) -> dict[str, FloatArray]:
        """CoM sampled every ``dt`` over the whole walk, both ends included.

        A sample at a step switch is evaluated from the step that starts there.

        Returns:
            dict with ``t`` (T,) [s], ``x``, ``y`` (T,) [m], ``vx``, ``vy`` (T,) [m/s] and
            ``step`` (T,) the index of the support phase each sample belongs to.
        """
        dt = positive("dt", dt)
        if self.duration / dt > MAX_SAMPLES:  # refused before an array of that size is made
            shortest = self.duration / MAX_SAMPLES
            raise InputError("dt", dt, f"at least {shortest:.3g} s (at most {MAX_SAMPLES} samples)")
        t_sup = self.params.t_sup
        n = self.footholds.shape[0]
        t = np.arange(0.0, self.duration + 0.5 * dt, dt)
        t = t[t <= self.duration + 1e-12]
        step = np.minimum((t / t_sup + 1e-9).astype(int), n - 1)
        tau = t - step * t_sup
        lip = self.lip
        pos = np.empty((t.size, 2))
        vel = np.empty((t.size, 2))
        for k in range(n):
            mask = step == k
            if np.any(mask):
                pos[mask], vel[mask] = lip.state_at(
                    self.com_start[k], self.vel_start[k], self.footholds[k], tau[mask]
                )
        return {
            "t": t,
            "x": pos[:, 0],
            "y": pos[:, 1],
            "vx": vel[:, 0],
            "vy": vel[:, 1],
            "step": step,
        }


def optimal_foothold(
    lip: LIP,
    t_sup: float,
    com: FloatArray,
    vel: FloatArray,
    target_com: FloatArray,
    target_vel: FloatArray,
    a: float,
    b: float,
) -> FloatArray:
    """Foothold minimising ``a |x_d - x_f|^2 + b |v_d - v_f|^2`` after one support phase.

    Implements Kajita eq. (4.59) (document 004, code lines 74-77), per axis.

    Args:
        lip: the pendulum.
        t_sup: support duration [s].
        com, vel: CoM state at the start of the phase, shape (2,) [m], [m/s].
        target_com, target_vel: desired CoM state at its end, shape (2,).
        a, b: weights (not both zero).

    Returns:
        Foothold, shape (2,) [m].
    """
    tc = lip.Tc
    c = np.cosh(t_sup / tc)
    s = np.sinh(t_sup / tc)
    d = a * (c - 1.0) ** 2 + b * (s / tc) ** 2
    return np.asarray(
        -a * (c - 1.0) / d * (target_com - c * com - tc * s * vel)
        - b * s / (tc * d) * (target_vel - s / tc * com - c * vel)
    )


def lip_walk(params: LipWalkParams) -> LipWalk:
    """Generate the LIP walk of document 004 (turning version of its MATLAB code).

    Steps ``0..n-1`` follow the walk parameters; step ``n`` is the appended zero (stop) step whose
    foothold uses the stop weights. Straight and diagonal walking are the case ``theta = 0``.

    Args:
        params: validated walk parameters.

    Returns:
        The footholds, per-step initial CoM states and final state.
    """
    instance_of("params", params, LipWalkParams, "a LipWalkParams (see footfall.planning)")
    lip = LIP(params.z_c, params.g)
    t_sup = params.t_sup
    tc = lip.Tc
    c = np.cosh(t_sup / tc)
    s = np.sinh(t_sup / tc)
    sx = np.array([*params.sx, 0.0])
    sy = np.array([*params.sy, 0.0])
    theta = np.array([*params.headings, params.headings[-1]])
    n_phases = sx.size

    ideal = np.array(params.foot0, dtype=float)
    com = np.array(params.com0, dtype=float)
    vel = np.array(params.vel0, dtype=float)
    feet = np.empty((n_phases, 2))
    ideal_feet = np.empty((n_phases, 2))
    com_start = np.empty((n_phases, 2))
    vel_start = np.empty((n_phases, 2))

    for n in range(n_phases):
        if n > 0:
            # Advance the CoM over the previous support phase (closed form).
            com, vel = lip.state_at(com, vel, feet[n - 1], t_sup)
            # Ideal foothold of step n from the walk parameters of step n-1 (document indexing).
            step = np.array([sx[n - 1], -((-1.0) ** n) * sy[n - 1]])
            ideal = ideal + rot2(theta[n - 1]) @ step
        # Ideal end-of-step CoM state relative to the ideal foothold; velocity not rotated (erratum).
        bar = rot2(theta[n]) @ np.array([sx[n] / 2.0, (-1.0) ** n * sy[n] / 2.0])
        vbar = np.array([(c + 1.0) / (tc * s) * bar[0], (c - 1.0) / (tc * s) * bar[1]])
        last = n == n_phases - 1
        a = params.a_stop if last else params.a
        b = params.b_stop if last else params.b
        feet[n] = optimal_foothold(lip, t_sup, com, vel, ideal + bar, vbar, a, b)
        ideal_feet[n] = ideal
        com_start[n] = com
        vel_start[n] = vel

    final_com, final_vel = lip.state_at(com, vel, feet[-1], t_sup)
    return LipWalk(params, feet, ideal_feet, com_start, vel_start, final_com, final_vel)
