"""Compiled engine of :func:`footfall.sim.reduced.closed_loop.simulate`: the same closed loop, in numba.

Two kernels mirror the Python reference operation by operation, so both engines give the same
trajectories up to rounding:

* :func:`mpc_step` is :meth:`footfall.control.MPC.solve_theta` with the ``newton`` backend: the
  condensed MPC of document 000 eq. (5.19) at one control tick, the footstep eliminated, the torque
  discs (eq. 5.19e) handled by the projected Newton method on the dual of
  :func:`footfall.control.ball_qp.solve_ball_qp`, warm-started from the previous tick, with the same
  fallback (the last good solution shifted, or zero torque and the reference footstep) when a solve
  fails. It reads the zero-padded per-tick matrices of
  :attr:`footfall.control.mpc.CondensedMPC.padded`, which are built once by the Python code.
* :func:`walk` is the loop of ``simulate``: MPC, CoP clipped to the sole, the exact ALIP plant
  (eq. 5.2-5.7: the one-tick ZOH matrices, or the sub-step matrices when a push switches inside a
  tick), the fall test, and the double support with the moving contact (eq. 5.8-5.10). Every
  matrix, the noise, the push table and the fall constants come from the Python setup that the
  reference uses too; the kernel only runs the loop.

Everything compiled lives in this one module on purpose: numba's on-disk cache (``cache=True``) is
invalidated when the file defining a function changes, not when a compiled function it calls from
another file does, so splitting the kernels across modules could run a stale cache.

Solve times are read from the monotonic clock inside the kernel (``clock_gettime``), so the
reported MPC times are those of the compiled solve alone.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

#: CLOCK_MONOTONIC of <time.h> on Linux
_CLOCK_MONOTONIC = 1

#: return codes of :func:`ball_qp`
QP_CONVERGED = 0
QP_MAX_ITER = 1
QP_LINALG_ERROR = 2

#: slots of the integer MPC memory of :func:`mpc_step`
MEM_LAST_K = 0  # tick of the last good solution, -1 when there is none
MEM_SOLVES = 1
MEM_FALLBACKS = 2
MEM_ITERATIONS = 3  # Newton iterations of the latest solve
MEM_SIZE = 4


def _clock_ns_typer(typingctx: Any) -> tuple[Any, Any]:
    """Monotonic clock [ns] from ``clock_gettime``, called by its libc symbol name (an address
    baked into the code would not survive numba's on-disk cache)."""

    def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
        i32, i64 = ir.IntType(32), ir.IntType(64)
        timespec = ir.LiteralStructType([i64, i64])
        fnty = ir.FunctionType(i32, [i32, timespec.as_pointer()])
        fn = cgutils.get_or_insert_function(builder.module, fnty, "clock_gettime")
        ts = cgutils.alloca_once(builder, timespec)
        builder.call(fn, [ir.Constant(i32, _CLOCK_MONOTONIC), ts])
        sec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 0))
        nsec = builder.load(cgutils.gep_inbounds(builder, ts, 0, 1))
        return builder.add(builder.mul(sec, ir.Constant(i64, 1_000_000_000)), nsec)

    return types.int64(), codegen


_clock_ns: Any = intrinsic(_clock_ns_typer)


@njit(cache=True)
def monotonic_ns() -> int:
    """The kernel's clock [ns] (for tests)."""
    return _clock_ns()


@njit(cache=True)
def _pos(x: float) -> float:
    """``np.maximum(x, 0.0)``, NaN kept."""
    return 0.0 if x < 0.0 else x


@njit(cache=True)
def _clip(x: float, lo: float, hi: float) -> float:
    """Python's ``min(max(x, lo), hi)`` (NaN kept)."""
    y = lo if lo > x else x
    return hi if hi < y else y


