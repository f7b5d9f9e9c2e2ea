"""Whole-body inverse-dynamics QP: joint torques that realise task accelerations through contact
forces that respect friction, the sole and the torque limits (beyond the documents).

Document 000 plans the ALIP motion (eq. 5.1) and its ankle torque ``u`` (eq. 5.3); a robot
realises them with joint torques. This module is the standard answer of the field (TSID,
dairlib's operational-space controller, the WBC of Quadruped-PyMPC), written against arrays
only: it knows nothing of MuJoCo (:mod:`footfall.sim.wbc_model` fills the arrays from a MuJoCo
model).

Decision variables ``x = (qdd, f)``: generalised accelerations ``qdd`` (nv,) and one force
(3,) [N] per contact point, world axes. Joint torques are not variables: they follow from the
dynamics, ``tau = (M qdd + h - Jc^T f)[actuated]``, and are bounded through it.

Constraints:

- floating-base dynamics, the unactuated rows of ``M qdd + h = S^T tau + Jc^T f`` (equalities);
- every contact body does not accelerate: ``J_b qdd + Jdot_b qd = 0`` (6 rows per body);
- per contact point a linearised friction cone, the pyramid inscribed in Coulomb's cone
  (``|f . t_k| <= mu / sqrt(2) f . n``) and ``f . n >= min_normal``: with the points at the sole's
  corners the centre of pressure lies inside the sole by construction;
- ``tau_min <= tau <= tau_max``.

Tasks (weighted least squares, each residual scaled to its own units by its weight):

- :class:`MotionTask`: ``J qdd + Jdot qd = a*`` (a frame's, the posture's acceleration);
- :class:`WrenchTask`: rows of the contact wrench about a point, ``R w(f) = target``. The total
  force is ``m (cdd - g)`` exactly (Newton), so a CoM acceleration is a wrench task on the forces;
  the moment of one foot's forces about its sole centre is document 000's ankle torque ``u``
  (eq. 5.3), so ``u`` becomes the commanded centre of pressure; the moment about the CoM is the
  rate of the centroidal angular momentum.

The QP is dense and small (18 + 24 variables for a biped in double support) and solved by
``daqp``'s active-set method, warm-started from the last active set.

Equations (with ``Jc^T f = sum_i J_b^T [f_i; (p_i - o_b) x f_i]``, the contact points ``p_i``
rigidly attached to their body ``b`` whose reference point is ``o_b``)::

    min   sum_k w_k |J_k qdd + Jdot_k qd - a_k|^2 + sum_l w_l |R_l W_l f - t_l|^2
          + eps_q |qdd|^2 + eps_f |f|^2 + eps_tau |tau|^2
    s.t.  (M qdd + h - Jc^T f)[unactuated] = 0
          J_b qdd = -Jdot_b qd                      for every contact body b
          friction pyramid per point,  tau_min <= tau(qdd, f) <= tau_max
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from footfall._typing import FloatArray
from footfall.control._wbc_kernel import PYRAMID_SHARE, _tangents, assemble
from footfall.errors import InputError, SolverError

#: default regularisation weights of the accelerations [1/(m/s^2)^2], forces [1/N^2] and torques
QACC_REGULARISATION = 1e-6
FORCE_REGULARISATION = 1e-8
TORQUE_REGULARISATION = 1e-7
#: daqp exit flags that are a solution (1 optimal, 2 soft-optimal)
DAQP_OK = (1, 2)


def tangent_basis(normal: FloatArray) -> tuple[FloatArray, FloatArray]:
    """The two unit tangents (3,) of the friction pyramid of a contact with unit ``normal``."""
    t1, t2 = _tangents(np.asarray(normal, dtype=float))
    return np.asarray(t1), np.asarray(t2)


@dataclass(frozen=True)
class Contact:
    """A rigid body touching the ground at a few points (a flat sole: its corners).

    Attributes:
        name: for messages and results.
        jacobian: (6, nv) Jacobian of the body at ``origin``: rows 0-2 the linear velocity of
            that point, rows 3-5 the angular velocity, world axes.
        drift: (6,) ``Jdot qd`` of the same rows [m/s^2, rad/s^2].
        origin: (3,) reference point of the body [m], world.
        points: (k, 3) contact points [m], world, rigidly attached to the body.
        normal: (3,) unit contact normal (pointing into the robot).
        friction: Coulomb friction coefficient.
        min_normal: lower bound of each point's normal force [N].
        tangent: (3,) unit tangent (orthogonal to ``normal``) that sets the orientation of the
            friction pyramid: its faces bound the force along ``tangent`` and ``normal x
            tangent`` by ``mu / sqrt(2)``, its edges reach the cone (``mu``) half-way between
            them. None: any orientation. A contact that must hold a known tangential load (a
            foot on a slope) admits the most when that load points at an edge.
    """

    name: str
    jacobian: FloatArray
    drift: FloatArray
    origin: FloatArray
    points: FloatArray
    normal: FloatArray
    friction: float
    min_normal: float = 0.0
    tangent: FloatArray | None = None

    @property
    def n_points(self) -> int:
        return int(self.points.shape[0])

    @classmethod
    def point(
        cls,
        name: str,
        jacobian: FloatArray,
        drift: FloatArray,
        point: FloatArray,
        normal: FloatArray,
        friction: float,
        min_normal: float = 0.0,
        tangent: FloatArray | None = None,
    ) -> Contact:
        """A point foot (a quadruped's sphere on the ground): one force at ``point`` (3,) [m],
        whose velocity must not change (``jacobian`` (3, nv) and ``drift`` (3,) of the point,
        linear rows only). The body may turn about the point: its angular rows are left out
        (zero rows here, dropped from the QP's equalities by :meth:`WholeBodyController.solve`).
        """
        jac = np.zeros((6, np.asarray(jacobian).shape[-1]))
        jac[:3] = jacobian
        dr = np.zeros(6)
        dr[:3] = drift
        p = np.asarray(point, dtype=float)
        return cls(
            name,
            jac,
            dr,
            p,
            p.reshape(1, 3),
            np.asarray(normal, float),
            friction,
            min_normal,
            tangent,
        )


@dataclass(frozen=True)
class MotionTask:
    """``jacobian qdd + drift = acceleration`` in the least-squares sense, times ``weight``.

    Attributes:
        name: for results.
        jacobian: (r, nv).
        drift: (r,) ``Jdot qd``.
        acceleration: (r,) desired acceleration (PD feedback + feedforward).
        weight: scalar or (r,) weights of the squared residuals.
    """

    name: str
    jacobian: FloatArray
    drift: FloatArray
    acceleration: FloatArray
    weight: float | FloatArray = 1.0


@dataclass(frozen=True)
class WrenchTask:
    """``rows @ wrench = target``: rows of the wrench (force; moment about ``about``) of the
    contact forces of ``contacts`` (None: all contacts), times ``weight``.

    Attributes:
        name: for results.
        about: (3,) point of the moments [m].
        rows: (r, 6) selection / combination of (fx, fy, fz, mx, my, mz).
        target: (r,) [N, N m].
        weight: scalar or (r,) weights of the squared residuals.
        contacts: names of the contacts whose forces count; None: all.
    """

    name: str
    about: FloatArray
    rows: FloatArray
    target: FloatArray
    weight: float | FloatArray = 1.0
    contacts: tuple[str, ...] | None = None


@dataclass(frozen=True)
class WbcProblem:
    """One control tick's whole-body problem.

    Attributes:
        mass_matrix: (nv, nv) joint-space inertia ``M`` (with armature).
        bias: (nv,) ``h``: Coriolis, centrifugal and gravity forces minus passive forces, so that
            ``M qdd + h = S^T tau + Jc^T f``.
        actuated: (na,) indices of the actuated degrees of freedom (``S``); the others (the
            floating base) take no torque.
        torque_min, torque_max: (na,) torque limits [N m].
        contacts: bodies in contact this tick.
        motion_tasks, wrench_tasks: the tasks.
    """

    mass_matrix: FloatArray
    bias: FloatArray
    actuated: FloatArray
    torque_min: FloatArray
    torque_max: FloatArray
    contacts: tuple[Contact, ...] = ()
    motion_tasks: tuple[MotionTask, ...] = ()
    wrench_tasks: tuple[WrenchTask, ...] = ()

    @property
    def nv(self) -> int:
        return int(self.mass_matrix.shape[0])


@dataclass(frozen=True)
class WbcSolution:
    """Result of :meth:`WholeBodyController.solve`.

    Attributes:
        qacc: (nv,) generalised accelerations.
        torque: (na,) joint torques [N m] of ``actuated``.
        forces: per contact name, (k, 3) point forces on the robot [N], world.
        iterations: active-set iterations.
    """

    qacc: FloatArray
    torque: FloatArray
    forces: dict[str, FloatArray]
    iterations: int


def _weights(w: float | FloatArray, rows: int, name: str) -> FloatArray | float:
    """A task's weights: a scalar as it is, an array checked to be (rows,), finite, >= 0."""
    if isinstance(w, (int, float)):
        if not (math.isfinite(w) and w >= 0):
            raise InputError(f"task {name}.weight", w, "a non-negative number")
        return float(w)
    arr = np.asarray(w, dtype=float)
    if arr.shape != (rows,) or not np.all(np.isfinite(arr)) or np.any(arr < 0):
        raise InputError(f"task {name}.weight", w, f"a non-negative scalar or ({rows},) array")
    return arr


class WholeBodyController:
    """Builds and solves :class:`WbcProblem` QPs, warm-starting each from the last active set.

    Args:
        qacc_regularisation, force_regularisation, torque_regularisation: weights of
            ``|qdd|^2``, ``|f|^2`` and ``|tau|^2`` (keep the QP strictly convex and the
            solution unique).
    """

    def __init__(
        self,
        qacc_regularisation: float = QACC_REGULARISATION,
        force_regularisation: float = FORCE_REGULARISATION,
        torque_regularisation: float = TORQUE_REGULARISATION,
    ) -> None:
        import daqp

        self._daqp = daqp
        self.eps = (qacc_regularisation, force_regularisation, torque_regularisation)
        self._warm: tuple[tuple[int, ...], np.ndarray] | None = None
        self.failures = 0

    def solve(self, problem: WbcProblem, check: bool = True) -> WbcSolution:
        """Solve one tick's QP.

        Args:
            problem: the tick's problem.
            check: validate the arrays' shapes and values first (a caller that builds them
                itself, every tick, may skip it).

        Raises:
            InputError: on arrays of the wrong shapes or non-finite values.
            SolverError: when the QP has no solution (e.g. contacts whose dynamics cannot be
                met within the torque limits); the message names daqp's exit flag.
        """
        p = problem
        nv = p.nv
        if check:
            _check_problem(p)
        x, torque, iterations = self.solve_packed(_pack(p))
        forces = {}
        o = nv
        for c in p.contacts:
            forces[c.name] = x[o : o + 3 * c.n_points].reshape(-1, 3)
            o += 3 * c.n_points
        return WbcSolution(x[:nv].copy(), torque, forces, iterations)

    def solve_packed(self, packed: PackedProblem) -> tuple[FloatArray, FloatArray, int]:
        """Solve one tick's QP given as arrays (what :meth:`solve` does after packing its
        problem; a controller that fills the arrays itself skips the dataclasses). The arrays are
        not checked.

        Returns:
            ``x`` (n,) = (qdd (nv,), the contacts' point forces (3 per point) [N], in order),
            the joint torques (na,) [N m] and daqp's iterations.

        Raises:
            SolverError: as :meth:`solve`.
        """
        return self.solve_assembled(assemble(*packed, *self.eps))

    def solve_assembled(self, assembled: Assembled) -> tuple[FloatArray, FloatArray, int]:
        """:meth:`solve_packed` of the QP as :func:`footfall.control._wbc_kernel.assemble`
        returns it (for compiled code that packs and assembles in one call, with this
        controller's ``eps``)."""
        h_mat, g_vec, c_mat, lower, upper, n_eq, t_map, zero_row_value = assembled
        n = h_mat.shape[0]
        if zero_row_value:
            raise SolverError("whole-body QP: an equality row is zero but its value is not")
        senses = np.zeros(lower.shape[0], dtype=np.int32)
        senses[:n_eq] = 5
        key = (n, lower.shape[0])
        if self._warm is not None and self._warm[0] == key:
            senses[n_eq:][self._warm[1][n_eq:]] = 1  # last tick's active inequalities
        x, _fval, flag, info = self._daqp.solve(h_mat, g_vec, c_mat, upper, lower, senses)
        if flag not in DAQP_OK:
            self._warm = None
            self.failures += 1
            raise SolverError(f"whole-body QP has no solution (daqp exit flag {flag})")
        x = np.asarray(x)
        if not np.isfinite(x).all():
            # only non-finite data (an unchecked problem) gets here: no solution to return
            self._warm = None
            self.failures += 1
            raise SolverError("whole-body QP returned non-finite values (non-finite input?)")
        self._warm = (key, np.asarray(info["lam"]) != 0.0)
        torque = t_map[:, :n] @ x + t_map[:, n]
        return x, torque, int(info.get("iterations", 0))


#: :func:`footfall.control._wbc_kernel.assemble`'s QP: ``(H, g, C, lower, upper, n_eq, T,
#: zero_row_value)``
Assembled = tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray, int, FloatArray, bool]


class PackedProblem(NamedTuple):
    """A :class:`WbcProblem` as the arrays of :func:`footfall.control._wbc_kernel.assemble`
    (whose docstring gives the shapes), in its argument order: contacts, then motion rows, then
    wrench rows, each in the problem's order."""

    mass: FloatArray
    bias: FloatArray
    actuated: NDArray[np.int64]
    unactuated: NDArray[np.int64]
    torque_min: FloatArray
    torque_max: FloatArray
    jac: FloatArray
    drift: FloatArray
    origin: FloatArray
    points: FloatArray
    n_points: NDArray[np.int64]
    normal: FloatArray
    tangent: FloatArray
    friction: FloatArray
    min_normal: FloatArray
    motion_jac: FloatArray
    motion_rhs: FloatArray
    motion_w: FloatArray
    wrench_rows: FloatArray
    wrench_about: FloatArray
    wrench_target: FloatArray
    wrench_w: FloatArray
    wrench_mask: FloatArray


def _pack(p: WbcProblem) -> PackedProblem:
    """The problem as the arrays of :func:`footfall.control._wbc_kernel.assemble`."""
    nv = p.nv
    actuated = np.asarray(p.actuated, dtype=np.int64)
    free = np.ones(nv, dtype=bool)
    free[actuated] = False
    nc = len(p.contacts)
    kmax = max((c.n_points for c in p.contacts), default=0)
    jac = np.zeros((nc, 6, nv))
    drift = np.zeros((nc, 6))
    origin = np.zeros((nc, 3))
    points = np.zeros((nc, kmax, 3))
    n_points = np.zeros(nc, dtype=np.int64)
    normal = np.zeros((nc, 3))
    tangent = np.zeros((nc, 3))
    friction = np.zeros(nc)
    min_normal = np.zeros(nc)
    for i, c in enumerate(p.contacts):
        jac[i], drift[i], origin[i] = c.jacobian, c.drift, c.origin
        points[i, : c.n_points] = c.points
        n_points[i] = c.n_points
        normal[i], friction[i], min_normal[i] = c.normal, c.friction, c.min_normal
        if c.tangent is not None:
            tangent[i] = c.tangent
    rm = sum(t.acceleration.shape[0] for t in p.motion_tasks)
    m_jac, m_rhs, m_w = np.empty((rm, nv)), np.empty(rm), np.empty(rm)
    r0 = 0
    for t in p.motion_tasks:
        r1 = r0 + t.acceleration.shape[0]
        m_jac[r0:r1] = t.jacobian
        m_rhs[r0:r1] = t.acceleration - t.drift
        m_w[r0:r1] = t.weight
        r0 = r1
    rw = sum(wt.target.shape[0] for wt in p.wrench_tasks)
    w_rows, w_about = np.empty((rw, 6)), np.empty((rw, 3))
    w_target, w_weight, w_mask = np.empty(rw), np.empty(rw), np.zeros((rw, nc))
    names = [c.name for c in p.contacts]
    r0 = 0
    for wt in p.wrench_tasks:
        r1 = r0 + wt.target.shape[0]
        w_rows[r0:r1], w_about[r0:r1], w_target[r0:r1] = wt.rows, wt.about, wt.target
        w_weight[r0:r1] = wt.weight
        for i, nm in enumerate(names):
            if wt.contacts is None or nm in wt.contacts:
                w_mask[r0:r1, i] = 1.0
        r0 = r1
    return PackedProblem(
        np.ascontiguousarray(p.mass_matrix, dtype=float),
        np.asarray(p.bias, dtype=float),
        actuated,
        np.flatnonzero(free).astype(np.int64),
        np.asarray(p.torque_min, dtype=float),
        np.asarray(p.torque_max, dtype=float),
        jac,
        drift,
        origin,
        points,
        n_points,
        normal,
        tangent,
        friction,
        min_normal,
        m_jac,
        m_rhs,
        m_w,
        w_rows,
        w_about,
        w_target,
        w_weight,
        w_mask,
    )


def _check_problem(p: WbcProblem) -> None:
    """Shapes and finiteness of a problem's arrays (:class:`InputError` naming the field)."""
    nv = p.nv
    _shape("mass_matrix", p.mass_matrix, (nv, nv))
    _shape("bias", p.bias, (nv,))
    na = np.asarray(p.actuated).shape[0]
    # a torque without a limit is +-inf (MujocoWbcModel gives it so), never NaN
    _shape("torque_min", p.torque_min, (na,), allow_inf=True)
    _shape("torque_max", p.torque_max, (na,), allow_inf=True)
    if np.any(np.asarray(p.torque_min) > np.asarray(p.torque_max)):
        raise InputError("torque_min", p.torque_min, "<= torque_max")
    act = np.asarray(p.actuated)
    if act.size and (act.min() < 0 or act.max() >= nv or np.unique(act).size != act.size):
        raise InputError("actuated", act.tolist(), f"distinct indices in [0, {nv})")
    names = [c.name for c in p.contacts]
    if len(set(names)) != len(names):
        raise InputError("contacts", names, "distinct contact names")
    for c in p.contacts:
        _shape(f"contact {c.name}.jacobian", c.jacobian, (6, nv))
        _shape(f"contact {c.name}.drift", c.drift, (6,))
        _shape(f"contact {c.name}.origin", c.origin, (3,))
        _shape(f"contact {c.name}.normal", c.normal, (3,))
        if c.points.ndim != 2 or c.points.shape[1] != 3 or c.points.shape[0] < 1:
            raise InputError(f"contact {c.name}.points", c.points.shape, "(k, 3) with k >= 1")
        _shape(f"contact {c.name}.points", c.points, c.points.shape)
        if not math.isfinite(c.friction) or c.friction <= 0:
            raise InputError(f"contact {c.name}.friction", c.friction, "a positive number")
        if abs(float(np.linalg.norm(c.normal)) - 1.0) > 1e-6:
            raise InputError(f"contact {c.name}.normal", c.normal.tolist(), "a unit vector")
        if c.tangent is not None:
            _shape(f"contact {c.name}.tangent", c.tangent, (3,))
            tg = np.asarray(c.tangent, dtype=float)
            if abs(float(np.linalg.norm(tg)) - 1.0) > 1e-6 or abs(float(tg @ c.normal)) > 1e-6:
                raise InputError(
                    f"contact {c.name}.tangent", tg.tolist(), "a unit vector orthogonal to normal"
                )
    for t in p.motion_tasks:
        r = t.acceleration.shape[0] if np.ndim(t.acceleration) == 1 else -1
        _weights(t.weight, r, t.name)
        _shape(f"task {t.name}.acceleration", t.acceleration, (r,))
        _shape(f"task {t.name}.jacobian", t.jacobian, (r, nv))
        _shape(f"task {t.name}.drift", t.drift, (r,))
    for wt in p.wrench_tasks:
        r = wt.target.shape[0] if np.ndim(wt.target) == 1 else -1
        _weights(wt.weight, r, wt.name)
        _shape(f"task {wt.name}.target", wt.target, (r,))
        _shape(f"task {wt.name}.rows", wt.rows, (r, 6))
        _shape(f"task {wt.name}.about", wt.about, (3,))
        unknown = set(wt.contacts or ()) - set(names)
        if unknown:
            raise InputError(f"task {wt.name}.contacts", sorted(unknown), f"names among {names}")


def _shape(name: str, a: FloatArray, shape: tuple[int, ...], allow_inf: bool = False) -> None:
    """Raise :class:`InputError` naming ``name`` unless ``a`` has ``shape`` and finite values
    (``allow_inf``: +-inf allowed, NaN never)."""
    arr = np.asarray(a)
    if arr.shape != shape:
        raise InputError(name, arr.shape, f"shape {shape}")
    bad = np.isnan(arr) if allow_inf else ~np.isfinite(arr)
    if np.any(bad):
        raise InputError(name, "non-finite values", "finite numbers")


__all__ = [
    "PYRAMID_SHARE",
    "Assembled",
    "Contact",
    "MotionTask",
    "PackedProblem",
    "WbcProblem",
    "WbcSolution",
    "WholeBodyController",
    "WrenchTask",
    "tangent_basis",
]
