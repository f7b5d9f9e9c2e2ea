"""Strictly convex QP with one 2-D Euclidean ball per variable block, solved through its dual.

The condensed MPC of document 000 eq. (5.19) (:mod:`footfall.control.mpc`) leaves, once the
footstep is eliminated, ``minimise 1/2 v^T P v + q^T v`` s.t. ``||v_j||_2 <= 1`` for each 2-D
torque block ``v_j`` (eq. 5.19e in scaled torques). For multipliers ``lambda >= 0`` the minimiser
is ``v(lambda) = -(P + Lambda)^-1 q``; the concave dual is maximised by a projected Newton method
(Bertsekas 1982) with an Armijo search, warm-started by the caller. Slater's condition holds
(``v = 0`` is strictly feasible), so there is no duality gap; the returned ``v`` is projected onto
the balls (a move of at most the tolerance), so the constraints hold exactly.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg.lapack import dposv, dpotrf, dtrtri

from footfall._typing import FloatArray

#: stop when the dual projected gradient 1/2 (1 - ||u_j / U_max||^2) is below this (a relative
#: error of 1e-9 in the torque norms; the dual objective is only known to ~1e-13 relative, so much
#: tighter tolerances would stall the line search)
DUAL_TOL = 1e-9
#: projected Newton iteration limit (a well-posed instance takes fewer than 15)
MAX_NEWTON_ITER = 50


def solve_ball_qp(
    p: FloatArray,
    q: FloatArray,
    lam0: FloatArray | None = None,
    tol: float = DUAL_TOL,
    max_iter: int = MAX_NEWTON_ITER,
) -> tuple[FloatArray, FloatArray, int, bool]:
    """Minimise ``1/2 v^T P v + q^T v`` s.t. ``||v_j||_2 <= 1`` for each 2-D block ``v_j``.

    Projected Newton on the dual (see the module docstring). ``P`` must be positive definite.

    Args:
        p: (n, n) with n even.
        q: (n,).
        lam0: warm start for the multipliers (n / 2,), >= 0.
        tol: tolerance on the dual projected gradient ``1/2 (1 - ||v_j||^2)``.
        max_iter: iteration limit.

    Returns:
        ``(v (n,), lambda (n / 2,), iterations, converged)``; ``v`` is projected onto the balls.
    """
    n = q.shape[0]
    n_b = n // 2
    if lam0 is None:
        lam = _cold_start(p, q)
    else:
        lam = np.maximum(np.asarray(lam0, dtype=float), 0.0)
    s, v, phi = _ball_dual(p, q, lam)
    converged = False
    it = 0
    for it in range(max_iter + 1):
        vb = v.reshape(n_b, 2)
        grad = 0.5 * (1.0 - np.einsum("ij,ij->i", vb, vb))
        viol = np.where(lam > 0.0, np.abs(grad), np.maximum(-grad, 0.0))
        if viol.max() <= tol:
            converged = True
            break
        if it == max_iter:
            break
        step = _newton_step(lam, grad, vb, s)
        alpha = 1.0
        while True:
            lam_new = np.maximum(lam + alpha * step, 0.0)
            s_new, v_new, phi_new = _ball_dual(p, q, lam_new)
            decrease = float(grad @ (lam_new - lam))
            # Accept on sufficient decrease, or when the predicted decrease is below the rounding
            # error of phi (then only the gradient test above is meaningful).
            if phi_new <= phi + 1e-4 * decrease or abs(decrease) <= 1e-13 * (1.0 + abs(phi)):
                break
            if alpha < 1e-10:
                break
            alpha *= 0.5
        lam, s, v, phi = lam_new, s_new, v_new, phi_new
    vb = v.reshape(n_b, 2)
    norms = np.sqrt(np.einsum("ij,ij->i", vb, vb))
    vb = vb / np.maximum(norms, 1.0)[:, None]
    return vb.ravel(), lam, it, converged


def _cold_start(p: FloatArray, q: FloatArray) -> FloatArray:
    """Multipliers (n / 2,) of the cold start of :func:`solve_ball_qp`.

    The exact multiplier of each block alone with ``P ~ P_jj I``: ``||q_j|| / (P_jj + lambda_j) = 1``
    at the unconstrained norm ``||v_j|| = ||q_j|| / P_jj``.
    """
    n = q.shape[0]
    diag = np.arange(n)
    pjj = 0.5 * (p[diag[::2], diag[::2]] + p[diag[1::2], diag[1::2]])
    v_unc = np.linalg.solve(p, -q).reshape(n // 2, 2)
    return np.asarray(pjj * np.maximum(np.linalg.norm(v_unc, axis=1) - 1.0, 0.0))


def _ball_dual(
    p: FloatArray, q: FloatArray, lam: FloatArray
) -> tuple[FloatArray, FloatArray, float]:
    """Dual of :func:`solve_ball_qp` at ``lam``: ``(S = (P + Lambda)^-1, v = -S q, phi)`` with
    ``phi = 1/2 q^T S q + 1/2 sum(lambda)`` the dual objective to minimise.

    Raises:
        numpy.linalg.LinAlgError: ``P + Lambda`` is not positive definite.
    """
    diag = np.arange(q.shape[0])
    mat = p.copy()
    mat[diag, diag] += np.repeat(lam, 2)
    # S = (P + Lambda)^-1 = L^-T L^-1 from the Cholesky factor (LAPACK directly: the numpy
    # wrappers cost more than the arithmetic at this size).
    chol, info = dpotrf(mat, lower=1, clean=1)
    if info != 0:
        raise np.linalg.LinAlgError(f"P + Lambda not positive definite (info {info})")
    linv, info = dtrtri(chol, lower=1)
    if info != 0:
        raise np.linalg.LinAlgError(f"singular Cholesky factor (info {info})")
    s = linv.T @ linv
    v = -(s @ q)
    return s, v, float(-0.5 * (q @ v) + 0.5 * lam.sum())


def _newton_step(lam: FloatArray, grad: FloatArray, vb: FloatArray, s: FloatArray) -> FloatArray:
    """Projected Newton direction on the dual multipliers (n_b,) of :func:`solve_ball_qp`.

    Multipliers at (or within eps of) zero whose gradient pushes them down stay at zero (their
    step is the negative gradient); the free ones take the secular Newton step.
    """
    n_b = lam.shape[0]
    eps = min(1e-3, float(np.sqrt(np.sum((lam - np.maximum(lam - grad, 0.0)) ** 2))))
    bound = (lam <= eps) & (grad > 0.0)
    free = ~bound
    step = -grad
    if free.any():
        hess = np.einsum("ja,jalb,lb->jl", vb, s.reshape(n_b, 2, n_b, 2), vb)
        hf = hess[free][:, free] if bound.any() else hess
        hf.flat[:: hf.shape[0] + 1] += 1e-12 * (1.0 + np.trace(hf))
        # Secular (More-Sorensen) Newton step: Newton on 1/||v_j|| - 1, which is close to
        # linear in lambda (exactly so for P = p I), i.e. the dual Hessian system with the
        # gradient rescaled per block by 2 ||v_j||^2 / (1 + ||v_j||). Far fewer iterations than
        # Newton on the dual gradient; kept only while it is a descent direction of the dual.
        nrm = np.sqrt(1.0 - 2.0 * grad[free])
        rhs = np.stack([grad[free], grad[free] * 2.0 * nrm**2 / (1.0 + nrm)], axis=1)
        _, sol, info = dposv(hf, rhs)
        if info != 0:
            raise np.linalg.LinAlgError(f"singular dual Hessian (info {info})")
        step[free] = -sol[:, 1] if grad[free] @ sol[:, 1] > 0.0 else -sol[:, 0]
    return np.asarray(step)