@njit(cache=True)
def _cholesky(a: np.ndarray, n: int, chol: np.ndarray) -> bool:
    """Lower Cholesky factor of ``a[:n, :n]`` into ``chol``; False when a pivot is not > 0
    (LAPACK dpotrf's test for "not positive definite")."""
    for j in range(n):
        d = a[j, j]
        for k in range(j):
            d -= chol[j, k] * chol[j, k]
        if not d > 0.0:
            return False
        d = math.sqrt(d)
        chol[j, j] = d
        for i in range(j):
            chol[i, j] = 0.0
        for i in range(j + 1, n):
            s = a[i, j]
            for k in range(j):
                s -= chol[i, k] * chol[j, k]
            chol[i, j] = s / d
    return True


@njit(cache=True)
def _chol_solve(chol: np.ndarray, n: int, b: np.ndarray) -> None:
    """Solve ``L L^T x = b`` in place with the lower factor ``chol``."""
    for i in range(n):
        s = b[i]
        for k in range(i):
            s -= chol[i, k] * b[k]
        b[i] = s / chol[i, i]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for k in range(i + 1, n):
            s -= chol[k, i] * b[k]
        b[i] = s / chol[i, i]


@njit(cache=True)
def _evaluate(
    p: np.ndarray,
    q: np.ndarray,
    lam: np.ndarray,
    n: int,
    mat: np.ndarray,
    chol: np.ndarray,
    linv: np.ndarray,
    s: np.ndarray,
    v: np.ndarray,
) -> tuple[bool, float]:
    """Dual function of :func:`ball_qp` at ``lam``: ``S = (P + Lambda)^-1`` into ``s``,
    ``v = -S q`` into ``v``; returns ``(ok, phi)`` with ``phi = 1/2 q^T S q + 1/2 sum(lambda)``
    (the dual objective to minimise); ``ok`` is False when ``P + Lambda`` is not positive definite.
    """
    for i in range(n):
        for j in range(n):
            mat[i, j] = p[i, j]
    for b in range(n // 2):
        mat[2 * b, 2 * b] += lam[b]
        mat[2 * b + 1, 2 * b + 1] += lam[b]
    if not _cholesky(mat, n, chol):
        return False, math.nan
    # L^-1 column by column (forward substitution), then S = L^-T L^-1.
    for c in range(n):
        for i in range(c):
            linv[i, c] = 0.0
        linv[c, c] = 1.0 / chol[c, c]
        for i in range(c + 1, n):
            acc = 0.0
            for k in range(c, i):
                acc -= chol[i, k] * linv[k, c]
            linv[i, c] = acc / chol[i, i]
    for i in range(n):
        for j in range(i, n):
            acc = 0.0
            for k in range(j, n):
                acc += linv[k, i] * linv[k, j]
            s[i, j] = acc
            s[j, i] = acc
    qv = 0.0
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += s[i, j] * q[j]
        v[i] = -acc
        qv += q[i] * v[i]
    lam_sum = 0.0
    for b in range(n // 2):
        lam_sum += lam[b]
    return True, -0.5 * qv + 0.5 * lam_sum


@njit(cache=True)
def ball_qp(
    p: np.ndarray,
    q: np.ndarray,
    n: int,
    lam: np.ndarray,
    warm: bool,
    tol: float,
    max_iter: int,
    v_out: np.ndarray,
) -> tuple[int, int]:
    """Compiled :func:`footfall.control.ball_qp.solve_ball_qp`: minimise ``1/2 v^T P v + q^T v``
    s.t. ``||v_j|| <= 1`` per 2-D block, by projected (secular) Newton on the dual.

    Args:
        p: (>= n, >= n), leading (n, n) positive definite, n even.
        q: (>= n,).
        n: problem size.
        lam: multipliers (>= n / 2,): the warm start on entry when ``warm``, the result on exit.
        warm: use ``lam`` as the warm start (else the cold start of the reference).
        tol: tolerance on the dual projected gradient.
        max_iter: iteration limit.
        v_out: (>= n,) receives ``v``, projected onto the balls.

    Returns:
        ``(code, iterations)``: code :data:`QP_CONVERGED`, :data:`QP_MAX_ITER` or
        :data:`QP_LINALG_ERROR` (where the reference raises ``LinAlgError``).
    """
    n_b = n // 2
    mat = np.empty((n, n))
    chol = np.empty((n, n))
    linv = np.empty((n, n))
    s = np.empty((n, n))
    v = np.empty(n)
    s_new = np.empty((n, n))
    v_new = np.empty(n)
    lam_new = np.empty(n_b)
    grad = np.empty(n_b)
    step = np.empty(n_b)
    free = np.empty(n_b, dtype=np.int64)
    if warm:
        for b in range(n_b):
            lam[b] = _pos(lam[b])
    else:
        # Cold start: exact multiplier of each block alone with P ~ P_jj I.
        for i in range(n):
            for j in range(n):
                mat[i, j] = p[i, j]
            v[i] = -q[i]
        if not _cholesky(mat, n, chol):
            return QP_LINALG_ERROR, 0
        _chol_solve(chol, n, v)
        for b in range(n_b):
            pjj = 0.5 * (p[2 * b, 2 * b] + p[2 * b + 1, 2 * b + 1])
            nrm = math.sqrt(v[2 * b] * v[2 * b] + v[2 * b + 1] * v[2 * b + 1])
            lam[b] = pjj * _pos(nrm - 1.0)
    ok, phi = _evaluate(p, q, lam, n, mat, chol, linv, s, v)
    if not ok:
        return QP_LINALG_ERROR, 0
    converged = False
    it = 0
    for it in range(max_iter + 1):
        converged = True
        for b in range(n_b):
            g = 0.5 * (1.0 - (v[2 * b] * v[2 * b] + v[2 * b + 1] * v[2 * b + 1]))
            grad[b] = g
            viol = abs(g) if lam[b] > 0.0 else _pos(-g)
            if not viol <= tol:
                converged = False
        if converged or it == max_iter:
            break
        # Multipliers at (or within eps of) zero whose gradient pushes them down stay at zero.
        r2 = 0.0
        for b in range(n_b):
            e = lam[b] - _pos(lam[b] - grad[b])
            r2 += e * e
        r = math.sqrt(r2)
        eps = r if r < 1e-3 else 1e-3
        n_free = 0
        for b in range(n_b):
            step[b] = -grad[b]
            if not (lam[b] <= eps and grad[b] > 0.0):
                free[n_free] = b
                n_free += 1
        if n_free > 0:
            # Secular (More-Sorensen) Newton step on the free multipliers (see solve_ball_qp).
            hf = np.empty((n_free, n_free))
            trace = 0.0
            for a in range(n_free):
                ja = free[a]
                for c in range(n_free):
                    jc = free[c]
                    acc = 0.0
                    for x in range(2):
                        for y in range(2):
                            acc += v[2 * ja + x] * s[2 * ja + x, 2 * jc + y] * v[2 * jc + y]
                    hf[a, c] = acc
                trace += hf[a, a]
            for a in range(n_free):
                hf[a, a] += 1e-12 * (1.0 + trace)
            hchol = np.empty((n_free, n_free))
            if not _cholesky(hf, n_free, hchol):
                return QP_LINALG_ERROR, it
            sol0 = np.empty(n_free)
            sol1 = np.empty(n_free)
            for a in range(n_free):
                g = grad[free[a]]
                nrm = math.sqrt(1.0 - 2.0 * g)
                sol0[a] = g
                sol1[a] = g * 2.0 * (nrm * nrm) / (1.0 + nrm)
            _chol_solve(hchol, n_free, sol0)
            _chol_solve(hchol, n_free, sol1)
            descent = 0.0
            for a in range(n_free):
                descent += grad[free[a]] * sol1[a]
            for a in range(n_free):
                step[free[a]] = -sol1[a] if descent > 0.0 else -sol0[a]
        alpha = 1.0
        phi_new = phi
        while True:
            for b in range(n_b):
                lam_new[b] = _pos(lam[b] + alpha * step[b])
            ok, phi_new = _evaluate(p, q, lam_new, n, mat, chol, linv, s_new, v_new)
            if not ok:
                return QP_LINALG_ERROR, it
            decrease = 0.0
            for b in range(n_b):
                decrease += grad[b] * (lam_new[b] - lam[b])
            # Sufficient decrease, or a predicted decrease below the rounding error of phi.
            if phi_new <= phi + 1e-4 * decrease or abs(decrease) <= 1e-13 * (1.0 + abs(phi)):
                break
            if alpha < 1e-10:
                break
            alpha *= 0.5
        for b in range(n_b):
            lam[b] = lam_new[b]
        s, s_new = s_new, s
        v, v_new = v_new, v
        phi = phi_new
    for b in range(n_b):
        nrm = math.sqrt(v[2 * b] * v[2 * b] + v[2 * b + 1] * v[2 * b + 1])
        den = nrm if nrm > 1.0 else 1.0
        v_out[2 * b] = v[2 * b] / den
        v_out[2 * b + 1] = v[2 * b + 1] / den
    return (QP_CONVERGED if converged else QP_MAX_ITER), it


@njit(cache=True)
def mpc_step(
    k_s: int,
    theta: np.ndarray,
    ps: np.ndarray,
    pr: np.ndarray,
    n_b_all: np.ndarray,
    first_block: np.ndarray,
    gain: np.ndarray,
    q_map: np.ndarray,
    p_scaled: np.ndarray,
    d_theta: np.ndarray,
    d_u: np.ndarray,
    u_limits: np.ndarray,
    tol: float,
    max_iter: int,
    mem: np.ndarray,
    last_u: np.ndarray,
    last_lam: np.ndarray,
    last_foot: np.ndarray,
    torque: np.ndarray,
    foot: np.ndarray,
) -> bool:
    """One MPC solve at tick ``k_s`` (eq. 5.19): compiled ``MPC.solve_theta`` (newton backend).

    Args:
        k_s: control tick of the single support.
        theta: ``[x_measured (4), d_ref (2), x_next_ref (4)]`` (10,).
        ps: stance footstep p_i (3,) [m].
        pr: planned next footstep (3,) [m].
        n_b_all .. u_limits: the fields of :class:`footfall.control.mpc.PaddedMPC`.
        tol, max_iter: Newton tolerance and iteration limit.
        mem: integer memory (:data:`MEM_SIZE`,) kept across ticks: last good tick (-1: none),
            solve and fallback counters, iterations of this solve.
        last_u: torques [N m] of the last good solution (NU,), kept across ticks.
        last_lam: its multipliers (NU / 2,), kept across ticks.
        last_foot: its next footstep (3,) [m], kept across ticks.
        torque: receives the torque to apply now (2,) [N m].
        foot: receives the solution's next footstep (3,) [m].

    Returns:
        True when the solve failed and the fallback was returned.
    """
    n = 2 * n_b_all[k_s]
    n_b = n // 2
    last_k = mem[MEM_LAST_K]
    if last_k >= 0 and k_s <= last_k:
        last_k = -1  # a new single support: nothing to shift
        mem[MEM_LAST_K] = -1
    mem[MEM_SOLVES] += 1
    mem[MEM_ITERATIONS] = 0
    failed = False
    total = 0.0
    for i in range(theta.shape[0]):
        total += theta[i]
    u = np.empty(n)
    lam = np.zeros(n_b)
    if not math.isfinite(total):
        failed = True
    else:
        g = gain[k_s]
        worst = 0.0
        for i in range(n):
            acc = 0.0
            for c in range(theta.shape[0]):
                acc += g[i, c] * theta[c]
            u[i] = acc
        for b in range(n_b):
            vx = u[2 * b] / u_limits[0]
            vy = u[2 * b + 1] / u_limits[1]
            nrm2 = vx * vx + vy * vy
            worst = nrm2 if nrm2 > worst else worst
        if worst > 1.0:
            # A torque disc is active: the dual Newton method on the scaled problem.
            qm = q_map[k_s]
            q = np.empty(n)
            for i in range(n):
                acc = 0.0
                for c in range(theta.shape[0]):
                    acc += qm[i, c] * theta[c]
                q[i] = acc
            warm = last_k >= 0
            if warm:
                shift = first_block[k_s] - first_block[last_k]
                for b in range(n_b):
                    lam[b] = last_lam[b + shift]
            code, iters = ball_qp(p_scaled[k_s], q, n, lam, warm, tol, max_iter, u)
            mem[MEM_ITERATIONS] = iters
            if code != QP_CONVERGED:
                failed = True
            else:
                total = 0.0
                for i in range(n):
                    u[i] *= u_limits[i % 2]
                    total += u[i]
                failed = not math.isfinite(total)
    if failed:
        mem[MEM_FALLBACKS] += 1
        if last_k >= 0:
            shift = first_block[k_s] - first_block[last_k]
            torque[0] = last_u[2 * shift]
            torque[1] = last_u[2 * shift + 1]
            foot[:] = last_foot
        else:
            torque[0] = 0.0
            torque[1] = 0.0
            if math.isfinite(pr[0]) and math.isfinite(pr[1]) and math.isfinite(pr[2]):
                foot[:] = pr
            else:
                foot[:] = ps
        return True
    dt_, du_ = d_theta[k_s], d_u[k_s]
    for r in range(2):
        acc = 0.0
        for c in range(theta.shape[0]):
            acc += dt_[r, c] * theta[c]
        acc2 = 0.0
        for c in range(n):
            acc2 += du_[r, c] * u[c]
        foot[r] = ps[r] + (acc + acc2)
    foot[2] = pr[2]
    torque[0] = u[0]
    torque[1] = u[1]
    mem[MEM_LAST_K] = k_s
    last_u[:n] = u
    last_lam[:n_b] = lam
    last_foot[:] = foot
    return False


@njit(cache=True)
def _matvec(a: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    """``out = a @ x`` (``out`` may not alias ``x``)."""
    for r in range(a.shape[0]):
        acc = 0.0
        for c in range(a.shape[1]):
            acc += a[r, c] * x[c]
        out[r] = acc


@njit(cache=True)
def _matvec_add(
    a: np.ndarray, x: np.ndarray, b: np.ndarray, u: np.ndarray, out: np.ndarray
) -> None:
    """``out = a @ x + b @ u`` (``out`` may not alias ``x``)."""
    for r in range(a.shape[0]):
        acc = 0.0
        for c in range(a.shape[1]):
            acc += a[r, c] * x[c]
        acc2 = 0.0
        for c in range(b.shape[1]):
            acc2 += b[r, c] * u[c]
        out[r] = acc + acc2


@njit(cache=True)
def walk(
    x0: np.ndarray,
    foot0: np.ndarray,
    refs: tuple[np.ndarray, ...],
    mpc: tuple[np.ndarray, ...],
    newton: tuple[float, int],
    plant: tuple[np.ndarray, ...],
    pushes: tuple[np.ndarray, ...],
    errors: tuple[np.ndarray, ...],
    fall: tuple[np.ndarray, ...],
    scalars: np.ndarray,
    n_ds: int,
    out: tuple[np.ndarray, ...],
    mem: np.ndarray,
) -> tuple[int, int, bool, float, float]:
    """The closed loop of ``simulate`` over the whole walk (see the module docstring).

    Args:
        x0: initial ALIP state (4,).
        foot0: initial stance footstep (3,) [m].
        refs: per phase (n phases): planned next footstep (n, 3) [m], planned state after the
            reset (n, 4), cosine and sine of the stance heading (n,).
        mpc: the :class:`footfall.control.mpc.PaddedMPC` fields ``(n_b .. u_limits)``.
        newton: Newton tolerance and iteration limit.
        plant: true-plant matrices ``(Ad_tick (4, 4), Bd_tick (4, 2), Ad_sub, Bd_sub,
            Ad_ds_tick (8, 8), Ad_ds_sub (8, 8), Bd_ds_sub (8, 2))``.
        pushes: push torque per tick row and sub-step (rows, n_sub, 2) [N m]; per row, any push /
            the same push on every sub-step.
        errors: state-estimate noise per single-support tick (n M, 4), landing error per step
            (n, 2) [m].
        fall: ``exp(-omega T_r)`` per tick (M,), and the fall-test constants d0, d_span (4,) [m].
        scalars: ``[dt, dt_ds, t_ds, m g, 1 / (m z_H omega), sole half-length, half-width]``.
        n_ds: double-support ticks.
        out: preallocated sample arrays (zeros) ``t, stance, single, com, cop, cop_offset,
            torque_cmd, torque, saturated`` filled up to the returned sample count, then the
            landed footsteps (n + 1, 3), the solve times (n M,) [s] and the final state (4,).
        mem: MPC integer memory (:data:`MEM_SIZE`,), last good tick -1.

    Returns:
        ``(samples, footsteps, fell, fall_time, t)``.
    """
    p_refs = refs[0]
    out_feet, out_x = out[9], out[11]
    n = p_refs.shape[0]
    m_ticks = fall[0].shape[0]
    nu = mpc[2].shape[1]
    # MPC memory across ticks (last good torques, multipliers, footstep) and its outputs.
    solver = (np.zeros(nu), np.zeros(nu // 2), np.zeros(3), np.zeros(2), np.zeros(3))
    x = x0.copy()
    # work space: x_new, u, u_p, s_aug, s_new, theta
    work = (np.empty(4), np.empty(2), np.empty(2), np.empty(8), np.empty(8), np.empty(10))
    out_feet[0] = foot0
    n_feet = 1
    fell = False
    fall_time = math.nan
    j = 0
    n_solve = 0
    t = 0.0
    for i in range(n):
        stance = out_feet[n_feet - 1]
        j, t, n_solve, fell = _single_support(
            i, j, t, n_solve, x, stance, refs, mpc, newton, plant, pushes, errors[0], fall,
            scalars, n_ds, out, mem, solver, work
        )  # fmt: skip
        if fell:
            fall_time = t
            break
        row = i * (m_ticks + n_ds) + m_ticks  # push row of the first double-support tick
        j, t = _double_support(
            i, j, t, x, stance, solver[4], errors[1], plant, pushes, row, scalars, n_ds, out, work
        )
        n_feet += 1
        if not _finite4(x):
            fell, fall_time = True, t
            break
    out_x[:] = x
    return j, n_feet, fell, fall_time, t


@njit(cache=True)
def _single_support(
    i: int,
    j: int,
    t: float,
    n_solve: int,
    x: np.ndarray,
    stance: np.ndarray,
    refs: tuple[np.ndarray, ...],
    mpc: tuple[np.ndarray, ...],
    newton: tuple[float, int],
    plant: tuple[np.ndarray, ...],
    pushes: tuple[np.ndarray, ...],
    noise: np.ndarray,
    fall: tuple[np.ndarray, ...],
    scalars: np.ndarray,
    n_ds: int,
    out: tuple[np.ndarray, ...],
    mem: np.ndarray,
    solver: tuple[np.ndarray, ...],
    work: tuple[np.ndarray, ...],
) -> tuple[int, float, int, bool]:
    """Phase ``i``'s single support from sample ``j``, time ``t``, solve ``n_solve``: per tick
    the MPC on the noisy state, the clipped CoP, the true plant (``x`` in place), the fall test.

    Returns:
        ``(j, t, n_solve, fell)`` after the last tick (the tick of the fall when it fell).
    """
    p_refs, x_refs, cos_h, sin_h = refs
    theta, out_solve_time = work[5], out[10]
    m_ticks = fall[0].shape[0]
    n_b_all, first_block, gain, q_map, p_scaled, d_theta, d_u, u_limits = mpc
    last_u, last_lam, last_foot, torque, foot = solver
    tol, max_iter = newton
    out_t, out_stance, out_single, out_com, out_cop = out[0], out[1], out[2], out[3], out[4]
    out_cop_off, out_tau_cmd, out_tau, out_sat = out[5], out[6], out[7], out[8]
    ad_t, bd_t, ad_s, bd_s = plant[0], plant[1], plant[2], plant[3]
    push_tab, push_any, push_const = pushes
    decay, d0, d_span = fall
    mg, kxi, hx, hy = scalars[3], scalars[4], scalars[5], scalars[6]
    x_new, u, u_p = work[0], work[1], work[2]
    n_sub = push_tab.shape[1]
    cth, sth = cos_h[i], sin_h[i]
    theta[4] = p_refs[i, 0] - stance[0]
    theta[5] = p_refs[i, 1] - stance[1]
    theta[6:] = x_refs[i]
    for k in range(m_ticks):
        for r in range(4):
            theta[r] = x[r] + noise[i * m_ticks + k, r]
        t0 = _clock_ns()
        mpc_step(
            k, theta, stance, p_refs[i], n_b_all, first_block, gain, q_map, p_scaled, d_theta,
            d_u, u_limits, tol, max_iter, mem, last_u, last_lam, last_foot, torque, foot
        )  # fmt: skip
        out_solve_time[n_solve] = (_clock_ns() - t0) * 1e-9
        n_solve += 1
        ox, oy, cx, cy, wx, wy = _sole_cop(torque[0], torque[1], cth, sth, mg, hx, hy)
        u[0], u[1] = mg * wy, -mg * wx
        out_t[j], out_stance[j], out_single[j] = t, i, True
        out_com[j, 0], out_com[j, 1] = stance[0] + x[0], stance[1] + x[1]
        out_cop[j, 0], out_cop[j, 1] = stance[0] + wx, stance[1] + wy
        out_cop_off[j, 0], out_cop_off[j, 1] = cx, cy
        out_tau_cmd[j, 0], out_tau_cmd[j, 1] = torque[0], torque[1]
        out_tau[j, 0], out_tau[j, 1] = u[0], u[1]
        out_sat[j] = cx != ox or cy != oy
        j += 1
        jt = i * (m_ticks + n_ds) + k
        if not push_any[jt]:
            _matvec_add(ad_t, x, bd_t, u, x_new)
            x[:] = x_new
        elif push_const[jt]:
            u_p[0], u_p[1] = u[0] + push_tab[jt, 0, 0], u[1] + push_tab[jt, 0, 1]
            _matvec_add(ad_t, x, bd_t, u_p, x_new)
            x[:] = x_new
        else:
            for q in range(n_sub):
                u_p[0], u_p[1] = u[0] + push_tab[jt, q, 0], u[1] + push_tab[jt, q, 1]
                _matvec_add(ad_s, x, bd_s, u_p, x_new)
                x[:] = x_new
        t += scalars[0]
        # Fall test on the true state.
        if not _finite4(x) or _beyond(x, cth, sth, kxi, decay[k], d0, d_span):
            return j, t, n_solve, True
    return j, t, n_solve, False


@njit(cache=True)
def _sole_cop(
    t0: float, t1: float, cth: float, sth: float, mg: float, hx: float, hy: float
) -> tuple[float, float, float, float, float, float]:
    """CoP of the torque command ``(t0, t1)`` in the foot frame (heading cosine ``cth``, sine
    ``sth``), ``(ox, oy)``, clipped to the sole half-sizes, ``(cx, cy)``, and the clipped CoP
    back in the world frame relative to the foot, ``(wx, wy)`` [m]."""
    cwx, cwy = -t1 / mg, t0 / mg
    ox, oy = cth * cwx + sth * cwy, -sth * cwx + cth * cwy
    cx, cy = _clip(ox, -hx, hx), _clip(oy, -hy, hy)
    wx, wy = cth * cx - sth * cy, sth * cx + cth * cy
    return ox, oy, cx, cy, wx, wy


@njit(cache=True)
def _beyond(
    x: np.ndarray,
    cth: float,
    sth: float,
    kxi: float,
    e: float,
    d0: np.ndarray,
    d_span: np.ndarray,
) -> bool:
    """Fall bound: the instantaneous capture point ``(x + kxi L_y, y - kxi L_x)`` in the foot
    frame lies beyond ``d0 + d_span e`` in one of the directions (+x, -x, +y, -y)."""
    gx, gy = x[0] + kxi * x[3], x[1] - kxi * x[2]
    fx, fy = cth * gx + sth * gy, -sth * gx + cth * gy
    return (
        fx > d0[0] + d_span[0] * e
        or -fx > d0[1] + d_span[1] * e
        or fy > d0[2] + d_span[2] * e
        or -fy > d0[3] + d_span[3] * e
    )


@njit(cache=True)
def _finite4(x: np.ndarray) -> bool:
    """All four entries of the ALIP state are finite."""
    return (
        math.isfinite(x[0]) and math.isfinite(x[1]) and math.isfinite(x[2]) and math.isfinite(x[3])
    )


@njit(cache=True)
def _double_support(
    i: int,
    j: int,
    t: float,
    x: np.ndarray,
    stance: np.ndarray,
    next_foot: np.ndarray,
    place_err: np.ndarray,
    plant: tuple[np.ndarray, ...],
    pushes: tuple[np.ndarray, ...],
    row: int,
    scalars: np.ndarray,
    n_ds: int,
    out: tuple[np.ndarray, ...],
    work: tuple[np.ndarray, ...],
) -> tuple[int, float]:
    """Phase ``i``'s double support from sample ``j`` at time ``t``: the contact point moves
    linearly to the new foot (eq. 5.8-5.10), which is recorded as landed footstep ``i + 1``; ``x``
    ends relative to it. ``row`` is the push-table row of its first tick. Returns the next sample
    index and the time."""
    ad_ds, ad_dss, bd_dss = plant[4], plant[5], plant[6]
    push_tab, push_any = pushes[0], pushes[1]
    out_t, out_stance, out_com, out_cop, out_feet = out[0], out[1], out[3], out[4], out[9]
    s_aug, s_new = work[3], work[4]
    dt_ds, t_ds = scalars[1], scalars[2]
    px, py = next_foot[0] + place_err[i, 0], next_foot[1] + place_err[i, 1]
    dx, dy = px - stance[0], py - stance[1]
    s_aug[:4] = x
    s_aug[4], s_aug[5] = 0.0, 0.0
    s_aug[6], s_aug[7] = dx / t_ds, dy / t_ds
    for k in range(n_ds):
        out_t[j], out_stance[j] = t, i
        out_com[j, 0], out_com[j, 1] = stance[0] + s_aug[0], stance[1] + s_aug[1]
        out_cop[j, 0], out_cop[j, 1] = stance[0] + s_aug[4], stance[1] + s_aug[5]
        j += 1
        jt = row + k
        if not push_any[jt]:
            _matvec(ad_ds, s_aug, s_new)
            s_aug[:] = s_new
        else:
            for q in range(push_tab.shape[1]):
                _matvec_add(ad_dss, s_aug, bd_dss, push_tab[jt, q], s_new)
                s_aug[:] = s_new
        t += dt_ds
    x[:] = s_aug[:4]
    x[0] -= dx
    x[1] -= dy
    n_feet = i + 1
    out_feet[n_feet, 0], out_feet[n_feet, 1], out_feet[n_feet, 2] = px, py, next_foot[2]
    return j, t
