"""MPC footstep / ankle-torque adjuster of document 000, section 5.4 (eq. 5.19a-e).

At every control tick ``k_s`` of single-support phase ``i`` (standing on footstep ``p_i``), from the
measured ALIP state, the controller optimises the remaining ankle torques ``u_{i,k}``
(``k = k_s .. M-1``) and the horizontal position of the next footstep ``p_{i+1}``:

    minimise  sum_{k=k_s+1}^{M} dt (x_k - x_k^ref)^T Q (x_k - x_k^ref)
            + sum_{k=k_s}^{M-1} dt u_k^T R u_k                                    (5.19a)
            + (p_{i+1} - p_{i+1}^ref)^T W (p_{i+1} - p_{i+1}^ref)
            + (x_{i+1,1} - x_{i+1,1}^ref)^T Q_f (x_{i+1,1} - x_{i+1,1}^ref)
    s.t.      x_{k+1} = A_d x_k + B_d u_k                                         (5.19b)
              x_{i+1,1} = A_r x_M + B_r (p_{i+1} - p_i)                            (5.19c)
              x_{k_s} = x_measured                                                (5.19d)
              ||u_k||_2 <= U_max                                                  (5.19e)

Beyond the document, (5.19e) may be an ellipse ``(u_x / U_x)^2 + (u_y / U_y)^2 <= 1`` (argument
``torque_limits`` of :func:`build_mpc`): a rectangular sole allows a larger pitch torque ``u_y``
(CoP along the foot) than roll torque ``u_x`` (CoP across it). ``U_x = U_y = U_max`` is the
document's ball and the default.

``x_k^ref`` is the zero-torque ("natural") trajectory from the measured state, so
``x_k - x_k^ref`` depends on the torques only: the tracking term is a torque-shaping term whose
Hessian does not depend on the measurement.

Discretisation (how the planner's K nodes meet the M control ticks). The MPC runs at the control
rate: one single support has ``M = round(T_ss / dt_c)`` ticks and the dynamics (5.19b) use the exact
ZOH matrices of one tick, so the prediction matches a plant that holds each torque for a tick. The
torque is *blocked* on the planner's node grid: the M ticks are split into ``K - 1`` blocks of
(almost) equal whole numbers of ticks, and the torque is constant within a block. At tick ``k_s``
the decision variables are the torques of the blocks that are not over yet (the current block is
partial) and the next footstep, so the horizon shrinks as ``k_s`` grows and the problem has at most
``2 (K - 1) + 2`` variables. The stage terms are summed over every tick and scaled by ``dt_c``
(``Q`` and ``R`` are weights per second), so the cost does not depend on the control rate.

Condensed form. States are eliminated: with ``z = [u_blocks; d]``, ``d = p_{i+1} - p_i`` (x, y) and
the parameter ``theta = [x_measured (4), d_ref (2), x_{i+1,1}^ref (4)]`` the cost is
``1/2 z^T H z + z^T F theta + c(theta)`` with ``H``, ``F`` precomputed for every ``k_s`` by
:func:`build_mpc`. ``B_r`` has a zero z column (eq. 5.10), so the footstep height does not enter the
dynamics; it is kept at the reference height.

Solver (an exact equivalent of the SOC constraint). The footstep is unconstrained, so it is
eliminated in closed form; what is left is a strictly convex QP in the torque blocks with one 2-D
Euclidean ball per block (eq. 5.19e as ``1/2 (||u_j||^2 - U_max^2) <= 0``, not a box; an ellipse
becomes a ball in the scaled torques ``v = S^-1 u``, ``S = diag(U_x, U_y)``). It is solved
exactly through its dual: for multipliers ``lambda >= 0`` the minimiser is
``u(lambda) = -(P + Lambda)^-1 q`` and the concave dual is maximised by a projected Newton method
(Bertsekas 1982; :func:`footfall.control.ball_qp.solve_ball_qp`) with an Armijo search,
warm-started from the previous tick's multipliers. Slater's
condition holds (``u = 0`` is strictly feasible), so there is no duality gap, and the returned
torques are projected onto the balls (a move of at most the tolerance) so (5.19e) holds exactly.
When no ball is active the solution is one matrix-vector product with a precomputed gain. A
Clarabel (interior-point SOCP) backend solves the same condensed problem for cross-checking.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from enum import Enum
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from footfall._typing import FloatArray
from footfall._validate import finite, instance_of, positive
from footfall.control.ball_qp import solve_ball_qp
from footfall.errors import InputError
from footfall.models.biped import BipedParams

#: index slices into the parameter vector theta = [x_measured, d_ref, x_next_ref]
THETA_X = slice(0, 4)
THETA_D = slice(4, 6)
THETA_XREF = slice(6, 10)
N_THETA = 10

#: MPC backends
SOLVERS = ("newton", "clarabel")

#: a footstep this far [m] outside its polygon still counts as inside (solver tolerance)
POLYGON_TOL = 1e-7
#: Clarabel gap and feasibility tolerance of the footstep-polygon solve
POLYGON_GAP_TOL = 1e-10


class MPCStatus(str, Enum):
    """Outcome of one MPC solve."""

    OPTIMAL = "optimal"  # solved to tolerance
    FALLBACK = "fallback"  # the solve failed; the last good solution, shifted, is returned


@dataclass(frozen=True)
class MPCWeights:
    """Weights of the MPC cost (eq. 5.19a), given in physical units so that defaults transfer.

    The velocity weights act on the angular momentum through ``v = L / (m z_H)``, i.e. the
    momentum entries of ``Q`` and ``Q_f`` are ``q_vel / (m z_H)^2``.

    Attributes:
        q_pos: Q on the CoM position deviation from the natural trajectory [1/(m^2 s)].
        q_vel: Q on the CoM velocity deviation from the natural trajectory [1/((m/s)^2 s)].
        r: R on the ankle torque [1/((N m)^2 s)] of a robot of ``r_mass``; 1e-3 makes 15 N m held
            for a 0.4 s step cost 0.09.
        r_mass: the mass [kg] ``r`` was chosen for, or None (the default: ``R = r`` for every
            robot, document 000's weight). Given, a robot of mass ``m`` gets
            ``R = r (r_mass / m)^2``: the same weight on the centre-of-pressure shift
            ``u / (m g)`` whatever the robot weighs (the ankle's torque per metre of CoP grows
            with the weight on it; the velocity weights are scaled by the mass already). The
            MuJoCo walker gives the mass of footfall's biped, on which its weights were chosen
            (:data:`footfall.sim.biped.options.WEIGHTS_MASS`).
        w: W on the next-footstep deviation from the plan [1/m^2]; 10 makes 10 cm cost 0.1.
        qf_pos: Q_f on the CoM position (relative to the new foot) at the start of the next step
            [1/m^2].
        qf_vel: Q_f on the CoM velocity at the start of the next step [1/(m/s)^2].
        qf_dcm: Q_f on the divergent component (capture point) ``xi = c + v / omega`` at the start
            of the next step [1/m^2]. Only the divergent component needs correcting: the
            convergent one decays by itself, so a Q_f that weighs it (a rank-2 term
            ``C_xi^T C_xi``) lets the footstep absorb pushes instead of the ankle (capture-point
            stepping); diagonal position/velocity weights alone make the one-step horizon fight a
            velocity error with torque and saturate. 1000 makes a 1 cm error cost 0.1.

    The defaults were chosen in the reduced-order closed loop (``footfall.sim``): with
    ``qf_dcm = 0`` and ``qf_pos = qf_vel = 100`` a 10 N s sideways push on the flat scene makes the
    robot fall, with these it recovers.
    """

    q_pos: float = 1.0
    q_vel: float = 0.1
    r: float = 1e-3
    w: float = 10.0
    qf_pos: float = 1.0
    qf_vel: float = 1.0
    qf_dcm: float = 1000.0
    r_mass: float | None = None

    def __post_init__(self) -> None:
        for name in ("q_pos", "q_vel", "qf_pos", "qf_vel", "qf_dcm"):
            v = finite(f"weights.{name}", getattr(self, name))
            if v < 0.0:
                raise InputError(f"weights.{name}", v, "a finite number >= 0")
            object.__setattr__(self, name, v)
        # R > 0 and W > 0 make the condensed Hessian positive definite (unique solution).
        object.__setattr__(self, "r", positive("weights.r", self.r))
        object.__setattr__(self, "w", positive("weights.w", self.w))
        if self.r_mass is not None:
            object.__setattr__(self, "r_mass", positive("weights.r_mass", self.r_mass))

    def torque_weight(self, mass: float) -> float:
        """R's diagonal [1/((N m)^2 s)] for a robot of ``mass`` [kg] (see ``r_mass``)."""
        return self.r if self.r_mass is None else self.r * (self.r_mass / mass) ** 2

    def matrices(self, robot: BipedParams) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``(Q (4, 4), R (2, 2), W (2, 2), Q_f (4, 4))`` of eq. (5.19a) for ``robot``."""
        mzh2 = (robot.mass * robot.com_height) ** 2
        q = np.diag([self.q_pos, self.q_pos, self.q_vel / mzh2, self.q_vel / mzh2])
        qf = np.diag([self.qf_pos, self.qf_pos, self.qf_vel / mzh2, self.qf_vel / mzh2])
        # xi = c + v / omega with v = (L_y, -L_x) / (m z_H)
        k = 1.0 / (robot.mass * robot.com_height * robot.alip().omega)
        c_xi = np.array([[1.0, 0.0, 0.0, k], [0.0, 1.0, -k, 0.0]])
        qf = qf + self.qf_dcm * c_xi.T @ c_xi
        return q, self.torque_weight(robot.mass) * np.eye(2), self.w * np.eye(2), qf


@dataclass(frozen=True, eq=False)
class CondensedMPC:
    """The condensed MPC of eq. (5.19) for one gait, precomputed for every tick ``k_s``.

    Built by :func:`build_mpc`. Per-tick entries are tuples indexed by ``k_s`` (0..M-1); ``n_b`` is
    the number of remaining torque blocks at that tick and ``n_u = 2 n_b``.

    Attributes:
        robot: robot parameters (the controller's model).
        weights: cost weights.
        control_dt: control period dt_c = T_ss / M [s].
        n_ticks: M, control ticks per single support.
        n_nodes: K, planner nodes per single support (K - 1 torque blocks).
        block_edges: tick index where each block starts, plus M at the end, shape (K,).
        ad: one-tick ZOH state matrix (4, 4) (eq. 5.7a).
        bd: one-tick ZOH input matrix (4, 2) (eq. 5.7b).
        ar: reset map state matrix (4, 4) (eq. 5.9).
        br: reset map input matrix (4, 3) (eq. 5.10, corrected).
        Q, R, W, Qf: cost matrices (4, 4), (2, 2), (2, 2), (4, 4).
        first_block: global index of the first remaining block at each ``k_s``.
        block_ticks: remaining ticks of each remaining block, shape (n_b,) per ``k_s``.
        a_end: end-of-single-support state from the measured state, ``x_M = a_end x + b_end u``,
            (4, 4) per ``k_s``.
        b_end: (4, n_u) per ``k_s``.
        H: Hessian of the cost in ``z = [u; d]``, (n_u + 2, n_u + 2) per ``k_s``.
        F: linear term ``z^T F theta``, (n_u + 2, 10) per ``k_s``.
        c: constant term ``c(theta) = theta^T C theta``, (10, 10) per ``k_s``.
    """

    robot: BipedParams
    weights: MPCWeights
    control_dt: float
    n_ticks: int
    n_nodes: int
    block_edges: NDArray[np.int64]
    ad: FloatArray
    bd: FloatArray
    ar: FloatArray
    br: FloatArray
    Q: FloatArray
    R: FloatArray
    W: FloatArray
    Qf: FloatArray
    first_block: tuple[int, ...]
    block_ticks: tuple[NDArray[np.int64], ...]
    a_end: tuple[FloatArray, ...]
    b_end: tuple[FloatArray, ...]
    H: tuple[FloatArray, ...]
    F: tuple[FloatArray, ...]
    c: tuple[FloatArray, ...]
    #: semi-axes (U_x, U_y) [N m] of the torque bound (eq. 5.19e; equal = the document's ball)
    u_limits: FloatArray = field(default_factory=lambda: np.zeros(2))
    # Reduced problem in the scaled torques S^-1 u with the footstep eliminated (see solve).
    _p_scaled: tuple[FloatArray, ...] = field(repr=False, default=())
    _q_map: tuple[FloatArray, ...] = field(repr=False, default=())
    _gain: tuple[FloatArray, ...] = field(repr=False, default=())
    _d_theta: tuple[FloatArray, ...] = field(repr=False, default=())
    _d_u: tuple[FloatArray, ...] = field(repr=False, default=())
    _powers: FloatArray = field(repr=False, default_factory=lambda: np.zeros((0, 4, 4)))
    _sums: FloatArray = field(repr=False, default_factory=lambda: np.zeros((0, 4, 2)))

    @cached_property
    def padded(self) -> PaddedMPC:
        """The per-tick matrices of the solver stacked into zero-padded arrays (built once).

        The compiled engine (:mod:`footfall.sim.reduced._kernel`) reads these instead of the
        tuples; they hold exactly the same numbers.
        """
        return pad_condensed(self)

    def n_blocks(self, k_s: int) -> int:
        """Number of remaining torque blocks at tick ``k_s``."""
        return int(self.block_ticks[k_s].shape[0])

    def block_of_tick(self, k: int) -> int:
        """Global block index (0..K-2) that holds tick ``k``."""
        return int(np.searchsorted(self.block_edges, k, side="right") - 1)

    def stacked(self, k_s: int) -> tuple[FloatArray, FloatArray]:
        """Condensed prediction of the states at ticks ``k_s + 1 .. M`` (eq. 5.19b, d).

        ``x_k = Phi[k - k_s - 1] x_{k_s} + Gamma[k - k_s - 1] u`` with ``u`` the remaining torque
        blocks (n_u,), block ``j`` held over its ticks.

        Returns:
            ``(Phi (T, 4, 4), Gamma (T, 4, n_u))`` with ``T = M - k_s``.
        """
        m = self.n_ticks
        k = np.arange(k_s + 1, m + 1)
        phi = self._powers[k - k_s]
        j0 = self.first_block[k_s]
        n_b = self.n_blocks(k_s)
        gamma = np.zeros((k.shape[0], 4, 2 * n_b))
        for j in range(n_b):
            a = max(int(self.block_edges[j0 + j]), k_s)
            b = int(self.block_edges[j0 + j + 1])
            # Block j acts on ticks a..b-1; the state at tick k has felt min(k, b) - a of them,
            # the last one min(k, b) - 1 ticks ago: Ad^(k - min(k, b)) * sum_{i < n} Ad^i Bd.
            last = np.clip(k, a, b)
            gamma[:, :, 2 * j : 2 * j + 2] = self._powers[k - last] @ self._sums[last - a]
        return phi, gamma

    def cost(self, k_s: int, z: ArrayLike, theta: ArrayLike) -> float:
        """Condensed cost ``1/2 z^T H z + z^T F theta + c(theta)`` of eq. (5.19a)."""
        zz = np.asarray(z, dtype=float)
        th = np.asarray(theta, dtype=float)
        return float(0.5 * zz @ self.H[k_s] @ zz + zz @ self.F[k_s] @ th + th @ self.c[k_s] @ th)


@dataclass(frozen=True, eq=False)
class PaddedMPC:
    """The solver's view of a :class:`CondensedMPC`: per-tick matrices stacked along a first axis
    of length M and zero-padded to the largest number of torque variables ``NU = 2 (K - 1)``.

    At tick ``k_s`` only the leading ``n_u = 2 n_b[k_s]`` rows / columns are meaningful. Scaled
    torques ``v = S^-1 u``, ``S = diag(U_x, U_y)`` per block (the balls or ellipses of eq. 5.19e
    have radius 1); the footstep is eliminated.

    Attributes:
        n_b: remaining torque blocks per tick, shape (M,).
        first_block: global index of the first remaining block per tick, shape (M,).
        p_scaled: reduced Hessian in ``v``, shape (M, NU, NU).
        q_map: linear term of the reduced problem ``q = q_map theta``, shape (M, NU, 10).
        gain: unconstrained minimiser ``u = gain theta`` [N m], shape (M, NU, 10).
        d_theta: footstep offset ``d = d_theta theta + d_u u`` [m], shape (M, 2, 10).
        d_u: shape (M, 2, NU) [m / (N m)].
        u_limits: torque bound semi-axes (U_x, U_y) [N m], shape (2,).
    """

    n_b: NDArray[np.int64]
    first_block: NDArray[np.int64]
    p_scaled: FloatArray
    q_map: FloatArray
    gain: FloatArray
    d_theta: FloatArray
    d_u: FloatArray
    u_limits: FloatArray


def pad_condensed(mdl: CondensedMPC) -> PaddedMPC:
    """Stack the per-tick solver matrices of ``mdl`` into a :class:`PaddedMPC`."""
    m = mdl.n_ticks
    nu = 2 * (mdl.n_nodes - 1)
    n_b = np.array([mdl.n_blocks(k) for k in range(m)], dtype=np.int64)
    p_scaled = np.zeros((m, nu, nu))
    q_map = np.zeros((m, nu, N_THETA))
    gain = np.zeros((m, nu, N_THETA))
    d_u = np.zeros((m, 2, nu))
    for k in range(m):
        n = 2 * int(n_b[k])
        p_scaled[k, :n, :n] = mdl._p_scaled[k]
        q_map[k, :n] = mdl._q_map[k]
        gain[k, :n] = mdl._gain[k]
        d_u[k, :, :n] = mdl._d_u[k]
    return PaddedMPC(
        n_b=n_b,
        first_block=np.array(mdl.first_block, dtype=np.int64),
        p_scaled=p_scaled,
        q_map=q_map,
        gain=gain,
        d_theta=np.array(mdl._d_theta),
        d_u=d_u,
        u_limits=np.array(mdl.u_limits, dtype=float),
    )


def _check_int(name: str, value: object, lo: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer) or int(value) < lo:
        raise InputError(name, value, f"an integer >= {lo}")
    return int(value)


def build_mpc(
    robot: BipedParams,
    weights: MPCWeights | None = None,
    control_dt: float = 0.002,
    n_nodes: int | None = None,
    torque_limits: ArrayLike | None = None,
) -> CondensedMPC:
    """Build the condensed MPC of eq. (5.19) for every tick of a single support.

    Args:
        robot: robot parameters (mass, CoM height, T_ss, T_ds, U_max) of the controller's model.
        weights: cost weights (defaults: :class:`MPCWeights`).
        control_dt: requested control period [s]; the used period is ``T_ss / M`` with
            ``M = round(T_ss / control_dt)`` so that a single support is a whole number of ticks.
        n_nodes: K, nodes of the torque blocking (default ``robot.n_nodes``); K - 1 blocks.
        torque_limits: semi-axes ``(U_x, U_y)`` [N m] of the torque ellipse
            ``(u_x / U_x)^2 + (u_y / U_y)^2 <= 1``; default ``(U_max, U_max)``, the ball of
            eq. (5.19e).

    Returns:
        The precomputed :class:`CondensedMPC`.
    """
    instance_of("robot", robot, BipedParams, "a BipedParams (footfall.models.biped)")
    weights = weights or MPCWeights()
    if not isinstance(weights, MPCWeights):
        raise InputError("weights", weights, "an MPCWeights")
    control_dt = positive("control_dt", control_dt)
    k_nodes = _check_int("n_nodes", robot.n_nodes if n_nodes is None else n_nodes, 2)
    m = round(robot.t_ss / control_dt)
    if m < k_nodes - 1:
        raise InputError(
            "control_dt", control_dt, f"at most T_ss / (K - 1) = {robot.t_ss / (k_nodes - 1):g} s"
        )
    dt = robot.t_ss / m
    alip = robot.alip()
    ad, bd = alip.discretize(dt)
    ar, br = alip.reset_map(robot.t_ds)
    q, r, w, qf = weights.matrices(robot)
    edges = np.round(np.linspace(0, m, k_nodes)).astype(np.int64)
    powers, sums = _powers_and_sums(ad, bd, m)
    first, ticks = _blocks_by_tick(edges, m)
    proto = CondensedMPC(
        robot=robot,
        weights=weights,
        control_dt=dt,
        n_ticks=m,
        n_nodes=k_nodes,
        block_edges=edges,
        ad=ad,
        bd=bd,
        ar=ar,
        br=br,
        Q=q,
        R=r,
        W=w,
        Qf=qf,
        first_block=tuple(first),
        block_ticks=tuple(ticks),
        a_end=(),
        b_end=(),
        H=(),
        F=(),
        c=(),
        u_limits=_torque_limits(robot, torque_limits),
        _powers=powers,
        _sums=sums,
    )
    per_tick = [_condense_tick(proto, k_s) for k_s in range(m)]
    names = ("a_end", "b_end", "H", "F", "c", "_p_scaled", "_q_map", "_gain", "_d_theta", "_d_u")
    for name, val in zip(names, zip(*per_tick, strict=True), strict=True):
        object.__setattr__(proto, name, tuple(val))
    return proto


def _powers_and_sums(ad: FloatArray, bd: FloatArray, m: int) -> tuple[FloatArray, FloatArray]:
    """``A_d^n`` (m + 1, 4, 4) and ``sum_{j<n} A_d^j B_d`` (m + 1, 4, 2): n ticks of (5.19b)."""
    powers = np.empty((m + 1, 4, 4))
    sums = np.empty((m + 1, 4, 2))
    powers[0], sums[0] = np.eye(4), 0.0
    for n in range(1, m + 1):
        powers[n] = ad @ powers[n - 1]
        sums[n] = sums[n - 1] + powers[n - 1] @ bd
    return powers, sums


def _blocks_by_tick(edges: NDArray[np.int64], m: int) -> tuple[list[int], list[NDArray[np.int64]]]:
    """For every tick ``k_s``: the block it lies in, and the ticks each remaining block lasts."""
    first: list[int] = []
    ticks: list[NDArray[np.int64]] = []
    for k_s in range(m):
        j0 = int(np.searchsorted(edges, k_s, side="right") - 1)
        first.append(j0)
        t = edges[j0 + 1 :] - np.maximum(edges[j0:-1], k_s)
        ticks.append(t.astype(np.int64))
    return first, ticks


def _condense_tick(mdl: CondensedMPC, k_s: int) -> tuple[NDArray[Any], ...]:
    """The condensed cost of eq. (5.19) at tick ``k_s`` and its reduction to the torques.

    Returns:
        ``(a_end, b_end, H, F, c, P_scaled, q_map, gain, d_theta, d_u)`` of that tick (see
        :class:`CondensedMPC` and :class:`PaddedMPC`).
    """
    dt, ar, q, r, w, qf = mdl.control_dt, mdl.ar, mdl.Q, mdl.R, mdl.W, mdl.Qf
    phi, gamma = mdl.stacked(k_s)
    n_u = gamma.shape[2]
    n_z = n_u + 2
    h = np.zeros((n_z, n_z))
    # Stage terms (5.19a), summed over ticks and scaled by dt (weights per second).
    h[:n_u, :n_u] = 2.0 * dt * np.einsum("kai,ab,kbj->ij", gamma, q, gamma)
    h[:n_u, :n_u] += np.kron(np.diag(2.0 * dt * mdl.block_ticks[k_s]), r)
    # Footstep and next-step terms: residuals r_w = S_d z + D theta, r_f = C_z z + C_th theta.
    s_d = np.zeros((2, n_z))
    s_d[:, n_u:] = np.eye(2)
    d_map = np.zeros((2, N_THETA))
    d_map[:, THETA_D] = -np.eye(2)
    c_z = np.hstack([ar @ gamma[-1], mdl.br[:, :2]])  # (5.19c) with x_M from (5.19b)
    c_th = np.zeros((4, N_THETA))
    c_th[:, THETA_X] = ar @ phi[-1]
    c_th[:, THETA_XREF] = -np.eye(4)
    h += 2.0 * (s_d.T @ w @ s_d + c_z.T @ qf @ c_z)
    f = 2.0 * (s_d.T @ w @ d_map + c_z.T @ qf @ c_th)
    c = d_map.T @ w @ d_map + c_th.T @ qf @ c_th
    # Eliminate d (unconstrained): d = -H_dd^-1 (F_d theta + H_du u).
    h_uu, h_ud, h_dd = h[:n_u, :n_u], h[:n_u, n_u:], h[n_u:, n_u:]
    h_dd_inv = np.linalg.inv(h_dd)
    p_red = h_uu - h_ud @ h_dd_inv @ h_ud.T
    p_red = 0.5 * (p_red + p_red.T)
    f_red = f[:n_u] - h_ud @ h_dd_inv @ f[n_u:]
    # Scaled torques v = S^-1 u put the balls at radius 1 (better-conditioned multipliers).
    scale = np.tile(mdl.u_limits, n_u // 2)
    return (
        phi[-1],
        gamma[-1],
        h,
        f,
        c,
        scale[:, None] * p_red * scale[None, :],
        scale[:, None] * f_red,
        -np.linalg.solve(p_red, f_red),
        -h_dd_inv @ f[n_u:],
        -h_dd_inv @ h_ud.T,
    )


def _torque_limits(robot: BipedParams, torque_limits: ArrayLike | None) -> FloatArray:
    """Checked ``(U_x, U_y)`` [N m]; ``None`` gives the ball ``(U_max, U_max)`` of eq. (5.19e)."""
    if torque_limits is None:
        return np.array([robot.u_max, robot.u_max], dtype=float)
    try:
        lim = np.asarray(torque_limits, dtype=float)
    except (TypeError, ValueError):
        raise InputError("torque_limits", torque_limits, "two numbers (U_x, U_y) [N m]") from None
    if lim.shape != (2,) or not np.all(np.isfinite(lim)) or np.any(lim <= 0.0):
        raise InputError("torque_limits", torque_limits, "two finite numbers (U_x, U_y) > 0 [N m]")
    return lim


@dataclass(frozen=True)
class MPCSolution:
    """Result of one MPC solve (eq. 5.19).

    Attributes:
        k_s: control tick within the single support.
        torques: remaining block torques ``u`` [N m], shape (n_b, 2); row 0 is applied now.
        block_ticks: ticks each block lasts from now, shape (n_b,).
        next_footstep: optimised ``p_{i+1}`` (3,) [m] (height = reference height).
        status: :class:`MPCStatus`.
        fallback: True when the solve failed and the last good solution (shifted) is returned.
        solve_time: wall time of the solve [s].
        iterations: projected Newton iterations (0 when no torque bound is active).
        multipliers: dual variables of the torque balls (scaled problem), shape (n_b,).
        message: why a fallback happened.
    """

    k_s: int
    torques: FloatArray
    block_ticks: NDArray[np.int64]
    next_footstep: FloatArray
    status: MPCStatus
    fallback: bool
    solve_time: float
    iterations: int = 0
    multipliers: FloatArray = field(default_factory=lambda: np.zeros(0))
    message: str = ""

    @property
    def torque(self) -> FloatArray:
        """The torque to apply at this tick (2,) [N m]."""
        return self.torques[0]


def _check_polygon(a: ArrayLike, b: ArrayLike) -> tuple[FloatArray, FloatArray]:
    """The footstep polygon ``a p[:2] <= b`` of :meth:`MPC.solve_in_polygon` as checked arrays."""
    aa = np.asarray(a, dtype=float)
    bb = np.asarray(b, dtype=float)
    if aa.ndim != 2 or aa.shape[1] != 2 or aa.shape[0] < 1 or not np.all(np.isfinite(aa)):
        raise InputError("a", aa.tolist(), "finite edge normals of shape (E, 2), E >= 1")
    if bb.shape != (aa.shape[0],) or not np.all(np.isfinite(bb)):
        raise InputError("b", bb.tolist(), f"finite offsets of shape ({aa.shape[0]},)")
    return aa, bb


def _clarabel_in_polygon(
    p: FloatArray, q: FloatArray, a: FloatArray, b: FloatArray, n_u: int
) -> Any:
    """Clarabel's solution of ``min 1/2 z^T P z + q^T z`` over ``z = [v (n_u); d (2)]`` with
    ``a d <= b`` and ``||v_j|| <= 1`` per 2-D block (eq. 5.19e in the scaled torques)."""
    import clarabel
    from scipy import sparse

    n = n_u + 2
    rows = [np.hstack([np.zeros((a.shape[0], n_u)), a])]
    rhs = [b]
    for j in range(n_u // 2):  # (1, v_j) in the second-order cone
        blk = np.zeros((3, n))
        blk[1, 2 * j] = blk[2, 2 * j + 1] = -1.0
        rows.append(blk)
        rhs.append(np.array([1.0, 0.0, 0.0]))
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    # the torques are nearly free along some directions (R is small): solve to the
    # accuracy of the Newton backend, not Clarabel's default 1e-8 relative gap
    settings.tol_gap_abs = settings.tol_gap_rel = POLYGON_GAP_TOL
    settings.tol_feas = POLYGON_GAP_TOL
    cones = [clarabel.NonnegativeConeT(a.shape[0])]
    cones += [clarabel.SecondOrderConeT(3)] * (n_u // 2)
    return clarabel.DefaultSolver(
        sparse.triu(sparse.csc_matrix(p), format="csc"),
        q,
        sparse.csc_matrix(np.vstack(rows)),
        np.concatenate(rhs),
        cones,
        settings,
    ).solve()


class MPC:
    """The footstep / ankle-torque adjuster (eq. 5.19) running at the control rate.

    Holds the condensed model, warm starts and failure counters for one walk. Call
    :meth:`solve` at every tick of a single support with the measured state; ``k_s`` restarting
    from a smaller value marks a new single support.

    Args:
        condensed: output of :func:`build_mpc`.
        solver: ``newton`` (exact dual projected Newton, default) or ``clarabel`` (conic
            interior point on the same condensed problem).
    """

    def __init__(self, condensed: CondensedMPC, solver: str = "newton") -> None:
        if not isinstance(condensed, CondensedMPC):
            raise InputError("condensed", condensed, "a CondensedMPC from build_mpc")
        if solver not in SOLVERS:
            raise InputError("solver", solver, f"one of {', '.join(SOLVERS)}")
        self.model = condensed
        self.solver = solver
        self.n_solves = 0
        self.n_fallbacks = 0
        self._last: MPCSolution | None = None
        self._clarabel: dict[int, Any] = {}

    def reset(self) -> None:
        """Forget warm starts and the last solution (counters are kept)."""
        self._last = None

    def solve(
        self,
        k_s: int,
        x_measured: ArrayLike,
        p_stance: ArrayLike,
        p_next_ref: ArrayLike,
        x_next_ref: ArrayLike,
    ) -> MPCSolution:
        """Solve eq. (5.19) at tick ``k_s``.

        Args:
            k_s: control tick in the single support, 0 <= k_s < M.
            x_measured: measured ALIP state (4,) relative to the stance foot (eq. 5.19d).
            p_stance: stance footstep p_i (3,) [m].
            p_next_ref: planned next footstep p_{i+1}^ref (3,) [m].
            x_next_ref: planned state after the next reset x_{i+1,1}^ref (4,).

        Returns:
            The :class:`MPCSolution`; a failed solve returns the last good solution shifted to
            ``k_s`` (or zero torque and the reference footstep) with ``fallback=True``.
        """
        t0 = time.perf_counter()
        mdl = self.model
        if isinstance(k_s, bool) or not isinstance(k_s, int | np.integer):
            raise InputError("k_s", k_s, f"an integer tick in [0, {mdl.n_ticks})")
        k_s = int(k_s)
        if not 0 <= k_s < mdl.n_ticks:
            raise InputError("k_s", k_s, f"an integer tick in [0, {mdl.n_ticks})")
        x = np.asarray(x_measured, dtype=float)
        ps = np.asarray(p_stance, dtype=float)
        pr = np.asarray(p_next_ref, dtype=float)
        xr = np.asarray(x_next_ref, dtype=float)
        for name, arr, n in (
            ("x_measured", x, 4),
            ("p_stance", ps, 3),
            ("p_next_ref", pr, 3),
            ("x_next_ref", xr, 4),
        ):
            if arr.shape != (n,):
                raise InputError(name, arr.tolist(), f"shape ({n},)")
        theta = np.concatenate([x, pr[:2] - ps[:2], xr])
        return self.solve_theta(k_s, theta, ps, pr, t0)

    def solve_in_polygon(
        self,
        k_s: int,
        x_measured: ArrayLike,
        p_stance: ArrayLike,
        p_next_ref: ArrayLike,
        x_next_ref: ArrayLike,
        a: ArrayLike,
        b: ArrayLike,
    ) -> MPCSolution:
        """Eq. (5.19) with the next footstep also kept in the polygon ``a p_{i+1}[:2] <= b``.

        Beyond the document: document 000 leaves foothold regions and reach to the planner and
        its MPC moves the footstep freely. A walker that then clamps the footstep into its
        region throws away the correction the MPC counted on, and the ankle torque it chose
        assumed that correction. With the polygon in the problem the torques compensate for
        what the footstep cannot do. When the unconstrained optimum (:meth:`solve`) already
        lies in the polygon it is returned unchanged (it is then optimal here too); otherwise
        the condensed problem with the footstep as a variable, the torque balls and the
        polygon rows is solved with Clarabel (a conic interior point method).

        Args:
            k_s, x_measured, p_stance, p_next_ref, x_next_ref: as for :meth:`solve`.
            a: outward edge normals (E, 2) of the footstep polygon.
            b: offsets (E,) [m] (world frame, like ``p_stance``).

        Returns:
            The :class:`MPCSolution`. If the constrained solve fails (e.g. an empty polygon), the
            unconstrained solution with a ``message`` saying why.
        """
        aa, bb = _check_polygon(a, b)
        sol = self.solve(k_s, x_measured, p_stance, p_next_ref, x_next_ref)
        if sol.fallback or np.all(aa @ sol.next_footstep[:2] <= bb + POLYGON_TOL):
            return sol
        t0 = time.perf_counter()
        mdl = self.model
        k_s = int(k_s)
        ps = np.asarray(p_stance, dtype=float)
        pr = np.asarray(p_next_ref, dtype=float)
        theta = np.concatenate(
            [np.asarray(x_measured, float), pr[:2] - ps[:2], np.asarray(x_next_ref, float)]
        )
        n_u = 2 * mdl.n_blocks(k_s)
        # z = T [v; d] with v = S^-1 u: the balls have radius 1 as in the other backends
        scale = np.concatenate([np.tile(mdl.u_limits, n_u // 2), np.ones(2)])
        p = scale[:, None] * mdl.H[k_s] * scale[None, :]
        q = scale * (mdl.F[k_s] @ theta)
        try:
            res = _clarabel_in_polygon(p, q, aa, bb - aa @ ps[:2], n_u)
        except (ValueError, RuntimeError) as exc:  # pragma: no cover - solver internals
            return replace(sol, message=f"footstep polygon solve failed: {exc}")
        if str(res.status) not in ("Solved", "AlmostSolved"):
            return replace(
                sol, message=f"footstep polygon solve: {res.status} (polygon empty?); unconstrained"
            )
        z = np.asarray(res.x, dtype=float)
        vb = z[:n_u].reshape(-1, 2)
        vb = vb / np.maximum(np.linalg.norm(vb, axis=1), 1.0)[:, None]
        d = z[n_u:]
        duals = np.asarray(res.z, dtype=float)[aa.shape[0] :].reshape(-1, 3)[:, 0]
        out = MPCSolution(
            k_s=k_s,
            torques=vb * mdl.u_limits,
            block_ticks=mdl.block_ticks[k_s],
            next_footstep=np.array([ps[0] + d[0], ps[1] + d[1], pr[2]]),
            status=MPCStatus.OPTIMAL,
            fallback=False,
            solve_time=sol.solve_time + time.perf_counter() - t0,
            iterations=int(res.iterations),
            multipliers=duals,
        )
        self._last = out
        return out

    def solve_theta(
        self,
        k_s: int,
        theta: FloatArray,
        p_stance: FloatArray,
        p_next_ref: FloatArray,
        t0: float | None = None,
    ) -> MPCSolution:
        """:meth:`solve` without input checks, from the parameter vector (for simulation loops).

        Args:
            k_s: control tick, 0 <= k_s < M (not checked).
            theta: ``[x_measured (4), (p_next_ref - p_stance)[:2], x_next_ref (4)]``, shape (10,).
            p_stance: (3,) [m].
            p_next_ref: (3,) [m].
            t0: ``time.perf_counter()`` at the start of the caller's solve (for solve_time).
        """
        t0 = time.perf_counter() if t0 is None else t0
        mdl = self.model
        ps, pr = p_stance, p_next_ref
        if self._last is not None and k_s <= self._last.k_s:
            self._last = None  # a new single support: nothing to shift
        self.n_solves += 1
        # one reduction instead of isfinite().all(): a NaN or inf anywhere makes the sum non-finite
        if not math.isfinite(float(theta.sum())):
            return self._fallback(k_s, ps, pr, t0, "non-finite measurement or reference")
        lam0 = None
        if self._last is not None:
            shift = mdl.first_block[k_s] - mdl.first_block[self._last.k_s]
            lam0 = self._last.multipliers[shift:]
        try:
            if self.solver == "newton":
                u, lam, iters, ok = self._solve_newton(k_s, theta, lam0)
            else:
                u, lam, iters, ok = self._solve_clarabel(k_s, theta)
        except (np.linalg.LinAlgError, ValueError) as exc:
            return self._fallback(k_s, ps, pr, t0, f"solver error: {exc}")
        if not ok or not math.isfinite(float(u.sum())):
            return self._fallback(k_s, ps, pr, t0, "solver did not converge")
        d = mdl._d_theta[k_s] @ theta + mdl._d_u[k_s] @ u
        sol = MPCSolution(
            k_s=k_s,
            torques=u.reshape(-1, 2),
            block_ticks=mdl.block_ticks[k_s],
            next_footstep=np.array([ps[0] + d[0], ps[1] + d[1], pr[2]]),
            status=MPCStatus.OPTIMAL,
            fallback=False,
            solve_time=time.perf_counter() - t0,
            iterations=iters,
            multipliers=lam,
        )
        self._last = sol
        return sol

    def _solve_newton(
        self, k_s: int, theta: FloatArray, lam0: FloatArray | None
    ) -> tuple[FloatArray, FloatArray, int, bool]:
        mdl = self.model
        u_lim = mdl.u_limits
        u = mdl._gain[k_s] @ theta
        vb = u.reshape(-1, 2) / u_lim
        if np.einsum("ij,ij->i", vb, vb).max() <= 1.0:
            # No ball active: the unconstrained minimiser is optimal (all multipliers zero).
            return u, np.zeros(vb.shape[0]), 0, True
        q = mdl._q_map[k_s] @ theta
        v, lam, iters, ok = solve_ball_qp(mdl._p_scaled[k_s], q, lam0)
        return (v.reshape(-1, 2) * u_lim).ravel(), lam, iters, ok

    def _solve_clarabel(
        self, k_s: int, theta: FloatArray
    ) -> tuple[FloatArray, FloatArray, int, bool]:
        import clarabel
        from scipy import sparse

        mdl = self.model
        p = mdl._p_scaled[k_s]
        q = mdl._q_map[k_s] @ theta
        n = q.shape[0]
        n_b = n // 2
        solver = self._clarabel.get(k_s)
        if solver is None:
            # s = b - A v in the product of second-order cones (1, v_j) for each block.
            rows = []
            for j in range(n_b):
                rows.append(np.zeros(n))
                e = np.zeros((2, n))
                e[0, 2 * j] = e[1, 2 * j + 1] = -1.0
                rows.extend(e)
            a = sparse.csc_matrix(np.array(rows))
            b = np.tile([1.0, 0.0, 0.0], n_b)
            settings = clarabel.DefaultSettings()
            settings.verbose = False
            settings.presolve_enable = False
            cones = [clarabel.SecondOrderConeT(3)] * n_b
            solver = clarabel.DefaultSolver(sparse.triu(p, format="csc"), q, a, b, cones, settings)
            self._clarabel[k_s] = solver
        else:
            solver.update(q=q)
        res = solver.solve()
        ok = str(res.status) in ("Solved", "AlmostSolved")
        v = np.asarray(res.x, dtype=float)
        vb = v.reshape(n_b, 2)
        vb = vb / np.maximum(np.linalg.norm(vb, axis=1), 1.0)[:, None]
        z = np.asarray(res.z, dtype=float).reshape(n_b, 3)
        # The SOC multiplier z_0 of block j equals lambda_j ||v_j|| = lambda_j on the sphere.
        return (vb * mdl.u_limits).ravel(), z[:, 0], int(res.iterations), ok

    def _fallback(
        self, k_s: int, ps: FloatArray, pr: FloatArray, t0: float, message: str
    ) -> MPCSolution:
        """The last good solution shifted to ``k_s``, or zero torque and the reference footstep."""
        mdl = self.model
        self.n_fallbacks += 1
        n_b = mdl.n_blocks(k_s)
        last = self._last
        if last is not None:
            shift = mdl.first_block[k_s] - mdl.first_block[last.k_s]
            torques = last.torques[shift:]
            lam = last.multipliers[shift:]
            foot = last.next_footstep
        else:
            torques = np.zeros((n_b, 2))
            lam = np.zeros(n_b)
            foot = np.array(pr, dtype=float) if np.all(np.isfinite(pr)) else np.array(ps, float)
        return MPCSolution(
            k_s=k_s,
            torques=np.array(torques),
            block_ticks=mdl.block_ticks[k_s],
            next_footstep=np.array(foot),
            status=MPCStatus.FALLBACK,
            fallback=True,
            solve_time=time.perf_counter() - t0,
            multipliers=np.array(lam),
            message=message,
        )
